"""Square-root filters (:mod:`hinfnav.estimators.sqrt`): equal to the covariance (Joseph) forms where those are
well conditioned, and alive where those fail.

Expected values: the covariance forms of the package (their own tests tie them to filterpy); an exact-rational
Kalman filter written in this file (``fractions.Fraction``: no rounding at all) for P₀ = 10¹² I, R = 10⁻¹⁰ I;
Stone Soup's covariance-stability set-up (``stonesoup/updater/tests/test_kalman.py``,
``test_kalman_covariance_stability``: the prior covariance below, positions measured, a constant-velocity
prediction without process noise; R = 10⁻¹⁰ I here, a covariance the filters accept) and its square-root test's
published answer ``diag(0.04, 1e24)`` (``test_sqrt_kalman``).
"""

from fractions import Fraction

import numpy as np
import pytest

from hinfnav.core.exceptions import HinfnavError, InputError
from hinfnav.estimators import ExtendedKalmanFilter, HuberFilter, SigmaPointFilter
from hinfnav.estimators.smoothers import smooth
from hinfnav.estimators.sqrt import SquareRootEKF, chol_downdate, square_root, tria
from hinfnav.systems import ConstantTurn, LinearMeasurement, LinearSystem, RangeBearing
from hinfnav.systems.state import StateSpec

from test_smoothers import linear_record


def spec(n):
    return StateSpec(tuple(f"x{i}" for i in range(n)), ("",) * n)


def test_tria_and_downdate():
    rng = np.random.default_rng(0)
    A = rng.standard_normal((3, 4, 9))
    S = tria(A)
    np.testing.assert_allclose(S @ np.swapaxes(S, -1, -2), A @ np.swapaxes(A, -1, -2), rtol=1e-13, atol=1e-12)
    assert np.all(np.triu(S, 1) == 0) and np.all(np.diagonal(S, axis1=-2, axis2=-1) > 0)
    v = 0.3 * rng.standard_normal((3, 4))
    L = chol_downdate(S, v)  # closed form: L Lᵀ = S Sᵀ − v vᵀ
    np.testing.assert_allclose(L @ np.swapaxes(L, -1, -2), S @ np.swapaxes(S, -1, -2) - v[:, :, None] * v[:, None, :],
                               rtol=1e-12, atol=1e-12)
    with pytest.raises(np.linalg.LinAlgError):
        chol_downdate(S, 100 * v)


@pytest.mark.parametrize("missing", ["refuse", "skip"])
def test_sqrt_kalman_equals_joseph_on_a_well_conditioned_record(missing):
    system, meas, P0, _, y = linear_record(runs=3, N=40)
    if missing == "skip":
        y[1, 5] = np.nan
        y[2, 7, 0] = np.nan
    kf = ExtendedKalmanFilter(system, meas, P0=P0, missing=missing)
    u = np.zeros(y.shape[:2] + (1,))
    a = kf.estimate(y, u, np.zeros(4), diagnostics=True)
    b = square_root(kf).estimate(y, u, np.zeros(4), diagnostics=True)
    np.testing.assert_allclose(b.xhat, a.xhat, rtol=0, atol=1e-10 * np.abs(a.xhat).max())
    np.testing.assert_allclose(b.P, a.P, rtol=0, atol=1e-10 * np.abs(a.P).max())
    S_a, S_b = a.diagnostics["innovation_covariance"], b.diagnostics["innovation_covariance"]
    np.testing.assert_allclose(S_b, np.broadcast_to(S_a, S_b.shape), rtol=0, atol=1e-10 * np.abs(S_a).max())


CT = ConstantTurn(1.0, sigma_accel=0.05, sigma_turn_rate=1e-3)
RB = RangeBearing(5, sigma_range=5.0, sigma_bearing=0.01)
X0 = np.array([-1000.0, 150.0, 0.0, -12.0, 0.02])
P0_CT = np.diag([30.0, 30.0, 3.0, 3.0, 0.03]) ** 2


def turn_record(N=40):
    rng = np.random.default_rng(0)
    X = np.empty((2, N, 5))
    X[:, 0] = X0
    for k in range(1, N):
        X[:, k] = CT.f(X[:, k - 1])
    return RB.measure(X, rng.standard_normal((2, N, 2)))


@pytest.mark.parametrize("rule, options", [("unscented", {}), ("cubature", {}),
                                           ("unscented", {"alpha": 0.5}),  # W₀ᶜ = −0.25: a downdate
                                           ("unscented", {"alpha": 1.0, "beta": 0.0, "kappa": -2.0}),
                                           ("ekf", {})])
def test_sqrt_sigma_point_and_ekf_equal_covariance_forms_on_the_turn(rule, options):
    Y = turn_record()
    est = (ExtendedKalmanFilter(CT, RB, P0=P0_CT) if rule == "ekf"
           else SigmaPointFilter(CT, RB, P0=P0_CT, rule=rule, **options))
    a = est.estimate(Y, np.zeros((2, 40, 0)), X0)
    b = square_root(est).estimate(Y, np.zeros((2, 40, 0)), X0)
    np.testing.assert_allclose(b.xhat, a.xhat, rtol=0, atol=1e-10 * np.abs(a.xhat).max())
    np.testing.assert_allclose(b.P, a.P, rtol=0, atol=1e-10 * np.abs(a.P).max())


def exact_kalman(system, H, R, P0, y):
    """The Kalman filter in exact rational arithmetic (x̂(k|k), P(k|k)), from the floats given."""
    F = [[Fraction(v) for v in r] for r in system.Phi]
    Q = [[Fraction(v) for v in r] for r in system.Q]
    Hf = [[Fraction(v) for v in r] for r in H]
    Rf = [[Fraction(v) for v in r] for r in R]
    mm = lambda A, B: [[sum(A[i][k] * B[k][j] for k in range(len(B))) for j in range(len(B[0]))] for i in range(len(A))]
    T = lambda A: [list(r) for r in zip(*A)]
    add = lambda A, B: [[a + b for a, b in zip(ra, rb)] for ra, rb in zip(A, B)]
    sub = lambda A, B: [[a - b for a, b in zip(ra, rb)] for ra, rb in zip(A, B)]

    def inv2(S):
        a, b, c, d = S[0][0], S[0][1], S[1][0], S[1][1]
        det = a * d - b * c
        return [[d / det, -b / det], [-c / det, a / det]]

    P = [[Fraction(v) for v in r] for r in P0]
    x = [[Fraction(0)] for _ in range(len(P))]
    xs, Ps = [], []
    for yk in y:
        K = mm(mm(P, T(Hf)), inv2(add(mm(mm(Hf, P), T(Hf)), Rf)))
        x = add(x, mm(K, sub([[Fraction(v)] for v in yk], mm(Hf, x))))
        P = sub(P, mm(mm(K, Hf), P))
        xs.append([float(v[0]) for v in x])
        Ps.append([[float(v) for v in r] for r in P])
        x, P = mm(F, x), add(mm(mm(F, P), T(F)), Q)
    return np.array(xs), np.array(Ps)


def test_p0_1e12_and_r_1e_minus_10_against_exact_arithmetic():
    system, meas, _, _, y = linear_record(runs=1, N=8)
    P0, R = 1e12 * np.eye(4), 1e-10 * np.eye(2)
    xe, Pe = exact_kalman(system, meas.H, R, P0, y[0])
    u = np.zeros((1, 8, 1))
    def rel(h):  # the largest error relative to each step's scale
        return ((np.abs(h.xhat[0] - xe).max(axis=1) / np.abs(xe).max(axis=1)).max(),
                (np.abs(h.P[0] - Pe).max(axis=(1, 2)) / np.abs(Pe).max(axis=(1, 2))).max())

    kf = ExtendedKalmanFilter(system, meas, P0=P0, R=R)
    ckf = SigmaPointFilter(system, meas, P0=P0, R=R, rule="cubature")
    for est in (square_root(kf), square_root(ckf)):
        ex, eP = rel(est.estimate(y, u, np.zeros(4)))
        assert ex < 1e-10 and eP < 1e-10, (est.name, ex, eP)  # measured: ≤ 1.5e-11 (P of step 1)
    ex, eP = rel(kf.estimate(y, u, np.zeros(4)))
    assert eP > 1e-4 and ex > 1e-5  # the Joseph form runs but its P is off by 1.7e-3, x̂ by 2.7e-4 (measured)
    with pytest.raises(HinfnavError, match="not positive definite"):
        ckf.estimate(y, u, np.zeros(4))  # the covariance-form cubature filter stops at step 0


STONESOUP_P = np.array([
    [1.64385383e06, 1.00001250e06, -2.48073899e05, -5.86573934e-08, -4.03756199e05, -5.86573934e-08],
    [1.00001250e06, 1.00002500e06, 5.24472545e-09, 0.0, -3.90355011e-08, 0.0],
    [-2.48073899e05, 5.24472545e-09, 2.03087457e06, 1.92001250e06, 1.58877383e05, 1.34045255e-08],
    [-5.86573934e-08, 0.0, 1.92001250e06, 1.92002500e06, -2.38775732e-09, 0.0],
    [-4.03756199e05, -3.90355011e-08, 1.58877383e05, -2.38775732e-09, 2.19190854e06, 1.92001250e06],
    [-5.86573934e-08, 0.0, 1.34045255e-08, 0.0, 1.92001250e06, 1.92002500e06]])


@pytest.mark.parametrize("rule", ["cubature", "unscented"])
def test_stone_soup_covariance_stability_setup(rule):
    system = LinearSystem(np.kron(np.eye(3), [[1.0, 1.0], [0.0, 1.0]]), np.zeros((6, 1)), np.zeros((6, 1)), 1.0,
                          spec(6))
    H = np.zeros((3, 6))
    H[0, 0] = H[1, 2] = H[2, 4] = 1.0
    meas = LinearMeasurement(H, np.eye(3))
    est = SigmaPointFilter(system, meas, P0=STONESOUP_P, R=1e-10 * np.eye(3), rule=rule)
    y = np.zeros((1, 20, 3))
    with pytest.raises(HinfnavError, match="step 0"):
        est.estimate(y, np.zeros((1, 20, 1)), np.zeros(6))
    sq = square_root(est)
    state = sq.start(np.zeros(6))
    for k in range(20):
        state, out = sq.update(state, y[:, k])
        if k == 0:  # positions pinned by the readings: P⁺ = (P⁻¹ + R⁻¹)⁻¹ ≈ R on them (to 1e-10 relative)
            np.testing.assert_allclose(np.diag(out.P[0])[[0, 2, 4]], 1e-10, rtol=1e-6)
        state = sq.predict(state)
        S = state.extra["S"][0]
        assert np.all(np.isfinite(S)) and np.all(np.isfinite(state.x))
        # definiteness measured without forming P: the singular values of its factor (σ² are P's eigenvalues)
        assert np.linalg.svd(S, compute_uv=False).min() > 0


def test_stone_soup_sqrt_kalman_1e24_prior():
    # Stone Soup's test_sqrt_kalman: P⁻ = [[1e24, 1e-24], [1e-24, 1e24]], H = [1 0], R = 0.04, reading −6.23;
    # its published posterior covariance diag(0.04, 1e24), to rtol 5e-3
    system = LinearSystem(np.eye(2), np.zeros((2, 1)), np.zeros((2, 1)), 1.0, spec(2))
    meas = LinearMeasurement([[1.0, 0.0]], [[0.2]])
    sq = SquareRootEKF(system, meas, P0=np.array([[1e24, 1e-24], [1e-24, 1e24]]))
    state, out = sq.update(sq.start(np.array([-6.45, 0.7])), np.array([[-6.23]]))
    np.testing.assert_allclose(out.P[0], np.diag([0.04, 1e24]), rtol=5e-3, atol=5e-3 * 0.04)
    np.testing.assert_allclose(out.xhat[0, 0], -6.23, rtol=1e-12)


def test_square_root_refusals_and_smoothing():
    system, meas, P0, _, y = linear_record(runs=2, N=20)
    with pytest.raises(InputError, match="no square-root form"):
        square_root(HuberFilter(system, meas, P0=P0))
    kf = ExtendedKalmanFilter(system, meas, P0=P0)
    a, b = smooth(kf, y, None, np.zeros(4)), smooth(square_root(kf), y, None, np.zeros(4))
    np.testing.assert_allclose(b.xhat, a.xhat, rtol=0, atol=1e-10 * np.abs(a.xhat).max())
    ukf = SigmaPointFilter(system, meas, P0=P0, rule="cubature")
    c, d = smooth(ukf, y, None, np.zeros(4)), smooth(square_root(ukf), y, None, np.zeros(4))
    np.testing.assert_allclose(d.xhat, c.xhat, rtol=0, atol=1e-10 * np.abs(c.xhat).max())
    np.testing.assert_allclose(c.xhat, a.xhat, rtol=0, atol=1e-10 * np.abs(a.xhat).max())  # linear: URTS = RTS


def test_build_estimator_covariance_form_sqrt():
    import hinfnav.papers  # noqa: F401  (registers the papers' estimators)
    from hinfnav.estimators import build_estimator
    from hinfnav.papers import sun2011
    scenario = sun2011.Scenario()
    assert type(build_estimator(scenario, "ekf", covariance_form="sqrt")).__name__ == "SquareRootEKF"
    assert type(build_estimator(scenario, "ekf")).__name__ == "ExtendedKalmanFilter"
    with pytest.raises(InputError, match="no square-root form"):
        build_estimator(scenario, "published", covariance_form="sqrt")
    with pytest.raises(InputError, match="covariance_form"):
        build_estimator(scenario, "ekf", covariance_form="cholesky")
