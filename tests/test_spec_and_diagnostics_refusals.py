"""Refusals of options that would be ignored (issue 36, items 5 and 8).

A campaign's options for an estimator the grid does not run (a misspelt name)
and a diagnostic a filter does not report are refused naming them, where before
they were silently ignored.
"""

import numpy as np
import pytest

import hinfnav.papers  # noqa: F401 - registers Sun 2011's scenario and estimators
from hinfnav.campaign import Campaign
from hinfnav.core.exceptions import FilterDivergedError, InputError
from hinfnav.estimators import ExtendedKalmanFilter, SigmaPointFilter
from hinfnav.systems import LinearMeasurement, LinearSystem, StateSpec

GRID = {"scenario": "sun2011", "estimator": ["ekf", "hbf"], "duration_s": [20.0], "rms_window_s": [[0.0, 20.0]]}


def test_options_for_an_estimator_not_in_the_grid_refused():
    with pytest.raises(InputError, match=r"estimator_options\.hbff: 'hbff' is not an estimator of the grid"):
        Campaign(grid=GRID, runs=2, windows={"all": [0.0, 20.0]}, estimator_options={"hbff": {"gamma": 2.0}})
    ok = Campaign(grid=GRID, runs=2, windows={"all": [0.0, 20.0]}, estimator_options={"hbf": {"gamma": 2.0}})
    assert ok.estimator_options == {"hbf": {"gamma": 2.0}}


SYS = LinearSystem(np.array([[1.0, 0.1], [0.0, 1.0]]), np.zeros((2, 0)), 0.1 * np.eye(2), 0.1,
                   StateSpec(labels=("p", "v"), units=("m", "m/s")))
SENSOR = LinearMeasurement([[1.0, 0.0]], [[1.0]])


def test_unknown_diagnostic_refused():
    ekf = ExtendedKalmanFilter(SYS, SENSOR, P0=np.eye(2))
    y = np.zeros((2, 5, 1))
    hist = ekf.estimate(y, np.zeros((2, 5, 0)), np.zeros(2), diagnostics=["innovation"])
    assert hist.diagnostics["innovation"].shape == (2, 5, 1)
    with pytest.raises(InputError, match=r"unknown diagnostic 'innovatoin'.*it reports: .*innovation"):
        ekf.estimate(y, np.zeros((2, 5, 0)), np.zeros(2), diagnostics=["innovatoin"])


@pytest.mark.parametrize("make", [
    lambda: ExtendedKalmanFilter(SYS, SENSOR, P0=np.eye(2)),
    lambda: SigmaPointFilter(SYS, SENSOR, P0=np.eye(2)),
])
def test_absurd_readings_refused_and_non_finite_estimates_raise(make):
    est = make()
    y = np.zeros((2, 5, 1))
    y[1, 2, 0] = 1e300  # finite, but its square overflows
    for backend in ("numpy", "auto"):  # the same refusal whatever the path (it is checked at the door)
        with pytest.raises(InputError, match=r"magnitude 1e\+300, beyond 1e\+150"):
            est.estimate(y, np.zeros((2, 5, 0)), np.zeros(2), backend=backend)
    # a plant that multiplies the covariance by 1e200 per step overflows at step 2: raised there, not NaN returned
    wild = LinearSystem(1e100 * np.eye(2), np.zeros((2, 0)), np.eye(2), 0.1, SYS.state)
    est = type(est)(wild, SENSOR, P0=np.eye(2))
    with pytest.raises(FilterDivergedError, match=r"diverged at step \d"):
        est.estimate(np.ones((1, 6, 1)), np.zeros((1, 6, 0)), np.zeros(2))


@pytest.mark.parametrize("backend", ["numpy", "auto"])
def test_nonfinite_flag_policy_carries_the_diverged_runs_on(backend):
    # the campaign's policy (issue 36 item 5, "raises, or flags per a documented policy"): the same wild plant as
    # above, two runs; the covariance multiplies by 1e200 a step, so it overflows at step 2 (closed form:
    # 1e200² > 1.8e308); with nonfinite="flag" the history comes back, finite before, not finite from there on
    wild = LinearSystem(1e100 * np.eye(2), np.zeros((2, 0)), np.eye(2), 0.1, SYS.state)
    est = ExtendedKalmanFilter(wild, SENSOR, P0=np.eye(2))
    est.nonfinite = "flag"
    hist = est.estimate(np.ones((2, 6, 1)), np.zeros((2, 6, 0)), np.zeros(2), backend=backend)
    P = hist.P if hist.P.ndim == 4 else hist.P[None]  # (runs, steps, n, n), or one covariance shared by the runs
    finite = np.isfinite(P).all(axis=(0, 2, 3))
    assert finite[:2].all() and not finite[-1]
    with pytest.raises(InputError, match="nonfinite must be one of 'raise', 'flag'"):
        est.nonfinite = "ignore"


def test_campaign_cells_flag_nonfinite_runs():
    # a campaign cell counts a run that blows up as diverged instead of failing the whole cell
    from hinfnav.campaign.runner import _estimator
    from hinfnav.papers.sun2011 import Scenario

    est = _estimator(Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0)), "sun2011", {}, "ekf", {})
    assert est.nonfinite == "flag"
