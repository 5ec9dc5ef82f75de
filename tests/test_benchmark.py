"""The cross-paper benchmark (issue 18): a bound in every cell, the table and summary, small sizes.

The full benchmark is ``python -m hinfnav reproduce --paper benchmark`` (README: its measured time).
"""

import json

import numpy as np
import pytest

import hinfnav.papers  # noqa: F401  (registers every paper's scenario and estimators)
from hinfnav.analysis.pcrb import posterior_crb, rms_bound
from hinfnav.campaign.registry import build_scenario
from hinfnav.campaign.runner import run_campaign
from hinfnav.campaign.spec import Campaign
from hinfnav.papers.benchmark import SCENARIOS, cell_bound, cell_kalman_limit, reproduce
from hinfnav.systems.hill import measurement_matrix


def test_pcrb_equals_the_riccati_limit_on_a_linear_gaussian_cell():
    # Sun 2011's chaser without maneuver, delta = 0, Gaussian noise: linear-Gaussian. Its posterior CRB (Monte Carlo
    # over 5 simulated truths) has Jacobians Φ and C that are the same on every run, so the Monte Carlo standard
    # error of the expectations is exactly zero and the recursion is the Kalman covariance recursion; from P0 = 0
    # it converges geometrically to the Riccati limit. Over 100–1000 s (steps 1000–10000 at T = 0.1 s), the
    # tolerance 1e-3 (relative) covers the remaining transient (measured 2e-5) and nothing else.
    sc = build_scenario("sun2011")
    model = sc.truth_model(maneuver=False)
    sys_, meas = model.system, model.measurement
    truth_x = np.broadcast_to(model.x0, (5, model.n_steps + 1, 6))
    diag = posterior_crb(truth_x, sys_.Phi, measurement_matrix(), sys_.B @ sys_.B.T, meas.D @ meas.D.T,
                         np.zeros((6, 6)), diagonal_only=True)
    rms = rms_bound(diag, 1000)
    lim = cell_kalman_limit(sc, maneuver=False, delta=0.0)
    assert np.sqrt(np.mean(rms[:3] ** 2)) == pytest.approx(lim["pos_m"], rel=1e-3)
    assert np.sqrt(np.mean(rms[3:] ** 2)) == pytest.approx(lim["vel_mps"], rel=1e-3)


def test_the_kalman_filter_reaches_the_bound_within_its_interval():
    # The same cell with the Kalman filter told the (zero) input: E[RMS²] equals the Riccati limit², so the
    # ratio's 95 % interval over 20 runs (the campaign's, from the runs' mean squares) must contain 1.
    spec = Campaign(name="kf", runs=20, batch_size=20, windows={"steady": (100.0, 1000.0)},
                    grid={"scenario": "sun2011", "estimator": ["ekf_known_input"], "maneuver": [False]})
    cell = run_campaign(spec, client="serial", progress=False).attrs["cells"][0]
    bound = cell_bound(build_scenario("sun2011"), {"maneuver": False}, "gaussian", {"steady": (100, 1000)},
                       ("position", "velocity"))
    for q in ("position", "velocity"):
        g = cell["statistics"]["windows"]["steady"]["groups"][q]
        b = bound["windows"]["steady"][q]
        assert g["rms_ci95_low"] / b <= 1.0 <= g["rms_ci95_high"] / b


def test_benchmark_summary_on_a_small_grid(tmp_path):
    chosen = ["ekf_converted", "model_ekf"]
    summary = reproduce(tmp_path, runs=3, client="serial", progress=False, scenarios=["shi2018"], bound_runs=4,
                        grids={"shi2018": {"maneuver": [True]}}, estimators={"shi2018": chosen})
    assert summary["scenarios"] == ["shi2018"] and summary["estimators"]["shi2018"] == chosen
    cells = summary["cells"]
    assert len(cells) == len(summary["estimators"]["shi2018"]) * 2 * 2  # estimators x noises x quantities
    for c in cells:
        assert {"scenario", "estimator", "conditions", "noise", "rms", "bound", "ratio", "ratio_low", "ratio_high",
                "nees"} <= set(c)
        assert c["bound_kind"] == "pcrb" and c["ratio"] == pytest.approx(c["rms"] / c["bound"], rel=1e-12)
        assert c["ratio_low"] <= c["ratio"] <= c["ratio_high"]
    # every other registered estimator is listed with its reason
    unfit = summary["non_fitting"]["shi2018"]
    assert "attitude2018" in unfit["aekf"] and "sun2011" in unfit["designed"]
    assert {b["quantity"] for b in summary["best"]} == set(SCENARIOS["shi2018"]["quantities"])
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk["non_fitting"]["shi2018"] == unfit and (tmp_path / "heatmap_shi2018.png").exists()
    assert "## Which estimator wins where" in (tmp_path / "table.md").read_text()
