"""``python -m hinfnav design --objective h2`` (issue 12): the fields it prints and their relations."""

import json

import pytest

from hinfnav.cli import main
from hinfnav.papers.sun2011 import format_mixed_design_report

TODAY = ("delta_bar", "form", "gamma", "lmi_gamma", "verified_norm", "worst_delta", "spectral_radius", "solver",
         "method", "solve_time_s", "total_time_s", "dt", "A_F", "B_F", "C_F", "deltas_checked", "attempts")


def _run(capsys, *argv):
    assert main(["design", "--delta-bar", "0.05", "--objective", "h2", *argv]) == 0
    return capsys.readouterr().out


def test_design_h2_with_gamma_json(capsys, tmp_path):
    out = json.loads(_run(capsys, "--gamma", "0.4", "--json", "--save", str(tmp_path / "mixed.json")))
    assert set(TODAY) <= set(out)
    assert out["objective"] == "h2" and out["gamma_bound"] == 0.4 and out["lmi_gamma"] == 0.4
    # certified relations (not fitted numbers): sampled ≤ certified, certified γ within the bound
    assert out["verified_norm"] <= out["gamma"] <= 0.4
    assert out["h2_verified"] <= out["h2_bound"]
    assert out["h2_bound"] <= out["h2_lmi"] * (1 + 1e-6)
    assert (tmp_path / "mixed.json").exists() and out["saved_to"].endswith("mixed.json")


def test_design_h2_front_reports_the_knee(capsys):
    out = json.loads(_run(capsys, "--points", "2", "--json"))
    assert len(out["front"]) == 3 and out["front"][-1]["gamma_bound"] is None
    # issue 22: the knee is a row of the front (the H2 row included) chosen on its certified γ and ν
    assert out["knee"] in (0, 1, 2) and out["knee_gamma"] == out["front"][out["knee"]]["gamma"]
    assert out["knee_gamma_bound"] == out["front"][out["knee"]]["gamma_bound"]
    assert out["gamma_star"] < out["front"][0]["gamma_bound"]
    text = format_mixed_design_report(out)  # what the command prints without --json
    assert "knee (Kneedle)" in text and "certified ν" in text


@pytest.mark.parametrize("argv, word", [(["--form", "observer"], "observer"), (["--points", "1"], "points")])
def test_design_h2_bad_options(capsys, argv, word):
    assert main(["design", "--objective", "h2", "--gamma", "0.4", *argv]) == 2
    assert word in capsys.readouterr().err


def test_gamma_needs_objective_h2(capsys):
    assert main(["design", "--gamma", "0.4"]) == 2
    assert "--objective h2" in capsys.readouterr().err
