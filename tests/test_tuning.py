"""The consistency tuner (issue 33, item 3): a mis-tuned Kalman filter on a linear-Gaussian cell gets its Q and R back.

The cell: 2-D constant velocity at 1 Hz, q = 0.5 m²/s³, R = 4 m² I, 40 runs x 120 steps (fixed seed). The filter
is told Q x 10 and R x 0.2; the tuner's scales must bring them to within 10 % of the truth's (source: the
simulation's own Q and R), with the average NEES and NIS inside their 95 % bands.
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators.kalman import ExtendedKalmanFilter
from hinfnav.metrics.tuning import consistency_averages, tune_consistency
from hinfnav.systems.linear import LinearSystem
from hinfnav.systems.measurements import LinearMeasurement
from hinfnav.systems.state import StateSpec

T, q, r = 1.0, 0.5, 4.0
F = np.block([[np.eye(2), T * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
Q = q * np.block([[T**3 / 3 * np.eye(2), T**2 / 2 * np.eye(2)], [T**2 / 2 * np.eye(2), T * np.eye(2)]])
R = r * np.eye(2)
STATE = StateSpec(labels=("x", "y", "vx", "vy"), units=("m", "m", "m/s", "m/s"))
SYSTEM = LinearSystem(Phi=F, Gamma=np.zeros((4, 1)), B=np.linalg.cholesky(Q), dt=T, state=STATE)
MEAS = LinearMeasurement(np.hstack([np.eye(2), np.zeros((2, 2))]), np.sqrt(r) * np.eye(2))
P0 = np.diag([4.0, 4.0, 1.0, 1.0])
X0 = np.array([0.0, 0.0, 3.0, -1.0])


def _cell(runs=40, n=120, seed=11):
    rng = np.random.default_rng(seed)
    x = np.empty((runs, n, 4))
    x[:, 0] = X0 + rng.standard_normal((runs, 4)) @ np.linalg.cholesky(P0).T
    for k in range(1, n):
        x[:, k] = x[:, k - 1] @ F.T + rng.standard_normal((runs, 4)) @ np.linalg.cholesky(Q).T
    y = x[..., :2] + np.sqrt(r) * rng.standard_normal((runs, n, 2))
    return x, y, np.zeros((runs, n, 1))


@pytest.mark.slow  # ~5 s: about 140 filter runs of the Nelder-Mead search
def test_mis_tuned_kalman_filter_recovers_q_and_r():
    x, y, u = _cell()
    Q_told, R_told = 10.0 * Q, 0.2 * R

    def build(Q_scale, R_scale):
        return ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0, Q=Q_scale * Q_told, R=R_scale * R_told)

    before = consistency_averages(build(1.0, 1.0), x, y, u, X0, skip=15)
    res = tune_consistency(build, {"Q_scale": 1.0, "R_scale": 1.0}, x, y, u, X0, skip=15, xatol=0.01)
    # the mis-tuned filter is outside its bands (measured NEES 11.5 for n = 4, NIS 4.5 for m = 2)
    assert not (res.nis_band[0] <= before[1] <= res.nis_band[1])
    assert res.inside, (res.nees, res.nees_band, res.nis, res.nis_band)
    # Q and R recovered within 10 % of the truth's: the told ones times the scales
    np.testing.assert_allclose(res.scales["Q_scale"] * 10.0, 1.0, rtol=0.10)
    np.testing.assert_allclose(res.scales["R_scale"] * 0.2, 1.0, rtol=0.10)
    assert res.cost < 1e-2 < res.cost_initial
    # the RMS cost is reported: tuned towards the truth the Kalman filter's error cannot grow by much (it is the
    # optimal filter at the true Q, R); it shrinks here (measured -17 % position, -53 % velocity)
    assert np.all(res.rms <= 1.02 * res.rms_initial)


def test_bad_tuning_inputs_are_named():
    x, y, u = _cell(runs=2, n=20)
    build = lambda s: ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0, Q=s * Q)
    with pytest.raises(InputError, match="initial"):
        tune_consistency(build, {"s": -1.0}, x, y, u, X0)
    with pytest.raises(InputError, match="skip"):
        tune_consistency(build, {"s": 1.0}, x, y, u, X0, skip=50)


def test_theta_of_the_recursive_hinf_filter_is_tuned_to_its_nees():
    from hinfnav.estimators.recursive_hinf import RecursiveHInfinityFilter

    # told the true Q and R, the recursive H∞ filter's θ > 0 inflates its P (NEES below n = 4, measured 3.71 at
    # θ = 0.05); tuning θ alone on the NEES brings the average to n (the minimiser of J, here reachable: J → 0)
    x, y, u = _cell()

    def build(theta):
        return RecursiveHInfinityFilter(SYSTEM, MEAS, theta=theta, P0=P0, Q=Q, R=R, uses_input=False)

    res = tune_consistency(build, {"theta": 0.05}, x, y, u, X0, skip=15, use_nis=False, components=False, xatol=0.01)
    np.testing.assert_allclose(res.nees, 4.0, rtol=0.01)
    assert res.inside and 0 < res.scales["theta"] < 0.05 < build(0.05).theta_max()
