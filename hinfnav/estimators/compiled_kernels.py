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

@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
def _mv(A, x):
    n, k = A.shape
    out = np.empty(n)
    for i in range(n):
        s = 0.0
        for j in range(k):
            s += A[i, j] * x[j]
        out[i] = s
    return out


@njit(cache=True, error_model="numpy")
def _mm_to(A, B, out):
    """out = A B (no allocation; the zero entries of A skipped: Φ, I − K H and the augmented blocks are sparse)."""
    n, k = A.shape
    p = B.shape[1]
    for i in range(n):
        for c in range(p):
            out[i, c] = 0.0
        for j in range(k):
            a = A[i, j]
            if a != 0.0:
                for c in range(p):
                    out[i, c] += a * B[j, c]


@njit(cache=True, error_model="numpy")
def _mmt_to(A, B, out):
    """out = A Bᵀ (no allocation; the zero entries of B skipped)."""
    n, k = A.shape
    p = B.shape[0]
    for i in range(n):
        for c in range(p):
            out[i, c] = 0.0
    for c in range(p):
        for j in range(k):
            b = B[c, j]
            if b != 0.0:
                for i in range(n):
                    out[i, c] += A[i, j] * b


@njit(cache=True, error_model="numpy")
def _mmt_sym_to(A, B, out):
    """out = A Bᵀ for a product known to be symmetric (F P Fᵀ, (I − KH) P (I − KH)ᵀ): the upper triangle
    computed (the zero entries of B skipped), the lower one mirrored."""
    n, k = A.shape
    for i in range(n):
        for c in range(i, n):
            out[i, c] = 0.0
    for c in range(n):
        for j in range(k):
            b = B[c, j]
            if b != 0.0:
                for i in range(c + 1):
                    out[i, c] += A[i, j] * b
    for i in range(n):
        for c in range(i):
            out[i, c] = out[c, i]


@njit(cache=True, error_model="numpy")
def _mv_to(A, x, out):
    """out = A x (no allocation)."""
    n, k = A.shape
    for i in range(n):
        s = 0.0
        for j in range(k):
            s += A[i, j] * x[j]
        out[i] = s


@njit(cache=True, error_model="numpy")
def _chol_to(A, L):
    """L = the lower Cholesky factor of A (no allocation); False if A is not positive definite."""
    n = A.shape[0]
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            return False
        d = np.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            t = A[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
            L[j, i] = 0.0
    return True


@njit(cache=True, error_model="numpy")
def _inv_to(A, L, out):
    """out = A⁻¹ of a symmetric positive definite A, by its Cholesky factor in L; False if not definite."""
    n = A.shape[0]
    if not _chol_to(A, L):
        return False
    for c in range(n):
        for i in range(n):
            s = 1.0 if i == c else 0.0
            for k in range(i):
                s -= L[i, k] * out[k, c]
            out[i, c] = s / L[i, i]
        for i in range(n - 1, -1, -1):
            s = out[i, c]
            for k in range(i + 1, n):
                s -= L[k, i] * out[k, c]
            out[i, c] = s / L[i, i]
    _sym(out)
    return True


@njit(cache=True, error_model="numpy")
def _lin(a, X, b, Y):
    """a X + b Y (1-D or 2-D arrays of one shape), a new array."""
    out = np.empty_like(X)
    xf, yf, of = X.ravel(), Y.ravel(), out.ravel()
    for i in range(xf.size):
        of[i] = a * xf[i] + b * yf[i]
    return out


@njit(cache=True, error_model="numpy")
def _eye_minus(B):
    """I − B."""
    out = -B
    for i in range(B.shape[0]):
        out[i, i] += 1.0
    return out


@njit(cache=True, error_model="numpy")
def _maxabs(x):
    s = 0.0
    for v in x:
        s = max(s, abs(v))
    return s


@njit(cache=True, error_model="numpy")
def _sym(A):
    n = A.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            v = 0.5 * (A[i, j] + A[j, i])
            A[i, j] = v
            A[j, i] = v


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
def _spd_inv(A):
    L, ok = _chol(A)
    if not ok:
        return A, False
    X = _chol_solve(L, np.eye(A.shape[0]))
    _sym(X)
    return X, True


@njit(cache=True, error_model="numpy")
def _finite(A):
    for v in A.ravel():
        if not np.isfinite(v):
            return False
    return True


# -- the Huber M-estimation (huber.py / huber_regression.py) ------------------------------

@njit(cache=True, error_model="numpy")
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
    z = _mv(M, x)
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


@njit(cache=True, error_model="numpy")
def _huber_general(P, A, e, dx, gamma, tol, max_iter):
    """The whole whitened regression ``M = [A; L_P⁻¹]``, ``y = [e; 0]`` minimised from dx: ``(dx, P⁺, ok)``."""
    m, n = A.shape
    L_P, ok = _chol(P)
    if not ok:
        return dx, P, False
    M = np.empty((m + n, n))
    M[:m] = A
    M[m:] = _tri_inv(L_P)
    yv = np.zeros(m + n)
    yv[:m] = e
    dx = _minimise(M, yv, dx, gamma, tol, max_iter)
    w = _psi(_residual(M, dx, yv), gamma)
    Pp, ok = _spd_inv(_normal(M, w))
    return dx, Pp, ok


@njit(cache=True, error_model="numpy")
def _huber_newton_m(P, A, PAT, C, e, c, Cc, gamma, Pp, dx):
    """The first Newton point in the measurement space (huber.py's ``_minimise_measurement_space``).

    From the Kalman point c, the Newton point of the current split of the
    measurement rows with every prior row quadratic,
    ``c − (g − E T⁻¹ E C g)`` (``g = c + ρ'(C c − e)``, ``E`` = 1 on the rows
    within gamma and 0 beyond, ``T = I + E C E``); when it reproduces the split
    and keeps every prior row ``L_Pᵀ Aᵀ c`` within gamma it is the minimiser:
    ``δx = P Aᵀ c`` and ``P⁺ = P − U (E_w C E_w + I)⁻¹ Uᵀ`` (``U = P Aᵀ E_w``,
    ``E_w = diag(√ψ)``) are written and True returned; otherwise False.
    """
    m = C.shape[0]
    n = P.shape[0]
    slack = 1e-12 * gamma
    zm, grad, E = np.empty(m), np.empty(m), np.empty(m)
    for i in range(m):
        zm[i] = Cc[i] - e[i]
        q = abs(zm[i]) <= gamma
        grad[i] = c[i] + (zm[i] if q else gamma * np.sign(zm[i]))
        E[i] = 1.0 if q else 0.0
    T = np.empty((m, m))
    for i in range(m):
        for j in range(m):
            T[i, j] = E[i] * C[i, j] * E[j] + (1.0 if i == j else 0.0)
    Ti, ok = _spd_inv(T)
    if not ok:
        return False
    Cg = _mv(C, grad)
    for i in range(m):
        Cg[i] *= E[i]
    w = _mv(Ti, Cg)
    cand = np.empty(m)
    for i in range(m):
        cand[i] = c[i] - (grad[i] - E[i] * w[i])
    zc = _mv(C, cand)
    for i in range(m):
        zc[i] -= e[i]
        if E[i] == 1.0:
            if not abs(zc[i]) <= gamma + slack:
                return False
        elif not np.sign(zm[i]) * zc[i] >= gamma - slack:
            return False
    L_P, ok = _chol(P)
    if not ok:
        return False
    ATc = np.zeros(n)
    for i in range(m):
        for j in range(n):
            ATc[j] += A[i, j] * cand[i]
    for j in range(n):  # prior rows L_Pᵀ Aᵀ c: beyond gamma (weight < 1), the whole regression decides
        s = 0.0
        for k in range(j, n):
            s += L_P[k, j] * ATc[k]
        if not abs(s) <= gamma:
            return False
    psi = _psi(zc, gamma)
    for i in range(m):
        E[i] = np.sqrt(psi[i])
        for j in range(m):
            T[i, j] = 0.0
    for i in range(m):
        for j in range(m):
            T[i, j] = E[i] * C[i, j] * E[j] + (1.0 if i == j else 0.0)
    Ti, ok = _spd_inv(T)
    if not ok:
        return False
    U = np.empty((n, m))
    for i in range(n):
        for j in range(m):
            U[i, j] = PAT[i, j] * E[j]
    UT = _mm(U, Ti)
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(m):
                s += UT[i, k] * U[j, k]
            Pp[i, j] = P[i, j] - s
    _sym(Pp)
    _mv_to(PAT, cand, dx)
    return True


@njit(cache=True, error_model="numpy")
def _joseph_to(P, H, R, nu, symmetrize, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx):
    """(J1)-(J2) into Pp, dx and K (no allocation); False if S is not positive definite.

    ``(I − K H) P (I − K H)ᵀ`` as ``T₂ − (T₂ Hᵀ) Kᵀ`` with ``T₂ = P − K (H P)``
    (the same products, H's zeros skipped), plus ``K R Kᵀ``; the upper
    triangle is computed and mirrored.
    """
    n = P.shape[0]
    m = H.shape[0]
    _mmt_to(P, H, PHT)  # P Hᵀ (= (H P)ᵀ, P symmetric)
    _mm_to(H, PHT, S)
    for i in range(m):
        for j in range(m):
            S[i, j] += R[i, j]
    if not _inv_to(S, Lm, Si):
        return False
    _mm_to(PHT, Si, K)
    for i in range(n):  # T₂ = P − K (H P) = P − K PHTᵀ
        for j in range(n):
            s = P[i, j]
            for c in range(m):
                s -= K[i, c] * PHT[j, c]
            T2[i, j] = s
    _mmt_to(T2, H, KR)  # T₂ Hᵀ (n, m)
    _mm_to(K, R, T1[:, :m])
    for i in range(n):
        for j in range(i, n):
            s = T2[i, j]
            for c in range(m):
                s += (T1[i, c] - KR[i, c]) * K[j, c]
            Pp[i, j] = s
            if j > i:
                Pp[j, i] = s
    _mv_to(K, nu, dx)
    return True


@njit(cache=True, error_model="numpy")
def _huber_to(P, A, LRi, nu, gamma, tol, max_iter, e, PAT, C, Lm, Si, c, Cc, KW, Pp, dx):
    """Huber's correction (huber_correct with x_prior 0) into Pp and dx; False if a factorisation fails.

    The Kalman solution ``c = (C + I)⁻¹ e``, ``δx = P Aᵀ c`` first (C = A P Aᵀ,
    e = L_R⁻¹ ν); when every whitened residual, measurement ``C c − e`` and prior
    ``L_P⁻¹ δx``, is within gamma (the prior rows checked by ``cᵀ C c ≤ γ²``
    first, as huber_correct does) it is the M-estimate; otherwise the whole
    regression is minimised (:func:`_huber_general`).
    """
    n = P.shape[0]
    m = A.shape[0]
    _mv_to(LRi, nu, e)
    _mmt_to(P, A, PAT)
    _mm_to(A, PAT, C)
    _sym(C)
    for i in range(m):
        C[i, i] += 1.0
    ok = _inv_to(C, Lm, Si)
    for i in range(m):
        C[i, i] -= 1.0
    if not ok:
        return False
    _mv_to(Si, e, c)
    _mv_to(PAT, c, dx)
    _mv_to(C, c, Cc)
    inside = True
    cCc = 0.0
    for i in range(m):
        cCc += c[i] * Cc[i]
        if not abs(Cc[i] - e[i]) <= gamma:
            inside = False
    if inside and cCc > gamma * gamma:  # a prior row may be beyond gamma: L_P⁻¹ δx
        L_P, ok = _chol(P)
        if not ok:
            return False
        z = dx.copy()
        for i in range(n):
            s = z[i]
            for k in range(i):
                s -= L_P[i, k] * z[k]
            z[i] = s / L_P[i, i]
            if not abs(z[i]) <= gamma:
                inside = False
    if not inside and _huber_newton_m(P, A, PAT, C, e, c, Cc, gamma, Pp, dx):
        return True
    if not inside:
        dx2, Pp2, ok = _huber_general(P, A, e, dx.copy(), gamma, tol, max_iter)
        Pp[:] = Pp2
        dx[:] = dx2
        return ok
    _mm_to(PAT, Si, KW)
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(m):
                s += KW[i, k] * PAT[j, k]
            Pp[i, j] = P[i, j] - s
    _sym(Pp)
    return True


@njit(cache=True, error_model="numpy")
def _mean_step(K, H, yk, x, xp, nu):
    """ν = y − H x, x⁺ = x + K ν into xp (no allocation)."""
    n, m = K.shape
    for i in range(m):
        s = yk[i]
        for j in range(n):
            s -= H[i, j] * x[j]
        nu[i] = s
    for i in range(n):
        s = x[i]
        for j in range(m):
            s += K[i, j] * nu[j]
        xp[i] = s


@njit(cache=True, error_model="numpy")
def _propagate_to(F, G, uk, xp, x, use_input):
    """x = F x⁺ (+ G u) (no allocation)."""
    n = F.shape[0]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += F[i, j] * xp[j]
        if use_input:
            for j in range(G.shape[1]):
                s += G[i, j] * uk[j]
        x[i] = s


@njit(cache=True, error_model="numpy")
def _fade_to(PPT, Qd, H, trRQ, V0, beta, trR, a, PHt, P):
    """(S2)-(S4) into P: ``c = tr N / Σ aᵢ Mᵢᵢ``, ``P = Λ^{1/2} Φ P Φᵀ Λ^{1/2} + Q_d``.

    ``tr N = tr V₀ − β tr R − tr(H Q_d Hᵀ)`` (``trRQ`` the last), ``Mᵢᵢ = (Φ P Φᵀ Hᵀ H)ᵢᵢ``.
    """
    n = PPT.shape[0]
    m = H.shape[0]
    trN = -beta * trR - trRQ
    for i in range(m):
        trN += V0[i, i]
    _mmt_to(PPT, H, PHt)
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
    for i in range(n):
        for j in range(n):
            P[i, j] = sl[i] * PPT[i, j] * sl[j] + Qd[i, j]


@njit(cache=True, error_model="numpy")
def _moment_to(V0, nu, rho, first):
    """(S1) in place: γγᵀ at the first reading, else (ρ V₀ + γγᵀ)/(1 + ρ)."""
    m = nu.size
    for i in range(m):
        for j in range(m):
            gg = nu[i] * nu[j]
            V0[i, j] = gg if first else (rho * V0[i, j] + gg) / (1.0 + rho)


@njit(cache=True, error_model="numpy")
def _store(xhat, r, k, x, n_rep):
    for i in range(n_rep):
        xhat[r, k, i] = x[i]


@njit(cache=True, error_model="numpy")
def _record(P, n_rep, r, k, Pdiag, Pfull, keep):
    if keep == 1:
        for i in range(n_rep):
            Pdiag[r, k, i] = P[i, i]
    elif keep == 2:
        for i in range(n_rep):
            for j in range(n_rep):
                Pfull[r, k, i, j] = P[i, j]


@njit(cache=True, error_model="numpy")
def kalman_batch(F, G, H, Qd, R, P0, x0, y, u, use_input, filtered, symmetrize, huber, LRi, gamma, tol, max_iter,
                 strong, rho, beta, a, shared, n_rep, keep, xhat, Pdiag, Pfull):
    """The Kalman core over all runs and steps (see the module docstring); fills xhat, Pdiag/Pfull; ok."""
    runs, steps, m = y.shape
    n = F.shape[0]
    PHT, K, KR, PHt = np.empty((n, m)), np.empty((n, m)), np.empty((n, m)), np.empty((n, m))
    S, Lm, Si = np.empty((m, m)), np.zeros((m, m)), np.empty((m, m))
    T1, T2, Pp, P, PPT = np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n))
    x, xp, dx, nu, e, c, Cc = np.empty(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    if shared:  # the data-independent gain sequence, once
        K_seq = np.empty((steps, n, m))
        P[:] = P0
        for k in range(steps):
            if not _joseph_to(P, H, R, nu, symmetrize, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx):
                return False
            K_seq[k] = K
            _record(Pp if filtered else P, n_rep, 0, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                _mm_to(F, Pp, T1)
                _mmt_sym_to(T1, F, P)
                for i in range(n):
                    for j in range(n):
                        P[i, j] += Qd[i, j]
        if not _finite(K_seq):
            return False
        for r in range(runs):
            x[:] = x0
            for k in range(steps):
                _mean_step(K_seq[k], H, y[r, k], x, xp, nu)
                _store(xhat, r, k, xp if filtered else x, n_rep)
                if k < steps - 1:
                    _propagate_to(F, G, u[r, k], xp, x, use_input)
        return True
    A = _mm(LRi, H) if huber else H
    HQH = _mmt(_mm(H, Qd), H)
    trRQ, trR = np.trace(HQH), np.trace(R)
    V0 = np.zeros((m, m))
    for r in range(runs):
        x[:] = x0
        P[:] = P0
        for k in range(steps):
            for i in range(m):
                s = y[r, k, i]
                for j in range(n):
                    s -= H[i, j] * x[j]
                nu[i] = s
            if strong and k > 0:
                _moment_to(V0, nu, rho[r], k == 1)
                _fade_to(PPT, Qd, H, trRQ, V0, beta[r], trR, a, PHt, P)
            if huber:
                ok = _huber_to(P, A, LRi, nu, gamma, tol, max_iter, e, PHT, S, Lm, Si, c, Cc, KR, Pp, dx)
            else:
                ok = _joseph_to(P, H, R, nu, symmetrize, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx)
            if not ok or not _finite(Pp) or not _finite(dx):
                return False
            for i in range(n):
                xp[i] = x[i] + dx[i]
            _store(xhat, r, k, xp if filtered else x, n_rep)
            _record(Pp if filtered else P, n_rep, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                _propagate_to(F, G, u[r, k], xp, x, use_input)
                _mm_to(F, Pp, T1)
                _mmt_sym_to(T1, F, PPT)
                for i in range(n):
                    for j in range(n):
                        P[i, j] = PPT[i, j] + Qd[i, j]
    return True


# -- the sigma-point filter ------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def _offsets_to(P, scale, center, A, L, D):
    """Sigma-point offsets (U1)/(U3) about zero into the rows of D (N, n); False if P is not definite."""
    n = P.shape[0]
    for i in range(n):
        for j in range(n):
            A[i, j] = scale * P[i, j]
    if not _chol_to(A, L):
        return False
    o = 1 if center else 0
    for j in range(n):
        D[0, j] = 0.0
    for i in range(n):
        for j in range(n):
            D[o + i, j] = L[j, i]
            D[o + n + i, j] = -L[j, i]
    return True


@njit(cache=True, error_model="numpy")
def _wcov_to(Wc, A, B, out, add):
    """out = Σ Wc_s A_s B_sᵀ + add."""
    N, p = A.shape
    q = B.shape[1]
    for i in range(p):
        for j in range(q):
            s = 0.0
            for t in range(N):
                s += Wc[t] * A[t, i] * B[t, j]
            out[i, j] = s + add[i, j]


@njit(cache=True, error_model="numpy")
def sigma_point_batch(F, G, H, Q, R, P0, x0, y, u, use_input, filtered, Wm, Wc, scale, center, keep, xhat, Pdiag,
                      Pfull):
    """(U1)-(U5) on a linear model, every run and step; fills xhat, Pdiag/Pfull; ok."""
    runs, steps, m = y.shape
    n = F.shape[0]
    N = Wm.size
    A, L, P, Pp = np.empty((n, n)), np.zeros((n, n)), np.empty((n, n)), np.empty((n, n))
    D, Y, Xf = np.empty((N, n)), np.empty((N, m)), np.empty((N, n))
    S, Lm, Si, Pxy, K, KS = (np.empty((m, m)), np.zeros((m, m)), np.empty((m, m)), np.empty((n, m)),
                             np.empty((n, m)), np.empty((n, m)))
    zero_nm = np.zeros((n, m))
    x, xp, ym, yx, base, ref = np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(n), np.empty(m)
    for r in range(runs):
        x[:] = x0
        P[:] = P0
        for k in range(steps):
            if not _offsets_to(P, scale, center, A, L, D):
                return False
            _mmt_to(D, H, Y)  # H (x + δ) = H x + H δ
            _mv_to(H, x, yx)
            for s in range(N):
                for i in range(m):
                    Y[s, i] += yx[i]
            for i in range(m):
                ref[i] = Y[0, i] if center else yx[i]
                ym[i] = ref[i]
            for s in range(N):
                for i in range(m):
                    ym[i] += Wm[s] * (Y[s, i] - ref[i])
            for s in range(N):
                for i in range(m):
                    Y[s, i] -= ym[i]
            _wcov_to(Wc, Y, Y, S, R)
            _wcov_to(Wc, D, Y, Pxy, zero_nm)
            if not _inv_to(S, Lm, Si):
                return False
            _mm_to(Pxy, Si, K)
            for i in range(n):
                s = x[i]
                for j in range(m):
                    s += K[i, j] * (y[r, k, j] - ym[j])
                xp[i] = s
            _mm_to(K, S, KS)
            _mmt_to(KS, K, Pp)
            for i in range(n):
                for j in range(n):
                    Pp[i, j] = P[i, j] - Pp[i, j]
            _sym(Pp)
            _store(xhat, r, k, xp if filtered else x, n)
            _record(Pp if filtered else P, n, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                if not _offsets_to(Pp, scale, center, A, L, D):
                    return False
                _mmt_to(D, F, Xf)  # F (x + δ) + G u
                _propagate_to(F, G, u[r, k], xp, base, use_input)
                for i in range(n):
                    x[i] = 0.0
                for s in range(N):
                    for i in range(n):
                        Xf[s, i] += base[i]
                        x[i] += Wm[s] * Xf[s, i]
                for s in range(N):
                    for i in range(n):
                        Xf[s, i] -= x[i]
                _wcov_to(Wc, Xf, Xf, P, Q)
    return True


# -- the recursive H-infinity filter ------------------------------------------------------

@njit(cache=True, error_model="numpy")
def _frobenius(A):
    s = 0.0
    for v in A.ravel():
        s += v * v
    return np.sqrt(s)


@njit(cache=True, error_model="numpy")
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
    if not _finite(FK):
        return False
    x, xp, nu = np.empty(n), np.empty(n), np.empty(m)
    I_n = np.eye(n)
    for r in range(runs):
        x[:] = x0
        for k in range(steps):
            _store(xhat, r, k, x, n)
            # x⁺ = F x + F K (y − H x) + G u: the mean step with gain F K from x, then x = I·x⁺ + G u
            for i in range(m):
                s = y[r, k, i]
                for j in range(n):
                    s -= H[i, j] * x[j]
                nu[i] = s
            for i in range(n):
                s = 0.0
                for j in range(n):
                    s += F[i, j] * x[j]
                for j in range(m):
                    s += FK[k, i, j] * nu[j]
                xp[i] = s
            _propagate_to(I_n, G, u[r, k], xp, x, use_input)
    return True
