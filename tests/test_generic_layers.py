"""Generic systems, measurement models, estimators and the closed loop, away from any paper.

Expected values: closed forms (Riccati steady state, finite differences,
exact inverses) and identities (two computations of the same thing).
"""

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.analysis import steady_state_kalman
from hinfnav.control import LinearFeedback
from hinfnav.estimators import ExtendedKalmanFilter, LTIFilter
from hinfnav.papers.sun2011 import Scenario, make_estimator
from hinfnav.sim import TruthModel, run_estimator, simulate_closed_loop, simulate_truth
from hinfnav.systems import LinearMeasurement, LinearSystem, RangeAzimuthElevation, Saturated, StateSpec


def _random_system(seed=1, n=4, m=2, mu=1):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A *= 0.9 / max(abs(np.linalg.eigvals(A)))
    state = StateSpec(labels=[f"s{i}" for i in range(n)], units=["m"] * n, groups={"all": range(n)})
    system = LinearSystem(A, rng.standard_normal((n, mu)), 0.1 * rng.standard_normal((n, n)), 0.5, state)
    meas = LinearMeasurement(rng.standard_normal((m, n)), 0.2 * np.eye(m))
    return system, meas


def test_kalman_filter_on_a_random_system_reaches_the_riccati_steady_state():
    system, meas = _random_system()
    ekf = ExtendedKalmanFilter(system, meas, P0=np.eye(4))
    state = ekf.start(np.zeros(4), runs=1)
    for _ in range(400):
        state, out = ekf.update(state, np.zeros((1, 2)))
        state = ekf.predict(state)
    P_pred, P_filt, _ = steady_state_kalman(system.Phi, meas.C, system.Q, meas.R)  # closed form (DARE)
    np.testing.assert_allclose(out.P[0], P_filt, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(state.P, P_pred, rtol=1e-9, atol=1e-12)


def test_dimensions_come_from_the_system_not_from_a_paper():
    system, meas = _random_system(n=5, m=3, mu=2)
    model = TruthModel(system, meas, np.ones(5), 50)
    truth = simulate_truth(model, runs=2, seed=4)
    assert truth.x.shape == (2, 51, 5) and truth.y.shape == (2, 51, 3) and truth.u.shape == (2, 51, 2)
    G = np.linalg.solve(np.eye(5), np.ones((5, 3))) * 0.01
    lti = LTIFilter(system.Phi - G @ meas.C, -G, -np.eye(5), system, meas, name="observer")
    res = run_estimator(lti, truth, np.zeros(5))
    assert res.xhat.shape == (2, 51, 5)
    assert res.state.labels == ("s0", "s1", "s2", "s3", "s4")


def test_range_azimuth_elevation_jacobian_matches_finite_differences():
    rng = np.random.default_rng(3)
    C_bl = np.linalg.qr(rng.standard_normal((3, 3)))[0]
    model = RangeAzimuthElevation(6, 0.1, 1e-4, C_bl)
    x = np.array([[600.0, 550.0, 1040.0, 0.1, 0.2, 0.3], [-200.0, 40.0, -30.0, 0.0, 0.0, 0.0]])
    J = model.jacobian(x)
    h = 1e-4
    for r in range(2):
        num = np.stack([(model.function(x[r] + h * e) - model.function(x[r] - h * e)) / (2 * h) for e in np.eye(6)], axis=1)
        np.testing.assert_allclose(J[r], num, rtol=1e-6, atol=1e-12)  # central differences, O(h²)
    np.testing.assert_allclose(model.inverse(model.function(x)), x[:, :3], rtol=1e-12)  # exact inverse, eq. (7)


def test_converted_position_covariance_is_J_R_J_transpose():
    model = RangeAzimuthElevation(6, 0.5, 2e-3)
    m = np.array([1200.0, 0.4, -0.3])
    h = np.array([1e-3, 1e-7, 1e-7])
    J = np.stack([(model.inverse(m + d) - model.inverse(m - d)) / (2 * d[i]) for i, d in enumerate(np.diag(h))], axis=1)
    np.testing.assert_allclose(model.position_covariance(m), J @ model.R @ J.T, rtol=1e-6)


def test_saturated_measurement_clips_and_flags():
    meas = Saturated(LinearMeasurement(np.eye(2), np.eye(2)), lower=[-1.0, -np.inf], upper=[1.0, 2.0])
    y, flags = meas.clip(np.array([[0.5, 3.0], [-4.0, -9.0]]))
    np.testing.assert_array_equal(y, [[0.5, 2.0], [-1.0, -9.0]])
    np.testing.assert_array_equal(flags, [[False, True], [True, False]])
    with pytest.raises(hn.InputError, match="lower"):
        Saturated(LinearMeasurement(np.eye(2), np.eye(2)), lower=[1.0, 0.0], upper=[0.0, 1.0])


def test_closed_loop_on_the_true_state_equals_the_open_loop_truth():
    sc = Scenario(duration_s=50.0, rms_window_s=(10.0, 50.0))
    est = make_estimator(sc, "ekf_known_input")
    closed = simulate_closed_loop(sc, est, sc.controller(True, source="truth"), runs=3, seed=5)
    opened = run_estimator(est, simulate_truth(sc.truth_model(maneuver=True), runs=3, seed=5), sc.xhat0)
    # x(k+1) = Φx + Γ(Kx) + Bw against (Φ + ΓK)x + Bw: the same up to round-off
    np.testing.assert_allclose(closed.x, opened.x, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(closed.xhat, opened.xhat, rtol=1e-9, atol=1e-9)


def test_closed_loop_on_the_estimate_converges_like_the_ideal_loop():
    # separation principle: x⁺ = (Φ + ΓK) x − ΓK e + B w with e the Kalman error (0.06 m,
    # 0.02 m/s per axis): the maneuver from 1.3 km must still converge, and the noise-driven
    # range after it stays of the same size as with u = K x on the same noise
    sc = Scenario(duration_s=1500.0, rms_window_s=(100.0, 1500.0))
    est = make_estimator(sc, "ekf_known_input")
    ms = {}
    for source in ("truth", "estimate"):
        res = simulate_closed_loop(sc, est, LinearFeedback(sc.K, source=source), runs=20, seed=1)
        late = res.t >= 900.0  # the maneuver has settled by ~800 s
        rng = np.linalg.norm(res.x[:, :, :3], axis=-1)
        assert rng[:, 0].min() > 1300.0 and np.all(rng[:, -1] < 10.0), source
        ms[source] = float(np.mean(rng[:, late] ** 2))
    assert 0.5 < ms["estimate"] / ms["truth"] < 2.0, ms


def test_state_spec_checks_its_groups():
    with pytest.raises(hn.InputError, match="group"):
        StateSpec(labels=["a", "b"], units=["m", "m/s"], groups={"bad": (0, 1)})
    spec = StateSpec(labels=["a", "b"], units=["m", "m"], groups={"both": (0, 1)})
    with pytest.raises(hn.InputError, match="unknown state group"):
        spec.indices("position")
