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


def _option(parser, command, flag):
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    return next(a for a in sub._actions if flag in a.option_strings)


def test_cli_choices_are_read_from_the_registries():
    # issue 23: the options' choices are the package's registries and lists (not re-typed), and each command
    # accepts exactly those names (argparse checks by the same object), with the options' spelling unchanged
    from hinfnav.cli import _parser
    from hinfnav.estimators.registry import registered_estimators
    from hinfnav.lmi.solve import SOLVERS
    from hinfnav.noise import NOISE_NAMES
    from hinfnav.papers import PAPERS, SELECTIONS
    from hinfnav.papers.sun2011 import FILTER_NAMES, Scenario

    parser = _parser()
    expected = {
        ("simulate", "--filter"): registered_estimators(Scenario()),
        ("simulate", "--noise"): NOISE_NAMES,
        ("design", "--solver"): SOLVERS,
        ("reproduce", "--paper"): tuple(SELECTIONS) + tuple(PAPERS),
    }
    for (command, flag), names in expected.items():
        assert tuple(_option(parser, command, flag).choices) == tuple(names), (command, flag)
    assert set(FILTER_NAMES) < set(expected["simulate", "--filter"])  # Sun's own and the other papers' that fit
    for name in expected["simulate", "--filter"]:
        assert parser.parse_args(["simulate", "--filter", name]).filter == name
    with pytest.raises(SystemExit):
        parser.parse_args(["simulate", "--filter", "designed_observer_x"])


def test_building_the_parser_reads_no_registry():
    # `python -m hinfnav --help` stays fast: the registries are read when a value is checked, not before
    code = ("import sys; from hinfnav.cli import _parser; _parser(); "
            "print([m for m in ('hinfnav.papers', 'hinfnav.lmi.solve', 'hinfnav.noise', 'cvxpy') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "[]", out.stdout + out.stderr


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
