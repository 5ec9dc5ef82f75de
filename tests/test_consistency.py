"""Consistency, never silent (issue 17 item 6): NEES and NIS with χ² bounds, and the divergence flag.

Closed-form checks of the bounds and of the normalized errors, the Kalman
filter's NEES on a linear-Gaussian cell of Sun 2011's chaser (streaming,
full histories, the command line and a campaign cell agree), and strong
tracking on a track with 7 % outliers: it runs away to ~1e100 m with
finite numbers, and is flagged ``diverged`` with a warning.
"""

import json

import numpy as np
import pytest
from scipy.stats import chi2

import hinfnav
import hinfnav.papers
from hinfnav.campaign import Campaign, run_campaign
from hinfnav.cli import main
from hinfnav.core.exceptions import FilterDivergenceWarning, InputError
from hinfnav.estimators.augmented import AugmentedInputKF, AugmentedInputSTKF
from hinfnav.metrics import (
    DIVERGENCE_FACTOR,
    ConsistencyAccumulator,
    chi2_bounds,
    consistency,
    monte_carlo_statistics,
    normalized_squared,
)
from hinfnav.papers.shi2018.scenario import ContaminatedNoise
from hinfnav.papers.shi2018.scenario import Scenario as ShiScenario
from hinfnav.papers.sun2011 import Scenario
from hinfnav.sim import SimulationResult
from hinfnav.systems.attitude import attitude_state_spec

#: Sun 2011's chaser, free motion, cut to 300 s; the Kalman filter's covariance is steady after ~50 s.
LINEAR = Scenario(duration_s=300.0, rms_window_s=(50.0, 300.0))
WINDOW = {"steady": (50.0, 300.0)}
RUNS = 20


# -- closed forms ----------------------------------------------------------------------------------------------


def test_chi2_bounds_closed_form():
    # χ²(2) is exponential with mean 2: its p-quantile is −2 ln(1 − p) (closed form); one run, n = 2
    lo, hi = chi2_bounds(2, 1)
    assert lo == pytest.approx(-2 * np.log(0.975), rel=1e-12) and hi == pytest.approx(-2 * np.log(0.025), rel=1e-12)
    # N runs of a 1-dof statistic: N·mean ~ χ²(N); N = 2 is χ²(2) again, divided by N (closed form)
    lo, hi = chi2_bounds(1, 2)
    assert lo == pytest.approx(-np.log(0.975), rel=1e-12) and hi == pytest.approx(-np.log(0.025), rel=1e-12)
    # N = 50 runs of a 6-dof NEES, against scipy directly (C3)
    assert chi2_bounds(6, 50) == pytest.approx(tuple(chi2.ppf([0.025, 0.975], 300) / 50), rel=1e-14)
    for bad in ({"dof": 0}, {"runs": 0}, {"level": 1.5}):
        with pytest.raises(InputError, match=next(iter(bad))):
            chi2_bounds(**{"dof": 3, "runs": 1, **bad})


def test_normalized_squared_by_hand():
    # eᵀP⁻¹e by hand: diag(1, 4) with e = (1, 2) gives 1 + 4/4 = 2; [[2, 1], [1, 2]] with e = (1, 1):
    # P⁻¹ = [[2, −1], [−1, 2]]/3, so (2 − 1 − 1 + 2)/3 = 2/3
    e = np.array([[1.0, 2.0], [1.0, 1.0]])
    P = np.array([np.diag([1.0, 4.0]), [[2.0, 1.0], [1.0, 2.0]]])
    assert normalized_squared(e, P) == pytest.approx([2.0, 2.0 / 3.0], rel=1e-14)
    # a covariance shared by the runs (stride 0, inverted once) gives the per-run numbers
    shared = np.broadcast_to(P, (3,) + P.shape)
    assert np.array_equal(normalized_squared(np.broadcast_to(e, (3, 2, 2)), shared),
                          normalized_squared(np.broadcast_to(e, (3, 2, 2)), np.ascontiguousarray(shared)))
    # a singular or non-finite covariance gives NaN, not an exception or a number
    out = normalized_squared(e, np.array([np.zeros((2, 2)), np.full((2, 2), np.nan)]))
    assert np.all(np.isnan(out))
    with pytest.raises(InputError, match="C must be square"):
        normalized_squared(e, np.eye(3))


def test_attitude_nees_uses_the_states_own_error():
    # x̂ rotated from x by a about z: the multiplicative error is (0, 0, a) rad in 9 error coordinates, while
    # the stored state has 10; with P = σ² I the NEES is a²/σ² (hand computation)
    a, sigma = 0.01, 0.02
    x = np.zeros((1, 3, 10))
    x[..., 3] = 1.0  # q = (0, 0, 0, 1), scalar last
    xhat = x.copy()
    xhat[..., 2], xhat[..., 3] = -np.sin(a / 2), np.cos(a / 2)  # q̂ = q ⊗ rotation by −a about z
    P = np.broadcast_to(sigma**2 * np.eye(9), (1, 3, 9, 9))
    res = SimulationResult(t=np.arange(3.0), x=x, xhat=xhat, u=np.zeros((1, 3, 0)), y=np.zeros((1, 3, 1)), P=P,
                           settings={"filter": "hand"}, state=attitude_state_spec(), xhat0=xhat[0, 0])
    stats, summary = consistency(res)
    assert stats.n == 9 and stats.nees == pytest.approx(np.full(3, (a / sigma) ** 2), rel=1e-9)
    assert summary["nis_dof"] is None and "no NIS" in summary["notes"][0] and not summary["diverged"]


# -- a linear-Gaussian cell: the Kalman filter is consistent ----------------------------------------------------


@pytest.fixture(scope="module")
def kalman_cell():
    return monte_carlo_statistics(LINEAR, "ekf_known_input", windows=WINDOW, runs=RUNS, seed=7, maneuver=False)


def test_kalman_filter_nees_and_nis_inside_their_bounds(kalman_cell):
    s = kalman_cell.consistency_summary
    w = s["windows"]["steady"]
    # (C3) with N = 20 runs: n = 6 state components, m = 3 position channels
    assert s["nees_dof"] == 6 and s["nis_dof"] == 3
    assert s["nees_bounds"][0] < w["nees"] < s["nees_bounds"][1]
    assert s["nis_bounds"][0] < w["nis"] < s["nis_bounds"][1]
    # the run-averaged NEES/NIS is inside its 95 % bounds at 95 % of the steps for a consistent filter; the
    # 2500 steps of the window are correlated (a few hundred independent ones), so the tolerance is ±0.05
    assert w["nees_inside"] == pytest.approx(0.95, abs=0.05)
    assert w["nis_inside"] == pytest.approx(0.95, abs=0.05)
    assert not s["diverged"] and s["diverged_runs"] == 0 and s["notes"] == []


def test_streaming_consistency_equals_the_full_histories(kalman_cell):
    # independent path: hinfnav.simulate keeps every history; NEES and NIS per step agree to rounding
    res = hinfnav.simulate(LINEAR, "ekf_known_input", runs=RUNS, seed=7, maneuver=False, batch_size=7)
    stats, summary = consistency(res, windows=WINDOW)
    np.testing.assert_allclose(stats.nees, kalman_cell.consistency.nees, rtol=1e-12)
    np.testing.assert_allclose(stats.nis, kalman_cell.consistency.nis, rtol=1e-12)
    mine, ref = summary["windows"]["steady"], kalman_cell.consistency_summary["windows"]["steady"]
    assert {k: mine[k] for k in ("nees", "nis")} == pytest.approx({k: ref[k] for k in ("nees", "nis")}, rel=1e-12)
    assert (mine["nees_inside"], mine["nis_inside"]) == (ref["nees_inside"], ref["nis_inside"])


def test_simulate_json_reports_consistency(capsys):
    assert main(["simulate", "--filter", "ekf_known_input", "--no-maneuver", "--runs", "3", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    lo, hi = rep["nees_bounds"]
    assert (lo, hi) == pytest.approx(tuple(chi2.ppf([0.025, 0.975], 18) / 3), rel=1e-14)  # (C3), scipy directly
    assert lo < rep["nees"] < hi and 0.8 <= rep["nees_inside"] <= 1 and rep["nis"] > 0 and rep["diverged"] is False
    # a fixed-gain filter carries no covariance: null fields, and the reason
    assert main(["simulate", "--filter", "published", "--no-maneuver", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["nees"] is None and rep["nees_bounds"] is None and rep["nis"] is None and rep["diverged"] is False
    assert any("no covariance" in note for note in rep["consistency_notes"])


def test_campaign_cell_carries_consistency():
    spec = Campaign(grid={"scenario": "sun2011", "estimator": ["ekf_known_input", "published"], "maneuver": [False],
                          "noise": ["gaussian"], "duration_s": [60.0], "rms_window_s": [[10.0, 60.0]]},
                    runs=6, batch_size=4, windows={"steady": [10.0, 60.0]}, seed=1)
    table = run_campaign(spec, client="serial", progress=False)
    kf, lti = table.attrs["cells"]
    c = kf["statistics"]["consistency"]
    assert kf["diverged"] is False and kf["status"] == "ok"
    assert c["nees_bounds"] == pytest.approx(list(chi2.ppf([0.025, 0.975], 36) / 6), rel=1e-14)
    assert c["nees_bounds"][0] < c["windows"]["steady"]["nees"] < c["nees_bounds"][1]
    assert lti["statistics"]["consistency"]["windows"]["steady"]["nees"] is None
    rows = table[(table["quantity"] == "nees") & (table["statistic"] == "mean")]
    assert len(rows) == 2 and rows["value"].iloc[0] == c["windows"]["steady"]["nees"] and np.isnan(rows["value"].iloc[1])
    # the EKF not told the thrust, under the maneuver: its covariance is far too small for its error (measured mean
    # NEES ~3e4 against a bound of ~10), so the cell is flagged and the campaign warns; its runs did not blow up
    with pytest.warns(FilterDivergenceWarning, match="ekf in cell .* beyond 10 times its 95 % upper bound"):
        table = run_campaign(Campaign(**{**spec.as_dict(), "grid": {**spec.grid, "estimator": ["ekf"],
                                                                     "maneuver": [True]}}),
                             client="serial", progress=False)
    (cell,) = table.attrs["cells"]
    assert cell["diverged"] is True and cell["status"] == "ok" and cell["statistics"]["consistency"]["diverged_runs"] == 0
    assert table[table["statistic"] == "diverged"]["value"].tolist() == [1.0]


# -- strong tracking on an outlier track: flagged, never silent ---------------------------------------------------


def _outlier_track():
    """Shi 2018's track (range/azimuth/elevation sensor) cut to 200 s, with 7 % outliers of 10 σ."""
    sc = ShiScenario().replace(duration_s=200.0, maneuver_time_s=100.0, rms_window_s=(100.0, 200.0))
    # the class of the registered ekf_augmented_thrust_st (ρ = 0.95, β = 1), on this track: the unknown input
    # (acceleration, m/s²) as a random walk of density 1e-8 (m/s²)²/s, initial σ 1e-3 m/s²
    kw = dict(Q_input=1e-8 * np.eye(3), P0=sc.P0, P0_input=1e-6 * np.eye(3))
    return sc, AugmentedInputSTKF(sc.system(), sc.sensor(), name="strong_tracking", **kw), \
        AugmentedInputKF(sc.system(), sc.sensor(), name="plain", **kw)


def test_strong_tracking_on_outliers_is_flagged_diverged():
    sc, st, plain = _outlier_track()
    noise = ContaminatedNoise(eps=0.07, ratio=10.0)  # (1 − ε) N(0, σ²) + ε N(0, (10σ)²): 7 % outliers
    with pytest.warns(FilterDivergenceWarning, match="strong_tracking.*initial error scale"), np.errstate(all="ignore"):
        stats = monte_carlo_statistics(sc, st, windows={"late": sc.rms_window_s}, runs=4, seed=0, measurement_noise=noise)
    s = stats.consistency_summary
    # the failure of the issue: the estimates stay finite while the error runs away (here beyond 1e90 m)
    assert np.all(np.isfinite(stats["late"].max_abs)) and stats["late"].max_abs[:3].max() > 1e90
    assert s["diverged"] and s["diverged_runs"] >= 1 and stats.consistency.max_growth > DIVERGENCE_FACTOR
    assert s["diverged_level"] == 2
    # the same data without strong tracking: no runaway; but told R without the outliers its covariance is too
    # small (mean NEES about 7x n), which issue 35 flags at the bound: level 1, not 2
    with pytest.warns(FilterDivergenceWarning, match="plain.*over-confident"):
        ref = monte_carlo_statistics(sc, plain, windows={"late": sc.rms_window_s}, runs=4, seed=0, measurement_noise=noise)
    r = ref.consistency_summary
    assert r["diverged"] and r["diverged_level"] == 1 and r["diverged_runs"] == 0 and ref["late"].max_abs[:3].max() < 1e3


def test_accumulator_counts_every_run_once():
    acc = ConsistencyAccumulator(3)
    acc.add(np.arange(2.0), np.zeros((2, 2, 1)), np.ones((2, 2, 1, 1)))
    with pytest.raises(InputError, match="2 runs of 3"):
        acc.result()
