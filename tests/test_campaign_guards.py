"""Campaign folders and limits (issue 22): locks, another spec, orphan files, workers, bounds before work.

Every campaign here runs Sun 2011's chaser shortened to 20 s (200 steps) with a few runs, as in
``tests/test_campaign.py``; the processes started here are tiny campaigns too.
"""

import functools
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest

import hinfnav.papers  # noqa: F401 - registers Sun 2011's scenario and estimators
from hinfnav.campaign import Campaign, load_campaign, run_campaign
from hinfnav.cli import main
from hinfnav.core.exceptions import InputError
from hinfnav.io.outputs import atomic_output_dir, lock_path, output_lock
from hinfnav.papers.sun2011 import Scenario

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
WINDOWS = {"all": [0.0, 20.0]}


def _spec(runs=3, **grid):
    full = {"scenario": "sun2011", "estimator": ["ekf"], "maneuver": [True], "duration_s": [20.0],
            "rms_window_s": [[0.0, 20.0]], **grid}
    return Campaign(grid=full, runs=runs, batch_size=3, windows=WINDOWS, seed=1)


def _toml(path, runs, duration=20.0, estimators=("ekf",)):
    names = ", ".join(f'"{e}"' for e in estimators)
    path.write_text(f'runs = {runs}\nbatch_size = 50\n[grid]\nscenario = "sun2011"\nestimator = [{names}]\n'
                    f'maneuver = [true, false]\nduration_s = [{duration}]\nrms_window_s = [[0, {duration}]]\n'
                    f'[windows]\nall = [0, {duration}]\n')
    return path


def _campaign_cli(spec, out, *extra):
    return [sys.executable, "-m", "hinfnav", "campaign", str(spec), "--out", str(out), *extra]


def _wait_for(predicate, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


# -- locks -------------------------------------------------------------------------------------------------------

def test_two_campaign_processes_into_one_folder_one_refuses(tmp_path):
    spec = _toml(tmp_path / "c.toml", runs=200, duration=100.0)  # 2 cells of about half a second each
    out = tmp_path / "out"
    first = subprocess.Popen(_campaign_cli(spec, out, "--scheduler", "serial"), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=ENV)
    try:
        assert _wait_for(lambda: (out / "campaign.json").exists() or first.poll() is not None, 60)
        assert first.poll() is None, first.communicate()
        # the second process (this one) with the same spec, while the first works: refused, nothing computed twice
        with pytest.raises(InputError, match="another process is writing into"):
            run_campaign(load_campaign(spec), client="serial", out_dir=out, progress=False)
        stdout, stderr = first.communicate(timeout=120)
    finally:
        first.kill()
    assert first.returncode == 0, stderr[-2000:]
    assert "2 cells (2 computed, 0 reused)" in stdout
    assert not lock_path(out).exists()  # released and removed by its holder


def test_output_lock_is_the_os_lock_not_a_pid_file(tmp_path):
    out = tmp_path / "results"
    # a lock file naming a live process (pid 1 is always alive) but held by none: the PID file refused it as
    # "another process (pid 1)"; an OS-level lock is free as soon as no process holds it (PID reuse, other hosts)
    lock_path(out).write_text("1")
    with atomic_output_dir(out) as tmp:
        (tmp / "a.txt").write_text("1")
    assert (out / "a.txt").read_text() == "1" and not lock_path(out).exists()
    # held by another process: refused, for reproduce's atomic folders and campaign folders alike
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time\nfrom hinfnav.io.outputs import output_lock\n"
                               f"with output_lock({str(out)!r}):\n    print('held', flush=True)\n    time.sleep(60)\n"],
                              stdout=subprocess.PIPE, text=True, env=ENV)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(InputError, match="another process is writing"):
            with atomic_output_dir(out):
                pass
        with pytest.raises(InputError, match="another process is writing"):
            run_campaign(_spec(), client="serial", out_dir=out, progress=False)
        holder.send_signal(signal.SIGKILL)  # the OS releases the lock of a killed holder: no stale lock
        holder.wait(timeout=10)
        with output_lock(out):
            pass
    finally:
        holder.kill()


def test_folder_holding_another_spec_is_refused_naming_both(tmp_path):
    out = tmp_path / "out"
    first = run_campaign(_spec(runs=2), client="serial", out_dir=out, progress=False)
    assert first.attrs["computed"] == 1
    with pytest.raises(InputError, match=r"holds another campaign.*runs: 2 there, 3 here"):
        run_campaign(_spec(runs=3), client="serial", out_dir=out, progress=False)
    with pytest.raises(InputError, match=r"grid\.delta: None there, \[0\.0, 1\.0\] here"):
        run_campaign(_spec(runs=2, delta=[0.0, 1.0]), client="serial", out_dir=out, progress=False)
    # the refused runs touched nothing: the folder still says what it holds, and the same spec resumes it
    assert json.loads((out / "campaign.json").read_text())["spec"]["runs"] == 2
    assert run_campaign(_spec(runs=2), client="serial", out_dir=out, progress=False).attrs["reused"] == 1


def test_sigkill_during_a_local_cluster_campaign_leaves_no_worker_and_resume_no_tmp(tmp_path):
    spec = _toml(tmp_path / "c.toml", runs=300, duration=100.0)  # 2 cells of about a second each
    out = tmp_path / "out"
    parent = subprocess.Popen(_campaign_cli(spec, out, "--workers", "1"), stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, env=ENV)
    try:
        proc = psutil.Process(parent.pid)
        # killed while its worker computes the second cell (the first one is written)
        assert _wait_for(lambda: any((out / "cells").glob("*.json")) or parent.poll() is not None, 90)
        workers = proc.children(recursive=True)
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=10)
    finally:
        parent.kill()
    assert workers  # the LocalCluster's worker (and multiprocessing's helper) processes
    gone, alive = psutil.wait_procs(workers, timeout=5)
    for p in alive:
        p.kill()
    assert not alive, [p.cmdline()[:4] for p in alive]  # no worker outlives its parent by 5 s
    # a write killed between its temporary file and the rename leaves an orphan (planted here: SIGKILL cannot be
    # aimed between two system calls); the resume removes it, and computes only the missing cell
    (out / "cells" / ".0123456789abcdef0123.json.99999.tmp").write_text("{")
    (out / ".results.csv.99999.tmp").write_text("")
    resumed = run_campaign(load_campaign(spec), client="serial", out_dir=out, progress=False)
    assert resumed.attrs["reused"] >= 1 and resumed.attrs["reused"] + resumed.attrs["computed"] == 2
    assert not list(out.rglob("*.tmp")) and not lock_path(out).exists()


# -- limits and validation before work -----------------------------------------------------------------------------

def test_huge_runs_and_grids_are_refused_within_5_s_before_any_work(tmp_path):
    for spec, field in ((_spec(runs=10**12), "runs"),
                        (_spec(delta=list(np.linspace(0.0, 1.0, 200_000))), "grid")):
        start = time.perf_counter()
        with pytest.raises(InputError, match=f"^{field}.*exceed.*limit"):
            run_campaign(spec, client="serial", out_dir=tmp_path / "big", progress=False)
        assert time.perf_counter() - start < 5.0
        assert not (tmp_path / "big").exists()  # before any work: not even the folder
    # the limits are stated maxima that an explicit option lifts; the time estimate then refuses 10**12 runs
    with pytest.raises(InputError, match=r"estimator steps.*limit steps"):
        _spec(runs=10**12).cells(limits={"runs": 10**13})
    with pytest.raises(InputError, match=r"batch_size.*bytes per batch"):  # 10**6 runs × 201 steps × 27 numbers
        Campaign(grid=_spec().grid, runs=10**6, batch_size=10**6, windows=WINDOWS).cells()
    with pytest.raises(InputError, match="limits: unknown limit 'speed'"):
        _spec().cells(limits={"speed": 1})


def test_validation_tries_each_value_once_not_every_grid_point(monkeypatch):
    calls = {"n": 0}
    real = Scenario.truth_model

    @functools.wraps(real)  # the same signature: the conditions are read from it
    def counted(self, *args, **kwargs):
        calls["n"] += 1
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Scenario, "truth_model", counted)
    # 2 000 grid points: 40 δ × 50 masses (settings); a product of keys is tried value by value
    spec = _spec(delta=list(np.linspace(0.0, 1.0, 40)), mass=list(np.linspace(400.0, 600.0, 50)))
    start = time.process_time()  # CPU time: the machine running the tests may be shared
    assert len(spec.cells()) == 2000
    # first settings: every δ (40); each other mass: its first δ (49). Before issue 22: 2 000 (one per point)
    assert calls["n"] == 40 + 49
    assert time.process_time() - start < 5.0


def test_every_spec_error_is_found_before_any_cell_runs(tmp_path, capsys):
    out = tmp_path / "out"
    # bad estimator options: before issue 22 an empty table with the message in attrs["errors"]
    bad = Campaign(grid=_spec().grid, runs=3, windows=WINDOWS, estimator_options={"ekf": {"no_such_option": 1}})
    with pytest.raises(InputError, match=r"estimator_options\.ekf: cannot build 'ekf'.*no_such_option"):
        run_campaign(bad, client="serial", out_dir=out, progress=False)
    # a filter designed for T = 0.1 s on a scenario sampled at 0.3 s: refused, naming the estimator and dt
    with pytest.raises(InputError, match=r"grid\.estimator \('published'\).*dt = 0\.3"):
        run_campaign(_spec(estimator=["ekf", "published"], dt=[0.1, 0.3]), client="serial", out_dir=out,
                     progress=False)
    assert not out.exists()
    # the command line says what is wrong, and not "run the command again"
    path = _toml(tmp_path / "bad.toml", runs=3)
    path.write_text(path.read_text() + '[estimator_options.ekf]\nno_such_option = 1\n')
    assert main(["campaign", str(path), "--out", str(out), "--scheduler", "serial"]) == 2
    err = capsys.readouterr().err
    assert "estimator_options.ekf" in err and "again" not in err and "Traceback" not in err


def test_latin1_spec_file_names_the_file_and_the_encoding(tmp_path, capsys):
    path = tmp_path / "latin.toml"
    path.write_bytes(_toml(tmp_path / "c.toml", runs=3).read_bytes() + "# d\xe9calage\n".encode("latin-1"))
    with pytest.raises(InputError, match=r"latin\.toml is not UTF-8 text.*0xe9"):
        load_campaign(path)
    assert main(["campaign", str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial"]) == 2
    assert "not UTF-8" in capsys.readouterr().err


def test_limit_option_of_the_command_line(tmp_path, capsys):
    path = _toml(tmp_path / "c.toml", runs=2_000_000)
    assert main(["campaign", str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial"]) == 2
    assert "runs = 2000000 exceeds the limit" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["campaign", str(path), "--out", str(tmp_path / "out"), "--limit", "runs"])


# -- what a new user tripped on ------------------------------------------------------------------------------------

def test_registered_estimators_in_a_fresh_process():
    code = ("import hinfnav as hn\nfrom hinfnav.estimators import registered_estimators\n"
            "print(','.join(registered_estimators())); print(','.join(hn.registered_estimators()))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=ENV, timeout=120)
    assert res.returncode == 0, res.stderr[-2000:]
    first, second = (set(line.split(",")) for line in res.stdout.split())
    # the papers register these (hinfnav/papers/*/__init__.py); before issue 22 the list was empty
    assert {"published", "ekf", "hbf", "recursive_hinf", "yang2020_fused"} <= first and first == second


def test_readme_and_docstring_show_the_main_guard():
    readme = (ROOT / "README.md").read_text()
    block = readme[readme.index("## Campaigns"):].split("```python", 1)[1].split("```", 1)[0]
    assert "run_campaign" in block and 'if __name__ == "__main__":' in block
    assert 'if __name__ == "__main__":' in run_campaign.__doc__
