"""The Huber-based filter (hinfnav.estimators.HuberFilter) and the reading-dependent R of the EKF (issue 9, item 2).

Expected values are identities (the same update computed two ways), closed
forms (the Huber cost is the least-squares cost when no whitened residual
exceeds γ, so the HBF is then the Kalman filter), or the definition of the
Huber weights.
"""

import numpy as np
import pytest

import hinfnav as hn
import hinfnav.papers.shi2018
from hinfnav.core import InputError
from hinfnav.estimators import ExtendedKalmanFilter, HuberFilter, build_estimator, huber_update, registered_estimators
from hinfnav.papers import sun2011
from hinfnav.papers.shi2018 import EKF, HBF, Scenario
from hinfnav.systems.measurements import ConvertedPosition, RangeAzimuthElevation

SHORT = Scenario(duration_s=60.0, maneuver_time_s=30.0, rms_window_s=(20.0, 60.0))


@pytest.fixture(scope="module")
def truth():
    return SHORT.simulate_truth(runs=3, seed=11)


def test_hbf_is_the_kalman_filter_when_gamma_is_huge(truth):
    # Closed form: with no whitened residual beyond gamma the Huber cost is the
    # least-squares cost, whose minimiser and covariance are the Kalman update's.
    ekf = EKF(SHORT)
    hbf = HBF(SHORT, gamma=1e9)
    a = ekf.estimate(truth.y, truth.u, SHORT.xhat0)
    b = hbf.estimate(truth.y, truth.u, SHORT.xhat0)
    # round-off only (normal equations vs Joseph form over 150 steps)
    np.testing.assert_allclose(b.xhat, a.xhat, rtol=0, atol=1e-8 * np.abs(a.xhat).max())
    np.testing.assert_allclose(b.P, a.P, rtol=1e-7, atol=1e-10)


def test_hbf_is_the_kalman_filter_on_sun2011_when_gamma_is_huge():
    # Same identity on Sun 2011's chaser (linear position measurement, shared EKF covariance).
    sc = sun2011.Scenario(duration_s=20.0, rms_window_s=(5.0, 20.0))
    tr = hn.simulate_truth(sc.truth_model(maneuver=True), runs=2, seed=3)
    ekf = build_estimator(sc, "ekf_known_input")
    hbf = build_estimator(sc, "hbf", gamma=1e9)
    assert isinstance(hbf, HuberFilter) and hbf.uses_input and not hbf.shares_covariance
    a = ekf.estimate(tr.y, tr.u, sc.xhat0).xhat
    b = hbf.estimate(tr.y, tr.u, sc.xhat0).xhat
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-8 * np.abs(a).max())


def test_one_update_is_huber_update_on_the_measurement_and_prior(truth):
    # Independent computation: the filter solves the regression in the
    # correction delta = x - x_prior; huber_update on [z; x_prior] = [H; I] x
    # (Karlgaard & Schaub's form) must give the same posterior.
    hbf = HBF(SHORT)
    state = hbf.start(SHORT.xhat0, None, truth.y.shape[0])
    for k in range(40):  # well into the run, where some residuals exceed gamma
        state, out = hbf.update(state, truth.y[:, k])
        state = hbf.predict(state, truth.u[:, k])
    x_prior, P_prior = state.x, state.P
    y = truth.y[:, 40]
    meas = hbf.measurement
    ref = huber_update(x_prior, P_prior, meas.convert(y), meas.jacobian(x_prior), meas.noise_covariance(y), gamma=1.345)
    _, out = hbf.update(state, y)
    np.testing.assert_allclose(out.xhat, ref.x, rtol=0, atol=1e-9 * np.abs(ref.x).max())
    np.testing.assert_allclose(out.P, ref.P, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(out.diagnostics["weights"], ref.weights, rtol=1e-9)


def test_diagnostics_are_weights_iterations_and_convergence(truth):
    hist = HBF(SHORT).estimate(truth.y, truth.u, SHORT.xhat0, diagnostics=True)
    w = hist.diagnostics["weights"]
    assert w.shape == truth.y.shape[:2] + (3 + 6,)
    assert np.all((w > 0) & (w <= 1))
    assert np.any(w < 1)  # Gaussian noise: about 1 reading in 6 exceeds gamma = 1.345 sigma
    assert hist.diagnostics["iterations"].shape == truth.y.shape[:2]
    assert np.all(hist.diagnostics["iterations"] >= 1)
    assert np.all(hist.diagnostics["converged"])
    assert "innovation" in hist.diagnostics


def test_an_outlier_moves_the_hbf_less_than_the_ekf(truth):
    # Definition of the Huber weights: a reading 30 sigma off gets weight gamma/|zeta| < 1.
    y = truth.y.copy()
    k = 100
    y[:, k, 0] += 30 * SHORT.sigma_range
    outs = {}
    for est in (EKF(SHORT), HBF(SHORT)):
        clean = est.estimate(truth.y, truth.u, SHORT.xhat0).xhat[:, k]
        hit = est.estimate(y, truth.u, SHORT.xhat0, diagnostics=True)
        outs[type(est).__name__] = np.linalg.norm((hit.xhat[:, k] - clean)[:, :3], axis=1)
        if isinstance(est, HuberFilter):
            assert np.all(hit.diagnostics["weights"][:, k, :3].min(axis=1) < 0.2)
    assert np.all(outs["HuberFilter"] < 0.5 * outs["ExtendedKalmanFilter"]), outs


def test_hbf_is_registered_and_runs_on_sun2011_through_simulate():
    sc = sun2011.Scenario(duration_s=20.0, rms_window_s=(5.0, 20.0))
    assert "hbf" in registered_estimators(sc)
    assert {"hbf", "ekf_converted"} <= set(registered_estimators(SHORT))
    assert "ekf_converted" not in registered_estimators(sc)
    res = hn.simulate(sc, "hbf", runs=2, seed=0, maneuver=True)
    assert res.settings["filter"] == "hbf"
    assert np.all(np.isfinite(res.xhat))
    # after 20 s the position error is at the measurement noise level (D = 0.1 m), not the 30-40 m initial error
    assert np.abs(res.error[:, -50:, :3]).max() < 1.0


def test_from_ekf_keeps_the_model_and_refuses_other_objects():
    ekf = EKF(SHORT)
    hbf = HuberFilter.from_ekf(ekf, gamma=2.0)
    assert hbf.system is ekf.system and hbf.measurement is ekf.measurement
    np.testing.assert_array_equal(hbf.Q, ekf.Q)
    np.testing.assert_array_equal(hbf.P0, ekf.P0)
    assert hbf.gamma == 2.0 and hbf.uses_input == ekf.uses_input
    with pytest.raises(InputError, match="ekf"):
        HuberFilter.from_ekf("not a filter")


@pytest.mark.parametrize("option, value, word", [("gamma", 0.0, "gamma"), ("gamma", -1.0, "gamma"),
                                                 ("max_iter", 0, "max_iter"), ("tol", 0.0, "tol")])
def test_bad_options_name_the_parameter(option, value, word):
    with pytest.raises(InputError, match=word):
        HBF(SHORT, **{option: value})


def test_ekf_on_a_converted_measurement_uses_the_reading_covariance(truth):
    # Closed form: one Kalman update with R_1 = J(m_1) R J(m_1)^T of the first reading.
    ekf = EKF(SHORT)
    assert ekf.R is None and not ekf.shares_covariance
    state = ekf.start(SHORT.xhat0, None, 3)
    y = truth.y[:, 0]
    _, out = ekf.update(state, y)
    meas = ekf.measurement
    R1 = meas.noise_covariance(y)
    H = meas.H
    P = SHORT.P0
    for r in range(3):
        K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R1[r])
        x = SHORT.xhat0 + K @ (meas.convert(y[r]) - H @ SHORT.xhat0)
        np.testing.assert_allclose(out.xhat[r], x, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(out.P[r], (np.eye(6) - K @ H) @ P, rtol=1e-9, atol=1e-9)
    # an explicit R overrides the reading-dependent one (and the covariance is then shared)
    fixed = ExtendedKalmanFilter(SHORT.system(), meas, P0=SHORT.P0, R=np.eye(3) * 100.0)
    assert fixed.shares_covariance and fixed.R_of_reading is None


def test_converted_position_model():
    sensor = RangeAzimuthElevation(6, 2.0, 1e-3)
    conv = ConvertedPosition(sensor)
    x = np.array([[500.0, 3000.0, 100.0, 0.1, -1.0, 0.3]])
    y = sensor.function(x)
    # identities: the reading's labels and units, position prediction, exact conversion of a noise-free reading
    assert conv.labels == sensor.labels and conv.units == sensor.units
    np.testing.assert_allclose(conv.function(x), x[:, :3])
    np.testing.assert_allclose(conv.residual(y, conv.function(x)), 0.0, atol=1e-9)
    np.testing.assert_allclose(conv.noise_covariance(y), sensor.position_covariance(y))
    # first order: Monte Carlo covariance of converted noisy readings matches J R J^T within 3 %
    rng = np.random.default_rng(0)
    v = rng.standard_normal((200_000, 3))
    z = conv.convert(sensor.measure(np.broadcast_to(x, (200_000, 6)), v))
    C = np.cov(z.T)
    np.testing.assert_allclose(np.diag(C), np.diag(conv.noise_covariance(y)[0]), rtol=0.03)
    with pytest.raises(InputError, match="reading"):
        conv.R  # noqa: B018
    with pytest.raises(InputError, match="sensor"):
        ConvertedPosition("radar")
