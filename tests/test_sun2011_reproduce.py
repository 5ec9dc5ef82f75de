"""Reproduction of Table 1 and Figs 2-7: smoke tests against the paper's values, and the regression.

Runs the command-line job once, at the paper's 100 Monte Carlo runs and seed 0 (issue 21: its cost is the
per-step overhead of the 10 001-step runs, measured the same for 8 runs as for 100, so the one run serves
both), and checks the files, the JSON fields, the paper's numbers, determinism, and that
``reproduce --seed 0`` gives the numbers it gave before the package was reshaped.

Expected values of the regression: ``tests/data/sun2011_summary_seed0_runs100.json``, the
``summary.json`` written by ``python -m hinfnav reproduce --seed 0`` (100 runs)
at commit 7c2aec2, before issue 7's restructuring; the 52 interval bounds
(``mc_ci95_*``) re-recorded at issue 22, when the intervals became Student t
(t_{0.975, 99} = 1.984 instead of 1.96; nothing else moved). Tolerance 1e-9
relative (issue 7); the comparison is ``benchmarks/compare_summaries.py``.

The rows of the filters designed here by an SDP solver (``hinf_designed``, ``hinf_observer``) are
compared at 1e-5 relative instead: the interior-point solver's iterates depend on the BLAS kernels
of the machine, and the same code gives those designs to about 1e-6 on different CPUs (measured:
at most 2.7e-6 relative between two x86-64 machines, every other leaf within 1e-9).
"""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from hinfnav.papers.sun2011 import PAPER_TABLE1, reproduce, table1
from hinfnav.plotting.save import read_provenance

RUNS = 100
ROOT = Path(__file__).resolve().parents[1]
EXPECTED = ROOT / "tests" / "data" / "sun2011_summary_seed0_runs100.json"


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    d = tmp_path_factory.mktemp("results")
    summary = reproduce(d, seed=0, runs=RUNS, progress=False)
    return d, summary


def _comparator():
    spec = importlib.util.spec_from_file_location("compare_summaries", ROOT / "benchmarks" / "compare_summaries.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.compare


def test_reproduce_seed0_matches_the_numbers_before_the_reshaping(out):
    d, _ = out
    new = json.loads((d / "summary.json").read_text())
    old = json.loads(EXPECTED.read_text())
    problems, worst, n, _ = _comparator()(old, new, 1e-9)
    assert n > 250
    solver_rows = ("/hinf_designed/", "/hinf_observer/")
    strict = [p for p in problems if not any(key in p for key in solver_rows)]
    assert not strict, "\n".join(strict[:20])
    loose, _, _, _ = _comparator()(old, new, 1e-5)
    assert not loose, "\n".join(loose[:20])


def test_every_file_is_produced(out):
    d, _ = out
    for i in range(2, 8):
        for ext in ("png", "pdf"):
            f = d / f"fig{i}.{ext}"
            assert f.is_file() and f.stat().st_size > 5000, f
    for name in ("table1.csv", "table1.md", "summary.json"):
        assert (d / name).is_file()
    assert "paper: H∞" in (d / "table1.md").read_text()


def test_summary_json_fields(out):
    d, _ = out
    s = json.loads((d / "summary.json").read_text())
    for case in ("no_maneuver", "maneuver"):
        for key in ("ekf", "hinf_published", "hinf_designed", "paper_ekf", "paper_hinf"):
            assert {"pos_m", "vel_mps"} <= set(s["table1"][case][key]), (case, key)
    assert {"pos_m", "vel_mps"} <= set(s["kalman_limit"])


@pytest.mark.parametrize("case", ["no_maneuver", "maneuver"])
def test_published_hinf_matches_table1_within_25_percent(out, case):
    # paper, Table 1: H∞ 0.2 m and 0.8 m/s in both cases; issue tolerance "about 25 %"
    _, s = out
    cell = s["table1"][case]["hinf_published"]
    assert cell["pos_m"] == pytest.approx(PAPER_TABLE1[case]["hinf"]["pos_m"], rel=0.25)
    assert cell["vel_mps"] == pytest.approx(PAPER_TABLE1[case]["hinf"]["vel_mps"], rel=0.25)


def test_designed_filter_with_maneuver_and_its_failure_without(out):
    # measured finding (notebook 04): the LMI-optimal filter (δ̄ = 0.05) is not in observer form,
    # so its error carries the plant's transient from x0: with maneuver it navigates (position
    # below the published filter's 0.2 m, velocity below 1 m/s); without maneuver, where the
    # design has no guarantee, its velocity error exceeds 5 m/s
    _, s = out
    assert s["designed_filter"]["gamma"] > 0
    man = s["table1"]["maneuver"]["hinf_designed"]
    assert man["pos_m"] < 0.2 and man["vel_mps"] < 1.0
    assert s["table1"]["no_maneuver"]["hinf_designed"]["vel_mps"] > 5.0


def test_observer_form_filter_navigates_in_both_cases(out):
    # extension (notebook 03 §8): the robust filter constrained to observer form has an error
    # independent of the trajectory; its noise-only stationary std is 0.085 m and 0.015 m/s
    # with maneuver (Lyapunov, kalman.lti_error_covariance) and 0.024 m/s told u = 0 without;
    # from the paper's initial state it stays below 0.1 m and 0.06 m/s in both cases
    _, s = out
    for case in ("no_maneuver", "maneuver"):
        cell = s["table1"][case]["hinf_observer"]
        assert cell["pos_m"] < 0.1 and cell["vel_mps"] < 0.06, (case, cell)
    assert s["observer_filter"]["gamma"] >= s["designed_filter"]["gamma"] - 1e-6


def test_ekf_without_maneuver_sits_at_the_kalman_limit(out):
    # the EKF with the true Q, R is the optimal linear filter here: its RMS equals the
    # steady-state Riccati value (independent computation) within 15 % for one run of 9000 samples
    _, s = out
    cell = s["table1"]["no_maneuver"]["ekf"]
    lim = s["kalman_limit"]
    assert cell["pos_m"] == pytest.approx(lim["pos_m"], rel=0.15)
    assert cell["vel_mps"] == pytest.approx(lim["vel_mps"], rel=0.15)


def test_paper_ekf_numbers_are_below_the_kalman_limit(out):
    # stated plainly in notebook 04: Table 1's EKF 0.04 m and 0.001 m/s are below the
    # steady-state Kalman error for the stated noise (≈ 0.063 m and ≈ 0.022 m/s)
    _, s = out
    assert PAPER_TABLE1["no_maneuver"]["ekf"]["pos_m"] < s["kalman_limit"]["pos_m"]
    assert PAPER_TABLE1["no_maneuver"]["ekf"]["vel_mps"] < 0.1 * s["kalman_limit"]["vel_mps"]


def test_ekf_fails_in_the_first_500_s_with_maneuver(out):
    # paper, §4 and Fig 4: the EKF does not converge in the first 500 s with maneuver.
    # Measured: over 100-500 s the unknown-input EKF is 5x (position) and 50x (velocity) worse
    # than the same EKF told the thrust (which sits at the Kalman limit), its velocity error is
    # worse than the H∞ filter's 0.8 m/s, and after 500 s it recovers to within 2x of the limit
    # in position.
    _, s = out
    early = s["ekf_maneuver_windows"]["100-500 s"]
    late = s["ekf_maneuver_windows"]["500-1000 s"]
    hinf = s["table1"]["maneuver"]["hinf_published"]
    known = s["table1"]["maneuver"]["ekf_known_input"]
    assert early["pos_m"] > 5 * known["pos_m"]
    assert early["vel_mps"] > 50 * known["vel_mps"]
    assert early["vel_mps"] > hinf["vel_mps"]
    assert late["pos_m"] < 2 * s["kalman_limit"]["pos_m"]


def test_same_seed_same_numbers():
    a = table1(runs=3, seed=5)
    b = table1(runs=3, seed=5)
    for case in a.cells:
        for key in a.cells[case]:
            assert a.cells[case][key] == b.cells[case][key]
    c = table1(runs=3, seed=6)
    assert c.cells["maneuver"]["hinf_published"]["pos_m"] != a.cells["maneuver"]["hinf_published"]["pos_m"]
    np.testing.assert_equal(a.ekf_windows, b.ekf_windows)


def test_every_figure_file_carries_the_summarys_provenance(out):
    # issue 23: this run's files read back (PNG text chunk, PDF Info) hold summary.json's provenance
    prov = json.loads((out[0] / "summary.json").read_text())["provenance"]
    files = sorted(out[0].glob("*.p[nd][gf]"))  # every figure of the run, each format
    assert prov["paper"] == "sun2011" and len(files) >= 12 and [read_provenance(f) for f in files] == [prov] * len(files)
