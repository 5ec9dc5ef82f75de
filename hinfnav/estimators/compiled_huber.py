"""Huber's M-estimation correction for the compiled kernels (numba; imported with :mod:`.compiled_kernels`).

The same estimate as :func:`hinfnav.estimators.huber.huber_correct` (with a
zero prior in error coordinates): the Kalman solution when every whitened
residual is within gamma; else the Newton point in the measurement space
(``huber.py``'s ``_minimise_measurement_space``) when it reproduces its split;
else the whole whitened regression ``M = [L_R⁻¹ H; L_P⁻¹]`` minimised by the
Newton/IRLS/backtracking iterations of
:func:`hinfnav.estimators.huber_regression.minimise`.

numba's on-disk cache checks only the file of the function it compiles: after editing
this module, delete the kernels' cache (``__pycache__/compiled_*.nbi``/``.nbc`` or
``NUMBA_CACHE_DIR``) or touch :mod:`hinfnav.estimators.compiled_kernels`.
"""

import numpy as np
from numba import njit

from .compiled_linalg import (chol, chol_solve, chol_to, inv_to, lin, maxabs, mm_to, mmt_to, mv, mv_to, sym,
                              tri_inv)

__all__ = ["huber_to"]

_BETAS = (0.0, 1e-1, 1e-2, 1e-3)  # as hinfnav.estimators.huber_regression.BETAS
_N_BACKTRACK = 11  # BACKTRACK = 0.5 ** arange(11)


@njit(cache=True, error_model="numpy")
def _jacobi_chol(A):
    """``(L, s, ok)``: the Cholesky factor L of ``diag(s) A diag(s)``, ``s = 1/√diag(A)`` (Jacobi scaling)."""
    n = A.shape[0]
    s = np.empty(n)
    for i in range(n):
        d = A[i, i]
        if not (np.isfinite(d) and d > 0.0):
            return A, s, False
        s[i] = 1.0 / np.sqrt(d)
    As = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            As[i, j] = A[i, j] * s[i] * s[j]
    L, ok = chol(As)
    return L, s, ok


@njit(cache=True, error_model="numpy")
def _scaled_solve(A, b, usable):
    """``A⁻¹ b`` by the Jacobi-scaled Cholesky factor (``_spd_solve``); ``(x, ok)``, x = 0 when not ok."""
    n = A.shape[0]
    x = np.zeros(n)
    if not usable:
        return x, False
    L, s, ok = _jacobi_chol(A)
    if not ok:
        return x, False
    rhs = np.empty((n, 1))
    for i in range(n):
        rhs[i, 0] = s[i] * b[i]
    X = chol_solve(L, rhs)
    for i in range(n):
        x[i] = s[i] * X[i, 0]
        if not np.isfinite(x[i]):
            return np.zeros(n), False
    return x, True


@njit(cache=True, error_model="numpy")
def _normal(M, w):
    """Mᵀ diag(w) M."""
    r, n = M.shape
    A = np.zeros((n, n))
    for k in range(r):
        if w[k] != 0.0:
            for i in range(n):
                a = w[k] * M[k, i]
                for j in range(n):
                    A[i, j] += a * M[k, j]
    return A


@njit(cache=True, error_model="numpy")
def _huber_cost(z, gamma):
    c = 0.0
    for v in z:
        a = abs(v)
        c += 0.5 * a * a if a <= gamma else gamma * a - 0.5 * gamma * gamma
    return c


@njit(cache=True, error_model="numpy")
def _psi(z, gamma):
    w = np.empty(z.size)
    for i in range(z.size):
        a = abs(z[i])
        w[i] = 1.0 if a <= gamma else gamma / max(a, gamma)
    return w


@njit(cache=True, error_model="numpy")
def _residual(M, x, yv):
    """M x − y."""
    z = mv(M, x)
    for i in range(z.size):
        z[i] -= yv[i]
    return z


@njit(cache=True, error_model="numpy")
def _minimise(M, yv, x, gamma, tol, max_iter):
    """:func:`hinfnav.estimators.huber_regression.minimise` for one regression; returns x."""
    r, n = M.shape
    MT = M.T.copy()
    slack = 1e-12 * gamma
    x = x.copy()
    d = np.empty(r)
    g = np.empty(r)
    for _ in range(max_iter):
        zeta = _residual(M, x, yv)
        psi = _psi(zeta, gamma)
        nq = 0
        for i in range(r):
            if abs(zeta[i]) <= gamma:
                nq += 1
                g[i] = zeta[i]
            else:
                g[i] = gamma * np.sign(zeta[i])
        grad = mv(MT, g)
        cands = np.empty((len(_BETAS), n))
        exact = False
        for b in range(len(_BETAS)):
            beta = _BETAS[b]
            for i in range(r):
                d[i] = 1.0 if abs(zeta[i]) <= gamma else beta * psi[i]
            dx, ok = _scaled_solve(_normal(M, d), grad, (nq >= n) if beta == 0.0 else True)
            cands[b] = lin(1.0, x, -1.0, dx)
            if beta == 0.0 and ok:
                zc = _residual(M, cands[0], yv)
                exact = True
                for i in range(r):
                    if abs(zeta[i]) <= gamma:
                        if not abs(zc[i]) <= gamma + slack:
                            exact = False
                    elif not np.sign(zeta[i]) * zc[i] >= gamma - slack:
                        exact = False
                if exact:
                    return cands[0]
        # IRLS step (weights psi) and the backtracked Newton candidates: the cheapest is kept
        for i in range(r):
            g[i] = psi[i] * yv[i]
        xn, _ = _scaled_solve(_normal(M, psi), mv(MT, g), True)
        step = maxabs(mv(M, lin(1.0, xn, -1.0, x)))
        best = xn
        best_cost = _huber_cost(_residual(M, xn, yv), gamma)
        for b in range(len(_BETAS)):
            f = 1.0
            for _t in range(_N_BACKTRACK):
                trial = np.empty(n)
                for i in range(n):  # x + (cand − x) f, as huber_regression.minimise
                    trial[i] = x[i] + (cands[b, i] - x[i]) * f
                cost = _huber_cost(_residual(M, trial, yv), gamma)
                if cost < best_cost:
                    best, best_cost = trial, cost
                f *= 0.5
        x = best
        if step <= tol:
            break
    return x


@njit(cache=True, error_model="numpy")
def _inv_eye_plus_scaled(C, E, T, Lt, Ti):
    """Ti = T⁻¹ for T = I + diag(E) C diag(E) (no allocation); False if T is not positive definite."""
    m = E.shape[0]
    for i in range(m):
        for j in range(m):
            T[i, j] = E[i] * C[i, j] * E[j] + (1.0 if i == j else 0.0)
    return inv_to(T, Lt, Ti)


@njit(cache=True, error_model="numpy")
def _minus_outer(P, X, Y, out):
    """out = P − X Yᵀ (summed in the order of the NumPy reference), then symmetrised: the Huber posterior."""
    n, m = X.shape
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(m):
                s += X[i, k] * Y[j, k]
            out[i, j] = P[i, j] - s
    sym(out)


@njit(cache=True, error_model="numpy")
def _huber_general(P, A, e, dx, gamma, tol, max_iter):
    """The whole whitened regression ``M = [A; L_P⁻¹]``, ``y = [e; 0]`` minimised from dx: ``(dx, P⁺, ok)``."""
    m, n = A.shape
    L_P, ok = chol(P)
    if not ok:
        return dx, P, False
    M = np.empty((m + n, n))
    M[:m] = A
    M[m:] = tri_inv(L_P)
    yv = np.zeros(m + n)
    yv[:m] = e
    dx = _minimise(M, yv, dx, gamma, tol, max_iter)
    w = _psi(_residual(M, dx, yv), gamma)
    Pp, ok = _covariance(_normal(M, w))
    return dx, Pp, ok


@njit(cache=True, error_model="numpy")
def _covariance(A):
    """``(A⁻¹, ok)`` by the Jacobi-scaled Cholesky factor, symmetrised (huber_regression.covariance)."""
    n = A.shape[0]
    L, s, ok = _jacobi_chol(A)
    if not ok:
        return A, False
    Li = tri_inv(L)
    P = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            t = 0.0
            for k in range(n):
                t += Li[k, i] * Li[k, j]
            P[i, j] = t * s[i] * s[j]
    sym(P)
    return P, True


@njit(cache=True, error_model="numpy")
def _weighted(C, b, d):
    """huber.py's ``_weighted``: ``(b − E T⁻¹ E C b, ok)``, ``E = diag(√d)``, ``T = I + E C E``."""
    m = C.shape[0]
    E = np.sqrt(d)
    T = np.empty((m, m))
    for i in range(m):
        for j in range(m):
            T[i, j] = E[i] * C[i, j] * E[j] + (1.0 if i == j else 0.0)
    Ti = np.empty((m, m))
    if not inv_to(T, np.zeros((m, m)), Ti):
        return b.copy(), False
    Cb = mv(C, b)
    for i in range(m):
        Cb[i] *= E[i]
    w = mv(Ti, Cb)
    out = np.empty(m)
    for i in range(m):
        out[i] = b[i] - E[i] * w[i]
    return out, True


@njit(cache=True, error_model="numpy")
def _mspace(C, e, Bm, c, gamma, tol, max_iter):
    """huber.py's ``_minimise_measurement_space`` for one run: ``(c, iterations, left, ok)``.

    ``Bm = L_Pᵀ Aᵀ`` (n, m) maps c to the whitened prior residuals. Each
    iteration: the Newton points of the current split (weights 1 within gamma,
    β ψ beyond, β in BETAS); the first, if it reproduces the split with every
    prior row within gamma, ends it; else, if a prior row is beyond gamma at
    the current point, the run is ``left`` to the whole regression; else the
    cheapest of the IRLS step and the backtracked Newton steps is taken (the
    same candidates in the same order as the NumPy reference, so an
    unconverged iteration stops at the same point).
    """
    m = C.shape[0]
    n = Bm.shape[0]
    slack = 1e-12 * gamma
    c = c.copy()
    nb = len(_BETAS)
    cands = np.empty((nb, m))
    d = np.empty(m)
    grad = np.empty(m)
    its = 0
    for _ in range(max_iter):
        zm = _residual(C, c, e)
        zp = mv(Bm, c)
        psi = _psi(zm, gamma)
        for i in range(m):
            grad[i] = c[i] + (zm[i] if abs(zm[i]) <= gamma else gamma * np.sign(zm[i]))
        for b in range(nb):
            for i in range(m):
                d[i] = 1.0 if abs(zm[i]) <= gamma else _BETAS[b] * psi[i]
            w, ok = _weighted(C, grad, d)
            if not ok:
                return c, its, False, False
            for i in range(m):
                cands[b, i] = c[i] - w[i]
        zc = _residual(C, cands[0], e)
        zpc = mv(Bm, cands[0])
        exact = True
        for i in range(m):
            if abs(zm[i]) <= gamma:
                if not abs(zc[i]) <= gamma + slack:
                    exact = False
            elif not np.sign(zm[i]) * zc[i] >= gamma - slack:
                exact = False
        for i in range(n):
            if not abs(zpc[i]) <= gamma + slack:
                exact = False
        if exact:
            return cands[0].copy(), its + 1, False, True
        for i in range(n):
            if abs(zp[i]) > gamma:
                return c, its, True, True
        pe = np.empty(m)
        for i in range(m):
            pe[i] = psi[i] * e[i]
        cI, ok = _weighted(C, pe, psi)
        if not ok:
            return c, its, False, False
        dc = lin(1.0, cI, -1.0, c)
        step = max(maxabs(mv(C, dc)), maxabs(mv(Bm, dc)))
        best = cI
        best_cost = _huber_cost(_residual(C, cI, e), gamma) + _huber_cost(mv(Bm, cI), gamma)
        for b in range(nb):
            f = 1.0
            for _t in range(_N_BACKTRACK):
                trial = np.empty(m)
                for i in range(m):
                    trial[i] = c[i] + (cands[b, i] - c[i]) * f
                cost = _huber_cost(_residual(C, trial, e), gamma) + _huber_cost(mv(Bm, trial), gamma)
                if cost < best_cost:
                    best, best_cost = trial, cost
                f *= 0.5
        c = best
        its += 1
        if step <= tol:
            break
    return c, its, False, True


@njit(cache=True, error_model="numpy")
def _huber_out(P, A, PAT, C, e, c, gamma, tol, max_iter, Pp, dx, LP, wm, wmm, wnm):
    """huber_correct's branch for a run whose Kalman point has a whitened residual beyond gamma.

    The iterations in the measurement space (:func:`_mspace`); at their point
    ``δx = P Aᵀ c`` and ``P⁺ = P − U (E C E + I)⁻¹ Uᵀ`` (``U = P Aᵀ E``,
    ``E = diag(√ψ)`` of the measurement rows); when the run was left to the
    whole regression (a prior row beyond gamma) or a prior row's weight is
    below 1 there, the whole regression from that point with the iterations
    left (:func:`_huber_general`).
    """
    m = C.shape[0]
    n = P.shape[0]
    if not chol_to(P, LP):
        return False
    Bm = np.zeros((n, m))  # L_Pᵀ Aᵀ
    for j in range(n):
        for i in range(m):
            s = 0.0
            for k in range(j, n):
                s += LP[k, j] * A[i, k]
            Bm[j, i] = s
    co, its, left, ok = _mspace(C, e, Bm, c, gamma, tol, max_iter)
    if not ok:
        return False
    mv_to(PAT, co, dx)
    zp = mv(Bm, co)
    general = left
    for i in range(n):
        if abs(zp[i]) > gamma:
            general = True
    if general:
        budget = max_iter - its if left else 0
        dx2, Pp2, ok = _huber_general(P, A, e, dx.copy(), gamma, tol, budget)
        Pp[:] = Pp2
        dx[:] = dx2
        return ok
    E, T, Lt, Ti, U, UTi = wm[0], wmm[0], wmm[1], wmm[2], wnm[0], wnm[1]
    zm = _residual(C, co, e)
    for i in range(m):  # E = diag(√ψ(z_m)) (_psi's weights)
        a = abs(zm[i])
        E[i] = np.sqrt(1.0 if a <= gamma else gamma / max(a, gamma))
    if not _inv_eye_plus_scaled(C, E, T, Lt, Ti):
        return False
    for i in range(n):
        for j in range(m):
            U[i, j] = PAT[i, j] * E[j]
    mm_to(U, Ti, UTi)
    _minus_outer(P, UTi, U, Pp)
    return True


@njit(cache=True, error_model="numpy")
def huber_to(P, A, LRi, nu, gamma, tol, max_iter, e, PAT, C, Lm, Si, c, Cc, KW, Pp, dx, LP, z, wm, wmm, wnm):
    """Huber's correction (huber_correct with x_prior 0) into Pp and dx; False if a factorisation fails.

    The Kalman solution ``c = (C + I)⁻¹ e``, ``δx = P Aᵀ c`` first (C = A P Aᵀ,
    e = L_R⁻¹ ν); when every whitened residual, measurement ``C c − e`` and prior
    ``L_P⁻¹ δx``, is within gamma (the prior rows checked by ``cᵀ C c ≤ γ²``
    first, as huber_correct does) it is the M-estimate; otherwise the whole
    regression is minimised (:func:`_huber_general`). LP (n, n), z (n), wm (8, m), wmm (3, m, m) and
    wnm (2, n, m) are scratch.
    """
    n = P.shape[0]
    m = A.shape[0]
    mv_to(LRi, nu, e)
    mmt_to(P, A, PAT)
    mm_to(A, PAT, C)
    sym(C)
    for i in range(m):
        C[i, i] += 1.0
    ok = inv_to(C, Lm, Si)
    for i in range(m):
        C[i, i] -= 1.0
    if not ok:
        return False
    mv_to(Si, e, c)
    mv_to(PAT, c, dx)
    mv_to(C, c, Cc)
    inside = True
    cCc = 0.0
    for i in range(m):
        cCc += c[i] * Cc[i]
        if not abs(Cc[i] - e[i]) <= gamma:
            inside = False
    if inside and cCc > gamma * gamma:  # a prior row may be beyond gamma: L_P⁻¹ δx
        if not chol_to(P, LP):
            return False
        for i in range(n):
            s = dx[i]
            for k in range(i):
                s -= LP[i, k] * z[k]
            z[i] = s / LP[i, i]
            if not abs(z[i]) <= gamma:
                inside = False
    if not inside:
        return _huber_out(P, A, PAT, C, e, c, gamma, tol, max_iter, Pp, dx, LP, wm, wmm, wnm)
    mm_to(PAT, Si, KW)
    _minus_outer(P, KW, PAT, Pp)
    return True
