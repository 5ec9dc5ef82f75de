"""numba kernels of the EKF and the sigma-point filter on a model's own compiled functions (imported on demand).

The model's functions (:mod:`hinfnav.systems.compiled`: ``f(x, u, t, p)``,
``F(x, u, t, p)``, ``h(x, p)``, ``H(x, p)``, ``residual(y, ŷ, p)``) are
arguments of first-class function type with fixed signatures, so each kernel
is compiled once (and cached on disk) for every model: a new model compiles
its own functions only.

* :func:`ekf_model_batch` — :class:`~hinfnav.estimators.ExtendedKalmanFilter`
  on a dynamics model or a linear system with any measurement model: per run
  and step, ``ŷ = h(x̂⁻)``, ``H = ∂h/∂x(x̂⁻)``, ``ν = r(y, ŷ)``, the Joseph
  update (J1)-(J2), then ``F = ∂f/∂x(x̂⁺)``, ``x̂⁻ = f(x̂⁺, u, t)``,
  ``P⁻ = F P⁺ Fᵀ + Q``, t = k Δt (the NumPy path's
  :meth:`~hinfnav.estimators.KalmanCore._update` and ``_predict``);
* :func:`sigma_point_model_batch` — :class:`~hinfnav.estimators.SigmaPointFilter`
  (U1)-(U5): points from the prior, ``ȳ = h(χ₀) + Σ Wᵐ r(Yᵢ, h(χ₀))``,
  ``S = Σ Wᶜ r(Yᵢ, ȳ) r(Yᵢ, ȳ)ᵀ + R``, ``P_xy``, ``K = P_xy S⁻¹``,
  ``P⁺ = P − K S Kᵀ`` (symmetrised); points from the posterior through f,
  ``P⁻ = Σ Wᶜ δᵢ δᵢᵀ + Q``.

``missing="skip"``: a NaN channel of yₖ reads as predicted and is removed
exactly as :func:`~hinfnav.estimators.correction.drop_missing` (and the
sigma-point filter's ``_without``) do: its row of H (its column of the output
deviations) and its innovation set to 0, its row and column of R to 0 with
``R_jj = 1``. With ``diag`` the innovation (NaN on a missing channel) and S of
every step are kept (the NIS inputs).

Each returns False when a factorisation fails or a number is not finite; the
caller then runs the NumPy reference, which raises its own error.
"""

import numpy as np
from numba import njit, types

from ..systems.compiled_functions import (DYNAMICS_JACOBIAN_SIGNATURE, DYNAMICS_SIGNATURE,
                                          MEASUREMENT_JACOBIAN_SIGNATURE, MEASUREMENT_SIGNATURE, RESIDUAL_SIGNATURE)
from .compiled_kernels import _joseph_to, _offsets_to, _record, _wcov_to
from .compiled_linalg import finite, inv_to, mm_to, mmt_to, sym

__all__ = ["ekf_model_batch", "sigma_point_model_batch"]

_F = types.FunctionType(DYNAMICS_SIGNATURE)
_FJ = types.FunctionType(DYNAMICS_JACOBIAN_SIGNATURE)
_H = types.FunctionType(MEASUREMENT_SIGNATURE)
_HJ = types.FunctionType(MEASUREMENT_JACOBIAN_SIGNATURE)
_RES = types.FunctionType(RESIDUAL_SIGNATURE)
_V = types.float64[::1]
_M = types.float64[:, ::1]
_A3 = types.float64[:, :, ::1]
_A4 = types.float64[:, :, :, ::1]
_B, _I, _D = types.boolean, types.int64, types.float64


@njit(cache=True, error_model="numpy")
def _reading(y, yhat, skip, yk, miss):
    """yₖ with its NaN channels (``skip``) replaced by ŷ into yk, miss[i] True there; any missing."""
    anym = False
    for i in range(y.size):
        v = y[i]
        if skip and np.isnan(v):
            yk[i] = yhat[i]
            miss[i] = True
            anym = True
        else:
            yk[i] = v
            miss[i] = False
    return anym


@njit(cache=True, error_model="numpy")
def _decouple(R, miss, Rk):
    """R with the rows and columns of the missing channels 0 and ``R_jj = 1`` (drop_missing)."""
    m = R.shape[0]
    for i in range(m):
        for j in range(m):
            Rk[i, j] = R[i, j] if not (miss[i] or miss[j]) else (1.0 if i == j else 0.0)


@njit(cache=True, error_model="numpy")
def _keep_diag(r, k, nu_raw, miss, S, nu_hist, S_hist):
    m = nu_raw.size
    for i in range(m):
        nu_hist[r, k, i] = np.nan if miss[i] else nu_raw[i]
        for j in range(m):
            S_hist[r, k, i, j] = S[i, j]


@njit(types.boolean(_F, _FJ, _H, _HJ, _RES, _V, _V, _M, _M, _M, _V, _A3, _A3, _D, _B, _B, _I, _A3, _A3, _A4, _B,
                    _A3, _A4), cache=True, error_model="numpy")
def ekf_model_batch(f, fj, h, hj, res, pf, ph, Q, R, P0, x0, y, u, dt, filtered, skip, keep, xhat, Pdiag, Pfull, diag,
                    nu_hist, S_hist):
    """The EKF over all runs and steps (see the module docstring); fills xhat, Pdiag/Pfull (keep 1/2), the NIS
    inputs (diag); ok."""
    runs, steps, m = y.shape
    n = x0.size
    PHT, K, KR = np.empty((n, m)), np.empty((n, m)), np.empty((n, m))
    S, Lm, Si, Rk, Hk = np.empty((m, m)), np.zeros((m, m)), np.empty((m, m)), np.empty((m, m)), np.empty((m, n))
    T1, T2, Pp, P = np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n))
    x, xp, dx, nu, yk = np.empty(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m)
    miss = np.zeros(m, dtype=np.bool_)
    for r in range(runs):
        x[:] = x0
        P[:] = P0
        for k in range(steps):
            yhat = h(x, ph)
            H = hj(x, ph)
            if yhat.size != m or H.shape[0] != m or H.shape[1] != n:
                return False
            anym = _reading(y[r, k], yhat, skip, yk, miss)
            nu_raw = res(yk, yhat, ph)
            if nu_raw.size != m:
                return False
            for i in range(m):
                nu[i] = 0.0 if miss[i] else nu_raw[i]
                for j in range(n):
                    Hk[i, j] = 0.0 if miss[i] else H[i, j]
            if anym:
                _decouple(R, miss, Rk)
            else:
                Rk[:] = R
            if not _joseph_to(P, Hk, Rk, nu, False, PHT, S, Lm, Si, K, T1, T2, KR, Pp, dx) or not finite(Pp) \
                    or not finite(dx):
                return False
            if diag:
                _keep_diag(r, k, nu_raw, miss, S, nu_hist, S_hist)
            for i in range(n):
                xp[i] = x[i] + dx[i]
                xhat[r, k, i] = xp[i] if filtered else x[i]
            _record(Pp if filtered else P, n, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                t = k * dt
                F = fj(xp, u[r, k], t, pf)
                xn = f(xp, u[r, k], t, pf)
                if xn.size != n or F.shape[0] != n or F.shape[1] != n:
                    return False
                for i in range(n):
                    if not np.isfinite(xn[i]):
                        return False
                    x[i] = xn[i]
                mm_to(F, Pp, T1)
                mmt_to(T1, F, P)
                for i in range(n):
                    for j in range(n):
                        P[i, j] += Q[i, j]
    return True


@njit(types.boolean(_F, _H, _RES, _V, _V, _M, _M, _M, _V, _A3, _A3, _D, _B, _V, _V, _D, _B, _B, _I, _A3, _A3, _A4,
                    _B, _A3, _A4), cache=True, error_model="numpy")
def sigma_point_model_batch(f, h, res, pf, ph, Q, R, P0, x0, y, u, dt, filtered, Wm, Wc, scale, center, skip, keep,
                            xhat, Pdiag, Pfull, diag, nu_hist, S_hist):
    """(U1)-(U5) over all runs and steps (see the module docstring); fills xhat, Pdiag/Pfull, the NIS inputs; ok."""
    runs, steps, m = y.shape
    n = x0.size
    N = Wm.size
    A, L, P, Pp = np.empty((n, n)), np.zeros((n, n)), np.empty((n, n)), np.empty((n, n))
    D, Xf, Y, dY = np.empty((N, n)), np.empty((N, n)), np.empty((N, m)), np.empty((N, m))
    S, Lm, Si, Rk = np.empty((m, m)), np.zeros((m, m)), np.empty((m, m)), np.empty((m, m))
    Pxy, K, KS = np.empty((n, m)), np.empty((n, m)), np.empty((n, m))
    zero_nm = np.zeros((n, m))
    x, xp, xs, ym, yk, nu = np.empty(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(m)
    miss = np.zeros(m, dtype=np.bool_)
    for r in range(runs):
        x[:] = x0
        P[:] = P0
        for k in range(steps):
            if not _offsets_to(P, scale, center, A, L, D):
                return False
            for s in range(N):
                for i in range(n):
                    xs[i] = x[i] + D[s, i]
                Ys = h(xs, ph)
                if Ys.size != m:
                    return False
                Y[s] = Ys
            ref = Y[0].copy() if center else h(x, ph)
            for i in range(m):
                ym[i] = 0.0
            for s in range(N):
                d = res(Y[s], ref, ph)
                for i in range(m):
                    ym[i] += Wm[s] * d[i]
            for i in range(m):
                ym[i] += ref[i]
            for s in range(N):
                dY[s] = res(Y[s], ym, ph)
            anym = _reading(y[r, k], ym, skip, yk, miss)
            nu_raw = res(yk, ym, ph)
            for i in range(m):
                nu[i] = 0.0 if miss[i] else nu_raw[i]
            if anym:
                for s in range(N):
                    for i in range(m):
                        if miss[i]:
                            dY[s, i] = 0.0
                _decouple(R, miss, Rk)
            else:
                Rk[:] = R
            _wcov_to(Wc, dY, dY, S, Rk)
            _wcov_to(Wc, D, dY, Pxy, zero_nm)
            if not inv_to(S, Lm, Si):
                return False
            if diag:
                _keep_diag(r, k, nu_raw, miss, S, nu_hist, S_hist)
            mm_to(Pxy, Si, K)
            for i in range(n):
                s_ = 0.0
                for j in range(m):
                    s_ += K[i, j] * nu[j]
                xp[i] = x[i] + s_
            mm_to(K, S, KS)
            mmt_to(KS, K, Pp)
            for i in range(n):
                for j in range(n):
                    Pp[i, j] = P[i, j] - Pp[i, j]
            sym(Pp)
            if not finite(Pp) or not finite(xp):
                return False
            for i in range(n):
                xhat[r, k, i] = xp[i] if filtered else x[i]
            _record(Pp if filtered else P, n, r, k, Pdiag, Pfull, keep)
            if k < steps - 1:
                if not _offsets_to(Pp, scale, center, A, L, D):
                    return False
                t = k * dt
                for s in range(N):
                    for i in range(n):
                        xs[i] = xp[i] + D[s, i]
                    xf = f(xs, u[r, k], t, pf)
                    if xf.size != n:
                        return False
                    Xf[s] = xf
                for i in range(n):
                    v = 0.0
                    for s in range(N):
                        v += Wm[s] * Xf[s, i]
                    if not np.isfinite(v):
                        return False
                    x[i] = v
                for s in range(N):
                    for i in range(n):
                        Xf[s, i] -= x[i]
                _wcov_to(Wc, Xf, Xf, P, Q)
    return True
