"""Filter ideas as strategies on one Kalman core (issue 37 item 2): any idea × any moment rule, no new class.

Expected values are identities or closed-form limits: Huber's weights are 1 when the threshold γ exceeds every
whitened residual, so Huber × sigma-point is the sigma-point filter (the Kalman correction on the statistical
linearisation (M1) equals K = P_xy S⁻¹, P⁺ = P⁻ − K S Kᵀ by the expansion in hinfnav/estimators/moments.py);
strong tracking with every fading factor λ = 1 (a weakening factor β large enough that N of (S2) is negative) is
the filter it fades, exactly (x·1 = x); on the linearised rule the composed strategies are the named classes
HuberFilter and StrongTrackingEKF, bitwise.
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import (CorrentropyFilter, ExtendedKalmanFilter, HuberFilter, SigmaPointFilter,
                                StrongTrackingEKF, build_estimator, registered_estimators)
from hinfnav.estimators.compiled import why_numpy
from hinfnav.estimators.huber_filter import HuberStrategy
from hinfnav.estimators.moments import statistical_linearisation
from hinfnav.estimators.strategies import compose
from hinfnav.papers.shi2018 import Scenario as ShiScenario
from hinfnav.sim import simulate_truth

SHI = ShiScenario(duration_s=30.0, rms_window_s=(4.0, 30.0), maneuver_time_s=15.0)


@pytest.fixture(scope="module")
def truth():
    return simulate_truth(SHI.truth_model(), runs=3, seed=7)


def _run(est, tr, **kw):
    return est.estimate(tr.y, tr.u, SHI.xhat0, backend="numpy", diagnostics=True, **kw)


def test_huber_ukf_with_infinite_threshold_is_the_ukf(truth):
    ukf = _run(build_estimator(SHI, "ukf"), truth)
    est = build_estimator(SHI, "huber_ukf", correction={"name": "huber", "gamma": 1e12})
    assert type(est) is SigmaPointFilter and est.strategies == ("huber",)  # no new class
    hub = _run(est, truth)
    # closed form: every Huber weight is 1 (no whitened residual reaches γ = 1e12)
    np.testing.assert_array_equal(hub.diagnostics["weights"], 1.0)
    # the same correction through (M1): equal to rounding (positions ~1e5 m; 1e-9 relative)
    np.testing.assert_allclose(hub.xhat, ukf.xhat, rtol=1e-9, atol=1e-9 * np.abs(ukf.xhat).max())
    np.testing.assert_allclose(hub.P, ukf.P, rtol=1e-8, atol=1e-9 * np.abs(ukf.P).max())
    S = ukf.diagnostics["innovation_covariance"]
    np.testing.assert_allclose(hub.diagnostics["innovation_covariance"], S, rtol=1e-9, atol=1e-12 * np.abs(S).max())


def test_correntropy_ukf_with_infinite_bandwidth_is_the_ukf(truth):
    # closed form: G_σ(e) = exp(−e²/2σ²) is 1 in double precision for σ = 1e12 and every residual here
    ukf = _run(build_estimator(SHI, "ukf"), truth)
    mc = _run(build_estimator(SHI, "ukf", correction={"name": "correntropy", "sigma": 1e12}), truth)
    np.testing.assert_array_equal(mc.diagnostics["weights"], 1.0)
    np.testing.assert_allclose(mc.xhat, ukf.xhat, rtol=0, atol=1e-9 * np.abs(ukf.xhat).max())
    np.testing.assert_allclose(mc.P, ukf.P, rtol=0, atol=1e-9 * np.abs(ukf.P).max())


def test_strong_tracking_ukf_with_unit_fading_is_the_ukf(truth):
    ukf = _run(build_estimator(SHI, "ukf"), truth)
    est = build_estimator(SHI, "stukf", fading={"name": "strong_tracking", "beta": 1e15})  # N < 0 ⇒ λ = 1 (S3)
    assert type(est) is SigmaPointFilter and est.strategies == ("strong_tracking",)
    st = _run(est, truth)
    np.testing.assert_array_equal(st.diagnostics["fading"], 1.0)
    np.testing.assert_array_equal(st.xhat, ukf.xhat)  # Λ^{1/2} P Λ^{1/2} with Λ = I is P exactly
    np.testing.assert_array_equal(st.P, ukf.P)


def test_the_compositions_act(truth):
    ukf = _run(build_estimator(SHI, "ukf"), truth)
    hub = _run(build_estimator(SHI, "huber_ukf"), truth)
    st = _run(build_estimator(SHI, "stukf"), truth)
    assert (hub.diagnostics["weights"] < 1).any()  # γ = 1.345 down-weights some residuals of this run
    assert (st.diagnostics["fading"] > 1).any()   # the manoeuvre at 15 s fades the prior
    assert not np.allclose(hub.xhat, ukf.xhat) and not np.allclose(st.xhat, ukf.xhat)


def test_on_the_linearised_rule_the_strategies_are_the_named_classes(truth):
    ekf = ExtendedKalmanFilter(*_direct_model(), P0=SHI.P0)
    named_h = HuberFilter.from_ekf(ekf, gamma=1.5)
    named_s = StrongTrackingEKF(ekf.system, ekf.measurement, P0=ekf.P0, Q=ekf.Q, R=ekf.R, rho=0.9)
    named_c = CorrentropyFilter.from_ekf(ekf, sigma=3.0)
    for named, composed in [(named_h, compose(ekf, correction=HuberStrategy(gamma=1.5))),
                            (named_c, compose(ekf, correction={"name": "correntropy", "sigma": 3.0})),
                            (named_s, compose(ekf, fading={"name": "strong_tracking", "rho": 0.9}))]:
        a, b = _run(named, truth), _run(composed, truth)
        np.testing.assert_array_equal(a.xhat, b.xhat)  # the same functions on the same arrays: bitwise
        np.testing.assert_array_equal(a.P, b.P)


def _direct_model():
    ekf = build_estimator(SHI, "stekf")  # the range/angle EKF of Shi's scenario (constant R)
    return ekf.system, ekf.measurement


def test_statistical_linearisation_reproduces_the_moments():
    # (M1): H̃ P H̃ᵀ + R̃ = S and P H̃ᵀ = P_xy, on random moments
    rng = np.random.default_rng(0)
    A = rng.standard_normal((2, 4, 4))
    P = A @ np.swapaxes(A, -1, -2) + np.eye(4)
    Pxy = rng.standard_normal((2, 4, 3))
    B = rng.standard_normal((2, 3, 3))
    S = B @ np.swapaxes(B, -1, -2) + 10 * np.eye(3)
    H, R = statistical_linearisation(P, Pxy, S)
    np.testing.assert_allclose(P @ np.swapaxes(H, -1, -2), Pxy, atol=1e-12)
    np.testing.assert_allclose(H @ P @ np.swapaxes(H, -1, -2) + R, S, atol=1e-12)


def test_composed_filters_are_registered_run_on_numpy_and_refuse_what_they_cannot_do():
    assert {"huber_ukf", "stukf"} <= set(registered_estimators(SHI))
    est = build_estimator(SHI, "ukf", correction="huber")  # any registered filter of the core, by keyword
    assert est.strategies == ("huber",) and est.name == "huber_ukf"
    assert "huber strategy" in why_numpy(est)
    with pytest.raises(InputError, match="already has its own correction"):
        build_estimator(SHI, "hbf", correction="huber")
    with pytest.raises(InputError, match="already completes its prior"):
        build_estimator(SHI, "stekf", fading="strong_tracking")
    with pytest.raises(InputError, match="correction must be one of"):
        build_estimator(SHI, "ukf", correction="cauchy")
    with pytest.raises(InputError, match="gamma"):
        build_estimator(SHI, "ukf", correction={"name": "huber", "gamma": -1})
    with pytest.raises(InputError, match="square-root"):
        build_estimator(SHI, "huber_ukf", covariance_form="sqrt")
    with pytest.raises(InputError, match="constant R"):
        compose(build_estimator(SHI, "ukf", measurement="converted"), fading="strong_tracking")


def test_on_a_linear_model_the_sigma_point_compositions_are_the_ekf_ones():
    # independent check: on Sun 2011's chaser (linear dynamics, Cartesian position) the unscented transform is
    # exact, so the sigma-point moments are the Kalman ones and (M1) gives H̃ = H, R̃ = R: ST × UKF is the
    # strong-tracking EKF and Huber × UKF the Huber filter, to rounding, while their fading and weights act
    from hinfnav.papers.sun2011 import Scenario

    sun = Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0))
    tr = simulate_truth(sun.truth_model(maneuver=True), runs=2, seed=7, noise="mixture")
    for composed, named, acts in [("stukf", "stekf", lambda h: h.diagnostics["fading"].max() > 1.5),
                                  ("huber_ukf", "hbf", lambda h: h.diagnostics["weights"].min() < 0.9)]:
        a = build_estimator(sun, composed).estimate(tr.y, tr.u, sun.xhat0, backend="numpy", diagnostics=True)
        b = build_estimator(sun, named).estimate(tr.y, tr.u, sun.xhat0, backend="numpy", diagnostics=True)
        assert acts(b), named  # the idea is active on this record
        np.testing.assert_allclose(a.xhat, b.xhat, rtol=0, atol=1e-10 * np.abs(b.xhat).max())
        np.testing.assert_allclose(a.P, b.P, rtol=0, atol=1e-9 * np.abs(b.P).max())
