"""The recursive H∞ filter (Simon 2006, ch. 11, a-priori form) on the step contract (issue 12).

Expected values: an independent Kalman predictor written out here and scipy's
DARE (θ = 0), the scalar closed form of the steady state, filterpy's
HInfinityFilter (identical where its known defects do not bite, and off by
exactly the extra F where they do). The contract suite (tests/test_contract.py)
runs the registered ``recursive_hinf`` as well.
"""

import warnings

import numpy as np
import pytest
import scipy.linalg
from filterpy.hinfinity import HInfinityFilter

import hinfnav as hn
from hinfnav.papers import sun2011
from hinfnav.analysis import max_admissible_theta, steady_state_hinf
from hinfnav.estimators import build_estimator
from hinfnav.estimators.recursive_hinf import RecursiveHInfinityFilter
from hinfnav.papers.sun2011 import theta_study
from hinfnav.systems import LinearMeasurement, LinearSystem, StateSpec


def _model(F, H, Bq, Dv, Gamma=None):
    n = F.shape[0]
    st = StateSpec(tuple(f"s{i}" for i in range(n)), ("",) * n)
    Gamma = np.zeros((n, 0)) if Gamma is None else Gamma
    return LinearSystem(F, Gamma, Bq, 1.0, st), LinearMeasurement(H, Dv)


def _random(seed, n=3, m=2, rho=1.02):
    rng = np.random.default_rng(seed)
    F = rng.standard_normal((n, n))
    F *= rho / np.abs(np.linalg.eigvals(F)).max()
    return F, rng.standard_normal((m, n)), 0.3 * rng.standard_normal((n, n)), np.diag(rng.uniform(0.3, 1.0, m)), rng


def test_theta_zero_is_the_kalman_predictor():
    # independent reference: the textbook one-step predictor written out here, and scipy's DARE for the limit
    F, H, Bq, Dv, rng = _random(1)
    sysm, meas = _model(F, H, Bq, Dv)
    Q, R = Bq @ Bq.T, Dv @ Dv.T
    P0 = np.eye(3)
    est = RecursiveHInfinityFilter(sysm, meas, theta=0.0, P0=P0)
    y = rng.standard_normal((2, 400, 2))
    hist = est.estimate(y, np.zeros((2, 400, 0)), np.zeros(3))
    x, P = np.zeros((2, 3)), P0.copy()
    for k in range(400):
        np.testing.assert_allclose(hist.xhat[:, k], x, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(hist.P[0, k], P, rtol=1e-10, atol=1e-12)
        K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
        x = x @ F.T + (y[:, k] - x @ H.T) @ (F @ K).T
        P = F @ (P - K @ H @ P) @ F.T + Q
    P_dare = scipy.linalg.solve_discrete_are(F.T, H.T, Q, R)
    np.testing.assert_allclose(hist.P[0, -1], P_dare, rtol=1e-9)


def test_scalar_steady_state_closed_form():
    # Scalar steady state (see tests/test_hinf_riccati.py): a = H²/R − θ, b = 1 − F² − aQ,
    # P = 2Q / (b + sqrt(b² + 4aQ)), K = P/(1 + aP) · H/R
    F, H, Q, R = 0.9, 1.0, 0.5, 2.0
    theta_max = H * H / R + (1 - F) ** 2 / Q
    for theta in (0.0, 0.5 * theta_max, 0.95 * theta_max):
        a = H * H / R - theta
        b = 1 - F * F - a * Q
        P_ref = 2 * Q / (b + np.sqrt(b * b + 4 * a * Q))
        K_ref = P_ref / (1 + a * P_ref) * H / R
        sysm, meas = _model(np.array([[F]]), np.array([[H]]), np.array([[np.sqrt(Q)]]), np.array([[np.sqrt(R)]]))
        est = RecursiveHInfinityFilter(sysm, meas, theta=theta, P0=[[Q]])
        P = np.array([[Q]])
        for k in range(3000):
            K, P_next, margin, ok = est.riccati_step(P, k)
            assert ok and margin > 0
            P = P_next
        assert P[0, 0] == pytest.approx(P_ref, rel=1e-10)
        assert K[0, 0] == pytest.approx(K_ref, rel=1e-10)


def _filterpy(F, H, Q, R, theta, P0):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # it warns "DO NOT USE" on construction
        f = HInfinityFilter(F.shape[0], H.shape[0], 0, gamma=theta)
    f.F, f.H, f.V, f.W, f.Q, f.P = F.copy(), H.copy(), R, Q, np.eye(F.shape[0]), P0.copy()
    f.x = np.zeros((F.shape[0], 1))
    return f


@pytest.mark.parametrize("case", ["F = I", "F != I"])
def test_filterpy_hinfinity_filter_differs_by_its_extra_F(case):
    # filterpy 2.0's HInfinityFilter: gamma is Simon's θ, its Q is S̄ (L = I), W is the process noise,
    # V is R. Its update computes P_{k+1} = F P L Fᵀ + W (so P matches ours), but its gain F P L HᵀV⁻¹
    # already contains F and is added to the un-propagated x, which predict multiplies by F again:
    # x_{k+1} = F x + F² K (y − H x) instead of F x + F K (y − H x). With F = I the two coincide.
    rng = np.random.default_rng(2)
    if case == "F = I":
        F, H = np.eye(2), np.eye(2)
    else:
        F, H = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[1.0, 0.0]])
    sysm, meas = _model(F, H, np.diag([0.1, 0.2]), 0.5 * np.eye(H.shape[0]))
    theta, P0 = 0.05, np.eye(2)
    est = RecursiveHInfinityFilter(sysm, meas, theta=theta, P0=P0)
    y = rng.standard_normal((1, 60, H.shape[0]))
    hist = est.estimate(y, np.zeros((1, 60, 0)), np.zeros(2))
    f = _filterpy(F, H, sysm.Q, meas.R, theta, P0)
    xs = np.empty((60, 2))
    for k in range(60):
        np.testing.assert_allclose(f.P, hist.P[0, k], rtol=1e-12, atol=1e-14)  # same P recursion
        x = xs[k] = f.x.ravel()
        K = est.riccati_step(f.P, k)[0]
        f.update(y[0, k].reshape(-1, 1))
        f.predict()
        np.testing.assert_allclose(f.x.ravel(), F @ x + F @ F @ K @ (y[0, k] - H @ x), rtol=1e-12, atol=1e-12)
    if case == "F = I":
        np.testing.assert_allclose(xs, hist.xhat[0], rtol=1e-12, atol=1e-12)
    else:
        assert np.abs(xs - hist.xhat[0]).max() > 1e-2  # the estimates do differ


def test_existence_condition_checked_every_step():
    F, H, Bq, Dv, rng = _random(4)
    sysm, meas = _model(F, H, Bq, Dv)
    theta_max = max_admissible_theta(F, H, Bq @ Bq.T, Dv @ Dv.T)
    y = rng.standard_normal((2, 200, 2))
    u = np.zeros((2, 200, 0))
    ok = RecursiveHInfinityFilter(sysm, meas, theta=0.5 * theta_max, P0=Bq @ Bq.T + 1e-3 * np.eye(3))
    hist = ok.estimate(y, u, np.zeros(3), diagnostics=True)
    assert hist.diagnostics["existence_ok"].all() and (hist.diagnostics["existence_margin"] > 0).all()
    bad = RecursiveHInfinityFilter(sysm, meas, theta=3.0 * theta_max, P0=np.eye(3))
    with pytest.raises(hn.InputError, match=r"theta = .* violates the existence condition .* step"):
        bad.estimate(y, u, np.zeros(3))
    flag = RecursiveHInfinityFilter(sysm, meas, theta=3.0 * theta_max, P0=np.eye(3), on_violation="flag")
    hist = flag.estimate(y, u, np.zeros(3), diagnostics=True)
    assert not hist.diagnostics["existence_ok"].all()


def test_steady_gain_on_the_chaser_is_the_steady_state_hinf(short_scenario):
    # the registered filter's P after its recursion has converged equals steady_state_hinf's (same θ)
    est = build_estimator(short_scenario, "recursive_hinf")
    theta_max = max_admissible_theta(est.F, est.H, est.Q, est.R)
    assert est.theta == pytest.approx(0.5 * theta_max, rel=1e-12)
    P_ss, K_ss = steady_state_hinf(est.F, est.H, est.Q, est.R, est.theta)
    P, steady = est.P0, None
    for k in range(20000):
        K, P, _, _, steady = est._gain(P, k, steady)
        if steady is not None:
            break
    np.testing.assert_allclose(P, P_ss, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(K, K_ss, rtol=1e-8, atol=1e-10)


def test_theta_zero_on_the_chaser_sits_at_the_open_loop_kalman_limit(short_scenario):
    # stationary error at θ = 0 = the predicted Kalman limit without maneuver (the filter is told the thrust,
    # so its error obeys the open-loop model): 0.0802 m, 0.0224 m/s per axis (hinfnav.papers.sun2011.limits)
    st = theta_study(short_scenario, fractions=(0.0, 0.9), runs=2)
    kl = sun2011.kalman_limit(short_scenario, maneuver=False)
    assert st.pos_m_stat[0] == pytest.approx(np.sqrt(np.mean(kl.pos_m_predicted**2)), rel=1e-9)
    assert st.vel_mps_stat[0] == pytest.approx(np.sqrt(np.mean(kl.vel_mps_predicted**2)), rel=1e-9)
    assert st.vel_mps_stat[1] > st.vel_mps_stat[0]  # θ > 0 gives up accuracy in the mean-square sense


def test_frozen_gain_equals_the_full_recursion_and_uses_the_one_freeze():
    # the freeze is the package's one (steady.freeze_gain, rule (F2) every step): frozen and never-frozen filters
    # agree to 1e-9 relative (identity up to the 1e-14-per-step change the freeze ignores, over 600 steps)
    from hinfnav.estimators.steady import freeze_gain

    F, H, Bq, Dv, rng = _random(2, rho=0.9)
    sysm, meas = _model(F, H, Bq, Dv)
    theta = 0.5 * max_admissible_theta(F, H, Bq @ Bq.T, Dv @ Dv.T)
    y, u = rng.standard_normal((2, 600, 2)), np.zeros((2, 600, 0))
    kw = dict(theta=theta, P0=Bq @ Bq.T + 1e-3 * np.eye(3), uses_input=False)
    frozen = RecursiveHInfinityFilter(sysm, meas, **kw)
    full = RecursiveHInfinityFilter(sysm, meas, steady_tol=None, **kw)
    a = frozen.estimate(y, u, np.zeros(3))
    b = full.estimate(y, u, np.zeros(3))
    np.testing.assert_allclose(a.xhat, b.xhat, rtol=1e-9, atol=1e-12)
    state = frozen.start(np.zeros(3), runs=2)
    for k in range(600):
        state, _ = frozen.update(state, y[:, k])
        state = frozen.predict(state, None)
    assert state.extra["steady"] is not None  # the recursion did converge and freeze within 600 steps
    # (F2) by hand: ‖P − P_old‖_F ≤ tol ‖P_old‖_F, checked every step with every=1
    P_old = np.eye(2)
    assert freeze_gain(1e-3, 0, {"check_P": P_old}, every=1, rule="frobenius", P=P_old * (1 + 0.9e-3)) is not None
    assert freeze_gain(1e-3, 0, {"check_P": P_old}, every=1, rule="frobenius", P=P_old * (1 + 1.1e-3)) is None
    with pytest.raises(hn.InputError, match="rule"):
        freeze_gain(1e-3, 0, {}, every=1, rule="max", P=P_old)
