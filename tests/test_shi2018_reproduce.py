"""Reproduction of Shi & Wang (2018): files and fields of ``reproduce``, determinism, and the findings (issue 9, item 4).

The findings are asserted with wide, stated margins on reduced Monte Carlo
sets; the full numbers (100 runs) are in ``summary.json`` and notebook 12.
"""

import csv
import json

import numpy as np
import pytest

from hinfnav.papers.shi2018 import (
    PAPER_RESULTS,
    Scenario,
    filter_summary,
    paired_gap,
    reproduce,
    riccati_accuracy,
    run_case,
)
from hinfnav.papers.shi2018.reproduce import _run_jobs
from hinfnav.plotting.save import read_provenance

TINY = Scenario(duration_s=40.0, maneuver_time_s=20.0, rms_window_s=(10.0, 40.0))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("shi2018")
    summary = reproduce(out, runs=3, seed=0, progress=False, scenario=TINY, workers=1)
    return out, summary


def test_reproduce_writes_every_file(written):
    out, _ = written
    for name in ("fig3", "fig4", "fig5", "fig6", "mixture_position", "mixture_velocity", "maneuver_reaction", "sweeps"):
        for ext in ("png", "pdf"):
            assert (out / f"{name}.{ext}").stat().st_size > 1000, name
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [(r["case"], r["filter"]) for r in rows][:2] == [("gaussian", "EKF"), ("gaussian", "HBF")]
    assert len(rows) == 7
    assert "3.59" in (out / "results.md").read_text()  # the paper's EKF number beside ours


def test_summary_fields(written):
    out, summary = written
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["gaussian"]["hbf"]["mc_mean_pos_m"] == summary["gaussian"]["hbf"]["mc_mean_pos_m"]
    for case in ("gaussian", "mixture", "maneuver"):
        for f in ("hbf", "ekf"):
            s = summary[case][f]
            for key in ("pos_m", "vel_mps", "mc_mean_pos_m", "mc_mean_vel_mps"):
                assert np.isfinite(s[key]) and s[key] > 0, (case, f, key)
            lo, hi = s["mc_ci95_pos_m"]
            assert lo <= s["mc_mean_pos_m"] <= hi
    # the published numbers, as printed (paper, §3.1)
    assert summary["paper"]["results"]["gaussian"]["hbf"] == {"pos_m": 2.03, "vel_mps": 0.04}
    assert summary["paper"]["results"]["gaussian"]["ekf"] == {"pos_m": 3.59, "vel_mps": 0.11}
    assert set(summary["sensor_errors"]["one_sigma"]) == {"sigma_range_m", "sigma_angle_rad", "sigma_accel_mps2"}
    assert summary["kalman_limit"]["pos_m"] > 0 and summary["gaussian"]["kalman_limit"] == {
        k: summary["kalman_limit"][k] for k in ("pos_m", "vel_mps")}
    assert set(summary["verdicts"]) == {"gaussian", "mixture", "maneuver"}
    assert summary["settings"]["runs"] == 3
    assert len(summary["sensitivity"]) == 6 and len(summary["mistuning"]) == 4


def test_jobs_give_the_same_results_in_worker_processes():
    # Identity: a job is a pure function of its arguments (each case seeds its own runs), so
    # spreading the jobs over processes changes nothing; checked on cheap jobs (Kalman limits).
    jobs = [(riccati_accuracy, (TINY.replace(sigma_accel=f * TINY.sigma_accel),), {}) for f in (0.5, 1.0, 2.0)]
    here = _run_jobs(jobs, 1, False)
    there = _run_jobs(jobs, 2, False)
    for a, b in zip(here, there):
        np.testing.assert_array_equal(a.std, b.std)


@pytest.fixture(scope="module")
def full_cases():
    sc = Scenario()
    return {case: run_case(sc, case, runs=12, seed=1) for case in ("gaussian", "mixture")}


def test_gaussian_gap_of_the_paper_does_not_reproduce(full_cases):
    # Paper §3.1: HBF/EKF = 2.03/3.59 = 0.57 (position), 0.04/0.11 = 0.36 (velocity). With the
    # EKF calibrated to the paper's EKF (its Monte Carlo mean within 5 % of 3.59 m, 0.11 m/s) the
    # HBF is not better than the EKF: the Kalman filter is optimal under Gaussian noise.
    g = full_cases["gaussian"]
    gap = paired_gap(g.filters["hbf"], g.filters["ekf"])
    assert gap["pos_ratio"] > 0.97 and gap["vel_ratio"] > 0.97, gap
    ekf = filter_summary(g.filters["ekf"])
    assert ekf["mc_mean_pos_m"] == pytest.approx(PAPER_RESULTS["gaussian"]["ekf"]["pos_m"], rel=0.05)
    assert ekf["mc_mean_vel_mps"] == pytest.approx(PAPER_RESULTS["gaussian"]["ekf"]["vel_mps"], rel=0.05)


def test_mixture_claim_reproduces(full_cases):
    # Paper §3.2: the HBF is better under the mixture (eps = 0.6, sigma2 = 2 sigma1). The paired
    # HBF - EKF difference over 12 runs is negative with 95 % confidence, in position and velocity.
    m = full_cases["mixture"]
    gap = paired_gap(m.filters["hbf"], m.filters["ekf"])
    assert gap["pos_ci95_m"][1] < 0 and gap["vel_ci95_mps"][1] < 0, gap


def test_every_figure_file_carries_the_summarys_provenance(written):
    # issue 23: this run's files read back (PNG text chunk, PDF Info) hold summary.json's provenance
    prov = json.loads((written[0] / "summary.json").read_text())["provenance"]
    files = sorted(written[0].glob("*.p[nd][gf]"))  # every figure of the run, each format
    assert prov["paper"] == "shi2018" and len(files) >= 16 and [read_provenance(f) for f in files] == [prov] * len(files)
