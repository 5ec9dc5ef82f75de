"""Huber-robust measurement update (Karlgaard & Schaub, JGCD 2007).

The Kalman measurement update is written as a linear regression: the
measurement ``z`` and the prior mean ``x_prior`` are two observations of the
state,

.. math::

    \\begin{bmatrix} z \\\\ \\hat x^- \\end{bmatrix}
    = \\begin{bmatrix} H \\\\ I \\end{bmatrix} x + e, \\qquad
    \\operatorname{cov}(e) = \\operatorname{blockdiag}(R, P^-) = S S^T .

Whitening with the Cholesky factor ``S`` gives ``y = S^{-1}[z; x^-]`` and
``M = S^{-1}[H; I]``. Ordinary least squares on ``(M, y)`` is exactly the
Kalman update. The Huber update instead minimises
``sum_i rho_gamma(zeta_i)``, ``zeta = M x - y``, with the Huber loss
``rho(zeta) = zeta**2 / 2`` for ``|zeta| <= gamma`` and
``gamma |zeta| - gamma**2 / 2`` otherwise, by iteratively reweighted least
squares (IRLS) with weights ``psi = min(1, gamma / |zeta|)``, starting from
the Kalman (OLS) solution. The reported covariance is
``P = (M^T Psi M)^{-1}`` at the final weights.

Plain IRLS converges only linearly (hundreds of steps when several whitened
residuals are large), so each iteration also tries Newton steps of the
piecewise-quadratic cost, backtracked, and keeps the cheapest candidate,
IRLS step included: the cost falls at least as much as under IRLS and the
limit is the same Huber minimiser. Once the rows beyond ``gamma`` are
identified, the Newton point is the exact minimiser and the iteration ends.
"""

from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_positive

__all__ = ["HuberUpdate", "huber_update"]


@dataclass(frozen=True)
class HuberUpdate:
    """Result of :func:`huber_update`.

    Attributes
    ----------
    x : ndarray, shape (n,) or (runs, n)
        Posterior state estimate (the Huber M-estimate).
    P : ndarray, shape (n, n) or (runs, n, n)
        Posterior covariance ``(M^T Psi M)^{-1}`` at the final weights.
    weights : ndarray, shape (m + n,) or (runs, m + n)
        Final IRLS weights ``psi`` in (0, 1]; the first ``m`` belong to the
        whitened measurement rows, the last ``n`` to the whitened prior rows.
    iterations : int or ndarray of int, shape (runs,)
        Number of iterations after the initial OLS (Kalman) solve.
    converged : bool or ndarray of bool, shape (runs,)
        Whether the minimiser was reached (see ``tol``) within ``max_iter``.
    """

    x: np.ndarray
    P: np.ndarray
    weights: np.ndarray
    iterations: object
    converged: object


def _array(name, value, core_ndim, what):
    """Finite float array with ``core_ndim`` or ``core_ndim + 1`` dimensions."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be an array of real numbers; got {type(value).__name__} ({exc})") from None
    if arr.ndim not in (core_ndim, core_ndim + 1):
        raise InputError(
            f"{name} must be a {what} (ndim {core_ndim}) or a batch of them (ndim {core_ndim + 1}); got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must contain only finite numbers; it has NaN or inf entries")
    return arr


def _check_core_shape(name, arr, core_ndim, expected):
    got = arr.shape[arr.ndim - core_ndim:]
    if got != expected:
        raise InputError(
            f"{name} must have trailing shape {expected} (n from x_prior, m from z); got {got} (full shape {arr.shape})"
        )


def _cholesky(name, C):
    """Lower Cholesky factor of a (batch of) symmetric positive definite matrices."""
    scale = np.max(np.abs(C), axis=(-2, -1), keepdims=True)
    asym = np.abs(C - np.swapaxes(C, -1, -2))
    if np.any(asym > 1e-10 * scale):
        raise InputError(f"{name} must be symmetric; it differs from its transpose by up to {asym.max():.3g}")
    try:
        return np.linalg.cholesky(C)
    except np.linalg.LinAlgError:
        raise InputError(f"{name} must be positive definite; its Cholesky factorisation fails") from None


def _weighted_ls(M, y, w):
    """Solve ``min sum_i w_i (M_i x - y_i)^2`` for a batch, by QR of sqrt(w) M.

    Returns the solution and the upper-triangular factor ``U`` with
    ``U^T U = M^T diag(w) M``.
    """
    sw = np.sqrt(w)
    Q, U = np.linalg.qr(sw[..., :, None] * M, mode="reduced")
    rhs = np.einsum("...ji,...j->...i", Q, sw * y)
    x = np.linalg.solve(U, rhs[..., None])[..., 0]
    return x, U


def _newton_steps(M, y, x, zeta, gamma):
    """Newton-type candidates for the Huber cost at ``x``, and whether the first is exact.

    The cost is piecewise quadratic: with ``Q`` the rows where
    ``|zeta| <= gamma``, its gradient is ``g = M^T rho'(zeta)`` and its Hessian
    ``M_Q^T M_Q``. The Newton point ``x - (M_Q^T M_Q)^{-1} g`` solves the
    stationarity condition for this classification; if it reproduces the
    classification it is the minimiser (global, by convexity). When
    ``M_Q`` has too few rows the Hessian is singular, so further candidates
    give the linear rows a small curvature ``beta * psi`` (``beta`` in
    ``_BETAS``); ``beta = 1`` would be the IRLS step.
    """
    n = M.shape[-1]
    quad = np.abs(zeta) <= gamma
    sign = np.sign(zeta)
    grad = np.einsum("rji,rj->ri", M, np.where(quad, zeta, gamma * sign))
    psi = _huber_weights(zeta, gamma)
    cands, exact = [], None
    for beta in _BETAS:
        d = np.where(quad, 1.0, beta * psi)
        _, U = np.linalg.qr(np.sqrt(d)[..., :, None] * M, mode="reduced")
        diag = np.abs(np.diagonal(U, axis1=-2, axis2=-1))
        ok = diag.min(axis=-1) > 1e-10 * np.maximum(diag.max(axis=-1), np.finfo(float).tiny)
        U = np.where(ok[:, None, None], U, np.eye(n))  # singular runs: dummy step, rejected by cost or flag
        dx = np.linalg.solve(U, np.linalg.solve(np.swapaxes(U, -1, -2), grad[..., None]))[..., 0]
        cands.append(x - dx)
        if beta == 0.0:
            zc = np.einsum("rij,rj->ri", M, x - dx) - y
            slack = 1e-12 * gamma
            same = np.where(quad, np.abs(zc) <= gamma + slack, sign * zc >= gamma - slack).all(axis=-1)
            exact = ok & same
    return np.stack(cands, axis=1), exact


_BETAS = (0.0, 1e-1, 1e-2, 1e-3)
_BACKTRACK = 0.5 ** np.arange(11)


def _huber_cost(zeta, gamma):
    a = np.abs(zeta)
    return np.sum(np.where(a <= gamma, 0.5 * a * a, gamma * a - 0.5 * gamma * gamma), axis=-1)


def _huber_weights(zeta, gamma):
    a = np.abs(zeta)
    return np.where(a <= gamma, 1.0, gamma / np.maximum(a, gamma))


def huber_update(x_prior, P_prior, z, H, R, *, gamma=1.345, tol=1e-10, max_iter=50):
    """Huber M-estimate measurement update, batched over runs.

    Parameters
    ----------
    x_prior : array_like, shape (n,) or (runs, n)
        Prior (a priori) state estimate.
    P_prior : array_like, shape (n, n) or (runs, n, n)
        Prior covariance, symmetric positive definite.
    z : array_like, shape (m,) or (runs, m)
        Measurement.
    H : array_like, shape (m, n) or (runs, m, n)
        Measurement matrix.
    R : array_like, shape (m, m) or (runs, m, m)
        Measurement noise covariance, symmetric positive definite.
    gamma : float, optional
        Huber threshold on the whitened residuals (> 0). The default 1.345
        gives 95 % efficiency at the Gaussian.
    tol : float, optional
        A run stops once its Newton point is verified exact, or once the IRLS
        step changes no whitened residual by more than ``tol`` (> 0).
    max_iter : int, optional
        Largest number of iterations (>= 1).

    Returns
    -------
    HuberUpdate
        Frozen dataclass with fields ``x``, ``P``, ``weights``,
        ``iterations``, ``converged``. Arrays carry the batch axis when any
        input does; otherwise ``iterations`` is an int and ``converged`` a bool.

    Raises
    ------
    InputError
        On a wrong shape, non-finite entry, inconsistent batch size, a
        non-symmetric or non-positive-definite covariance, or a bad option;
        the message names the parameter.

    Notes
    -----
    When every whitened residual of the Kalman solution is at most ``gamma``
    the weights stay 1 and the result is the Kalman update
    ``x = x^- + K (z - H x^-)``, ``P = (P^{-1} + H^T R^{-1} H)^{-1}``.
    Inputs without a batch axis are broadcast over the runs of those with
    one; no Python loop runs over the batch.

    References
    ----------
    C. D. Karlgaard and H. Schaub, "Huber-Based Divided Difference
    Filtering", J. Guidance, Control, and Dynamics 30(3), 2007.
    """
    gamma = as_positive("gamma", gamma)
    tol = as_positive("tol", tol)
    max_iter = as_int_at_least("max_iter", max_iter, 1)
    x_prior = _array("x_prior", x_prior, 1, "vector")
    P_prior = _array("P_prior", P_prior, 2, "matrix")
    z = _array("z", z, 1, "vector")
    H = _array("H", H, 2, "matrix")
    R = _array("R", R, 2, "matrix")
    n, m = x_prior.shape[-1], z.shape[-1]
    if n < 1:
        raise InputError("x_prior must have at least one state entry")
    if m < 1:
        raise InputError("z must have at least one measurement entry")
    _check_core_shape("P_prior", P_prior, 2, (n, n))
    _check_core_shape("H", H, 2, (m, n))
    _check_core_shape("R", R, 2, (m, m))

    inputs = {"x_prior": (x_prior, 1), "P_prior": (P_prior, 2), "z": (z, 1), "H": (H, 2), "R": (R, 2)}
    runs, first = None, None
    for name, (arr, core) in inputs.items():
        if arr.ndim == core + 1:
            if runs is None:
                runs, first = arr.shape[0], name
            elif arr.shape[0] != runs:
                raise InputError(f"{name} has {arr.shape[0]} runs but {first} has {runs}; batch sizes must agree")
    batched = runs is not None
    if batched and runs < 1:
        raise InputError(f"{first} must hold at least one run; got an empty batch")
    nr = runs if batched else 1

    def full(arr, core):
        return np.broadcast_to(arr, (nr,) + arr.shape[arr.ndim - core:])

    L_R = full(_cholesky("R", R), 2)
    L_P = full(_cholesky("P_prior", P_prior), 2)
    x0, zz, HH = full(x_prior, 1), full(z, 1), full(H, 2)

    # Whitened regression: M = S^{-1} [H; I], y = S^{-1} [z; x_prior].
    M = np.concatenate([np.linalg.solve(L_R, HH), np.linalg.solve(L_P, np.broadcast_to(np.eye(n), (nr, n, n)))], axis=1)
    y = np.concatenate([np.linalg.solve(L_R, zz[..., None])[..., 0], np.linalg.solve(L_P, x0[..., None])[..., 0]], axis=1)

    x, _ = _weighted_ls(M, y, np.ones((nr, m + n)))  # ordinary least squares = Kalman update
    iterations = np.zeros(nr, dtype=int)
    converged = np.zeros(nr, dtype=bool)
    for _ in range(max_iter):
        act = np.flatnonzero(~converged)
        if act.size == 0:
            break
        Ma, ya, xa = M[act], y[act], x[act]
        zeta = np.einsum("rij,rj->ri", Ma, xa) - ya
        xn, _ = _weighted_ls(Ma, ya, _huber_weights(zeta, gamma))  # IRLS step
        step = np.max(np.abs(np.einsum("rij,rj->ri", Ma, xn - xa)), axis=1)
        # Newton step of the piecewise-quadratic cost, backtracked; keep the
        # cheapest of it and the IRLS step, so the cost decreases at least as
        # much as under plain IRLS.
        xc, exact = _newton_steps(Ma, ya, xa, zeta, gamma)
        dirs = (xc - xa[:, None])[:, :, None] * _BACKTRACK[None, None, :, None]
        trial = np.concatenate([xn[:, None], xa[:, None] + dirs.reshape(act.size, -1, n)], axis=1)
        cost = _huber_cost(np.einsum("rij,rtj->rti", Ma, trial) - ya[:, None], gamma)
        best = trial[np.arange(act.size), np.argmin(cost, axis=1)]
        x[act] = np.where(exact[:, None], xc[:, 0], best)
        iterations[act] += 1
        converged[act] = exact | (step <= tol)

    w = _huber_weights(np.einsum("rij,rj->ri", M, x) - y, gamma)
    _, U = _weighted_ls(M, y, w)
    Uinv = np.linalg.solve(U, np.broadcast_to(np.eye(n), (nr, n, n)))
    P = Uinv @ np.swapaxes(Uinv, -1, -2)
    P = 0.5 * (P + np.swapaxes(P, -1, -2))

    if batched:
        return HuberUpdate(x=x, P=P, weights=w, iterations=iterations, converged=converged)
    return HuberUpdate(x=x[0], P=P[0], weights=w[0], iterations=int(iterations[0]), converged=bool(converged[0]))
