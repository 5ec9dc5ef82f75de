"""RTS and fixed-lag smoothers (:mod:`hinfnav.estimators.smoothers`) against published and independent references.

Expected values:

* pykalman's robot data set (``tests/data/references/pykalman_robot.mat``, see its ``.md``): filtered and
  smoothed means and covariances of a MATLAB Kalman filter and RTS smoother (a published reference);
* filterpy 1.4.5's ``KalmanFilter.rts_smoother`` and ``UnscentedKalmanFilter.rts_smoother`` run on the same
  fixed records (independent implementations);
* an RTS loop written out in this file on the Huber filter's recorded posteriors;
* the fixed-lag smoother's definition: x̂(k|k+L) is the RTS estimate of the record cut at k+L.
"""

from pathlib import Path

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FilterpyKF
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter
from scipy import io

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import (
    ExtendedKalmanFilter,
    HuberFilter,
    LTIFilter,
    RecursiveHInfinityFilter,
    SigmaPointFilter,
    StrongTrackingEKF,
)
from hinfnav.estimators.smoothers import filter_smoother_consistency, smooth
from hinfnav.systems import ConstantTurn, LinearMeasurement, LinearSystem, RangeBearing
from hinfnav.systems.state import StateSpec

ROBOT = Path(__file__).parent / "data" / "references" / "pykalman_robot.mat"


def spec(n):
    return StateSpec(tuple(f"x{i}" for i in range(n)), ("",) * n)


def robot():
    """The robot model and record in hinfnav's form: offsets b_t as an input through Γ = I, y − d as readings."""
    d = io.loadmat(ROBOT)
    A, C, Q, R = d["A"], d["C"], d["Q"], d["R"]
    y = d["y"].T - d["d"][:, 0]
    Y = np.vstack([np.full((1, 2), np.nan), y])[None]  # t = 0 has no reading (masked in pykalman)
    U = np.vstack([d["b"].T, np.zeros((1, 5))])[None]  # b_t drives t -> t+1
    system = LinearSystem(A, np.eye(5), np.linalg.cholesky(Q), 1.0, spec(5))
    meas = LinearMeasurement(C, np.linalg.cholesky(R))
    kf = ExtendedKalmanFilter(system, meas, P0=d["P_0"], Q=Q, R=R, uses_input=True, missing="skip")
    ref = {key: np.asarray([v for v in d[key][0]]) for key in ("Vfilt", "Vsmooth")}
    ref.update(xfilt=d["xfilt"].T, xsmooth=d["xsmooth"].T)
    return kf, Y, U, d["x0"][:, 0], ref


def test_rts_equals_pykalman_robot_matlab_outputs():
    kf, Y, U, x0, ref = robot()
    s = smooth(kf, Y, U, x0)
    # published MATLAB outputs (501 steps, the first without a reading: missing="skip"); agreement to 1e-10
    np.testing.assert_allclose(s.x_filt[0], ref["xfilt"], rtol=0, atol=1e-10)
    np.testing.assert_allclose(s.P_filt[0], ref["Vfilt"], rtol=0, atol=1e-10)
    np.testing.assert_allclose(s.xhat[0], ref["xsmooth"], rtol=0, atol=1e-10)
    np.testing.assert_allclose(s.P[0], ref["Vsmooth"], rtol=0, atol=1e-10)
    assert np.abs(ref["xsmooth"] - ref["xfilt"]).max() > 1.0  # the reference is not the filter itself


def linear_record(runs=3, N=40, seed=4):
    rng = np.random.default_rng(seed)
    dt = 0.5
    Phi = np.array([[1, dt, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1.0]])
    B = np.array([[dt**2 / 2, 0], [dt, 0], [0, dt**2 / 2], [0, dt]]) * 0.3
    C = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
    system = LinearSystem(Phi, np.zeros((4, 1)), B, dt, spec(4))
    meas = LinearMeasurement(C, 0.8 * np.eye(2))
    P0 = np.diag([4.0, 1.0, 4.0, 1.0])
    x = np.empty((runs, N, 4))
    x[:, 0] = rng.standard_normal((runs, 4)) @ np.sqrt(P0)
    for k in range(1, N):
        x[:, k] = x[:, k - 1] @ Phi.T + rng.standard_normal((runs, 2)) @ B.T
    y = x @ C.T + 0.8 * rng.standard_normal((runs, N, 2))
    return system, meas, P0, x, y


def test_rts_and_fixed_lag_equal_filterpy_rts_smoother():
    system, meas, P0, _, y = linear_record()
    kf = ExtendedKalmanFilter(system, meas, P0=P0)
    s = smooth(kf, y, None, np.zeros(4))
    for r in range(y.shape[0]):
        ref = FilterpyKF(4, 2)
        ref.F, ref.H, ref.Q, ref.R, ref.P, ref.x = system.Phi, meas.H, system.Q, meas.R, P0.copy(), np.zeros(4)
        # filterpy's batch_filter predicts before each update: its first prior must be x̂(0|−1) = 0, P0
        xs_f, Ps_f = [], []
        for k in range(y.shape[1]):
            if k:
                ref.predict()
            ref.update(y[r, k])
            xs_f.append(ref.x.copy())
            Ps_f.append(ref.P.copy())
        xs, Ps, G, _ = ref.rts_smoother(np.array(xs_f), np.array(Ps_f))
        # identical algorithm (filterpy 1.4.5's rts_smoother): agreement to 1e-10
        np.testing.assert_allclose(s.x_filt[r], xs_f, rtol=0, atol=1e-10)
        np.testing.assert_allclose(s.xhat[r], xs, rtol=0, atol=1e-10)
        np.testing.assert_allclose(s.P[r], Ps, rtol=0, atol=1e-10)
        np.testing.assert_allclose(s.gain[r], G[:-1], rtol=0, atol=1e-10)
    # fixed lag at lag = record length − 1 (or more) is the RTS smoother; lag 0 is the filter
    for lag in (y.shape[1] - 1, 500):
        f = smooth(kf, y, None, np.zeros(4), lag=lag)
        np.testing.assert_allclose(f.xhat, s.xhat, rtol=0, atol=1e-12)
        np.testing.assert_allclose(f.P, s.P, rtol=0, atol=1e-12)
    f0 = smooth(kf, y, None, np.zeros(4), lag=0)
    np.testing.assert_allclose(f0.xhat, s.x_filt, rtol=0, atol=0)


@pytest.mark.parametrize("lag", [1, 5])
def test_fixed_lag_is_rts_of_the_record_cut_at_k_plus_lag(lag):
    # definition of the fixed-lag estimate x̂(k|k+L), with a skipped reading in one run (missing="skip")
    system, meas, P0, _, y = linear_record(runs=2, N=25, seed=9)
    y[1, 7] = np.nan
    y[0, 3, 1] = np.nan
    kf = ExtendedKalmanFilter(system, meas, P0=P0, missing="skip")
    f = smooth(kf, y, None, np.zeros(4), lag=lag)
    for k in range(y.shape[1]):
        end = min(k + lag, y.shape[1] - 1)
        cut = smooth(kf, y[:, :end + 1], None, np.zeros(4))
        np.testing.assert_allclose(f.xhat[:, k], cut.xhat[:, k], rtol=0, atol=1e-11)
        np.testing.assert_allclose(f.P[:, k], cut.P[:, k], rtol=0, atol=1e-11)


def test_unscented_rts_equals_filterpy():
    dt, N = 1.0, 30
    model = ConstantTurn(dt, sigma_accel=0.05, sigma_turn_rate=1e-3)
    sensor = RangeBearing(5, sigma_range=5.0, sigma_bearing=0.01)
    x0 = np.array([-1000.0, 150.0, 0.0, -12.0, 0.02])
    P0 = np.diag([30.0, 30.0, 3.0, 3.0, 0.03]) ** 2
    rng = np.random.default_rng(2)
    x = np.empty((N, 5))
    x[0] = x0
    for k in range(1, N):
        x[k] = model.f(x[k - 1][None])[0]
    y = sensor.measure(x[None], rng.standard_normal((1, N, 2)))
    ukf = SigmaPointFilter(model, sensor, P0=P0)
    s = smooth(ukf, y, None, x0)
    pts = MerweScaledSigmaPoints(5, alpha=1.0, beta=2.0, kappa=0.0)
    ref = UnscentedKalmanFilter(5, 2, dt, hx=sensor.function, fx=lambda v, dt: model.f(v[None])[0], points=pts,
                                z_mean_fn=lambda s_, w: s_[0] + w @ sensor.residual(s_, s_[0]),
                                residual_z=sensor.residual)
    ref.x, ref.P, ref.Q, ref.R = x0.copy(), P0.copy(), model.Q.copy(), sensor.R.copy()
    ref.sigmas_f = pts.sigma_points(ref.x, ref.P)
    xs_f, Ps_f = [], []
    for k in range(N):
        if k:
            ref.predict()
        ref.update(y[0, k])
        xs_f.append(ref.x.copy())
        Ps_f.append(ref.P.copy())
    xs, Ps, _ = ref.rts_smoother(np.array(xs_f), np.array(Ps_f))
    # filterpy 1.4.5's URTS (Särkkä 2008), same sigma points: agreement to 1e-10 of the scale
    np.testing.assert_allclose(s.xhat[0], xs, rtol=1e-10, atol=1e-10 * np.abs(xs).max())
    np.testing.assert_allclose(s.P[0], Ps, rtol=1e-10, atol=1e-10 * np.abs(Ps).max())
    assert np.abs(s.xhat[0] - s.x_filt[0]).max() > 1e-3


def test_huber_smoother_equals_a_written_out_rts_loop():
    system, meas, P0, _, y = linear_record(runs=2, N=30, seed=1)
    y[0, 10] += 25.0  # an outlier: the Huber weights make P per run
    hbf = HuberFilter(system, meas, P0=P0, gamma=1.0)
    s = smooth(hbf, y, None, np.zeros(4))
    h = hbf.estimate(y, np.zeros(y.shape[:2] + (1,)), np.zeros(4))
    np.testing.assert_allclose(s.x_filt, h.xhat, rtol=0, atol=1e-12)
    F, Q = system.Phi, system.Q
    for r in range(2):  # independent: (S1)-(S3) written out with the filter's own posteriors
        xs, Ps = h.xhat[r].copy(), h.P[r].copy()
        for k in range(y.shape[1] - 2, -1, -1):
            Pp = F @ h.P[r, k] @ F.T + Q
            G = h.P[r, k] @ F.T @ np.linalg.inv(Pp)
            xs[k] = h.xhat[r, k] + G @ (xs[k + 1] - F @ h.xhat[r, k])
            Ps[k] = h.P[r, k] + G @ (Ps[k + 1] - Pp) @ G.T
        np.testing.assert_allclose(s.xhat[r], xs, rtol=0, atol=1e-10)
        np.testing.assert_allclose(s.P[r], Ps, rtol=0, atol=1e-10)


def test_filter_smoother_consistency_on_a_matched_model():
    # under the filter's own model the ratios are standard normal: |ratio| > 3 with probability 0.27 %
    system, meas, P0, _, y = linear_record(runs=200, N=30, seed=7)
    s = smooth(ExtendedKalmanFilter(system, meas, P0=P0), y, None, np.zeros(4))
    c = s.consistency()
    r = c["ratio"][:, :-1]  # the last sample: filter = smoother (NaN)
    assert np.all(np.isnan(c["ratio"][:, -1]))
    assert np.all(np.isfinite(r))
    assert np.all(c["fraction_exceeding"] < 0.01)
    assert abs(np.nanstd(r) - 1.0) < 0.05  # 24 000 ratios: sd of their sd ≈ 0.005
    # a wrong model (the readings 10× noisier than the filter believes) fails the test
    bad = smooth(ExtendedKalmanFilter(system, meas, P0=P0), 10 * y, None, np.zeros(4))
    assert np.all(filter_smoother_consistency(bad.x_filt, bad.P_filt, bad.xhat, bad.P)["fraction_exceeding"] > 0.05)


def test_hinf_and_deferred_prior_filters_are_refused_with_the_reason():
    system, meas, P0, _, y = linear_record(runs=1, N=5)
    hinf = RecursiveHInfinityFilter(system, meas, theta=1e-3, P0=P0)
    with pytest.raises(InputError, match="H∞ filter.*not an error covariance.*hinf_fixed_lag"):
        smooth(hinf, y, None, np.zeros(4))
    lti = LTIFilter(0.5 * np.eye(4), np.zeros((4, 2)), np.eye(4), system, meas)
    with pytest.raises(InputError, match="fixed-gain"):
        smooth(lti, y, None, np.zeros(4))
    with pytest.raises(InputError, match="completes its prior"):
        smooth(StrongTrackingEKF(system, meas, P0=P0), y, None, np.zeros(4))
    with pytest.raises(InputError, match="lag"):
        smooth(ExtendedKalmanFilter(system, meas, P0=P0), y, None, np.zeros(4), lag=-1)


@pytest.mark.parametrize("lag", [0, 3])
def test_hinf_fixed_lag_at_theta_0_is_the_kalman_fixed_lag_smoother(lag):
    from hinfnav.estimators.hinf_smoother import hinf_fixed_lag
    system, meas, P0, x, y = linear_record(runs=2, N=30, seed=5)
    u = np.zeros(y.shape[:2] + (1,))
    # θ = 0: Simon's filter is the Kalman predictor, on the lag-augmented state the Kalman fixed-lag smoother
    # (independent: the RTS-window fixed-lag smoother of this module)
    h0 = hinf_fixed_lag(RecursiveHInfinityFilter(system, meas, theta=0.0, P0=P0), y, u, np.zeros(4), lag)
    ref = smooth(ExtendedKalmanFilter(system, meas, P0=P0), y, None, np.zeros(4), lag=lag)
    np.testing.assert_allclose(h0.xhat, ref.xhat, rtol=0, atol=1e-10 * np.abs(ref.xhat).max())
    # θ > 0: a different estimate, the existence condition holding at every step of the augmented recursion
    h1 = hinf_fixed_lag(RecursiveHInfinityFilter(system, meas, theta=0.05, P0=P0), y, u, np.zeros(4), lag)
    assert np.all(h1.diagnostics["existence_margin"] > 0)
    assert np.abs(h1.xhat - h0.xhat).max() > 1e-6
    with pytest.raises(InputError, match="theta"):  # a θ beyond what the augmented recursion admits
        hinf_fixed_lag(RecursiveHInfinityFilter(system, meas, theta=50.0, P0=P0), y, u, np.zeros(4), lag)
