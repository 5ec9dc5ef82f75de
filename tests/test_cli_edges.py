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


@pytest.mark.slow
@pytest.mark.xfail(reason="open (issue 36): on the merged main of stop 29 the 2-worker campaign ran to its end "
                   "(exit 0) through five SIGINTs to its process group on this machine, whichever backend; "
                   "passed on the issue-36 branch alone; cause not yet found", strict=False)
def test_ctrl_c_during_a_campaign_is_one_line(tmp_path):
    # a real campaign on a LocalCluster of 2 workers, interrupted after its start: the workers ignore Ctrl-C
    # (they start with it ignored), the command stops in one line with status 130
    import os
    import signal
    import time
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = tmp_path / "c.toml"
    spec.write_text('runs = 20000\nbatch_size = 50\n[grid]\nscenario = "sun2011"\nestimator = ["ekf", "published"]\n'
                    'duration_s = [100.0]\nrms_window_s = [[0, 100.0]]\n[windows]\nall = [0, 100.0]\n')
    # the NumPy path (the default when this test was written): the compiled one finishes these runs before the
    # interrupt arrives, and many more runs make the in-flight work outlast the test
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg", HINFNAV_BACKEND="numpy")
    proc = subprocess.Popen([sys.executable, "-m", "hinfnav", "campaign", str(spec), "--out", str(tmp_path / "out"),
                             "--workers", "2"], cwd=root, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True,
                            # as in a terminal: a runner started in the background (nohup … &) ignores SIGINT, and an
                            # ignored signal is inherited, so the command would never see the Ctrl-C
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    import psutil

    deadline = time.monotonic() + 120  # until the cluster is up: 2 nannies and their 2 workers
    while len(psutil.Process(proc.pid).children(recursive=True)) < 4 and time.monotonic() < deadline:
        time.sleep(0.2)
    time.sleep(5.0)
    os.killpg(proc.pid, signal.SIGINT)  # what the terminal does: the whole process group
    # a Ctrl-C that lands while the cluster is still starting is ignored (documented): the user presses it again
    for _ in range(5):
        try:
            proc.wait(timeout=20)
            break
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    ours = [line for line in err.splitlines() if "resource_tracker" not in line and "warnings.warn" not in line]
    # multiprocessing's resource tracker may add its own 2-line leak warning (a semaphore of the stopped cluster)
    assert len(ours) == 1 and "interrupted" in ours[0] and "Traceback" not in err, err


@pytest.mark.slow
def test_reproduce_with_one_run_writes_strict_json(tmp_path):
    # one run: the spread statistics are undefined (NaN), written as null (15 s of CPU)
    from hinfnav.papers import reproduce

    reproduce("sun2011", tmp_path / "r1", runs=1, jobs=1, progress=False)
    text = (tmp_path / "r1" / "summary.json").read_text()
    json.loads(text, parse_constant=_refuse)
    assert "null" in text
