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

The minimisation (:mod:`hinfnav.estimators.huber_regression`) starts from
the Kalman solution; each iteration takes the Newton point of the current
split of the rows into those within and beyond ``gamma`` where it is
verified exact, else the cheapest of the IRLS step and backtracked Newton
steps.

Speed: the measurement space. While every whitened prior row stays within
``gamma`` (prior weight 1), every weighted least-squares solution is
``x = x^- + P^- A^T c`` with ``A = L_R^{-1} H`` and an m-vector ``c``
(matrix inversion lemma): with ``C = A P^- A^T`` the whitened residuals are
``zeta = [C c - e; L_P^T A^T c]`` (``e = L_R^{-1}(z - H x^-)``), a solve
with weights ``d`` on the measurement rows is
``c = b - E T^{-1} E C b`` (``E = diag(sqrt(d))``, ``T = I + E C E``, m x m),
and ``P = P^- - P^- A^T E T^{-1} E A P^-``. The iterations are then those of
the whole regression, done in m dimensions (3 for a position fix, against the
n + m rows of the regression); a run whose Kalman residuals all lie within
``gamma`` is finished after the Kalman update (its prior rows are checked by
``||L_P^{-1} dx||_2^2 = c^T C c <= gamma^2`` before any factorisation of P).
A run where a prior row leaves the quadratic zone is handed to the solver on
the whole regression. Both give the same minimiser (tested against cvxpy to
1e-8 and against the whole-regression solver).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..core.linalg import inv_spd, matmul_shared
from ..core.validation import as_int_at_least, as_positive
from .huber_regression import (
    BACKTRACK,
    BETAS,
    covariance,
    huber_cost,
    huber_weights,
    minimise,
    mv,
    normal_matrix,
)

__all__ = ["HuberUpdate", "huber_correct", "huber_update", "whitening"]


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


def huber_update(x_prior: ArrayLike, P_prior: ArrayLike, z: ArrayLike, H: ArrayLike, R: ArrayLike, *,
                 gamma: float = 1.345, tol: float = 1e-10, max_iter: int = 50) -> HuberUpdate:
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

    _cholesky("R", R)
    _cholesky("P_prior", P_prior)
    x, P, w, iterations, converged = huber_correct(full(x_prior, 1), full(P_prior, 2), full(z, 1), H, R,
                                                   gamma=gamma, tol=tol, max_iter=max_iter)
    if batched:
        return HuberUpdate(x=x, P=P, weights=w, iterations=iterations, converged=converged)
    return HuberUpdate(x=x[0], P=P[0], weights=w[0], iterations=int(iterations[0]), converged=bool(converged[0]))


def _swap(M):
    return np.swapaxes(M, -1, -2)


def _weighted(C, b, d):
    """``c`` of the weighted solve ``(P^{-1} + A^T D A)^{-1} A^T b = P A^T c``: ``b - E T^{-1} E C b``.

    ``E = diag(sqrt(d))``, ``T = I + E C E``; batched over any leading axes
    (C (..., m, m), b and d (..., m)); T ≥ I, so the inverse always exists.
    """
    E = np.sqrt(d)
    T = E[..., :, None] * C * E[..., None, :] + np.eye(C.shape[-1])
    return b - E * mv(inv_spd(T), E * mv(C, b))


def _residuals(C, e, B, c):
    """Whitened residuals ``(C c - e, B c)`` of the measurement and prior rows at ``c`` (any leading axes)."""
    return (C @ c[..., None])[..., 0] - e, (B @ c[..., None])[..., 0]


def _minimise_measurement_space(C, e, B, c, gamma, tol, max_iter):
    """The iterations of :func:`huber_regression.minimise` in the measurement space.

    The Newton point is that of the current split of the measurement rows
    with every prior row quadratic (the prior rows are within gamma at the
    minimiser of almost every update, even when the Kalman correction of an
    outlier takes them beyond it); where it reproduces that split and keeps
    the prior rows within gamma it satisfies the optimality conditions of the
    convex cost, hence is the minimiser. Otherwise the IRLS and damped Newton
    steps of the whole-regression solver are taken, in m dimensions, while
    the prior rows are within gamma at the current point.

    Returns ``(c, iterations, converged, left)``; ``left`` marks the runs
    stopped at a point with a prior row beyond gamma whose Newton point was
    not exact (their ``c`` is that point; the caller finishes them on the
    whole regression).
    """
    runs, m = c.shape
    c = c.copy()
    iterations = np.zeros(runs, dtype=int)
    converged = np.zeros(runs, dtype=bool)
    left = np.zeros(runs, dtype=bool)
    slack = 1e-12 * gamma
    for _ in range(max_iter):
        act = np.flatnonzero(~(converged | left))
        if act.size == 0:
            break
        Ca, ea, Ba, ca = C[act], e[act], B[act], c[act]
        zm, zp = _residuals(Ca, ea, Ba, ca)
        quad = np.abs(zm) <= gamma
        sign = np.sign(zm)
        grad = ca + np.where(quad, zm, gamma * sign)  # A^T grad is the gradient (prior rows quadratic)
        psi = huber_weights(zm, gamma)
        # Newton points for weights 1 (quadratic rows) and beta * psi (linear rows), beta in BETAS
        d = np.where(quad[:, None, :], 1.0, np.asarray(BETAS)[None, :, None] * psi[:, None, :])
        cand = ca[:, None] - _weighted(Ca[:, None], grad[:, None], d)
        # the first (beta = 0) is the minimiser if it reproduces the split (prior rows within gamma)
        zc, zpc = _residuals(Ca, ea, Ba, cand[:, 0])
        exact = (np.where(quad, np.abs(zc) <= gamma + slack, sign * zc >= gamma - slack).all(axis=-1)
                 & (np.abs(zpc) <= gamma + slack).all(axis=-1))
        c_next = cand[:, 0].copy()
        step = np.zeros(act.size)
        # Not exact, and a prior row beyond gamma here: the other steps need the whole regression
        gone = ~exact & np.any(np.abs(zp) > gamma, axis=-1)
        left[act[gone]] = True
        rest = np.flatnonzero(~exact & ~gone)
        if rest.size:
            Cr, er, Br, cr = Ca[rest], ea[rest], Ba[rest], ca[rest]
            cI = _weighted(Cr, psi[rest] * er, psi[rest])  # IRLS step
            dm, dp = _residuals(Cr, 0.0, Br, cI - cr)
            step[rest] = np.maximum(np.max(np.abs(dm), axis=-1), np.max(np.abs(dp), axis=-1))
            dirs = (cand[rest] - cr[:, None])[:, :, None] * BACKTRACK[None, None, :, None]
            trial = np.concatenate([cI[:, None], cr[:, None] + dirs.reshape(rest.size, -1, m)], axis=1)
            tm, tp = _residuals(Cr[:, None], er[:, None], Br[:, None], trial)
            cost = huber_cost(tm, gamma) + huber_cost(tp, gamma)
            c_next[rest] = trial[np.arange(rest.size), np.argmin(cost, axis=1)]
        keep = act[~gone]
        c[keep] = c_next[~gone]
        iterations[keep] += 1
        converged[keep] = (exact | (step <= tol))[~gone]
    return c, iterations, converged, left


def whitening(R):
    """``L_R^{-1}`` (= ``L_Rᵀ R⁻¹``) of the lower Cholesky factor of R (m, m) or a batch (runs, m, m)."""
    try:
        L_R = np.linalg.cholesky(R)
    except np.linalg.LinAlgError:
        raise InputError("R must be positive definite; its Cholesky factorisation fails") from None
    return _swap(L_R) @ inv_spd(R)


def huber_correct(x_prior, P_prior, z, H, R, *, gamma, tol, max_iter, LRi=None):
    """The Huber update of :func:`huber_update` on checked, batched inputs (no validation).

    ``x_prior`` (runs, n) or None (zero: ``z`` is then the innovation),
    ``P_prior`` (runs, n, n), ``z`` (runs, m); ``H`` (m, n) or (runs, m, n),
    ``R`` (m, m) or (runs, m, m), both symmetric positive definite
    covariances; ``LRi``, optionally, :func:`whitening` of a constant R
    computed once. Returns ``(x, P, weights, iterations, converged)`` with a
    leading runs axis. For filters, which build their inputs themselves; see
    the module docstring for the method.
    """
    runs, n = P_prior.shape[0], P_prior.shape[-1]
    m = z.shape[-1]
    if x_prior is None:
        x_prior = np.zeros((runs, n))
        innovation = z
    else:
        innovation = z - mv(H, x_prior)
    LRi = whitening(R) if LRi is None else LRi
    A = LRi @ H  # whitened measurement matrix
    e = mv(LRi, innovation)  # one matrix-vector product per run (a 2-D product would round differently for 1 run)
    AT = _swap(A)
    PAT = matmul_shared(P_prior, AT)
    C = _swap(PAT) @ AT if A.ndim == 3 else matmul_shared(_swap(PAT), AT)  # A P Aᵀ = (P Aᵀ)ᵀ Aᵀ (P symmetric)
    C = 0.5 * (C + _swap(C))
    Si = inv_spd(C + np.eye(m))
    c = mv(Si, e)  # the Kalman (least-squares) solution, x = x_prior + P Aᵀ c
    zm = mv(C, c) - e
    # prior rows: |L_P^{-1} dx| <= ||L_P^{-1} dx||_2 = sqrt(cᵀ C c); factor P only where that bound exceeds gamma
    meas_in = np.all(np.abs(zm) <= gamma, axis=-1)
    need = np.flatnonzero(~meas_in | (np.sum(c * mv(C, c), axis=-1) > gamma * gamma))
    inside = meas_in.copy()
    B = None
    if need.size:
        try:
            L_P = np.linalg.cholesky(P_prior[need])
        except np.linalg.LinAlgError:
            raise InputError("P_prior must be positive definite; its Cholesky factorisation fails") from None
        B = _swap(L_P) @ (AT[need] if AT.ndim == 3 else AT)  # L_Pᵀ Aᵀ: prior residuals L_P^{-1} P Aᵀ c
        inside[need] &= np.all(np.abs(mv(B, c[need])) <= gamma, axis=-1)
    # P = (Mᵀ M)⁻¹ = P − P Aᵀ S⁻¹ A P for every run (weights 1: the Kalman covariance; K_w = P Aᵀ S⁻¹);
    # the runs out are overwritten below with their weights
    Kw = PAT @ Si
    P = P_prior - Kw @ _swap(PAT)
    P = 0.5 * (P + _swap(P))
    iterations = np.ones(runs, dtype=int)
    converged = inside.copy()
    w = np.ones((runs, m + n))
    x = x_prior + mv(PAT, c)

    out = np.flatnonzero(~inside)
    if out.size:
        pos = np.searchsorted(need, out)  # rows of B for the runs out
        Co = C[out]
        Ao = A[out] if A.ndim == 3 else A
        co, its, conv, left = _minimise_measurement_space(Co, e[out], B[pos], c[out], gamma, tol, max_iter)
        zm, zp = _residuals(Co, e[out], B[pos], co)
        wo = np.concatenate([huber_weights(zm, gamma), huber_weights(zp, gamma)], axis=-1)
        xo = x_prior[out] + mv(PAT[out], co)
        E = np.sqrt(wo[:, :m])
        U = PAT[out] * E[:, None, :]
        Po = P_prior[out] - U @ inv_spd(E[:, :, None] * Co * E[:, None, :] + np.eye(m)) @ _swap(U)
        Po = 0.5 * (Po + _swap(Po))
        general = np.flatnonzero(left | (wo[:, m:] < 1).any(axis=-1))
        if general.size:
            # a prior row beyond gamma: the whole whitened regression M = [A; L_P^{-1}], y = [e; 0] in dx
            g = out[general]
            LPi = np.linalg.inv(np.linalg.cholesky(P_prior[g]))
            M = np.concatenate([np.broadcast_to(Ao, (g.size, m, n)) if Ao.ndim == 2 else Ao[general], LPi], axis=1)
            y = np.concatenate([e[g], np.zeros((g.size, n))], axis=1)
            dx0 = mv(PAT[g], co[general])
            remaining = max_iter - its[general]
            its_g, conv_g = np.zeros(g.size, dtype=int), conv[general].copy()
            dx = dx0.copy()
            for budget in np.unique(remaining[left[general] & (remaining > 0)]):  # the iterations each run has left
                todo = np.flatnonzero(left[general] & (remaining == budget))
                dx[todo], its_g[todo], conv_g[todo] = minimise(M[todo], y[todo], dx0[todo], gamma, tol, int(budget))
            its[general] += its_g
            conv[general] = conv_g
            wo[general] = huber_weights(mv(M, dx) - y, gamma)
            xo[general] = x_prior[g] + dx
            Po[general] = covariance(normal_matrix(M, wo[general]))
        x[out], P[out], w[out], iterations[out], converged[out] = xo, Po, wo, its, conv
    return x, P, w, iterations, converged
