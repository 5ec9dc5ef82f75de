"""numba kernels of the compiled backend (imported only by :mod:`hinfnav.estimators.compiled`, on demand).

Every kernel runs a whole batch of runs over all steps in one call; the
matrices are small (n ≤ ~10, m ≤ ~5), so the products, Cholesky factors and
solves are written as plain loops (no BLAS call per product). The equations
are those of the NumPy reference, numbered as there:

* :func:`kalman_batch` — the Kalman core on a linear model with a constant
  measurement matrix: prediction ``x⁺ = F x + G u``, ``P⁻ = F P Fᵀ + Q_d``;
  the Joseph update (J1)-(J2) (:mod:`hinfnav.estimators.correction`), or
  Huber's M-estimation (:mod:`hinfnav.estimators.huber`, the whole whitened
  regression and the same Newton/IRLS/backtracking iterations as
  :func:`hinfnav.estimators.huber_regression.minimise`); optionally strong
  tracking's deferred prior (S1)-(S4) (:mod:`hinfnav.estimators.adaptive`).
  With ``shared`` the covariance and gain do not depend on the data: one
  recursion serves every run.
* :func:`sigma_point_batch` — the unscented/cubature filter (U1)-(U5) of
  :mod:`hinfnav.estimators.sigma_point` on a linear model.
* :func:`recursive_hinf_batch` — Simon's a-priori recursive H∞ filter
  (:mod:`hinfnav.estimators.recursive_hinf`), gain recursion with the steady
  freeze, then the mean recursion of every run.

Each returns False when a factorisation fails or a number is not finite; the
caller then runs the NumPy reference, which raises its own error.
"""

import numpy as np
from numba import njit

__all__ = ["kalman_batch", "sigma_point_batch", "recursive_hinf_batch"]

_BETAS = (0.0, 1e-1, 1e-2, 1e-3)  # as hinfnav.estimators.huber_regression.BETAS
_N_BACKTRACK = 11  # BACKTRACK = 0.5 ** arange(11)


# -- small dense linear algebra ------------------------------------------------------------

@njit(cache=True)
def _mm(A, B):
    """A B."""
    n, k = A.shape
    p = B.shape[1]
    out = np.zeros((n, p))
    for i in range(n):
        for j in range(k):
            a = A[i, j]
            if a != 0.0:
                for c in range(p):
                    out[i, c] += a * B[j, c]
    return out


@njit(cache=True)
def _mmt(A, B):
    """A Bᵀ."""
    n, k = A.shape
    p = B.shape[0]
    out = np.empty((n, p))
    for i in range(n):
        for c in range(p):
            s = 0.0
            for j in range(k):
                s += A[i, j] * B[c, j]
            out[i, c] = s
    return out


@njit(cache=True)
def _mv(A, x):
    n, k = A.shape
    out = np.empty(n)
    for i in range(n):
        s = 0.0
        for j in range(k):
            s += A[i, j] * x[j]
        out[i] = s
    return out


@njit(cache=True)
def _lin(a, X, b, Y):
    """a X + b Y (1-D or 2-D arrays of one shape), a new array."""
    out = np.empty_like(X)
    xf, yf, of = X.ravel(), Y.ravel(), out.ravel()
    for i in range(xf.size):
        of[i] = a * xf[i] + b * yf[i]
    return out


@njit(cache=True)
def _eye_minus(B):
    """I − B."""
    out = -B
    for i in range(B.shape[0]):
        out[i, i] += 1.0
    return out


@njit(cache=True)
def _maxabs(x):
    s = 0.0
    for v in x:
        s = max(s, abs(v))
    return s


@njit(cache=True)
def _sym(A):
    n = A.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            v = 0.5 * (A[i, j] + A[j, i])
            A[i, j] = v
            A[j, i] = v


@njit(cache=True)
def _chol(A):
    """Lower Cholesky factor of a symmetric matrix; ``(L, ok)``."""
    n = A.shape[0]
    L = np.zeros((n, n))
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            return L, False
        d = np.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            t = A[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
    return L, True


@njit(cache=True)
def _chol_solve(L, B):
    """(L Lᵀ)⁻¹ B for a lower factor L and B (n, p)."""
    n, p = B.shape
    X = B.copy()
    for c in range(p):
        for i in range(n):
            s = X[i, c]
            for k in range(i):
                s -= L[i, k] * X[k, c]
            X[i, c] = s / L[i, i]
        for i in range(n - 1, -1, -1):
            s = X[i, c]
            for k in range(i + 1, n):
                s -= L[k, i] * X[k, c]
            X[i, c] = s / L[i, i]
    return X


@njit(cache=True)
def _tri_inv(L):
    """L⁻¹ of a lower-triangular L."""
    n = L.shape[0]
    X = np.zeros((n, n))
    for c in range(n):
        for i in range(c, n):
            s = 1.0 if i == c else 0.0
            for k in range(c, i):
                s -= L[i, k] * X[k, c]
            X[i, c] = s / L[i, i]
    return X


@njit(cache=True)
def _spd_inv(A):
    L, ok = _chol(A)
    if not ok:
        return A, False
    X = _chol_solve(L, np.eye(A.shape[0]))
    _sym(X)
    return X, True


@njit(cache=True)
def _finite(A):
    for v in A.ravel():
        if not np.isfinite(v):
            return False
    return True


# -- the Huber M-estimation (huber.py / huber_regression.py) ------------------------------

@njit(cache=True)
def _scaled_solve(A, b, usable):
    """``A⁻¹ b`` by the Jacobi-scaled Cholesky factor (``_spd_solve``); ``(x, ok)``, x = 0 when not ok."""
    n = A.shape[0]
    s = np.empty(n)
    x = np.zeros(n)
    if not usable:
        return x, False
    for i in range(n):
        d = A[i, i]
        if not (np.isfinite(d) and d > 0.0):
            return x, False
        s[i] = 1.0 / np.sqrt(d)
    As = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            As[i, j] = A[i, j] * s[i] * s[j]
    L, ok = _chol(As)
    if not ok:
        return x, False
    rhs = np.empty((n, 1))
    for i in range(n):
        rhs[i, 0] = s[i] * b[i]
    X = _chol_solve(L, rhs)
    for i in range(n):
        x[i] = s[i] * X[i, 0]
        if not np.isfinite(x[i]):
            return np.zeros(n), False
    return x, True


@njit(cache=True)
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


@njit(cache=True)
def _huber_cost(z, gamma):
    c = 0.0
    for v in z:
        a = abs(v)
        c += 0.5 * a * a if a <= gamma else gamma * a - 0.5 * gamma * gamma
    return c


@njit(cache=True)
def _psi(z, gamma):
    w = np.empty(z.size)
    for i in range(z.size):
        a = abs(z[i])
        w[i] = 1.0 if a <= gamma else gamma / max(a, gamma)
    return w


@njit(cache=True)
def _residual(M, x, yv):
    """M x − y."""
    z = _mv(M, x)
    for i in range(z.size):
        z[i] -= yv[i]
    return z


@njit(cache=True)
def _innovation(H, x, yk):
    """y − H x."""
    z = _mv(H, x)
    for i in range(z.size):
        z[i] = yk[i] - z[i]
    return z


@njit(cache=True)
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
        grad = _mv(MT, g)
        cands = np.empty((len(_BETAS), n))
        exact = False
        for b in range(len(_BETAS)):
            beta = _BETAS[b]
            for i in range(r):
                d[i] = 1.0 if abs(zeta[i]) <= gamma else beta * psi[i]
            dx, ok = _scaled_solve(_normal(M, d), grad, (nq >= n) if beta == 0.0 else True)
            cands[b] = _lin(1.0, x, -1.0, dx)
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
        xn, _ = _scaled_solve(_normal(M, psi), _mv(MT, g), True)
        step = _maxabs(_mv(M, _lin(1.0, xn, -1.0, x)))
        best = xn
        best_cost = _huber_cost(_residual(M, xn, yv), gamma)
        for b in range(len(_BETAS)):
            f = 1.0
            for _t in range(_N_BACKTRACK):
                trial = _lin(1.0 - f, x, f, cands[b])
                cost = _huber_cost(_residual(M, trial, yv), gamma)
                if cost < best_cost:
                    best, best_cost = trial, cost
                f *= 0.5
        x = best
        if step <= tol:
            break
    return x


@njit(cache=True)
def _huber_correct(P, A, e, gamma, tol, max_iter):
    """Huber correction in error coordinates (huber_correct with x_prior 0): ``(dx, P⁺, ok)``.

    ``A = L_R⁻¹ H`` (m, n), ``e = L_R⁻¹ ν``. The Kalman solution first; if a
    whitened residual (measurement or prior row) exceeds gamma, the whole
    regression ``M = [A; L_P⁻¹]``, ``y = [e; 0]`` is minimised from it.
    """
    m, n = A.shape
    PAT = _mmt(P, A)
    C = _mm(A, PAT)
    _sym(C)
    S = _eye_minus(-C)
    Si, ok = _spd_inv(S)
    if not ok:
        return np.zeros(n), P, False
    c = _mv(Si, e)
    dx = _mv(PAT, c)
    zm = _residual(C, c, e)
    L_P, ok = _chol(P)
    if not ok:
        return dx, P, False
    LPi = _tri_inv(L_P)
    zp = _mv(LPi, dx)
    if _maxabs(zm) <= gamma and _maxabs(zp) <= gamma:
        Pp = _lin(1.0, P, -1.0, _mmt(_mm(PAT, Si), PAT))
        _sym(Pp)
        return dx, Pp, True
    M = np.empty((m + n, n))
    M[:m] = A
    M[m:] = LPi
    yv = np.zeros(m + n)
    yv[:m] = e
    dx = _minimise(M, yv, dx, gamma, tol, max_iter)
    w = _psi(_residual(M, dx, yv), gamma)
    Pp, ok = _spd_inv(_normal(M, w))
    return dx, Pp, ok


# -- the Kalman core ----------------------------------------------------------------------

@njit(cache=True)
def _joseph(P, H, R, nu, symmetrize):
    """(J1)-(J2): ``(dx, P⁺, K, ok)``."""
    n = P.shape[0]
    PHT = _mmt(P, H)
    S = _lin(1.0, _mm(H, PHT), 1.0, R)
    Si, ok = _spd_inv(S)
    if not ok:
        return np.zeros(n), P, PHT, False
    K = _mm(PHT, Si)
    IKH = _eye_minus(_mm(K, H))
    Pp = _lin(1.0, _mmt(_mm(IKH, P), IKH), 1.0, _mmt(_mm(K, R), K))
    if symmetrize:
        _sym(Pp)
    return _mv(K, nu), Pp, K, True


@njit(cache=True)
def _fade(PPT, Qd, H, R, V0, beta, a):
    """(S2)-(S4): ``P(k+1|k) = Λ^{1/2} Φ P Φᵀ Λ^{1/2} + Q_d``."""
    n = PPT.shape[0]
    m = H.shape[0]
    N = _lin(1.0, V0, -1.0, _lin(beta, R, 1.0, _mmt(_mm(H, Qd), H)))
    trN = 0.0
    for i in range(m):
        trN += N[i, i]
    PHt = _mmt(PPT, H)
    den = 0.0
    for i in range(n):
        s = 0.0
        for j in range(m):
            s += PHt[i, j] * H[j, i]
        den += a[i] * s
    c = trN / den if den > 0 else 0.0
    sl = np.empty(n)
    for i in range(n):
        sl[i] = np.sqrt(max(1.0, a[i] * c))
    P = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            P[i, j] = sl[i] * PPT[i, j] * sl[j] + Qd[i, j]
    return P


@njit(cache=True)
def _moment(V0, nu, rho, first):
    """(S1): γγᵀ at the first reading, else (ρ V₀ + γγᵀ)/(1 + ρ)."""
    m = nu.size
    V = np.empty((m, m))
    for i in range(m):
        for j in range(m):
            gg = nu[i] * nu[j]
            V[i, j] = gg if first else (rho * V0[i, j] + gg) / (1.0 + rho)
    return V


@njit(cache=True)
def _propagate(F, G, u, x, use_input):
    """F x (+ G u)."""
    out = _mv(F, x)
    if use_input:
        gu = _mv(G, u)
        for i in range(out.size):
            out[i] += gu[i]
    return out


@njit(cache=True)
def _store(xhat, r, k, x, n_rep):
    for i in range(n_rep):
        xhat[r, k, i] = x[i]


@njit(cache=True)
def _record(P, n_rep, r, k, Pdiag, Pfull, keep):
    if keep == 1:
        for i in range(n_rep):
            Pdiag[r, k, i] = P[i, i]
    elif keep == 2:
        for i in range(n_rep):
            for j in range(n_rep):
                Pfull[r, k, i, j] = P[i, j]


@njit(cache=True)
def kalman_batch(F, G, H, Qd, R, P0, x0, y, u, use_input, filtered, symmetrize, huber, LRi, gamma, tol, max_iter,
                 strong, rho, beta, a, shared, n_rep, keep, xhat, Pdiag, Pfull):
    """The Kalman core over all runs and steps (see the module docstring); fills xhat, Pdiag/Pfull; ok."""
    runs, steps, m = y.shape
    n = F.shape[0]
    if shared:  # the data-independent gain sequence, once
        K_seq = np.empty((steps, n, m))
        P = P0.copy()
        for k in range(steps):
            _, Pp, K, ok = _joseph(P, H, R, np.zeros(m), symmetrize)
            if not ok:
                return False
            K_seq[k] = K
            _record(Pp if filtered else P, n_rep, 0, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                P = _lin(1.0, _mmt(_mm(F, Pp), F), 1.0, Qd)
        for r in range(runs):
            x = x0.copy()
            for k in range(steps):
                xp = _lin(1.0, x, 1.0, _mv(K_seq[k], _innovation(H, x, y[r, k])))
                _store(xhat, r, k, xp if filtered else x, n_rep)
                if k < steps - 1:
                    x = _propagate(F, G, u[r, k], xp, use_input)
        return True
    A = _mm(LRi, H) if huber else H
    for r in range(runs):
        x = x0.copy()
        P = P0.copy()
        PPT = P0
        V0 = np.zeros((m, m))
        for k in range(steps):
            nu = _innovation(H, x, y[r, k])
            if strong and k > 0:
                V0 = _moment(V0, nu, rho[r], k == 1)
                P = _fade(PPT, Qd, H, R, V0, beta[r], a)
            if huber:
                dx, Pp, ok = _huber_correct(P, A, _mv(LRi, nu), gamma, tol, max_iter)
            else:
                dx, Pp, _, ok = _joseph(P, H, R, nu, symmetrize)
            if not ok or not _finite(Pp) or not _finite(dx):
                return False
            xp = _lin(1.0, x, 1.0, dx)
            _store(xhat, r, k, xp if filtered else x, n_rep)
            _record(Pp if filtered else P, n_rep, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                x = _propagate(F, G, u[r, k], xp, use_input)
                PPT = _mmt(_mm(F, Pp), F)
                P = _lin(1.0, PPT, 1.0, Qd)
    return True


# -- the sigma-point filter ------------------------------------------------------------

@njit(cache=True)
def _offsets(P, scale, center):
    """Sigma-point offsets (U1)/(U3) about zero: rows (N, n)."""
    n = P.shape[0]
    L, ok = _chol(scale * P)
    N = 2 * n + (1 if center else 0)
    D = np.zeros((N, n))
    o = 1 if center else 0
    for i in range(n):
        for j in range(n):
            D[o + i, j] = L[j, i]
            D[o + n + i, j] = -L[j, i]
    return D, ok


@njit(cache=True)
def _wcov(Wc, A, B):
    """Σ Wc_i A_i B_iᵀ."""
    N, p = A.shape
    q = B.shape[1]
    out = np.zeros((p, q))
    for s in range(N):
        for i in range(p):
            a = Wc[s] * A[s, i]
            for j in range(q):
                out[i, j] += a * B[s, j]
    return out


@njit(cache=True)
def _shift_rows(X, v, sign):
    """Rows of X plus (sign 1) or minus (sign −1) v, in place."""
    for s in range(X.shape[0]):
        for i in range(X.shape[1]):
            X[s, i] += sign * v[i]


@njit(cache=True)
def _weighted_mean(W, X, ref):
    """ref + Σ W_s (X_s − ref) (ref zero: the weighted mean)."""
    out = ref.copy()
    for s in range(X.shape[0]):
        for i in range(X.shape[1]):
            out[i] += W[s] * (X[s, i] - ref[i])
    return out


@njit(cache=True)
def sigma_point_batch(F, G, H, Q, R, P0, x0, y, u, use_input, filtered, Wm, Wc, scale, center, keep, xhat, Pdiag,
                      Pfull):
    """(U1)-(U5) on a linear model, every run and step; fills xhat, Pdiag/Pfull; ok."""
    runs, steps, m = y.shape
    n = F.shape[0]
    for r in range(runs):
        x = x0.copy()
        P = P0.copy()
        for k in range(steps):
            dX, ok = _offsets(P, scale, center)
            if not ok:
                return False
            Y = _mmt(dX, H)  # H (x + δ) = H x + H δ
            yx = _mv(H, x)
            _shift_rows(Y, yx, 1.0)
            ym = _weighted_mean(Wm, Y, Y[0].copy() if center else yx)
            _shift_rows(Y, ym, -1.0)
            S = _lin(1.0, _wcov(Wc, Y, Y), 1.0, R)
            Si, ok = _spd_inv(S)
            if not ok:
                return False
            K = _mm(_wcov(Wc, dX, Y), Si)
            xp = _lin(1.0, x, 1.0, _mv(K, _lin(1.0, y[r, k], -1.0, ym)))
            Pp = _lin(1.0, P, -1.0, _mmt(_mm(K, S), K))
            _sym(Pp)
            _store(xhat, r, k, xp if filtered else x, n)
            _record(Pp if filtered else P, n, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                dX, ok = _offsets(Pp, scale, center)
                if not ok:
                    return False
                Xf = _mmt(dX, F)  # F (x + δ) + G u
                _shift_rows(Xf, _propagate(F, G, u[r, k], xp, use_input), 1.0)
                x = _weighted_mean(Wm, Xf, np.zeros(n))
                _shift_rows(Xf, x, -1.0)
                P = _lin(1.0, _wcov(Wc, Xf, Xf), 1.0, Q)
    return True


# -- the recursive H-infinity filter ------------------------------------------------------

@njit(cache=True)
def _frobenius(A):
    s = 0.0
    for v in A.ravel():
        s += v * v
    return np.sqrt(s)


@njit(cache=True)
def recursive_hinf_batch(F, G, H, Q, Gm, HtRi, P0, x0, y, u, use_input, freeze, keep, xhat, Pdiag, Pfull):
    """Simon's a-priori recursive H∞ filter, every run and step; ok False when N ≯ 0 at some step."""
    runs, steps, m = y.shape
    n = F.shape[0]
    FK = np.empty((steps, n, m))
    P = P0.copy()
    steady = False
    for k in range(steps):
        _record(P, n, 0, k, Pdiag, Pfull, keep)
        if steady:
            FK[k] = FK[k - 1]
            continue
        C, ok = _chol(P)
        if not ok:
            return False
        N = _eye_minus(-_mm(_mm(C.T.copy(), Gm), C))
        _sym(N)
        Nc, ok = _chol(N)
        if not ok:
            return False
        CNC = _mm(C, _chol_solve(Nc, C.T.copy()))
        _sym(CNC)
        FK[k] = _mm(F, _mm(CNC, HtRi))
        Pn = _lin(1.0, _mmt(_mm(F, CNC), F), 1.0, Q)
        _sym(Pn)
        if _frobenius(_lin(1.0, Pn, -1.0, P)) <= freeze * _frobenius(P):
            steady = True
        else:
            P = Pn
    for r in range(runs):
        x = x0.copy()
        for k in range(steps):
            _store(xhat, r, k, x, n)
            x = _lin(1.0, _propagate(F, G, u[r, k], x, use_input), 1.0, _mv(FK[k], _innovation(H, x, y[r, k])))
    return True
