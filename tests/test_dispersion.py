"""Dispersed initial states x₀ ~ N(x̂₀, P₀), initial estimates per run, and consistency() on plain arrays.

Expected values: the χ² bounds (C3) of :mod:`hinfnav.metrics.consistency` (a linear-Gaussian Kalman filter whose
model is the truth's has a run-averaged NEES inside them at ~95 % of steps); the seeding rule of
:func:`hinfnav.sim.truth.dispersion_rngs` (run r's draw from its own stream); single-run estimates.
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import ExtendedKalmanFilter
from hinfnav.metrics import consistency
from hinfnav.metrics.consistency import chi2_bounds
from hinfnav.sim import TruthModel, simulate_truth
from hinfnav.sim.result import SimulationResult
from hinfnav.systems import LinearMeasurement, LinearSystem
from hinfnav.systems.state import StateSpec

DT = 1.0
PHI = np.array([[1, DT, 0, 0], [0, 1, 0, 0], [0, 0, 1, DT], [0, 0, 0, 1.0]])
B = np.array([[DT**2 / 2, 0], [DT, 0], [0, DT**2 / 2], [0, DT]]) * 0.2
SYSTEM = LinearSystem(PHI, np.zeros((4, 1)), B, DT, StateSpec(("x", "vx", "y", "vy"), ("m", "m/s", "m", "m/s")))
MEAS = LinearMeasurement(np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]]), 2.0 * np.eye(2))
XHAT0 = np.array([100.0, 5.0, -50.0, 1.0])
P0 = np.diag([400.0, 4.0, 400.0, 4.0])  # the initial error is large next to R: the first steps are the test


def run_nees(model, runs=1000, seed=0):
    truth = simulate_truth(model, runs=runs, seed=seed)
    kf = ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0)
    h = kf.estimate(truth.y, truth.u, XHAT0)
    stats, _ = consistency(truth.x, xhat=h.xhat, P=h.P, t=truth.t, xhat0=XHAT0, name="kf")
    return stats


def test_dispersed_x0_puts_the_kalman_nees_in_its_band_from_the_first_step():
    model = TruthModel(SYSTEM, MEAS, XHAT0, 30, x0_covariance=P0)
    stats = run_nees(model)
    lo, hi = stats.nees_bounds  # χ² 95 % bounds of the 1000-run average, 4 dof: about [3.83, 4.18]
    # the filter's model is the truth's and x₀ ~ N(x̂₀, P₀): the first steps' NEES in the per-step 95 % band …
    assert np.all((stats.nees[:5] >= lo) & (stats.nees[:5] <= hi)), stats.nees[:5]
    # … and every step's in the simultaneous 95 % band of the 31 steps (Bonferroni: each at 1 − 0.05/31). The
    # per-step band is left by chance at about 5 % of the steps (seeds 0-4 of this test: 3 % to 13 %).
    slo, shi = chi2_bounds(4, 1000, level=1 - 0.05 / stats.nees.size)
    assert np.all((stats.nees >= slo) & (stats.nees <= shi)), stats.nees
    assert np.mean((stats.nees >= lo) & (stats.nees <= hi)) >= 0.85
    # a fixed x₀ (one 2-σ offset in every run, the old practice) makes the early NEES meaningless
    fixed = TruthModel(SYSTEM, MEAS, XHAT0 + 2 * np.sqrt(np.diag(P0)), 30)
    early = run_nees(fixed).nees[:3]
    assert np.all(early > shi)  # 10.1, 7.4, 5.4 against an upper bound of about 4.2


def test_dispersion_streams_are_per_run_and_leave_the_noise_alone():
    model = TruthModel(SYSTEM, MEAS, XHAT0, 5, x0_covariance=P0)
    full = simulate_truth(model, runs=7, seed=3)
    part = simulate_truth(model, runs=3, seed=3, first_run=4)
    np.testing.assert_array_equal(full.x[4:], part.x)  # same numbers whatever the batch
    np.testing.assert_array_equal(model.initial_states(3, 3, 4), full.x[4:, 0])
    fixed = simulate_truth(TruthModel(SYSTEM, MEAS, XHAT0, 5), runs=7, seed=3)
    # the measurement noise of every run is the same with and without dispersion
    np.testing.assert_allclose(full.y - full.x[..., [0, 2]], fixed.y - fixed.x[..., [0, 2]], rtol=0, atol=1e-12)
    assert np.ptp(full.x[:, 0, 0]) > 10.0 and np.ptp(fixed.x[:, 0, 0]) == 0.0
    # a Generator seed draws the same as its int
    np.testing.assert_array_equal(model.initial_states(np.random.default_rng(3), 2), model.initial_states(3, 2))
    # the sample covariance of many draws is P₀: normalised by σ_i σ_j each entry has sd ≤ √2/√20000 = 0.01
    draws = model.initial_states(0, 20000)
    sd = np.sqrt(np.diag(P0))
    assert np.abs((np.cov(draws.T) - P0) / np.outer(sd, sd)).max() < 0.04
    with pytest.raises(InputError, match="x0_covariance"):
        TruthModel(SYSTEM, MEAS, XHAT0, 5, x0_covariance=-P0)


def test_initial_estimate_per_run_equals_runs_one_by_one():
    truth = simulate_truth(TruthModel(SYSTEM, MEAS, XHAT0, 10, x0_covariance=P0), runs=3, seed=1)
    xh0 = truth.x[:, 0] + np.array([1.0, 0.1, -1.0, 0.2])
    kf = ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0)
    h = kf.estimate(truth.y, truth.u, xh0)
    for r in range(3):
        one = kf.estimate(truth.y[r:r + 1], truth.u[r:r + 1], xh0[r])
        np.testing.assert_allclose(h.xhat[r], one.xhat[0], rtol=0, atol=1e-12)
    state = kf.start(xh0, runs=3)
    np.testing.assert_array_equal(state.x, xh0)
    with pytest.raises(InputError, match=r"xhat0 must have shape"):
        kf.estimate(truth.y, truth.u, xh0[:2])
    with pytest.raises(InputError, match="numba"):
        kf.estimate(truth.y, truth.u, xh0, backend="numba")


def test_consistency_of_arrays_equals_that_of_a_result():
    truth = simulate_truth(TruthModel(SYSTEM, MEAS, XHAT0, 10, x0_covariance=P0), runs=20, seed=2)
    h = ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0).estimate(truth.y, truth.u, XHAT0)
    res = SimulationResult(t=truth.t, x=truth.x, xhat=h.xhat, u=truth.u, y=truth.y, P=h.P, state=SYSTEM.state,
                           xhat0=XHAT0, settings={"filter": "kf"})
    a, sa = consistency(res)
    b, sb = consistency(truth.x, xhat=h.xhat, P=h.P, t=truth.t, xhat0=XHAT0, state=SYSTEM.state, name="kf")
    np.testing.assert_array_equal(a.nees, b.nees)
    assert sa == sb
    # shared covariance history (n_samples, n, n) accepted
    c, _ = consistency(truth.x, xhat=h.xhat, P=np.asarray(h.P[0]), t=truth.t)
    np.testing.assert_allclose(c.nees, a.nees, rtol=1e-12)
    with pytest.raises(InputError, match="xhat="):
        consistency(truth.x)


class Dispersed:
    """A scenario of one's own with dispersed initial states."""

    xhat0 = XHAT0

    def truth_model(self):
        return TruthModel(SYSTEM, MEAS, XHAT0, 8, x0_covariance=P0)


@pytest.mark.parametrize("closed_loop", [False, True])
def test_engine_draws_the_same_initial_states_whatever_the_batch(closed_loop):
    from hinfnav.sim import HistorySink, run_monte_carlo
    kf = ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0)
    law = (lambda x: np.zeros((x.shape[0], 1))) if closed_loop else None
    out = [run_monte_carlo(Dispersed(), {"kf": kf}, sink=HistorySink(XHAT0, 7), runs=7, seed=5, batch_size=b,
                           closed_loop=closed_loop, controller=law)["kf"] for b in (7, 3)]
    # the same numbers whatever the batch size, and they are the model's per-run draws
    np.testing.assert_array_equal(out[0].x, out[1].x)
    np.testing.assert_array_equal(out[0].x[:, 0], Dispersed().truth_model().initial_states(5, 7))
