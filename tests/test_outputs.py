"""Outputs a user can trust: atomic and locked reproduce folders, provenance, design files.

Expected behaviour (issue 8): an interrupted or concurrent ``reproduce`` never
leaves a folder that mixes two runs; bad ``--out`` is refused before any work;
a design saved for one sampling time is refused at another.
"""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

import hinfnav as hn
from hinfnav.papers import sun2011
from hinfnav.cli import FILTER_CHOICES, NOISE_CHOICES, PAPER_CHOICES, SOLVER_CHOICES, main
from hinfnav.io.outputs import MARKER, atomic_output_dir, check_output_dir

REPRO = [sys.executable, "-m", "hinfnav", "reproduce", "--paper", "sun2011", "--runs", "2"]


def _consistent(folder):
    """summary.json, table1.csv and the figures come from one run (same seed in each provenance)."""
    summary = json.loads((folder / "summary.json").read_text())
    seed = summary["provenance"]["seed"]
    head = [line for line in (folder / "table1.csv").read_text().splitlines() if line.startswith("# seed:")]
    assert head == [f"# seed: {seed}"]
    for i in range(2, 8):
        assert (folder / f"fig{i}.png").stat().st_size > 0
    return seed


def test_cli_choices_are_the_packages_own_lists():
    from hinfnav.lmi import SOLVERS
    from hinfnav.noise import NOISE_NAMES
    from hinfnav.papers import PAPERS
    from hinfnav.papers.sun2011 import FILTER_NAMES

    from hinfnav.estimators import registered_estimators

    assert set(FILTER_NAMES) <= set(FILTER_CHOICES)
    assert set(FILTER_CHOICES) == set(registered_estimators(sun2011.Scenario()))
    assert tuple(NOISE_CHOICES) == NOISE_NAMES
    assert tuple(SOLVER_CHOICES) == SOLVERS
    from hinfnav.papers import SELECTIONS

    assert tuple(PAPER_CHOICES) == tuple(SELECTIONS) + tuple(PAPERS)


def test_design_save_then_simulate_and_refusal_at_another_T(tmp_path, capsys):
    path = tmp_path / "d.json"
    assert main(["design", "--delta-bar", "0.3", "--save", str(path), "--json"]) == 0
    saved = json.loads(capsys.readouterr().out)
    assert saved["provenance"]["hinfnav"] == hn.__version__
    assert main(["simulate", "--design", str(path), "--json", "--runs", "2"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["filter"] == "design" and rep["provenance"]["runs"] == 2
    # the same design run from Python gives the same numbers (identity)
    d = sun2011.load_design(path)
    assert d.gamma == saved["gamma"]
    with pytest.raises(hn.InputError, match="T = 0.1 s"):
        sun2011.load_design(path, scenario=sun2011.Scenario(dt=1.0))
    edited = json.loads(path.read_text())
    edited["system"]["B"][0][0] *= 2
    path.write_text(json.dumps(edited))
    with pytest.raises(hn.InputError, match="fingerprint"):
        sun2011.load_design(path)


@pytest.mark.parametrize("bad", ["", "a_file", "a_file/sub"])
def test_out_is_checked_before_any_work(tmp_path, bad):
    (tmp_path / "a_file").write_text("x")
    target = "" if bad == "" else str(tmp_path / bad)
    with pytest.raises(hn.InputError, match="out"):
        check_output_dir(target)


def test_a_folder_with_foreign_files_is_not_replaced(tmp_path):
    (tmp_path / "mine.txt").write_text("keep me")
    with pytest.raises(hn.InputError, match="did not write"):
        with atomic_output_dir(tmp_path):
            pass
    assert (tmp_path / "mine.txt").read_text() == "keep me"


def test_atomic_folder_replaces_whole_or_not_at_all(tmp_path):
    out = tmp_path / "res"
    with atomic_output_dir(out) as tmp:
        (tmp / "a.txt").write_text("1")
    assert (out / "a.txt").read_text() == "1" and (out / MARKER).exists()
    with pytest.raises(RuntimeError):
        with atomic_output_dir(out) as tmp:
            (tmp / "a.txt").write_text("2")
            raise RuntimeError("interrupted")
    assert (out / "a.txt").read_text() == "1"  # the previous complete folder is untouched
    assert not (tmp_path / ".res.tmp").exists() and not (tmp_path / ".res.lock").exists()


def test_interrupted_and_concurrent_reproduce_never_mix_two_runs(tmp_path):
    out = tmp_path / "results"
    env = dict(os.environ, MPLBACKEND="Agg")
    first = subprocess.run(REPRO + ["--seed", "1", "--out", str(out)], capture_output=True, text=True, env=env,
                           timeout=300)
    assert first.returncode == 0, first.stderr[-2000:]
    assert _consistent(out) == 1
    # interrupted: kill a run with seed 2 while it works; the seed-1 folder must stay whole
    proc = subprocess.Popen(REPRO + ["--seed", "2", "--out", str(out)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=env)
    lock = tmp_path / ".results.lock"
    for _ in range(300):
        if lock.exists():
            break
        time.sleep(0.05)
    time.sleep(1.0)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert _consistent(out) == 1
    # concurrent: two runs at once (the stale lock of the killed one is taken over); one may be refused,
    # and whatever is left is whole
    procs = [subprocess.Popen(REPRO + ["--seed", str(s), "--out", str(out)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env) for s in (3, 4)]
    results = [p.communicate(timeout=300) + (p.returncode,) for p in procs]
    codes = [r[2] for r in results]
    assert 0 in codes, results
    for _, err, code in results:
        assert code == 0 or "another process" in err, err[-2000:]
    assert _consistent(out) in (3, 4)
