"""Command-line edges and strict outputs (issue 36, items 7 and 8).

Expected: exit status 2 and one line naming the option for an option that does
not apply; 130 and one line for Ctrl-C; strict JSON (no NaN/Infinity tokens,
parsed with a ``parse_constant`` that refuses them) for every JSON writer.
"""

import json
import subprocess
import sys

import numpy as np
import pytest

from hinfnav import cli
from hinfnav.io.outputs import dumps_strict, write_json


def _refuse(token):
    raise AssertionError(f"non-strict JSON token {token}")


def test_version_flag():
    out = subprocess.run([sys.executable, "-m", "hinfnav", "--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.startswith("hinfnav ")


@pytest.mark.parametrize("argv, words", [
    (["design", "--system", "examples/double_integrator.toml", "--delta-bar", "0.1"], "--delta-bar does not apply"),
    (["design", "--system", "examples/double_integrator.toml", "--points", "5"], "--points does not apply"),
    (["design", "--recertify", "d.json", "--solver", "SCS"], "--solver does not apply"),
    (["design", "--recertify", "d.json", "--form", "observer"], "--form does not apply"),
])
def test_design_options_that_do_not_apply_are_refused(argv, words, capsys):
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1


def test_ctrl_c_is_one_line(monkeypatch, capsys):
    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "_cmd_reproduce", interrupted)
    assert cli.main(["reproduce", "--paper", "sun2011", "--out", "nowhere"]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "interrupted" in err[0]


def test_json_writers_are_strict(tmp_path):
    data = {"rms": np.array([1.0, np.nan]), "worst": float("inf"), "n": np.int64(3)}
    path = tmp_path / "s.json"
    write_json(path, data)
    back = json.loads(path.read_text(), parse_constant=_refuse)
    assert back == {"rms": [1.0, None], "worst": None, "n": 3}
    assert json.loads(dumps_strict(data), parse_constant=_refuse) == back


def _sigint_ignored(pid):
    """Whether SIGINT is ignored in process ``pid`` (the SigIgn mask of /proc, bit 2)."""
    import signal
    from pathlib import Path

    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("SigIgn:"):
            return bool(int(line.split()[1], 16) & (1 << (signal.SIGINT - 1)))
    return False


def _start_as_in_a_terminal(argv, root, env):
    """Start ``python -m hinfnav argv`` in its own process group with SIGINT at its default, as a shell would.

    A test runner started in the background (``nohup … &`` from a non-interactive shell) has SIGINT ignored, and
    an ignored signal is inherited: without the reset the command never sees a Ctrl-C and runs to its end (the
    cause of the xfail this test carried: measured, a campaign whose main process had SigIgn bit 2 set ran on
    through five SIGINTs to its process group; with it at its default, one SIGINT stopped it in 5 s).
    """
    import signal

    return subprocess.Popen([sys.executable, "-m", "hinfnav", *argv], cwd=root, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _interrupt(proc, presses=5, every=20.0):
    """Ctrl-C to the process group (what the terminal does), again while it still runs; killed after that."""
    import os
    import signal

    for _ in range(presses):
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=every)
            break
        except subprocess.TimeoutExpired:
            pass
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    return proc.communicate(timeout=60)


def _one_line(err):
    # multiprocessing's resource tracker may add its own 2-line leak warning (a semaphore of the stopped cluster)
    ours = [line for line in err.splitlines() if "resource_tracker" not in line and "warnings.warn" not in line]
    return len(ours) == 1 and "interrupted" in ours[0] and "Traceback" not in err


@pytest.mark.slow
def test_ctrl_c_during_a_campaign_is_one_line(tmp_path):
    # a real campaign on a LocalCluster of 2 workers, interrupted after its start: the workers ignore Ctrl-C
    # (they start with it ignored), the command stops in one line with status 130 and leaves no partial output
    # (no results.csv, no temporary file; the finished cells stay, written whole, for a resume)
    import os
    import time
    from pathlib import Path

    import psutil

    root = Path(__file__).resolve().parents[1]
    spec = tmp_path / "c.toml"
    spec.write_text('runs = 20000\nbatch_size = 50\n[grid]\nscenario = "sun2011"\nestimator = ["ekf", "published"]\n'
                    'duration_s = [100.0]\nrms_window_s = [[0, 100.0]]\n[windows]\nall = [0, 100.0]\n')
    # the NumPy path: the compiled one may finish these runs before the interrupt arrives
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg", HINFNAV_BACKEND="numpy")
    out = tmp_path / "out"
    proc = _start_as_in_a_terminal(["campaign", str(spec), "--out", str(out), "--workers", "2"], root, env)
    assert not _sigint_ignored(proc.pid)
    deadline = time.monotonic() + 120  # until the cluster is up: its 2 worker processes (spawned)
    while time.monotonic() < deadline and proc.poll() is None and sum(
            "spawn_main" in " ".join(c.cmdline()) for c in psutil.Process(proc.pid).children(recursive=True)) < 2:
        time.sleep(0.2)
    time.sleep(5.0)
    # a Ctrl-C that lands while the cluster is still starting is ignored (documented): _interrupt presses again
    _, err = _interrupt(proc)
    assert proc.returncode == 130, err
    assert _one_line(err), err
    assert not (out / "results.csv").exists()
    assert not [p.name for p in out.rglob("*") if p.name.endswith(".tmp") or ".tmp" in p.name]


@pytest.mark.slow
def test_ctrl_c_during_reproduce_is_one_line(tmp_path):
    # reproduce sun2011 interrupted while it computes: status 130, one line, and no summary.json (published only
    # when complete)
    import os
    import time
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg")
    out = tmp_path / "r"
    proc = _start_as_in_a_terminal(["reproduce", "--paper", "sun2011", "--out", str(out), "--jobs", "1"], root, env)
    time.sleep(12.0)  # imports done, computing
    assert proc.poll() is None
    _, err = _interrupt(proc)
    assert proc.returncode == 130, err
    assert _one_line(err), err
    assert not (out / "summary.json").exists()


@pytest.mark.slow
def test_reproduce_with_one_run_writes_strict_json(tmp_path):
    # one run: the spread statistics are undefined (NaN), written as null (15 s of CPU)
    from hinfnav.papers import reproduce

    reproduce("sun2011", tmp_path / "r1", runs=1, jobs=1, progress=False)
    text = (tmp_path / "r1" / "summary.json").read_text()
    json.loads(text, parse_constant=_refuse)
    assert "null" in text
