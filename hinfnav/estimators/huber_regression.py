"""The Huber M-estimation on the whole whitened regression, batched over runs.

Minimises ``sum_i rho_gamma(zeta_i)``, ``zeta = M x - y``, for a batch of
regressions ``(M, y)`` (``M`` of full column rank). Plain IRLS converges only
linearly (hundreds of steps when several whitened residuals are large), so
each iteration first tries the Newton point of the piecewise-quadratic cost
for the current split of the rows into those within and beyond ``gamma``; if
it reproduces that split it is the exact minimiser and the iteration ends.
Otherwise the iteration keeps the cheapest of the IRLS step and backtracked
(damped) Newton steps: the cost falls at least as much as under IRLS and the
limit is the same Huber minimiser.

The weighted least-squares problems are solved by their normal equations,
scaled to a unit diagonal (Jacobi) before a Cholesky solve: for these small,
well-posed systems this loses nothing measurable against QR.

:func:`hinfnav.estimators.huber.huber_update` uses this solver only for the
runs where a whitened *prior* row leaves the quadratic zone; every other run
is solved in the measurement space (see that module), with the same
iterations and the same weights (:data:`BETAS`, :data:`BACKTRACK`,
:func:`huber_cost`, :func:`huber_weights` are shared).
"""

import numpy as np

__all__ = ["BACKTRACK", "BETAS", "huber_cost", "huber_weights", "minimise", "normal_matrix", "covariance", "mv"]

def _chol(A, pivot_tol=1e-12):
    """Cholesky factors of a batch of symmetric matrices; ``(L, ok)``.

    LAPACK factors the whole batch at once; if one matrix is not positive
    definite (LAPACK then fails for the batch) the factors are computed by
    columns vectorised over the batch, and ``ok`` is False for a run whose
    pivot falls to ``pivot_tol`` times its largest diagonal entry or below
    (singular or indefinite to working precision; its factor is meaningless).
    """
    try:
        return np.linalg.cholesky(A), np.ones(A.shape[0], dtype=bool)
    except np.linalg.LinAlgError:
        pass
    n = A.shape[-1]
    L = np.zeros_like(A)
    floor = pivot_tol * np.max(np.abs(np.diagonal(A, axis1=-2, axis2=-1)), axis=-1)
    ok = np.isfinite(floor)
    for j in range(n):
        lj = L[:, j, :j]
        d = A[:, j, j] - np.sum(lj * lj, axis=-1)
        good = d > floor
        ok &= good
        piv = np.sqrt(np.where(good, d, 1.0))
        L[:, j, j] = piv
        if j + 1 < n:
            L[:, j + 1:, j] = (A[:, j + 1:, j] - (L[:, j + 1:, :j] @ lj[:, :, None])[..., 0]) / piv[:, None]
    return L, ok


#: Below this many runs one LAPACK call per matrix is cheaper than the column loops.
_SMALL_BATCH = 48


def _tri_solve(L, b, lower=True):
    """``L^{-1} b`` (or ``L^{-T} b`` with ``lower=False``) for a batch of lower-triangular ``L``."""
    if L.shape[0] < _SMALL_BATCH:
        return np.linalg.solve(L if lower else np.swapaxes(L, -1, -2), b[..., None])[..., 0]
    n = L.shape[-1]
    x = np.zeros(np.broadcast_shapes(L.shape[:-1], b.shape))
    for i in range(n) if lower else reversed(range(n)):
        if lower:
            acc = np.sum(L[:, i, :i] * x[:, :i], axis=-1)
        else:
            acc = np.sum(L[:, i + 1:, i] * x[:, i + 1:], axis=-1)
        x[:, i] = (b[:, i] - acc) / L[:, i, i]
    return x


def _tri_inv(L):
    """``L^{-1}`` for a batch of lower-triangular ``L`` (forward substitution on the identity)."""
    if L.shape[0] < _SMALL_BATCH:
        return np.linalg.inv(L)
    n = L.shape[-1]
    X = np.zeros_like(L)
    for i in range(n):
        X[:, i, :i + 1] = -(L[:, i:i + 1, :i] @ X[:, :i, :i + 1])[:, 0] / L[:, i, i, None]
        X[:, i, i] = 1.0 / L[:, i, i]
    return X


def _scaled(A):
    """Jacobi scaling ``(s, S A S)``, ``s = diag(A)^{-1/2}`` (1 where the diagonal is not positive)."""
    d = np.diagonal(A, axis1=-2, axis2=-1)
    good = np.isfinite(d) & (d > 0)
    s = np.where(good, 1.0 / np.sqrt(np.where(good, d, 1.0)), 1.0)
    return s, A * s[:, :, None] * s[:, None, :], np.all(good, axis=-1)


def _spd_solve(A, b, usable=None):
    """Solve ``A x = b`` for a batch of symmetric positive (semi)definite ``A``; ``(x, ok)``.

    The matrices are scaled to a unit diagonal (Jacobi) and factored by
    :func:`_chol`. ``ok`` is False where the system is singular to working
    precision, where ``usable`` (a boolean per run, optional) is False, or
    where the solution is not finite (``x`` is then 0 there): the caller
    treats such runs as having no step.
    """
    s, As, ok = _scaled(A)
    if usable is not None:
        ok = ok & usable
    As = np.where(ok[:, None, None], As, np.eye(A.shape[-1]))
    L, good = _chol(As)
    ok = ok & good
    with np.errstate(all="ignore"):
        x = s * _tri_solve(L, _tri_solve(L, s * b), lower=False)
    ok = ok & np.all(np.isfinite(x), axis=-1)
    return np.where(ok[:, None], x, 0.0), ok


def mv(M, x):
    """``M x`` for a batch (``M`` (r, k, n), ``x`` (r, n))."""
    return (M @ x[..., None])[..., 0]


def mtv(M, v):
    """``M^T v`` for a batch (``M`` (r, k, n), ``v`` (r, k))."""
    return (v[..., None, :] @ M)[..., 0, :]


def normal_matrix(M, w):
    """``M^T diag(w) M`` for a batch."""
    return np.swapaxes(M * w[..., :, None], -1, -2) @ M


def _weighted_ls(M, y, w):
    """Solve ``min sum_i w_i (M_i x - y_i)^2`` for a batch (weights > 0, M of full column rank).

    Returns the solution and the normal matrix ``M^T diag(w) M``.
    """
    A = normal_matrix(M, w)
    x, _ = _spd_solve(A, mtv(M, w * y))
    return x, A


def covariance(A):
    """``A^{-1}`` of a batch of symmetric positive definite matrices (by the scaled Cholesky factor), symmetric."""
    s, As, _ = _scaled(A)
    Li = _tri_inv(_chol(As)[0])
    P = (np.swapaxes(Li, -1, -2) @ Li) * s[:, :, None] * s[:, None, :]
    return 0.5 * (P + np.swapaxes(P, -1, -2))


def _newton_steps(M, y, x, zeta, gamma, betas=None):
    """Newton-type candidates for the Huber cost at ``x``, and whether the first is exact.

    The cost is piecewise quadratic: with ``Q`` the rows where
    ``|zeta| <= gamma``, its gradient is ``g = M^T rho'(zeta)`` and its Hessian
    ``M_Q^T M_Q``. The Newton point ``x - (M_Q^T M_Q)^{-1} g`` solves the
    stationarity condition for this classification; if it reproduces the
    classification it is the minimiser (global, by convexity). When
    ``M_Q`` has too few rows the Hessian is singular, so further candidates
    give the linear rows a small curvature ``beta * psi`` (``beta`` in
    ``BETAS``, or ``betas`` when given, which must start with 0); ``beta = 1``
    would be the IRLS step.
    """
    n = M.shape[-1]
    quad = np.abs(zeta) <= gamma
    sign = np.sign(zeta)
    grad = mtv(M, np.where(quad, zeta, gamma * sign))
    psi = huber_weights(zeta, gamma)
    cands, exact = [], None
    for beta in BETAS if betas is None else betas:
        d = np.where(quad, 1.0, beta * psi)
        # singular runs (too few rows within gamma): no step, rejected by cost or flag
        dx, ok = _spd_solve(normal_matrix(M, d), grad, usable=(quad.sum(axis=-1) >= n) if beta == 0.0 else None)
        cands.append(x - dx)
        if beta == 0.0:
            zc = mv(M, x - dx) - y
            slack = 1e-12 * gamma
            same = np.where(quad, np.abs(zc) <= gamma + slack, sign * zc >= gamma - slack).all(axis=-1)
            exact = ok & same
    return np.stack(cands, axis=1), exact


BETAS = (0.0, 1e-1, 1e-2, 1e-3)
BACKTRACK = 0.5 ** np.arange(11)


def huber_cost(zeta, gamma):
    a = np.abs(zeta)
    return np.sum(np.where(a <= gamma, 0.5 * a * a, gamma * a - 0.5 * gamma * gamma), axis=-1)


def huber_weights(zeta, gamma):
    a = np.abs(zeta)
    return np.where(a <= gamma, 1.0, gamma / np.maximum(a, gamma))


def minimise(M, y, x, gamma, tol, max_iter):
    """Minimise ``sum rho_gamma(M x - y)`` from ``x`` for a batch; ``(x, iterations, converged)``.

    Each iteration takes the Newton point of the current split of the rows
    (within / beyond gamma) where it is verified exact, else the cheapest of
    the IRLS step and backtracked (damped) Newton steps.
    """
    runs, n = x.shape
    x = x.copy()
    iterations = np.zeros(runs, dtype=int)
    converged = np.zeros(runs, dtype=bool)
    for _ in range(max_iter):
        act = np.flatnonzero(~converged)
        if act.size == 0:
            break
        Ma, ya, xa = M[act], y[act], x[act]
        zeta = mv(Ma, xa) - ya
        # The Newton point of the current classification; where it is verified
        # exact it is the minimiser and nothing else is needed.
        x0c, exact = _newton_steps(Ma, ya, xa, zeta, gamma, betas=(0.0,))
        x_next = x0c[:, 0].copy()
        step = np.zeros(act.size)
        rest = np.flatnonzero(~exact)
        if rest.size:
            Mr, yr, xr, zr = Ma[rest], ya[rest], xa[rest], zeta[rest]
            xn, _ = _weighted_ls(Mr, yr, huber_weights(zr, gamma))  # IRLS step
            step[rest] = np.max(np.abs(mv(Mr, xn - xr)), axis=1)
            # Newton steps of the piecewise-quadratic cost, backtracked; keep the
            # cheapest of them and the IRLS step, so the cost decreases at least
            # as much as under plain IRLS.
            xc, _ = _newton_steps(Mr, yr, xr, zr, gamma)
            dirs = (xc - xr[:, None])[:, :, None] * BACKTRACK[None, None, :, None]
            trial = np.concatenate([xn[:, None], xr[:, None] + dirs.reshape(rest.size, -1, n)], axis=1)
            cost = huber_cost((trial @ np.swapaxes(Mr, -1, -2)) - yr[:, None], gamma)
            x_next[rest] = trial[np.arange(rest.size), np.argmin(cost, axis=1)]
        x[act] = x_next
        iterations[act] += 1
        converged[act] = exact | (step <= tol)
    return x, iterations, converged
