"""The sigma-point filter and the EKF on a nonlinear dynamics model, against filterpy, on the constant-turn problem.

Shared problem: a target in a constant turn with unknown turn rate
(:class:`hinfnav.systems.ConstantTurn`) tracked by a planar range/bearing
sensor (:class:`hinfnav.systems.RangeBearing`) at the origin. The track
crosses the negative x axis, so the bearing jumps from +π to −π: the
filters' angle handling is exercised. Expected values: filterpy's
``UnscentedKalmanFilter`` (with ``MerweScaledSigmaPoints`` of the same α, β, κ,
and the same mean/residual functions for the bearing) and filterpy's
``ExtendedKalmanFilter`` (its ``predict_x`` replaced by the model's f, its F
by the model's Jacobian), run step by step on the same data: an independent
implementation of the same algorithm.
"""

import numpy as np
import pytest
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEKF
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

import hinfnav as hn
import hinfnav.papers
from hinfnav.core.exceptions import HinfnavError, InputError
from hinfnav.estimators import (
    ExtendedKalmanFilter,
    HuberFilter,
    SigmaPointFilter,
    build_estimator,
    registered_estimators,
)
from hinfnav.estimators.sigma_point import merwe_weights
from hinfnav.papers import shi2018, sun2011
from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
from hinfnav.papers.attitude2018 import build_aekf
from hinfnav.sim import simulate_truth
from hinfnav.systems import (
    ConstantTurn,
    ConvertedRangeBearing,
    LinearMeasurement,
    LinearSystem,
    RangeBearing,
)
from hinfnav.systems.state import StateSpec

DT, N_STEPS, RUNS = 1.0, 60, 2
MODEL = ConstantTurn(DT, sigma_accel=0.05, sigma_turn_rate=1e-3)
SENSOR = RangeBearing(5, sigma_range=5.0, sigma_bearing=0.01)
X0 = np.array([-1000.0, 150.0, 0.0, -12.0, 0.02])  # crosses the −x axis (bearing ±π) after ~15 s
P0 = np.diag([30.0, 30.0, 3.0, 3.0, 0.03]) ** 2


def simulate(seed=11):
    """Truth (RUNS, N_STEPS, 5) and readings (RUNS, N_STEPS, 2) from an explicit Generator."""
    rng = np.random.default_rng(seed)
    LQ = np.linalg.cholesky(MODEL.Q + 1e-18 * np.eye(5))
    x = np.empty((RUNS, N_STEPS, 5))
    x[:, 0] = X0 + rng.standard_normal((RUNS, 5)) @ np.linalg.cholesky(P0).T
    for k in range(1, N_STEPS):
        x[:, k] = MODEL.f(x[:, k - 1], None, (k - 1) * DT) + rng.standard_normal((RUNS, 5)) @ LQ.T
    y = SENSOR.measure(x, rng.standard_normal((RUNS, N_STEPS, 2)))
    return x, y


def bearing_mean(sigmas, Wm):
    """Mean of sigma readings about the first (the centre): correct across ±π (the filter's rule (U5))."""
    ref = sigmas[0]
    return ref + Wm @ SENSOR.residual(sigmas, ref)


def run_steps(est, y, x0=X0):
    """(x̂, P) of every update by the step interface."""
    state = est.start(x0, P0, y.shape[0])
    xs, Ps = [], []
    for k in range(y.shape[1]):
        state, out = est.update(state, y[:, k])
        xs.append(out.xhat)
        Ps.append(out.P)
        state = est.predict(state)
    return np.stack(xs, 1), np.stack(Ps, 1)


@pytest.mark.parametrize("alpha, beta, kappa", [(1.0, 2.0, 0.0), (0.5, 2.0, 1.0), (0.3, 0.0, -2.0)])
def test_unscented_filter_equals_filterpy(alpha, beta, kappa):
    _, y = simulate()
    ukf = SigmaPointFilter(MODEL, SENSOR, P0=P0, alpha=alpha, beta=beta, kappa=kappa)
    xs, Ps = run_steps(ukf, y)
    assert np.any(np.abs(np.diff(y[:, :, 1], axis=1)) > 6.0)  # the bearing readings jump across ±π
    for r in range(RUNS):
        pts = MerweScaledSigmaPoints(5, alpha=alpha, beta=beta, kappa=kappa)
        ref = UnscentedKalmanFilter(5, 2, DT, hx=SENSOR.function, fx=lambda x, dt: MODEL.f(x[None])[0], points=pts,
                                    z_mean_fn=bearing_mean, residual_z=SENSOR.residual)
        ref.x, ref.P, ref.Q, ref.R = X0.copy(), P0.copy(), MODEL.Q.copy(), SENSOR.R.copy()
        ref.sigmas_f = pts.sigma_points(ref.x, ref.P)  # filterpy draws them in predict; the first step starts here
        for k in range(N_STEPS):
            ref.update(y[r, k])
            # identical algorithm: agreement to 1e-10 (relative to the state's and covariance's scale)
            np.testing.assert_allclose(xs[r, k], ref.x, rtol=1e-10, atol=1e-10 * np.abs(ref.x).max())
            np.testing.assert_allclose(Ps[r, k], ref.P, rtol=1e-10, atol=1e-10 * np.abs(ref.P).max())
            ref.predict()


def test_ekf_on_a_dynamics_model_equals_filterpy():
    _, y = simulate()
    ekf = ExtendedKalmanFilter(MODEL, SENSOR, P0=P0)
    xs, Ps = run_steps(ekf, y)

    class ConstantTurnEKF(FilterpyEKF):
        def predict_x(self, u=0):
            self.x = MODEL.f(self.x[None])[0]

    for r in range(RUNS):
        ref = ConstantTurnEKF(5, 2)
        ref.x, ref.P, ref.Q, ref.R = X0.copy(), P0.copy(), MODEL.Q.copy(), SENSOR.R.copy()
        for k in range(N_STEPS):
            ref.update(y[r, k], lambda x: SENSOR.jacobian(x), SENSOR.function, residual=SENSOR.residual)
            np.testing.assert_allclose(xs[r, k], ref.x, rtol=1e-10, atol=1e-10 * np.abs(ref.x).max())
            np.testing.assert_allclose(Ps[r, k], ref.P, rtol=1e-10, atol=1e-10 * np.abs(ref.P).max())
            ref.F = MODEL.jacobian(ref.x[None])[0]  # F at the posterior, then x⁻ = f(x̂), P⁻ = F P Fᵀ + Q
            ref.predict()


def test_cubature_rule_equals_the_zero_weight_centre_scaled_set():
    # (U3): the cubature points are the scaled set's with α = 1, β = 0, κ = 0, whose centre has weight 0
    # (independent: filterpy's UKF with those parameters)
    _, y = simulate(seed=3)
    xs, Ps = run_steps(SigmaPointFilter(MODEL, SENSOR, P0=P0, rule="cubature"), y)
    pts = MerweScaledSigmaPoints(5, alpha=1.0, beta=0.0, kappa=0.0)
    ref = UnscentedKalmanFilter(5, 2, DT, hx=SENSOR.function, fx=lambda x, dt: MODEL.f(x[None])[0], points=pts,
                                z_mean_fn=lambda s, w: s[1] + w @ SENSOR.residual(s, s[1]), residual_z=SENSOR.residual)
    ref.x, ref.P, ref.Q, ref.R = X0.copy(), P0.copy(), MODEL.Q.copy(), SENSOR.R.copy()
    ref.sigmas_f = pts.sigma_points(ref.x, ref.P)
    for k in range(N_STEPS):
        ref.update(y[0, k])
        np.testing.assert_allclose(xs[0, k], ref.x, rtol=1e-9, atol=1e-9 * np.abs(ref.x).max())
        np.testing.assert_allclose(Ps[0, k], ref.P, rtol=1e-9, atol=1e-9 * np.abs(ref.P).max())
        ref.predict()


def test_tracks_the_turn_and_batch_equals_steps():
    x, y = simulate(seed=5)
    ukf = SigmaPointFilter(MODEL, SENSOR, P0=P0)
    hist = ukf.estimate(y, np.zeros((RUNS, N_STEPS, 0)), X0, diagnostics=True)
    xs, _ = run_steps(ukf, y)
    np.testing.assert_array_equal(hist.xhat, xs)  # identity: the batch loop is the step loop
    assert hist.diagnostics["innovation_covariance"].shape == (RUNS, N_STEPS, 2, 2)
    # after 40 s the position error is within a few sensor σ_range·σ_bearing-scale errors (σ ≈ 10 m cross-range
    # at 1 km): 50 m is a loose, failing-if-diverged bound
    err = np.linalg.norm(x[:, 40:, :2] - hist.xhat[:, 40:, :2], axis=-1)
    assert err.max() < 50.0


def test_on_a_linear_model_it_is_the_kalman_filter():
    # the unscented transform is exact for linear maps (closed form): UKF = KF to rounding
    rng = np.random.default_rng(2)
    spec = StateSpec(("p", "v"), ("m", "m/s"))
    sys = LinearSystem(np.array([[1.0, 0.1], [0.0, 1.0]]), np.zeros((2, 0)), np.array([[0.005], [0.1]]), 0.1, spec)
    meas = LinearMeasurement(np.array([[1.0, 0.0]]), np.array([[0.5]]))
    y = rng.standard_normal((3, 40, 1))
    u = np.zeros((3, 40, 0))
    a = SigmaPointFilter(sys, meas, P0=np.eye(2), alpha=0.7, kappa=1.0).estimate(y, u, [0.0, 0.0])
    b = ExtendedKalmanFilter(sys, meas, P0=np.eye(2)).estimate(y, u, [0.0, 0.0])
    np.testing.assert_allclose(a.xhat, b.xhat, atol=1e-11)
    np.testing.assert_allclose(a.P, b.P, atol=1e-11)


def test_converted_measurement_runs_and_uses_reading_covariance():
    _, y = simulate(seed=8)
    conv = ConvertedRangeBearing(SENSOR)
    hist = SigmaPointFilter(MODEL, conv, P0=P0).estimate(y, np.zeros((RUNS, N_STEPS, 0)), X0, diagnostics=True)
    S = hist.diagnostics["innovation_covariance"]
    assert np.all(np.isfinite(hist.xhat))
    # S = H P⁻ Hᵀ + J R Jᵀ ⪰ J R Jᵀ: its trace exceeds that of the reading's covariance (closed form of (P4))
    assert np.all(np.trace(S, axis1=-2, axis2=-1) > np.trace(SENSOR.position_covariance(y), axis1=-2, axis2=-1))


def test_weights_and_bad_parameters():
    n_lam, Wm, _ = merwe_weights(5, 0.5, 2.0, 1.0)
    assert n_lam == pytest.approx(0.25 * 6)  # α²(n + κ), (U2)
    assert Wm.sum() == pytest.approx(1.0, abs=1e-14)  # the mean weights sum to one (U2)
    with pytest.raises(InputError, match="kappa"):
        SigmaPointFilter(MODEL, SENSOR, P0=P0, kappa=-5.0)
    with pytest.raises(InputError, match="rule"):
        SigmaPointFilter(MODEL, SENSOR, P0=P0, rule="spherical")
    with pytest.raises(InputError, match="alpha"):
        SigmaPointFilter(MODEL, SENSOR, P0=P0, alpha=0.0)
    ukf = SigmaPointFilter(MODEL, SENSOR, P0=P0)
    state = ukf.start(X0, P0)
    state.P = -state.P
    with pytest.raises(HinfnavError, match="step 0"):
        ukf.update(state, np.array([[1000.0, 3.0]]))


def test_registered_for_the_papers_that_name_it():
    chaser = sun2011.Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0))
    shi = shi2018.Scenario()
    assert "ukf" in registered_estimators(chaser) and "ukf" in registered_estimators(shi)
    truth = hn.simulate_truth(chaser.truth_model(maneuver=True), runs=2, seed=1)
    a = build_estimator(chaser, "ukf").estimate(truth.y, truth.u, chaser.xhat0)
    b = build_estimator(chaser, "ekf_known_input").estimate(truth.y, truth.u, chaser.xhat0)
    # linear dynamics and measurement: the unscented transform is exact, UKF = Kalman filter to rounding
    np.testing.assert_allclose(a.xhat, b.xhat, rtol=0, atol=1e-9)
    ukf = build_estimator(shi, "ukf")
    assert isinstance(ukf, SigmaPointFilter) and ukf.measurement.labels == ("range", "azimuth", "elevation")


def test_huber_filter_accepts_a_dynamics_model():
    # with a threshold no whitened residual reaches, Huber's M-estimation is the Kalman update (Shi & Wang 2018
    # §1.2: ρ quadratic inside γ), so on the constant-turn problem the HBF equals the EKF
    _, y = simulate(seed=9)
    a, Pa = run_steps(HuberFilter(MODEL, SENSOR, P0=P0, gamma=1e6), y)
    b, Pb = run_steps(ExtendedKalmanFilter(MODEL, SENSOR, P0=P0), y)
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(Pa, Pb, rtol=1e-9, atol=1e-9)


def test_quaternion_states_through_error_coordinates():
    # (U6) on paper 002's gyroless attitude problem. Independent reference: the attitude EKF (AEKF,
    # hinfnav.estimators.attitude). As α → 0 the unscented transform tends to the linearisation, so the UKF with
    # α = 1e-2 must agree with the AEKF far inside the estimation error (left: O(α²) terms and the AEKF's Taylor
    # e^{FΔt} against the Jacobian of the mean prediction); with α = 1 it must estimate as well (RMS within 1 %).
    sc = AttitudeScenario(orbits=0.05)  # 293 steps of 1 s
    truth = simulate_truth(sc.truth_model(), runs=2, seed=11)
    aekf = build_aekf(sc)
    ref = aekf.estimate(truth.y, truth.u, sc.xhat0)
    spec = sc.system().state
    rms = np.sqrt(np.mean(spec.error(truth.x, ref.xhat)[:, 150:] ** 2, axis=(0, 1)))  # per error coordinate
    for alpha in (1e-2, 1.0):
        ukf = SigmaPointFilter(sc.system(), sc.measurement, P0=sc.P0, Q=aekf.Qd, uses_input=True, alpha=alpha)
        hist = ukf.estimate(truth.y, truth.u, sc.xhat0)
        assert hist.P.shape == truth.x.shape[:2] + (9, 9)
        np.testing.assert_allclose(np.linalg.norm(hist.xhat[..., :4], axis=-1), 1.0, atol=1e-12)  # unit quaternions
        if alpha < 1:
            diff = np.abs(spec.error(ref.xhat, hist.xhat)[:, 150:]).max(axis=(0, 1))
            assert np.all(diff <= 1e-3 * rms), diff / rms
            np.testing.assert_allclose(hist.P, ref.P, rtol=0, atol=1e-6 * np.abs(ref.P).max())
        else:
            ukf_rms = np.sqrt(np.mean(spec.error(truth.x, hist.xhat)[:, 150:] ** 2, axis=(0, 1)))
            np.testing.assert_allclose(ukf_rms[:3], rms[:3], rtol=0.01)
    with pytest.raises(InputError, match="Q .* must be given"):
        SigmaPointFilter(sc.system(), sc.measurement, P0=sc.P0, uses_input=True)
