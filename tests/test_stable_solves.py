"""Numerically stable small solves (issue 32, item 4): both backends against an extended-precision reference.

The compiled kernels invert the innovation covariance S by its Cholesky
factor (``inv_to``; :func:`hinfnav.core.linalg.inv_spd_cholesky` is the same
operations in the same order in NumPy). The NumPy reference path keeps the
adjugate :func:`~hinfnav.core.linalg.inv_spd` for now (the papers' numbers are
rounding-sensitive: see core.linalg), with its own, looser tolerance below. The expected values are
computed in this file in ``numpy.longdouble`` (x87 extended precision, unit
round-off 5.4e-20): a Gauss-Jordan inverse with partial pivoting and a
Kalman / strong-tracking filter written out in long double.

Documented tolerances (each asserted below, with its cause):

* S ill-conditioned by the units of its channels (condition 1e12, a
  well-conditioned correlation matrix): both paths equal the long-double
  filter and each other to 1e-10 (Cholesky is invariant under diagonal
  scaling).
* S ill-conditioned by correlation (condition 1e12 of its correlation
  matrix): no backward-stable double-precision solve does better than about
  κ(S)·u = 1e-4 in the worst case; both paths stay within 1e-7 of the
  long-double filter (measured about 3e-9) and within 1e-10 at condition 1e6.
* Strong tracking: to 1e-10 with fading factors up to about 1e6; with
  factors of 1e10 (a 1e5 σ outlier) the Joseph update subtracts terms λ times
  larger than its result, both paths then within 1e-7 of the long-double
  filter (measured 1e-9 to 1e-8).
* Huber with an unconverged iteration: one update on the same inputs agrees to
  1e-9; over a filter run the truncated iteration amplifies rounding: the
  NumPy path itself moves by about 1e-3 when y is changed by one unit in the
  last place (max_iter = 2), and the two paths differ by no more than that.
"""

import numpy as np
import pytest

from hinfnav.core.linalg import inv_spd_cholesky as inv_spd  # the kernels' form (the NumPy path keeps the adjugate: see core.linalg)
from hinfnav.estimators import ExtendedKalmanFilter, HuberFilter, build_estimator
from hinfnav.estimators.huber import huber_correct
from hinfnav.papers.sun2011 import Scenario
from hinfnav.sim import simulate_truth
from hinfnav.systems import LinearMeasurement, LinearSystem, StateSpec

LD = np.longdouble
U = np.finfo(float).eps / 2
SUN = Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0))


def _inv_ld(S):
    """Gauss-Jordan inverse with partial pivoting in long double (the reference)."""
    n = S.shape[0]
    A = np.concatenate([np.asarray(S, dtype=LD), np.eye(n, dtype=LD)], axis=1)
    for c in range(n):
        p = c + int(np.argmax(np.abs(A[c:, c])))
        A[[c, p]] = A[[p, c]]
        A[c] /= A[c, c]
        for r in range(n):
            if r != c:
                A[r] -= A[r, c] * A[c]
    return A[:, n:]


def _kalman_ld(F, H, Q, R, P0, y, x0, fading=None, Gu=None):
    """The Kalman filter (J1)-(J2) in long double; with ``fading=(rho, beta, a)`` strong tracking (S1)-(S4);
    ``Gu`` (steps, n) the input's effect G u_k."""
    F, H, Q, R = (np.asarray(M, dtype=LD) for M in (F, H, Q, R))
    x, P = np.asarray(x0, dtype=LD), np.asarray(P0, dtype=LD)
    n, out, lam_max, V0, PPT = x.size, [], 1.0, None, None
    for k in range(y.shape[0]):
        nu = np.asarray(y[k], dtype=LD) - H @ x
        if fading is not None and k > 0:
            rho, beta, a = (np.asarray(v, dtype=LD) for v in fading)
            gg = np.outer(nu, nu)
            V0 = gg if k == 1 else (rho * V0 + gg) / (1 + rho)
            c = np.trace(V0 - beta * R - H @ Q @ H.T) / np.sum(a * np.diag(PPT @ H.T @ H))
            lam = np.maximum(1, a * c)
            lam_max = max(lam_max, float(lam.max()))
            s = np.sqrt(lam)
            P = s[:, None] * PPT * s[None, :] + Q
        K = P @ H.T @ _inv_ld(H @ P @ H.T + R)
        xp = x + K @ nu
        IKH = np.eye(n, dtype=LD) - K @ H
        Pp = IKH @ P @ IKH.T + K @ R @ K.T
        out.append(xp)
        x, PPT = F @ xp + (0 if Gu is None else np.asarray(Gu[k], dtype=LD)), F @ Pp @ F.T
        P = PPT + Q
    return np.array(out), lam_max


def _relative(ref, got):
    return float(np.max(np.abs(np.asarray(got, dtype=LD) - ref) / np.abs(ref).max(axis=0)))


def test_inv_spd_error_is_of_the_order_of_the_condition():
    # Reference: the long-double inverse. A backward-stable inverse errs by O(κ u); the former adjugate of
    # inv_spd erred by up to 1.6e5 κ u on these matrices (LU: 1.7 κ u), the Cholesky inverse by 1.9 κ u.
    rng = np.random.default_rng(0)
    for m in (1, 2, 3, 5, 8):
        for _ in range(30):
            Qm, _ = np.linalg.qr(rng.standard_normal((m, m)))
            S = (Qm * np.logspace(0, -rng.uniform(0, 12), m)) @ Qm.T
            S = 0.5 * (S + S.T)
            d = np.exp(rng.uniform(-8, 8, m))  # units: a diagonal scaling changes κ(S), not the error bound
            Sd = d[:, None] * S * d[None, :]
            for M, kappa in ((S, np.linalg.cond(S)), (Sd, np.linalg.cond(S))):
                ref = _inv_ld(M)
                err = np.max(np.abs(inv_spd(M) - ref) / np.abs(ref).max())
                assert err <= 20 * kappa * U, (m, err / (kappa * U))
    # a batch (elementwise path) gives the numbers of one matrix at a time (Python floats), exactly
    A = rng.standard_normal((20, 3, 3))
    S = A @ np.swapaxes(A, 1, 2) + np.eye(3)
    assert np.array_equal(inv_spd(S), np.array([inv_spd(s) for s in S]))
    with pytest.raises(np.linalg.LinAlgError):  # fallback: not positive definite and singular -> LU raises
        inv_spd(np.zeros((2, 2)))
    np.testing.assert_allclose(inv_spd(np.array([[1.0, 2.0], [2.0, 1.0]])), np.linalg.inv([[1.0, 2.0], [2.0, 1.0]]))


def _tracking_case(kind, cond):
    """A 3-axis constant-velocity target, 3 position channels; R of condition ``cond`` by units or by correlation."""
    dt = 1.0
    Phi = np.kron(np.eye(3), np.array([[1, dt], [0, 1]]))
    Bq = np.kron(np.eye(3), np.array([[dt**2 / 2], [dt]])) * 1e-3
    system = LinearSystem(Phi, np.zeros((6, 0)), Bq, dt, StateSpec(tuple(f"s{i}" for i in range(6)), ("",) * 6))
    H = np.zeros((3, 6))
    H[0, 0] = H[1, 2] = H[2, 4] = 1.0
    rng = np.random.default_rng(3)
    if kind == "units":  # channel 0 in units of 1e-3 m, channel 2 in km: S ~ diag(1e6, 1, 1e-6)
        scale = np.array([cond**0.25, 1.0, cond**-0.25])
        H, D = scale[:, None] * H, np.diag(scale * 0.1)
    else:
        Qm, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        D = Qm @ np.diag(np.sqrt(np.logspace(0, -np.log10(cond), 3)))
    meas = LinearMeasurement(H, D)
    x, ys = np.zeros(6), []
    for _ in range(50):
        ys.append(H @ x + D @ rng.standard_normal(3))
        x = Phi @ x + Bq @ rng.standard_normal(3)
    return system, meas, np.array(ys)


# tol: the compiled path (Cholesky inverse); tol_numpy: the NumPy reference, which keeps the adjugate inverse so that
# the papers' published numbers stay bitwise (core.linalg: the Cholesky form moves rounding-sensitive paper results
# by up to 9 %): on correlated ill-conditioned channels it is the less accurate path (measured 2.6e-6 at 1e12) --
# issue 32's open finding, bounded here so that a regression of either path fails.
@pytest.mark.parametrize("kind, cond, tol, tol_numpy", [("units", 1e12, 1e-10, 1e-10), ("correlated", 1e6, 1e-10, 1e-8),
                                                        ("correlated", 1e12, 1e-7, 1e-5)])
def test_kalman_paths_agree_with_extended_precision(kind, cond, tol, tol_numpy):
    system, meas, y = _tracking_case(kind, cond)
    P0 = np.eye(6) * (1e-12 if kind == "correlated" else 1.0)
    est = ExtendedKalmanFilter(system, meas, P0=P0)
    S0 = meas.H @ P0 @ meas.H.T + est.R
    assert np.linalg.cond(S0) >= 0.4 * cond  # the case is as ill-conditioned as it says
    ref, _ = _kalman_ld(system.Phi, meas.H, est.Q, est.R, P0, y, np.zeros(6))
    u = np.zeros((1, y.shape[0], 0))
    a = est.estimate(y[None], u, np.zeros(6), backend="numpy").xhat[0]
    b = est.estimate(y[None], u, np.zeros(6), backend="numba").xhat[0]
    assert _relative(ref, a) <= tol_numpy and _relative(ref, b) <= tol, (_relative(ref, a), _relative(ref, b))
    assert float(np.max(np.abs(a - b) / np.abs(a).max(axis=0))) <= tol_numpy


@pytest.mark.parametrize("sigmas, lam_low, tol", [(1e3, 1e5, 1e-10), (1e5, 1e9, 1e-7)])
def test_strong_tracking_paths_agree_with_extended_precision(sigmas, lam_low, tol):
    truth = simulate_truth(SUN.truth_model(maneuver=True), runs=1, seed=7)
    y = truth.y.copy()
    y[0, 100] += sigmas * np.sqrt(np.diag(SUN.measurement.R))
    est = build_estimator(SUN, "stekf")
    P0 = est.start(SUN.xhat0).P
    P0 = P0[0] if P0.ndim == 3 else P0
    ref, lam_max = _kalman_ld(est.F, est.measurement.H, est.Q, est.R, P0, y[0], SUN.xhat0,
                              fading=(est.rho, est.beta, est.a), Gu=truth.u[0] @ est.Gamma.T if est.uses_input else None)
    assert lam_max >= lam_low  # the fading factors are as large as the case says
    a = est.estimate(y, truth.u, SUN.xhat0, backend="numpy").xhat[0]
    b = est.estimate(y, truth.u, SUN.xhat0, backend="numba").xhat[0]
    assert _relative(ref, a) <= tol and _relative(ref, b) <= tol, (_relative(ref, a), _relative(ref, b))


def test_unconverged_huber_update_agrees_and_its_filter_is_rounding_sensitive():
    from hinfnav.estimators.compiled_huber import huber_to

    rng = np.random.default_rng(0)
    n, m, gamma = 6, 3, 1.345
    for trial in range(60):
        X = rng.standard_normal((n, n))
        P = X @ X.T + 0.1 * np.eye(n)
        H, R = rng.standard_normal((m, n)), 0.1 * np.eye(m)
        LRi = np.linalg.inv(np.linalg.cholesky(R))
        nu = rng.standard_normal(m) * np.where(rng.random(m) < 0.5, 30.0, 1.0)  # outliers: iterations needed
        for max_iter in (1, 2, 3, 50):
            x = huber_correct(None, P[None], nu[None], H, R, gamma=gamma, tol=1e-10, max_iter=max_iter, LRi=LRi)[0][0]
            dx, Pp = np.empty(n), np.empty((n, n))
            assert huber_to(P, LRi @ H, LRi, nu, gamma, 1e-10, max_iter, np.empty(m), np.empty((n, m)),
                            np.empty((m, m)), np.zeros((m, m)), np.empty((m, m)), np.empty(m), np.empty(m),
                            np.empty((n, m)), Pp, dx, np.zeros((n, n)), np.empty(n), np.empty((8, m)),
                            np.empty((3, m, m)), np.empty((2, n, m)))
            assert np.max(np.abs(dx - x)) <= 1e-9 * np.abs(x).max(), (trial, max_iter)
    # over a filter run: the NumPy path's own change under a one-ulp change of y bounds the paths' difference
    truth = simulate_truth(SUN.truth_model(maneuver=True), runs=7, seed=7)
    base = build_estimator(SUN, "hbf")
    est = HuberFilter(base.system, base.measurement, P0=base.P0, Q=base.Q, R=base.R, gamma=base.gamma, max_iter=2)
    y = truth.y[6:7]
    ulp = y * (1 + 2 * U * np.random.default_rng(3).choice([-1, 1], size=y.shape))
    a = est.estimate(y, truth.u[6:7], SUN.xhat0).xhat
    scale = np.abs(a).max(axis=(0, 1))
    own = np.max(np.abs(est.estimate(ulp, truth.u[6:7], SUN.xhat0).xhat - a) / scale)
    paths = np.max(np.abs(est.estimate(y, truth.u[6:7], SUN.xhat0, backend="numba").xhat - a) / scale)
    assert own > 1e-6  # the truncated iteration amplifies rounding (measured 1e-3 over 300 steps)
    assert paths <= 10 * own
