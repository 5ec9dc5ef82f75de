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
  recursion serves every run. Otherwise the runs go in blocks
  (:func:`.compiled_lanes.kalman_lanes`), the runs past the last whole
  block one at a time here.
* :func:`sigma_point_batch` — the unscented/cubature filter (U1)-(U5) of
  :mod:`hinfnav.estimators.sigma_point` on a linear model (one covariance
  recursion for every run, as the Kalman filter's).
* :func:`recursive_hinf_batch` — Simon's a-priori recursive H∞ filter
  (:mod:`hinfnav.estimators.recursive_hinf`), gain recursion with the steady
  freeze, then the mean recursion of every run.

The small linear algebra is in :mod:`.compiled_linalg`, Huber's correction
in :mod:`.compiled_huber`, the loops over blocks of runs (and every shared
gain's mean recursion) in :mod:`.compiled_lanes` (numba's cache does not see
a change there: see their docstrings).

Each returns False when a factorisation fails or a number is not finite; the
caller then runs the NumPy reference, which raises its own error.
"""

import numpy as np
from numba import njit

from .compiled_huber import huber_to
from .compiled_lanes import LANES, kalman_lanes, shared_means
from .compiled_linalg import (chol, chol_solve, chol_to, eye_minus, finite, inv_to, lin, mm, mm_to, mmt, mmt_sym_to,
                              mmt_to, mv_to, sym)

__all__ = ["kalman_batch", "lti_batch", "sigma_point_batch", "recursive_hinf_batch"]


# -- the Kalman core ----------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def _joseph_to(P, H, R, nu, symmetrize, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx):
    """(J1)-(J2) into Pp, dx and K (no allocation); False if S is not positive definite.

    ``(I − K H) P (I − K H)ᵀ`` as ``T₂ − (T₂ Hᵀ) Kᵀ`` with ``T₂ = P − K (H P)``
    (the same products, H's zeros skipped), plus ``K R Kᵀ``; the upper
    triangle is computed and mirrored.
    """
    n = P.shape[0]
    m = H.shape[0]
    mmt_to(P, H, PHT)  # P Hᵀ (= (H P)ᵀ, P symmetric)
    mm_to(H, PHT, S)
    for i in range(m):
        for j in range(m):
            S[i, j] += R[i, j]
    if not inv_to(S, Lm, Si):
        return False
    mm_to(PHT, Si, K)
    for i in range(n):  # T₂ = P − K (H P) = P − K PHTᵀ
        for j in range(n):
            s = P[i, j]
            for c in range(m):
                s -= K[i, c] * PHT[j, c]
            T2[i, j] = s
    mmt_to(T2, H, KR)  # T₂ Hᵀ (n, m)
    mm_to(K, R, T1[:, :m])
    for i in range(n):
        for j in range(i, n):
            s = T2[i, j]
            for c in range(m):
                s += (T1[i, c] - KR[i, c]) * K[j, c]
            Pp[i, j] = s
            if j > i:
                Pp[j, i] = s
    mv_to(K, nu, dx)
    return True


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
    mmt_to(PPT, H, PHt)
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
    dx0, wm, wmm, wnm = np.empty(n), np.empty((8, m)), np.empty((3, m, m)), np.empty((2, n, m))  # Huber's scratch
    if shared:  # the data-independent gain sequence, once
        K_seq = np.empty((steps, n, m))
        P[:] = P0
        for k in range(steps):
            if not _joseph_to(P, H, R, nu, symmetrize, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx):
                return False
            K_seq[k] = K
            _record(Pp if filtered else P, n_rep, 0, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                mm_to(F, Pp, T1)
                mmt_sym_to(T1, F, P)
                for i in range(n):
                    for j in range(n):
                        P[i, j] += Qd[i, j]
        if not finite(K_seq):
            return False
        return shared_means(K_seq, np.zeros((steps, m)), np.zeros((steps, n)), F, G, H, x0, y, u, use_input,
                            filtered, False, n_rep, xhat)
    r_start = runs - runs % LANES  # a covariance per run: whole blocks of runs together, the rest below
    if r_start and not kalman_lanes(F, G, H, Qd, R, P0, x0, y, u, use_input, filtered, huber, LRi, gamma, tol,
                                    max_iter, strong, rho, beta, a, n_rep, keep, xhat, Pdiag, Pfull):
        return False
    A = mm(LRi, H) if huber else H
    HQH = mmt(mm(H, Qd), H)
    trRQ, trR = np.trace(HQH), np.trace(R)
    V0 = np.zeros((m, m))
    for r in range(r_start, runs):
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
                ok = huber_to(P, A, LRi, nu, gamma, tol, max_iter, e, PHT, S, Lm, Si, c, Cc, KR, Pp, dx, T2, dx0,
                              wm, wmm, wnm)
            else:
                ok = _joseph_to(P, H, R, nu, symmetrize, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx)
            if not ok or not finite(Pp) or not finite(dx):
                return False
            for i in range(n):
                xp[i] = x[i] + dx[i]
            _store(xhat, r, k, xp if filtered else x, n_rep)
            _record(Pp if filtered else P, n_rep, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                _propagate_to(F, G, u[r, k], xp, x, use_input)
                mm_to(F, Pp, T1)
                mmt_sym_to(T1, F, PPT)
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
    if not chol_to(A, L):
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
    """(U1)-(U5) on a linear model, every run and step; fills xhat, Pdiag/Pfull (one covariance: P0 is shared);
    ok.

    On a linear model the sigma points' deviations from their weighted mean
    (``H (x + δᵢ) − ȳ``, ``F (x⁺ + δᵢ) − x̄``) do not depend on the state:
    the covariances, the gains and the mean offsets ``Σ Wmᵢ H δᵢ``,
    ``Σ Wmᵢ F δᵢ`` (zero but for rounding) are computed once, about zero,
    and every run's mean follows ``ȳ = H x + Σ Wmᵢ H δᵢ``,
    ``x̄ = F x⁺ + G u + Σ Wmᵢ F δᵢ`` (:func:`.compiled_lanes.shared_means`).
    """
    runs, steps, m = y.shape
    n = F.shape[0]
    N = Wm.size
    A, L, P, Pp = np.empty((n, n)), np.zeros((n, n)), np.empty((n, n)), np.empty((n, n))
    D, Y, Xf = np.empty((N, n)), np.empty((N, m)), np.empty((N, n))
    S, Lm, Si, Pxy, K, KS = (np.empty((m, m)), np.zeros((m, m)), np.empty((m, m)), np.empty((n, m)),
                             np.empty((n, m)), np.empty((n, m)))
    zero_nm = np.zeros((n, m))
    K_seq, by, bx = np.empty((steps, n, m)), np.empty((steps, m)), np.zeros((steps, n))
    P[:] = P0
    for k in range(steps):
        if not _offsets_to(P, scale, center, A, L, D):
            return False
        mmt_to(D, H, Y)  # H δ (the deviations about H x)
        for i in range(m):
            by[k, i] = 0.0
        for s in range(N):
            for i in range(m):
                by[k, i] += Wm[s] * Y[s, i]
        for s in range(N):
            for i in range(m):
                Y[s, i] -= by[k, i]
        _wcov_to(Wc, Y, Y, S, R)
        _wcov_to(Wc, D, Y, Pxy, zero_nm)
        if not inv_to(S, Lm, Si):
            return False
        mm_to(Pxy, Si, K)
        K_seq[k] = K
        mm_to(K, S, KS)
        mmt_to(KS, K, Pp)
        for i in range(n):
            for j in range(n):
                Pp[i, j] = P[i, j] - Pp[i, j]
        sym(Pp)
        _record(Pp if filtered else P, n, 0, k, Pdiag, Pfull, keep)
        if k < steps - 1:
            if not _offsets_to(Pp, scale, center, A, L, D):
                return False
            mmt_to(D, F, Xf)  # F δ
            for s in range(N):
                for i in range(n):
                    bx[k, i] += Wm[s] * Xf[s, i]
            for s in range(N):
                for i in range(n):
                    Xf[s, i] -= bx[k, i]
            _wcov_to(Wc, Xf, Xf, P, Q)
    if not (finite(K_seq) and finite(by) and finite(bx)):
        return False
    return shared_means(K_seq, by, bx, F, G, H, x0, y, u, use_input, filtered, False, n, xhat)


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
        C, ok = chol(P)
        if not ok:
            return False
        N = eye_minus(-mm(mm(C.T.copy(), Gm), C))
        sym(N)
        Nc, ok = chol(N)
        if not ok:
            return False
        CNC = mm(C, chol_solve(Nc, C.T.copy()))
        sym(CNC)
        FK[k] = mm(F, mm(CNC, HtRi))
        Pn = lin(1.0, mmt(mm(F, CNC), F), 1.0, Q)
        sym(Pn)
        if _frobenius(lin(1.0, Pn, -1.0, P)) <= freeze * _frobenius(P):
            steady = True
        else:
            P = Pn
    if not finite(FK):
        return False
    # x⁺ = F x + F K (y − H x) + G u: the mean step with gain F K from x, then x = I·x⁺ + G u
    return shared_means(FK, np.zeros((steps, m)), np.zeros((steps, n)), F, G, H, x0, y, u, use_input, False, True, n,
                        xhat)


# -- the LTI filter (12) ------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def lti_batch(A, B, C, M, H, xf0, y, u, use_input, skip, xhat):
    """The fixed-gain filter (12) of :class:`~hinfnav.estimators.lti.LTIFilter`, every run and step; ok.

    ``x̂ₖ = C_F x_fₖ`` (reported), ``x_fₖ₊₁ = A x_fₖ + B_F yₖ (+ M uₖ)`` with A the
    filter's effective matrix (``A_F − M K C_F`` with the known input) and
    ``M = C_F⁻¹ G``. With ``skip`` a NaN channel of yₖ is replaced by the
    reading the filter predicts, ``(H x̂ₖ)ᵢ`` (a linear measurement).
    """
    runs, steps, m = y.shape
    n = A.shape[0]
    x, xn, yk = np.empty(n), np.empty(n), np.empty(m)
    for r in range(runs):
        x[:] = xf0
        for k in range(steps):
            for i in range(n):
                s = 0.0
                for j in range(n):
                    s += C[i, j] * x[j]
                xhat[r, k, i] = s
            if k == steps - 1:
                break
            for i in range(m):
                v = y[r, k, i]
                if skip and np.isnan(v):
                    v = 0.0
                    for j in range(n):
                        v += H[i, j] * xhat[r, k, j]
                yk[i] = v
            for i in range(n):
                s = 0.0
                for j in range(n):
                    s += A[i, j] * x[j]
                d = 0.0
                for j in range(m):
                    d += B[i, j] * yk[j]
                if use_input:
                    for j in range(M.shape[1]):
                        d += M[i, j] * u[r, k, j]
                xn[i] = s + d
            x[:] = xn
            for i in range(n):
                if not np.isfinite(x[i]):
                    return False
    return True
