"""Steady state of the a-priori recursive H-infinity filter (Simon 2006, ch. 11).

The filter of D. Simon, *Optimal State Estimation* (Wiley, 2006), section 11.3,

.. math::

    K_k &= P_k [I - \\theta \\bar S P_k + H^T R^{-1} H P_k]^{-1} H^T R^{-1}, \\\\
    \\hat x_{k+1} &= F \\hat x_k + F K_k (y_k - H \\hat x_k), \\\\
    P_{k+1} &= F P_k [I - \\theta \\bar S P_k + H^T R^{-1} H P_k]^{-1} F^T + Q,

with :math:`\\bar S = L^T S L`, exists only while
:math:`P_k^{-1} - \\theta \\bar S + H^T R^{-1} H > 0` at every step. With
``theta = 0`` it is the one-step Kalman predictor.

The recursion is evaluated in a symmetric, inverse-free form. With any factor
``P = C C^T`` the push-through identity gives
``P (I + G P)^{-1} = C (I + C^T G C)^{-1} C^T``, ``G = H^T R^{-1} H - theta S̄``,
and ``C^T (P^{-1} + G) C = I + C^T G C =: N``, so the existence condition is
``N > 0`` (tested by a Cholesky factorisation; this form also covers a
singular ``P``, e.g. the start ``P_0 = Q`` when ``Q`` is singular). Then
``P_{k+1} = F C N^{-1} C^T F^T + Q`` and ``K_k = C N^{-1} C^T H^T R^{-1}``.

The iterates from ``P_0 = Q`` are computed by doubling (see ``_iterate``),
which yields exactly the subsequence ``P_{2^k - 1}`` in about ``log2 k``
steps. Why checking the existence condition at the limit suffices: if
``P* = Phi(P*)`` with ``N(P*) > 0``, then every ``P`` with ``Q <= P <= P*``
also satisfies it (``P^{-1} >= P*^{-1}``) and ``Phi`` is monotone there, so by
induction ``Q = P_0 <= P_1 <= ... <= P*``: every iterate satisfies the
condition and the iterates converge, to ``P*`` because the doubled
subsequence does. The iterates also increase with ``theta``, so the
admissible ``theta`` form an interval ``[0, theta_max)``, on which
:func:`max_admissible_theta` bisects with the same routine.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_matrix, as_nonnegative, as_positive

__all__ = ["max_admissible_theta", "steady_state_hinf"]

#: Default cap on recursion steps. The doubling covers ``2^j - 1`` steps in
#: ``j`` matrix updates, so 2^60 costs about 60 updates. The cap must not decide
#: admissibility: from ``P_0 = Q`` with ``F`` close to ``I`` (e.g. the chaser,
#: T ω₀ ≈ 1e-4) ``P_k`` grows about linearly from ``Q``, and near ``theta_max``
#: convergence takes ~10^6 steps; a cap of 1e5 (before issue 22) made the
#: bisection return 3.826 for a bound of 3.99989.
MAX_ITER = 2**60
_BLOWUP = 1e14  # growth of ||P|| relative to max(||Q||, 1) taken as divergence


def _symmetric(name, A, *, definite):
    scale = max(np.max(np.abs(A)), np.finfo(float).tiny)
    asym = np.max(np.abs(A - A.T))
    if asym > 1e-10 * scale:
        raise InputError(f"{name} must be symmetric; it differs from its transpose by up to {asym:.3g}")
    A = 0.5 * (A + A.T)
    lam_min = np.linalg.eigvalsh(A).min()
    if definite and lam_min <= 0:
        raise InputError(f"{name} must be positive definite; its smallest eigenvalue is {lam_min:.3g}")
    if not definite and lam_min < -1e-12 * scale:
        raise InputError(f"{name} must be positive semidefinite; its smallest eigenvalue is {lam_min:.3g}")
    return A


def _check_system(F, H, Q, R, L, S):
    F = as_matrix("F", F)
    n = F.shape[0]
    if n < 1 or F.shape != (n, n):
        raise InputError(f"F must be a non-empty square matrix; got shape {F.shape}")
    H = as_matrix("H", H, (None, n))
    m = H.shape[0]
    Q = _symmetric("Q", as_matrix("Q", Q, (n, n)), definite=False)
    R = _symmetric("R", as_matrix("R", R, (m, m)), definite=True)
    L = np.eye(n) if L is None else as_matrix("L", L, (None, n))
    q = L.shape[0]
    S = np.eye(q) if S is None else _symmetric("S", as_matrix("S", S, (q, q)), definite=False)
    W = H.T @ np.linalg.solve(R, H)
    return F, H, Q, R, 0.5 * (W + W.T), L.T @ S @ L


def _factor(P):
    """A square factor C with C C^T = P for a symmetric positive semidefinite P."""
    try:
        return np.linalg.cholesky(P)
    except np.linalg.LinAlgError:
        lam, V = np.linalg.eigh(P)
        return V * np.sqrt(np.clip(lam, 0.0, None))


def _existence_factor(P, G):
    """Cholesky factor of ``N = I + C^T G C`` (``P = C C^T``), or None if N is not > 0."""
    C = _factor(P)
    N = np.eye(P.shape[0]) + C.T @ G @ C
    try:
        return C, np.linalg.cholesky(0.5 * (N + N.T))
    except np.linalg.LinAlgError:
        return C, None


def _iterate(F, Q, W, Sbar, theta, tol, max_iter):
    """Run the recursion from ``P_0 = Q`` by doubling.

    The structure-preserving doubling algorithm (Chu, Fan & Lin, Linear
    Algebra Appl. 396, 2005) for ``X = A^T X (I + G X)^{-1} A + Q`` with
    ``A = F^T``, ``G = H^T R^{-1} H - theta S̄`` produces ``H_k = P_{2^k - 1}``
    exactly: the subsequence of the fixed-point iterates from ``P_0 = Q``.
    The existence condition is checked at every ``H_k`` and at the limit; by
    the monotonicity argument in the module notes the check at the limit
    ``P*`` implies it at every iterate (each ``P_k <= P*``).

    Returns ``(status, P, k)`` with ``status`` one of ``"converged"``,
    ``"existence"`` (condition violated at or before iterate ``k``),
    ``"diverged"`` or ``"max_iter"``; ``k`` counts recursion steps.
    """
    n = F.shape[0]
    eye = np.eye(n)
    G = W - theta * Sbar
    A, Gk, Hk = F.T.copy(), G.copy(), Q.copy()
    limit = _BLOWUP * max(np.linalg.norm(Q), 1.0)
    k = 0  # Hk == P_k
    while True:
        if _existence_factor(Hk, G)[1] is None:
            return "existence", Hk, k
        if 2 * k + 1 > max_iter:
            return "max_iter", Hk, k
        try:
            X = np.linalg.solve(eye + Gk @ Hk, np.hstack([A, Gk @ A.T]))
        except np.linalg.LinAlgError:
            return "existence", Hk, 2 * k + 1
        A, Gk, H_new = A @ X[:, :n], Gk + A @ X[:, n:], Hk + A.T @ Hk @ X[:, :n]
        Gk, H_new = 0.5 * (Gk + Gk.T), 0.5 * (H_new + H_new.T)
        k = 2 * k + 1
        norm = np.linalg.norm(H_new)
        if not np.all(np.isfinite(H_new)) or norm > limit:
            return "diverged", H_new, k
        if np.linalg.eigvalsh(H_new).min() < -1e-10 * norm:
            return "existence", H_new, k  # past a violation the recursion loses P >= 0
        step = np.linalg.norm(H_new - Hk)
        Hk = H_new
        if step <= tol * norm:
            # Certify: existence at the limit and a true fixed point, to within
            # the rounding of one step (amplified by cond(N) near the bound).
            C, Nc = _existence_factor(Hk, G)
            if Nc is None:
                return "existence", Hk, k
            T = np.linalg.solve(Nc, (F @ C).T).T
            slack = max(1e-8, 1e4 * np.finfo(float).eps * np.linalg.cond(Nc) ** 2)
            if np.linalg.norm(T @ T.T + Q - Hk) > slack * norm:
                return "existence", Hk, k  # the doubling went through a singular step
            return "converged", Hk, k


def _gain(P, W, Sbar, theta, H, R):
    """K = P (I - theta S̄ P + W P)^{-1} H^T R^{-1} = C N^{-1} C^T H^T R^{-1}, or None."""
    C, Nc = _existence_factor(P, W - theta * Sbar)
    if Nc is None:
        return None
    Y = np.linalg.solve(Nc, C.T @ np.linalg.solve(R, H).T)
    return C @ np.linalg.solve(Nc.T, Y)


def _admissible(F, Q, W, Sbar, theta, tol, max_iter):
    return _iterate(F, Q, W, Sbar, theta, tol, max_iter)[0] == "converged"


def _bisect_theta(F, Q, W, Sbar, rtol, tol, max_iter):
    """Largest admissible theta (``inf`` if unbounded, ``None`` if even 0 fails)."""
    if not _admissible(F, Q, W, Sbar, 0.0, tol, max_iter):
        return None
    if not np.any(Sbar):
        return np.inf
    lo, hi = 0.0, 1.0 / max(np.linalg.eigvalsh(Sbar).max() * max(np.linalg.norm(Q, 2), 1e-300), 1e-300)
    while _admissible(F, Q, W, Sbar, hi, tol, max_iter):
        lo, hi = hi, 2.0 * hi
        if hi > 1e300:
            return np.inf
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if _admissible(F, Q, W, Sbar, mid, tol, max_iter):
            lo = mid
        else:
            hi = mid
    return lo


def max_admissible_theta(F: ArrayLike, H: ArrayLike, Q: ArrayLike, R: ArrayLike, L: ArrayLike | None = None, S: ArrayLike | None = None,
                         rtol: float = 1e-6, *, tol: float = 1e-12, max_iter: int = MAX_ITER) -> float:
    """Largest ``theta`` for which the steady-state H-infinity filter exists.

    Parameters
    ----------
    F, H, Q, R, L, S : array_like
        As in :func:`steady_state_hinf`.
    rtol : float, optional
        Relative width of the final bisection bracket (> 0).
    tol, max_iter : optional
        Passed to the Riccati iteration run at each trial ``theta``. The
        default ``max_iter`` (:data:`MAX_ITER`, about 60 doubling updates) is
        large enough that the cap does not decide the bound; a small cap
        lowers it (a ``theta`` converging slowly counts as inadmissible).

    Returns
    -------
    float
        The lower end of the final bracket: ``theta`` values up to it were
        found admissible, the upper end (at most ``(1 + rtol)`` times larger)
        was not. ``inf`` if every ``theta`` is admissible (``S̄ = 0``).

    Raises
    ------
    InputError
        On bad input, or if even ``theta = 0`` (the Kalman predictor) fails to
        converge, e.g. because ``(F, H)`` is not detectable.

    Notes
    -----
    Admissible means: the recursion from ``P_0 = Q`` converges and the
    existence condition ``P^{-1} - theta S̄ + H^T R^{-1} H > 0`` holds at every
    iterate. Near the bound convergence slows; a ``theta`` needing more than
    ``max_iter`` iterations counts as inadmissible.
    """
    F, H, Q, R, W, Sbar = _check_system(F, H, Q, R, L, S)
    rtol = as_positive("rtol", rtol)
    tol = as_positive("tol", tol)
    max_iter = as_int_at_least("max_iter", max_iter, 1)
    theta_max = _bisect_theta(F, Q, W, Sbar, rtol, tol, max_iter)
    if theta_max is None:
        raise InputError(
            "the Riccati iteration fails even at theta = 0 (Kalman predictor); check that (F, H) is detectable"
        )
    return theta_max


def steady_state_hinf(F: ArrayLike, H: ArrayLike, Q: ArrayLike, R: ArrayLike, theta: float, L: ArrayLike | None = None,
                      S: ArrayLike | None = None, *, tol: float = 1e-12, max_iter: int = MAX_ITER) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Steady-state covariance bound and gain of the a-priori H-infinity filter.

    Parameters
    ----------
    F : array_like, shape (n, n)
        State transition matrix.
    H : array_like, shape (m, n)
        Measurement matrix.
    Q : array_like, shape (n, n)
        Process noise covariance (symmetric positive semidefinite).
    R : array_like, shape (m, m)
        Measurement noise covariance (symmetric positive definite).
    theta : float
        Performance bound parameter, ``theta >= 0`` (``0`` gives the Kalman
        predictor).
    L : array_like, shape (q, n), optional
        Selects the state combination ``z = L x`` to be estimated; default ``I``.
    S : array_like, shape (q, q), optional
        Weight of the estimation error of ``z`` (symmetric positive
        semidefinite); default ``I``.
    tol : float, optional
        Stop when ``||P_{2j+1} - P_j||_F <= tol ||P_{2j+1}||_F`` for the doubled
        iterates ``j = 2^k - 1``.
    max_iter : int, optional
        Largest number of recursion steps covered (doubling needs only about
        ``log2(max_iter)`` matrix updates); default :data:`MAX_ITER`.

    Returns
    -------
    P : ndarray, shape (n, n)
        Steady-state solution of the recursion.
    K : ndarray, shape (n, m)
        Steady-state gain ``P [I - theta S̄ P + H^T R^{-1} H P]^{-1} H^T R^{-1}``;
        the filter is ``x_{k+1} = F x_k + F K (y_k - H x_k)``. At ``theta = 0``,
        ``K = P H^T (H P H^T + R)^{-1}``.

    Raises
    ------
    InputError
        On bad input; or, naming ``theta``, when the existence condition
        ``P_k^{-1} - theta S̄ + H^T R^{-1} H > 0`` fails at some iterate or the
        iteration diverges or does not converge. The message then gives the
        largest admissible ``theta`` found by bisection with the same routine.
    """
    F, H, Q, R, W, Sbar = _check_system(F, H, Q, R, L, S)
    theta = as_nonnegative("theta", theta)
    tol = as_positive("tol", tol)
    max_iter = as_int_at_least("max_iter", max_iter, 1)

    status, P, k = _iterate(F, Q, W, Sbar, theta, tol, max_iter)
    K = _gain(P, W, Sbar, theta, H, R) if status == "converged" else None
    if K is not None:
        return P, K

    what = {
        "existence": f"the existence condition P^-1 - theta*S̄ + H^T R^-1 H > 0 fails at or before iterate {k}",
        "diverged": f"the Riccati iteration diverges (||P|| grows beyond {_BLOWUP:.0e} times ||Q||)",
        "max_iter": f"the Riccati iteration does not converge within max_iter = {max_iter} iterations",
        "converged": "the existence condition fails at the converged P",
    }[status]
    if theta == 0.0:
        raise InputError(f"theta = 0 (Kalman predictor): {what}; check that (F, H) is detectable")
    bound = _bisect_theta(F, Q, W, Sbar, 1e-6, tol, max_iter)
    if bound is None:
        hint = "even theta = 0 fails; check that (F, H) is detectable"
    elif np.isinf(bound):
        hint = "no finite bound on theta was found"
    else:
        hint = f"the largest admissible theta is about {bound:.6g}; choose theta below it"
    raise InputError(f"theta = {theta:g} is not admissible: {what}; {hint}")
