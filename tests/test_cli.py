"""Command line: JSON fields (a user-facing interface) and clear errors."""

import json
import subprocess
import sys

import pytest

from hinfnav.cli import main


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "hinfnav", *args], capture_output=True, text=True, timeout=300)


def test_help_lists_the_commands():
    out = run_cli("--help")
    assert out.returncode == 0
    for cmd in ("simulate", "design", "reproduce"):
        assert cmd in out.stdout


def test_reproduce_takes_a_paper(capsys):
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    assert "--paper" in capsys.readouterr().out


def test_simulate_json_fields():
    out = run_cli("simulate", "--filter", "published", "--json", "--runs", "2", "--seed", "3")
    assert out.returncode == 0, out.stderr
    rep = json.loads(out.stdout)
    for key in ("filter", "maneuver", "delta", "noise", "runs", "window_s", "rms_pos_m", "rms_vel_mps"):
        assert key in rep
    assert rep["filter"] == "published" and rep["maneuver"] is True and rep["runs"] == 2
    assert len(rep["rms_pos_m"]) == 3 and len(rep["rms_vel_mps"]) == 3
    # Table 1, H∞ column: 0.2 m and 0.8 m/s (one significant digit)
    assert all(0.15 <= v < 0.25 for v in rep["rms_pos_m"])
    assert all(0.75 <= v < 0.85 for v in rep["rms_vel_mps"])


def test_simulate_options_reach_the_simulation(capsys):
    assert main(["simulate", "--no-maneuver", "--delta", "0.5", "--noise", "uniform", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["maneuver"] is False and rep["delta"] == 0.5 and rep["noise"] == "uniform"


def test_simulate_table_output(capsys):
    assert main(["simulate", "--no-maneuver"]) == 0
    out = capsys.readouterr().out
    assert "position (m)" in out and "velocity (m/s)" in out


@pytest.mark.parametrize(
    "args, message",
    [
        (["simulate", "--runs", "0"], "--runs must be >= 1"),
        (["simulate", "--filter", "nope"], "invalid choice: 'nope'"),
        (["simulate", "--noise", "pink"], "invalid choice: 'pink'"),
        (["simulate", "--delta", "inf"], "--delta must be finite"),
        (["simulate", "--delta", "-3"], "delta must be > -1"),
        (["design", "--delta-bar", "-0.1"], "--delta-bar must be a finite number >= 0"),
        (["reproduce", "--paper", "nope"], "invalid choice: 'nope'"),
    ],
)
def test_bad_input_gives_a_clear_message_not_a_traceback(args, message):
    out = run_cli(*args)
    assert out.returncode == 2
    assert message in out.stderr
    assert "Traceback" not in out.stderr
