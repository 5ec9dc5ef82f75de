"""Run-blocked ("lane") loops of the compiled kernels (numba; imported with :mod:`.compiled_kernels`).

A batch's runs are independent: these loops advance a block of
:data:`LANES` runs together, every product's innermost loop running over the
block (``a[i, j, b]``, b the run in the block), so that one machine
instruction serves several runs (SIMD across runs) and the constant matrices'
entries are read once per block. The arithmetic of each run is that of the
one-run loops of :mod:`.compiled_kernels` (the same sums in the same order;
without fast-math the vectorised code rounds as the scalar one): blocking
changes the speed, not the numbers. A block past the batch's end repeats its
last run (computed, not stored).

* :func:`shared_means` — the mean recursion of every run when the gain
  sequence does not depend on the data (the Kalman filter and the
  sigma-point filter on a linear model, the recursive H∞ filter).
* :func:`kalman_lanes` — the Kalman core with a covariance per run: the
  Joseph update (J1)-(J2), optionally strong tracking's fading (S1)-(S4).

Equal entries of the constant matrices (F, H, their zeros) are skipped:
a skipped zero changes no finite sum.

numba's on-disk cache checks only the file of the function it compiles: after editing
this module, delete the kernels' cache (``__pycache__/compiled_*.nbi``/``.nbc`` or
``NUMBA_CACHE_DIR``) or touch :mod:`hinfnav.estimators.compiled_kernels`.
"""

import numpy as np
from numba import njit

from .compiled_huber import huber_to

__all__ = ["LANES", "kalman_lanes", "shared_means"]

#: Runs advanced together (a compile-time constant: the innermost loops have this fixed length).
LANES = 8


@njit(cache=True, error_model="numpy")
def _load(v, r0, nb, k, out):
    """out[i, b] = v[r0 + b, k, i] (the block's last run repeated past the batch's end)."""
    for b in range(LANES):
        r = r0 + min(b, nb - 1)
        for i in range(out.shape[0]):
            out[i, b] = v[r, k, i]


@njit(cache=True, error_model="numpy")
def _save(xhat, r0, nb, k, x, n_rep):
    for b in range(nb):
        for i in range(n_rep):
            xhat[r0 + b, k, i] = x[i, b]


@njit(cache=True, error_model="numpy")
def _innovation(H, yb, x, nu, s):
    """ν = y − H x in lanes (H's zeros skipped)."""
    m, n = H.shape
    for i in range(m):
        for b in range(LANES):
            s[b] = yb[i, b]
        for j in range(n):
            h = H[i, j]
            if h != 0.0:
                for b in range(LANES):
                    s[b] -= h * x[j, b]
        for b in range(LANES):
            nu[i, b] = s[b]


@njit(cache=True, error_model="numpy")
def _propagate(F, G, ub, xp, x, use_input, s):
    """x = F x⁺ (+ G u) in lanes (F's zeros skipped)."""
    n = F.shape[0]
    for i in range(n):
        for b in range(LANES):
            s[b] = 0.0
        for j in range(n):
            f = F[i, j]
            if f != 0.0:
                for b in range(LANES):
                    s[b] += f * xp[j, b]
        if use_input:
            for j in range(G.shape[1]):
                g = G[i, j]
                for b in range(LANES):
                    s[b] += g * ub[j, b]
        for b in range(LANES):
            x[i, b] = s[b]


@njit(cache=True, error_model="numpy")
def _one_run_means(K_seq, by, bx, F, G, H, I_n, x0, y, u, use_input, filtered, apriori, n_rep, xhat, r):
    """:func:`shared_means` of run r alone (the same sums)."""
    steps, m = y.shape[1], y.shape[2]
    n = F.shape[0]
    x, xp, nu = x0.copy(), np.empty(n), np.empty(m)
    for k in range(steps):
        for i in range(m):
            s = y[r, k, i]
            for j in range(n):
                h = H[i, j]
                if h != 0.0:
                    s -= h * x[j]
            nu[i] = s if apriori else s - by[k, i]
        if apriori:
            for i in range(n_rep):
                xhat[r, k, i] = x[i]
        for i in range(n):
            s = 0.0 if apriori else x[i]
            if apriori:
                for j in range(n):
                    f = F[i, j]
                    if f != 0.0:
                        s += f * x[j]
            for j in range(m):
                s += K_seq[k, i, j] * nu[j]
            xp[i] = s
        if not apriori:
            for i in range(n_rep):
                xhat[r, k, i] = xp[i] if filtered else x[i]
            if k == steps - 1:
                break
        A = I_n if apriori else F
        for i in range(n):
            s = 0.0
            for j in range(n):
                f = A[i, j]
                if f != 0.0:
                    s += f * xp[j]
            if use_input:
                for j in range(G.shape[1]):
                    s += G[i, j] * u[r, k, j]
            x[i] = s if apriori else s + bx[k, i]


@njit(cache=True, error_model="numpy")
def shared_means(K_seq, by, bx, F, G, H, x0, y, u, use_input, filtered, apriori, n_rep, xhat):
    """Every run's mean recursion with gains shared by all runs; fills xhat (runs, steps, n_rep).

    ``apriori`` False: ``ν = y − H x − b_y,k``, ``x⁺ = x + K_k ν``, then
    ``x = F x⁺ (+ G u) + b_x,k`` (xhat the filtered x⁺ or the predicted x);
    ``b_y``, ``b_x`` are the sigma-point filter's mean offsets (zero for the
    Kalman filter). ``apriori`` True (the recursive H∞ filter, gain ``F K``
    in K_seq): ``x⁺ = F x + (F K)_k (y − H x)``, ``x = x⁺ (+ G u)``, xhat the
    a-priori x.
    """
    runs, steps, m = y.shape
    n = F.shape[0]
    x, xp, nu = np.empty((n, LANES)), np.empty((n, LANES)), np.empty((m, LANES))
    yb, ub, s = np.empty((m, LANES)), np.empty((u.shape[2], LANES)), np.empty(LANES)
    I_n = np.eye(n)
    full = runs - runs % LANES
    for r in range(full, runs):  # the runs past the last full block, one at a time
        _one_run_means(K_seq, by, bx, F, G, H, I_n, x0, y, u, use_input, filtered, apriori, n_rep, xhat, r)
    for r0 in range(0, full, LANES):
        nb = min(LANES, runs - r0)
        for i in range(n):
            for b in range(LANES):
                x[i, b] = x0[i]
        for k in range(steps):
            _load(y, r0, nb, k, yb)
            _innovation(H, yb, x, nu, s)
            if apriori:
                _save(xhat, r0, nb, k, x, n_rep)
                _propagate(F, G, ub, x, xp, False, s)
                for i in range(n):
                    for j in range(m):
                        g = K_seq[k, i, j]
                        for b in range(LANES):
                            xp[i, b] += g * nu[j, b]
                if use_input:
                    _load(u, r0, nb, k, ub)
                _propagate(I_n, G, ub, xp, x, use_input, s)
                continue
            for i in range(m):
                for b in range(LANES):
                    nu[i, b] -= by[k, i]
            for i in range(n):
                for b in range(LANES):
                    s[b] = x[i, b]
                for j in range(m):
                    g = K_seq[k, i, j]
                    for b in range(LANES):
                        s[b] += g * nu[j, b]
                for b in range(LANES):
                    xp[i, b] = s[b]
            _save(xhat, r0, nb, k, xp if filtered else x, n_rep)
            if k < steps - 1:
                if use_input:
                    _load(u, r0, nb, k, ub)
                _propagate(F, G, ub, xp, x, use_input, s)
                for i in range(n):
                    for b in range(LANES):
                        x[i, b] += bx[k, i]
    return True


@njit(cache=True, error_model="numpy")
def _mat_ht(A, H, out):
    """out = A Hᵀ in lanes (``mmt_to``'s order: H's zeros skipped)."""
    n = A.shape[0]
    m = H.shape[0]
    for i in range(n):
        for c in range(m):
            for b in range(LANES):
                out[i, c, b] = 0.0
    for c in range(m):
        for j in range(H.shape[1]):
            h = H[c, j]
            if h != 0.0:
                for i in range(n):
                    for b in range(LANES):
                        out[i, c, b] += A[i, j, b] * h


@njit(cache=True, error_model="numpy")
def _left_product(A, X, out, L):
    """out = A X in the first ``L`` lanes (A's zeros skipped; each sum from 0 in the order of A's columns)."""
    for i in range(A.shape[0]):
        for j in range(X.shape[1]):
            for b in range(L):
                out[i, j, b] = 0.0
        for t in range(A.shape[1]):
            a = A[i, t]
            if a != 0.0:
                for j in range(X.shape[1]):
                    for b in range(L):
                        out[i, j, b] += a * X[t, j, b]


@njit(cache=True, error_model="numpy")
def _spd_inv(S, Lm, Si, s):
    """Si = S⁻¹ in lanes by the Cholesky factor Lm (``inv_to``'s order, symmetrised); the number of runs
    whose S is not positive definite (their entries then not finite or wrong: the caller gives up)."""
    m = S.shape[0]
    bad = 0
    for j in range(m):
        for b in range(LANES):
            s[b] = S[j, j, b]
        for k in range(j):
            for b in range(LANES):
                s[b] -= Lm[j, k, b] * Lm[j, k, b]
        for b in range(LANES):
            bad += not s[b] > 0.0
            Lm[j, j, b] = np.sqrt(s[b])
        for i in range(j + 1, m):
            for b in range(LANES):
                s[b] = S[i, j, b]
            for k in range(j):
                for b in range(LANES):
                    s[b] -= Lm[i, k, b] * Lm[j, k, b]
            for b in range(LANES):
                Lm[i, j, b] = s[b] / Lm[j, j, b]
    for c in range(m):
        for i in range(m):
            for b in range(LANES):
                s[b] = 1.0 if i == c else 0.0
            for k in range(i):
                for b in range(LANES):
                    s[b] -= Lm[i, k, b] * Si[k, c, b]
            for b in range(LANES):
                Si[i, c, b] = s[b] / Lm[i, i, b]
        for i in range(m - 1, -1, -1):
            for b in range(LANES):
                s[b] = Si[i, c, b]
            for k in range(i + 1, m):
                for b in range(LANES):
                    s[b] -= Lm[k, i, b] * Si[k, c, b]
            for b in range(LANES):
                Si[i, c, b] = s[b] / Lm[i, i, b]
    for i in range(m):
        for j in range(i + 1, m):
            for b in range(LANES):
                v = 0.5 * (Si[i, j, b] + Si[j, i, b])
                Si[i, j, b] = v
                Si[j, i, b] = v
    return bad


@njit(cache=True, error_model="numpy")
def _joseph(P, H, R, nu, PHT, S, Lm, Si, K, T2, KR, T1, Pp, dx, s):
    """(J1)-(J2) in lanes, as ``compiled_kernels._joseph_to`` per run; the number of runs whose S is not
    positive definite."""
    n = P.shape[0]
    m = H.shape[0]
    _mat_ht(P, H, PHT)
    _left_product(H, PHT, S, LANES)  # S = H (P Hᵀ) + R
    for i in range(m):
        for c in range(m):
            for b in range(LANES):
                S[i, c, b] += R[i, c]
    bad = _spd_inv(S, Lm, Si, s)
    for i in range(n):  # K = P Hᵀ S⁻¹
        for c in range(m):
            for b in range(LANES):
                s[b] = 0.0
            for j in range(m):
                for b in range(LANES):
                    s[b] += PHT[i, j, b] * Si[j, c, b]
            for b in range(LANES):
                K[i, c, b] = s[b]
    for i in range(n):  # T₂ = P − K (H P)
        for j in range(n):
            for b in range(LANES):
                s[b] = P[i, j, b]
            for c in range(m):
                for b in range(LANES):
                    s[b] -= K[i, c, b] * PHT[j, c, b]
            for b in range(LANES):
                T2[i, j, b] = s[b]
    _mat_ht(T2, H, KR)
    for i in range(n):  # T₁ = K R
        for c in range(m):
            for b in range(LANES):
                s[b] = 0.0
            for j in range(m):
                r = R[j, c]
                if r != 0.0:
                    for b in range(LANES):
                        s[b] += K[i, j, b] * r
            for b in range(LANES):
                T1[i, c, b] = s[b]
    for i in range(n):  # P⁺ = T₂ + (K R − T₂ Hᵀ) Kᵀ, the upper triangle, mirrored
        for j in range(i, n):
            for b in range(LANES):
                s[b] = T2[i, j, b]
            for c in range(m):
                for b in range(LANES):
                    s[b] += (T1[i, c, b] - KR[i, c, b]) * K[j, c, b]
            for b in range(LANES):
                Pp[i, j, b] = s[b]
                Pp[j, i, b] = s[b]
    for i in range(n):  # δx = K ν
        for b in range(LANES):
            s[b] = 0.0
        for j in range(m):
            for b in range(LANES):
                s[b] += K[i, j, b] * nu[j, b]
        for b in range(LANES):
            dx[i, b] = s[b]
    return bad


@njit(cache=True, error_model="numpy")
def _fade(PPT, Qd, H, trRQ, V0, beta, trR, a, PHt, P, s, c):
    """(S2)-(S4) in lanes into P, as ``compiled_kernels._fade_to`` per run."""
    n = PPT.shape[0]
    m = H.shape[0]
    for b in range(LANES):
        c[b] = -beta[b] * trR - trRQ
    for i in range(m):
        for b in range(LANES):
            c[b] += V0[i, i, b]
    _mat_ht(PPT, H, PHt)
    for b in range(LANES):
        s[b] = 0.0  # the denominator Σ aᵢ (Φ P Φᵀ Hᵀ H)ᵢᵢ
    for i in range(n):
        ai = a[i]
        for b in range(LANES):
            t = 0.0
            for j in range(m):
                t += PHt[i, j, b] * H[j, i]
            s[b] += ai * t
    for b in range(LANES):
        c[b] = c[b] / s[b] if s[b] > 0 else 0.0
    for i in range(n):  # the square roots of the fading factors, kept in PHt's first column
        for b in range(LANES):
            PHt[i, 0, b] = np.sqrt(max(1.0, a[i] * c[b]))
    for i in range(n):
        for j in range(n):
            q = Qd[i, j]
            for b in range(LANES):
                P[i, j, b] = PHt[i, 0, b] * PPT[i, j, b] * PHt[j, 0, b] + q


@njit(cache=True, error_model="numpy")
def kalman_lanes(F, G, H, Qd, R, P0, x0, y, u, use_input, filtered, huber, LRi, gamma, tol, max_iter, strong, rho,
                 beta, a, n_rep, keep, xhat, Pdiag, Pfull):
    """The Kalman core with a covariance per run of the runs in whole blocks of :data:`LANES` (the first
    ``runs − runs % LANES``); fills their xhat, Pdiag/Pfull; False when an S is not definite or a number not
    finite.

    The Joseph update (J1)-(J2) in lanes, or Huber's correction run by run
    (:func:`.compiled_huber.huber_to`, its iterations depend on the run's
    data) on copies of each run's P and ν; optionally strong tracking's
    fading; the prediction in lanes.
    """
    runs, steps, m = y.shape
    n = F.shape[0]
    L = LANES
    x, xp, dx = np.empty((n, L)), np.empty((n, L)), np.empty((n, L))
    nu, yb, ub, s, c = np.empty((m, L)), np.empty((m, L)), np.empty((u.shape[2], L)), np.empty(L), np.empty(L)
    P, Pp, PPT, T2 = np.empty((n, n, L)), np.empty((n, n, L)), np.empty((n, n, L)), np.empty((n, n, L))
    PHT, K, KR, T1 = np.empty((n, m, L)), np.empty((n, m, L)), np.empty((n, m, L)), np.empty((n, m, L))
    S, Lm, Si, V0 = np.empty((m, m, L)), np.zeros((m, m, L)), np.empty((m, m, L)), np.zeros((m, m, L))
    rb, bb = np.empty(L), np.empty(L)
    A = np.zeros((m, n))  # Huber's whitened measurement matrix L_R⁻¹ H and the one-run scratch of huber_to
    for i in range(m):
        for j in range(n):
            for t in range(m):
                A[i, j] += LRi[i, t] * H[t, j]
    P1, Pp1, dx1, nu1, e1, c1, Cc1 = (np.empty((n, n)), np.empty((n, n)), np.empty(n), np.empty(m), np.empty(m),
                                      np.empty(m), np.empty(m))
    PAT1, KW1, C1, Lm1, Si1 = np.empty((n, m)), np.empty((n, m)), np.empty((m, m)), np.zeros((m, m)), np.empty((m, m))
    LP1, z1, wm1, wmm1, wnm1 = np.zeros((n, n)), np.empty(n), np.empty((8, m)), np.empty((3, m, m)), np.empty((2, n, m))
    HQ = np.zeros((m, n))
    for i in range(m):  # tr(H Q_d Hᵀ)
        for j in range(n):
            for t in range(n):
                HQ[i, j] += H[i, t] * Qd[t, j]
    trRQ, trR = 0.0, 0.0
    for i in range(m):
        trR += R[i, i]
        t = 0.0
        for j in range(n):
            t += HQ[i, j] * H[i, j]
        trRQ += t
    for r0 in range(0, runs - runs % L, L):  # whole blocks only (the caller runs the rest one at a time)
        nb = min(L, runs - r0)
        for b in range(L):
            rb[b], bb[b] = rho[r0 + min(b, nb - 1)], beta[r0 + min(b, nb - 1)]
        for i in range(n):
            for b in range(L):
                x[i, b] = x0[i]
            for j in range(n):
                for b in range(L):
                    P[i, j, b] = P0[i, j]
        for k in range(steps):
            _load(y, r0, nb, k, yb)
            _innovation(H, yb, x, nu, s)
            if strong and k > 0:
                for i in range(m):  # (S1)
                    for j in range(m):
                        for b in range(L):
                            gg = nu[i, b] * nu[j, b]
                            V0[i, j, b] = gg if k == 1 else (rb[b] * V0[i, j, b] + gg) / (1.0 + rb[b])
                _fade(PPT, Qd, H, trRQ, V0, bb, trR, a, PHt=KR, P=P, s=s, c=c)
            if huber:
                for b in range(L):
                    for i in range(n):
                        for j in range(n):
                            P1[i, j] = P[i, j, b]
                    for i in range(m):
                        nu1[i] = nu[i, b]
                    if not huber_to(P1, A, LRi, nu1, gamma, tol, max_iter, e1, PAT1, C1, Lm1, Si1, c1, Cc1, KW1, Pp1,
                                    dx1, LP1, z1, wm1, wmm1, wnm1):
                        return False
                    for i in range(n):
                        dx[i, b] = dx1[i]
                        for j in range(n):
                            Pp[i, j, b] = Pp1[i, j]
            elif _joseph(P, H, R, nu, PHT, S, Lm, Si, K, T2, KR, T1, Pp, dx, s):
                return False
            for b in range(L):  # one sum per run: not finite when any of its entries is not
                s[b] = 0.0
            for i in range(n):
                for j in range(n):
                    for b in range(L):
                        s[b] += Pp[i, j, b]
                for b in range(L):
                    s[b] += dx[i, b]
            for b in range(L):
                if not np.isfinite(s[b]):
                    return False
            for i in range(n):
                for b in range(L):
                    xp[i, b] = x[i, b] + dx[i, b]
            _save(xhat, r0, nb, k, xp if filtered else x, n_rep)
            Pk = Pp if filtered else P
            if keep == 1:
                for b in range(nb):
                    for i in range(n_rep):
                        Pdiag[r0 + b, k, i] = Pk[i, i, b]
            elif keep == 2:
                for b in range(nb):
                    for i in range(n_rep):
                        for j in range(n_rep):
                            Pfull[r0 + b, k, i, j] = Pk[i, j, b]
            if k < steps - 1:
                if use_input:
                    _load(u, r0, nb, k, ub)
                _propagate(F, G, ub, xp, x, use_input, s)
                _left_product(F, Pp, T2, L)  # T₁ = F P⁺
                for i in range(n):  # Φ P⁺ Φᵀ: the upper triangle, mirrored
                    for j in range(i, n):
                        for b in range(L):
                            s[b] = 0.0
                        for t in range(n):
                            f = F[j, t]
                            if f != 0.0:
                                for b in range(L):
                                    s[b] += T2[i, t, b] * f
                        for b in range(L):
                            PPT[i, j, b] = s[b]
                            PPT[j, i, b] = s[b]
                for i in range(n):
                    for j in range(n):
                        q = Qd[i, j]
                        for b in range(L):
                            P[i, j, b] = PPT[i, j, b] + q
    return True
