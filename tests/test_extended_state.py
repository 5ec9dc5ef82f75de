"""Algorithms 1-3 of Yang et al. (2020) (hinfnav.estimators.extended_state).

Expected values come from independent computations written here (a plain
Kalman filter, a scalar loop of Algorithm 2 with scipy.stats.truncnorm's
moments, the printed formulas of Algorithm 1 and of the fusion (38)-(43)), or
from closed forms (θ*).
"""

import numpy as np
import pytest
from scipy.stats import truncnorm

import hinfnav as hn
from hinfnav.estimators.extended_state import ExtendedStateKalmanFilter, theta_star
from hinfnav.estimators.saturated_state import FusedExtendedStateFilter, SaturatedExtendedStateFilter
from hinfnav.papers.yang2020 import Scenario, build_alg1, build_alg2, build_fused
from hinfnav.sim import simulate_truth
from hinfnav.systems import LinearMeasurement

SC = Scenario(n_steps=400)


@pytest.fixture(scope="module")
def in_range():
    """Drag-free axes under the linear ADRC, disturbance -3 mN: the accelerometers never saturate."""
    model = SC.truth_model("dragfree", disturbance=-3e-3)
    tr = simulate_truth(model, runs=2, seed=5)
    assert not np.any(model.measurement.clip(tr.y)[1])
    return tr


@pytest.fixture(scope="module")
def saturating():
    """Clipped readings that cross the lower bound back and forth (synthetic: the filters need no truth here)."""
    k = np.arange(200)[:, None]
    y = -6e-6 + 3e-6 * np.sin(k / 25.0 + np.array([0.0, 2.0, 4.0])) + 1e-6 * np.sin(k / 3.0)
    y = np.clip(y, -6e-6, 6e-6)[None]
    flags = y <= -6e-6
    assert 0.3 < flags.mean() < 0.7
    return y, np.zeros((1, 200, 3))


def _plain_kf(alg, y, u):
    """Kalman filter with Algorithm 1's prediction, written out for the 9-state block system (no saturation)."""
    F, G, H = alg.system.Phi, alg.system.Gamma, alg.measurement.H
    theta = np.repeat(alg.theta, 1)[0]
    Q = np.zeros((9, 9))
    f = np.arange(6, 9)
    Q[f, f] = (1 + 1 / theta) * 4 * alg.q
    Q += G @ np.diag(alg.Sv) @ G.T
    R = np.diag(alg.Reff)
    x, P = np.zeros(9), 0.01 * np.eye(9)
    out = []
    for k in range(y.shape[0]):
        S = H @ P @ H.T + R
        K = P @ H.T @ np.linalg.inv(S)
        x = x + K @ (y[k] - H @ x)
        P = (np.eye(9) - K @ H) @ P
        out.append(x)
        x = F @ x + G @ u[k]
        P = (1 + theta) * F @ P @ F.T + Q
    return np.array(out)


def _close(a, b, tol):
    """Largest difference, component by component, relative to the largest |b| of that component."""
    scale = np.maximum(np.abs(b).max(axis=tuple(range(b.ndim - 1))), 1e-300)
    return np.all(np.abs(a - b).max(axis=tuple(range(b.ndim - 1))) <= tol * scale)


def test_algorithm2_equals_the_kalman_filter_when_nothing_saturates(in_range):
    alg = build_alg2(SC)
    assert np.all(alg.theta == alg.theta[0])  # three identical axes
    xhat = alg.estimate(in_range.y, in_range.u, np.zeros(9)).xhat
    for r in range(2):
        ref = _plain_kf(alg, in_range.y[r], in_range.u[r])
        # identity of (31)-(32) with the Kalman update (Joseph form against (I - KH)P): round-off only
        assert _close(xhat[r], ref, 1e-10)


def test_algorithm2_equals_algorithm1_on_the_same_system(in_range):
    # Algorithm 1's class on the 9-state block system with R + D^2 S and theta* of Algorithm 2: the same filter
    alg2 = build_alg2(SC)
    meas = LinearMeasurement(alg2.measurement.H, np.diag(np.sqrt(alg2.Reff)))
    Be = np.zeros((9, 3))
    Be[6:, :] = np.eye(3)
    alg1 = ExtendedStateKalmanFilter(alg2.system, meas, P0=0.01 * np.eye(9), B_e=Be, q=alg2.q / 3,  # l = 3 here
                                     S=np.diag(alg2.Sv), theta=alg2.theta[0])
    a = alg2.estimate(in_range.y, in_range.u, np.zeros(9)).xhat
    b = alg1.estimate(in_range.y, in_range.u, np.zeros(9)).xhat
    assert _close(a, b, 1e-10)


def _alg2_scalar(alg, y, mode):
    """Algorithm 2 for axis x as printed, one step at a time, with scipy.stats.truncnorm's moments (29)-(30)."""
    Ad, Bd, C, D = alg.A[0], alg.Bu[0], alg.C[0], alg.Dff[0]
    R, S, q = alg.Rv[0], alg.Sv[0], alg.q[0]
    lo, up = alg.lower[0], alg.upper[0]
    theta = np.sqrt(4 * q / 0.03)
    e3 = np.array([0.0, 0.0, 1.0])
    Q = (1 + 1 / theta) * 4 * q * np.outer(e3, e3) + S * np.outer(Bd, Bd)
    x, P = np.zeros(3), 0.01 * np.eye(3)
    out = []
    for yk in y:
        yhat = C @ x
        Sy = C @ P @ C + R + D**2 * S
        K = P @ C / Sy
        Pstar = (np.eye(3) - np.outer(K, C)) @ P @ (np.eye(3) - np.outer(K, C)).T + (R + D**2 * S) * np.outer(K, K)
        sat = yk <= lo or yk >= up
        if not sat or mode == "ideal":
            x, P = x + K * (yk - yhat), Pstar
        elif mode == "truncated":
            a, b = (-np.inf, lo) if yk <= lo else (up, np.inf)
            sd = np.sqrt(Sy)
            tn = truncnorm((a - yhat) / sd, (b - yhat) / sd, loc=yhat, scale=sd)
            x, P = x + K * (tn.mean() - yhat), Pstar + tn.var() * np.outer(K, K)
        out.append(x)
        x = Ad @ x
        P = (1 + theta) * Ad @ P @ Ad.T + Q
    return np.array(out)


@pytest.mark.parametrize("mode", ["truncated", "skip", "ideal"])
def test_algorithm2_matches_a_scalar_loop_of_the_printed_algorithm(saturating, mode):
    y, u = saturating
    alg = build_alg2(SC, mode=mode)
    xhat = alg.estimate(y, u, np.zeros(9)).xhat[0]
    for a in range(3):
        ref = _alg2_scalar(alg, y[0, :, a], mode)
        # the same algorithm computed two ways; scipy's truncnorm moments agree with ours to ~1e-12
        assert _close(xhat[:, [a, 3 + a, 6 + a]], ref, 1e-9)
    if mode == "skip":  # no update while clipped: the estimate then only moves by the prediction
        sat = y[0, :, 0] <= -6e-6
        k = np.nonzero(sat[1:] & sat[:-1])[0][5] + 1
        np.testing.assert_allclose(xhat[k, [0, 3, 6]], alg.A[0] @ xhat[k - 1, [0, 3, 6]], rtol=1e-12)


def test_truncated_update_adds_the_truncated_variance():
    alg = build_alg2(SC)
    X = np.zeros((1, 3, 3))
    P = np.broadcast_to(alg.P0, (1, 3, 3, 3)).copy()
    y = np.array([[-7e-6, 2e-6, 8e-6]])  # below, inside, above the range
    Xp, Pp, innov, sat, K = alg.kernel_update(X, P, y, np.zeros((1, 3)))
    np.testing.assert_array_equal(sat, [[True, False, True]])
    Sy = alg.C[0] @ alg.P0[0] @ alg.C[0] + alg.Reff[0]
    sd = np.sqrt(Sy)
    for a, (lo, hi) in ((0, (-np.inf, -6e-6)), (2, (6e-6, np.inf))):
        tn = truncnorm(lo / sd, hi / sd, loc=0.0, scale=sd)  # scipy takes standardized bounds
        assert innov[0, a] == pytest.approx(tn.mean(), rel=1e-10)
        Kk = K[0, a]
        IKC = np.eye(3) - np.outer(Kk, alg.C[a])
        expect = IKC @ alg.P0[a] @ IKC.T + (alg.Reff[a] + tn.var()) * np.outer(Kk, Kk)  # (34)
        np.testing.assert_allclose(Pp[0, a], expect, rtol=1e-10, atol=1e-22)
    assert innov[0, 1] == 2e-6  # inside the range: the reading itself (31)


def test_skip_keeps_the_prediction_and_ideal_never_flags():
    y = np.array([[-7e-6, -7e-6, -7e-6]])
    X = np.full((1, 3, 3), 1e-3)
    P = np.broadcast_to(0.01 * np.eye(3), (1, 3, 3, 3)).copy()
    Xs, Ps, _, sat, _ = build_alg2(SC, mode="skip").kernel_update(X, P, y, np.zeros((1, 3)))
    assert sat.all()
    np.testing.assert_array_equal(Xs, X)
    np.testing.assert_array_equal(Ps, P)
    Xi, _, _, sat_i, _ = build_alg2(SC, mode="ideal").kernel_update(X, P, y, np.zeros((1, 3)))
    assert not sat_i.any() and not np.array_equal(Xi, X)


def test_algorithm1_theta_star_and_prediction():
    alg = build_alg1(SC)
    q = SC.q
    # θ* = √(tr Q1 / tr P0), Q1 = 4 B_e (l diag q) B_eᵀ, l = 9, P0 = 0.01 I_27
    assert alg.theta == pytest.approx(np.sqrt(4 * 9 * q.sum() / (27 * 0.01)), rel=1e-14)
    assert theta_star(alg.Q1, alg.P0) == alg.theta
    P = np.diag(np.linspace(1e-6, 1e-3, 27))
    m = SC.model
    expect = (1 + alg.theta) * m.A_d @ P @ m.A_d.T + (1 + 1 / alg.theta) * 4 * 9 * m.B_e @ np.diag(q) @ m.B_e.T \
        + m.B_d @ np.diag(SC.input_std**2) @ m.B_d.T
    np.testing.assert_allclose(alg.predict_covariance(P, None), expect, rtol=1e-12, atol=1e-30)
    st = alg.start(np.zeros(27), runs=1)
    st, out = alg.update(st, np.zeros((1, 9)))
    assert out.diagnostics["theta"][0] == alg.theta


def test_nominal_increment_is_clipped_to_sqrt_q():
    # (9): Ĝ = sat(f̄_{k+1} − f̄_k, ±√q); a nominal model growing 1 mN per step exceeds √q ≈ 5.8 µN
    m = SC.model
    alg = ExtendedStateKalmanFilter(build_alg1(SC).system, build_alg1(SC).measurement, P0=SC.P0, B_e=m.B_e, q=SC.q,
                                    S=np.diag(SC.input_std**2), nominal=lambda k: np.full(9, 1e-3 * k))
    st = alg.start(np.zeros(27), runs=1)
    st2 = alg._predict(st, np.zeros((1, 9)))  # the prediction hook alone (the public predict needs an update first)
    G = st2.x[0, [6, 7, 8, 15, 16, 17, 24, 25, 26]]
    np.testing.assert_allclose(G, np.r_[np.sqrt(SC.q[:6]), np.zeros(3)], rtol=1e-12)


@pytest.mark.parametrize("reading", ["symmetric", "printed", "block"])
def test_fusion_eqs_38_to_43(reading):
    fused = build_fused(SC, covariance=reading)
    rng = np.random.default_rng(1)
    st = fused.start(np.zeros(27), runs=1)
    y = np.r_[rng.normal(0, 1e-7, 9), -2e-6, 1e-6, 3e-6][None]
    st1, out = fused.update(st, y)
    # the two algorithms on their own, from the same prior
    a1 = fused.alg1
    s1 = a1.start(np.zeros(27), runs=1)
    _, o1 = a1.update(s1, y[:, :9])
    X2, P2, _, _, _ = fused.alg2.kernel_update(st.extra["X2"], st.extra["P2"], y[:, 9:], np.zeros((1, 3)))
    idx = fused.idx
    np.testing.assert_allclose(out.xhat[0, idx[:6]], o1.xhat[0, idx[:6]], rtol=1e-12)  # r, ṙ of Algorithm 1 (38)
    np.testing.assert_allclose(out.xhat[0, idx[6:]], X2[0, :, 2], rtol=1e-12)  # f of Algorithm 2
    P = out.P[0]
    others = np.setdiff1d(np.arange(27), idx)
    assert np.all(P[np.ix_(idx, others)] == 0) and np.all(P[np.ix_(others, idx)] == 0)  # (41) zeroes them
    blk = np.array([idx[0], idx[3], idx[6]])  # axis x: r, ṙ, f
    P1 = o1.P if o1.P.ndim == 2 else o1.P[0]
    Po = P1[np.ix_(blk, blk)].copy()
    Po[2] = P2[0, 0, 2]  # Λ1 P1 + Λ2 P2 (39): rows r, ṙ from P1, row f from P2
    if reading == "symmetric":
        Po = 0.5 * (Po + Po.T)
    elif reading == "block":
        Po[:2, 2] = Po[2, :2] = 0.0
    np.testing.assert_allclose(P[np.ix_(blk, blk)], Po, rtol=1e-12, atol=1e-30)
    np.testing.assert_allclose(st1.extra["P2"][0, 0], Po, rtol=1e-12, atol=1e-30)  # (43)
    assert (reading == "printed") == (not np.allclose(P, P.T, rtol=0, atol=0))


def _frozen_run(fused, tr):
    st = fused.start(np.zeros(27), runs=1)
    xhat, k_freeze = [], None
    for k in range(tr.y.shape[1]):
        st, out = fused.update(st, tr.y[:, k])
        xhat.append(out.xhat[0])
        if k_freeze is None and st.extra["steady"] is not None:
            k_freeze = k
        st = fused.predict(st, tr.u[:, k])
    return np.array(xhat), k_freeze


def test_frozen_gains_match_the_full_recursion():
    # identical until the gains freeze; after, the estimates move by a fraction of their own errors that
    # shrinks with steady_tol (linearly: the distance to the limit is ~steady_tol/θ); T_Dtm (no process
    # noise, its recursion converges at the rate θ) is the slowest and is left out of the bound
    model = SC.truth_model("full", disturbance=-3e-3, n_steps=2200)
    tr = simulate_truth(model, runs=1, seed=4)
    exact = build_fused(SC).estimate(tr.y, tr.u, np.zeros(27)).xhat[0]
    keep = np.r_[0:24]
    ratios = []
    for tol in (1e-2, 3e-3):
        frozen, k = _frozen_run(build_fused(SC, steady_tol=tol), tr)
        assert k is not None and k > 500
        np.testing.assert_array_equal(frozen[:k], exact[:k])
        err = np.sqrt(np.mean((tr.x[0] - exact)[k:] ** 2, axis=0))
        ratios.append((np.abs(frozen - exact)[k:].max(axis=0) / err)[keep].max())
    assert ratios[1] < 0.1 and ratios[1] < 0.5 * ratios[0], ratios


def test_bad_inputs_name_the_parameter():
    m = SC.model
    with pytest.raises(hn.InputError, match="mode"):
        build_alg2(SC, mode="clip")
    with pytest.raises(hn.InputError, match="lower"):
        SaturatedExtendedStateFilter(m.axis_A_d, m.axis_B_d, m.axis_C, m.axis_D, R=1e-24, S=1e-16, q=1e-11,
                                     P0=np.eye(3), lower=1.0, upper=-1.0, dt=0.1)
    with pytest.raises(hn.InputError, match="q"):
        ExtendedStateKalmanFilter(build_alg1(SC).system, build_alg1(SC).measurement, P0=SC.P0, B_e=m.B_e,
                                  q=-SC.q)
    with pytest.raises(hn.InputError, match="alg1"):
        FusedExtendedStateFilter(build_alg2(SC), build_alg2(SC), indices=np.arange(9), input_indices=[3, 4, 5])
    with pytest.raises(hn.InputError, match="indices"):
        FusedExtendedStateFilter(build_alg1(SC), build_alg2(SC), indices=np.arange(8), input_indices=[3, 4, 5])
    with pytest.raises(hn.InputError, match="fused covariance"):
        build_fused(SC, covariance="average")
    with pytest.raises(hn.InputError, match="steady_tol"):
        build_alg1(SC, steady_tol=-1.0)
