"""Square-root (Cholesky-factor) forms of the Kalman and sigma-point filters, batched over runs.

The filters carry a lower-triangular factor ``S`` with ``P = S Sᵀ`` (kept in
``FilterState.extra["S"]``; ``FilterState.P`` and every reported P are
``S Sᵀ``) and never form P to propagate it: every step triangularises an
array whose product with its transpose is the new covariance,
``tria(A) = Rᵀ`` from the QR factorisation ``Aᵀ = Q R`` (signs set so the
diagonal is positive: the Cholesky factor of ``A Aᵀ``), so P stays positive
semidefinite by construction and its condition number enters as that of S,
its square root (Kaminski, Bryson & Schmidt, IEEE TAC 16(6), 1971; Grewal &
Andrews, *Kalman Filtering*, ch. 6).

**Kalman / extended Kalman** (:class:`SquareRootEKF`), with ``L_Q L_Qᵀ = Q``,
``L_R L_Rᵀ = R``:

* predict  ``S⁻ = tria([F S, L_Q])``                                            (Q1)
* update, the array algorithm (Morf & Kailath 1975):
  ``tria([[L_R, H S⁻], [0, S⁻]]) = [[S_e, 0], [K̄, S⁺]]``,
  ``K = K̄ S_e⁻¹``, ``x̂⁺ = x̂⁻ + K̄ S_e⁻¹ ν``                                    (Q2)

(``S_e S_eᵀ = H P⁻ Hᵀ + R``, ``S⁺ S⁺ᵀ = P⁻ − K S_e S_eᵀ Kᵀ``: the Joseph path's posterior, exactly.)

**Sigma-point** (:class:`SquareRootSigmaPointFilter`, the square-root UKF of
van der Merwe & Wan, ICASSP 2001, and the square-root CKF of Arasaratnam &
Haykin, IEEE TAC 54(6), 2009): the sigma points are ``x̂ ± √(n+λ) S_{:,i}``
((U1) with L = √(n+λ) S), and with deviations ``D_i`` of the propagated
points from their mean, ``d_i = √|W_i^c| D_i``,

* predict ``S⁻ = tria([d_i (W_i^c ≥ 0), L_Q])``, then a rank-one Cholesky
  downdate by each ``d_i`` with ``W_i^c < 0`` (the unscented centre for some α, β, κ, e.g. α = 0.5); (Q3)
* update  ``S_y = tria([√W_i^c dY_i, L_R])`` (downdates likewise),
  ``K = P_xy S_y⁻ᵀ S_y⁻¹``, and ``S⁺ = tria([√W_i^c (dX_i − K dY_i), K L_R])``
  — the "Joseph" form of P⁻ − K S Kᵀ over the points (Σ W^c dX dXᵀ = P⁻ for the
  symmetric sets), so S⁺ needs no downdate when every W^c ≥ 0 (the cubature rule,
  and the unscented set at its defaults α = 1, β = 2, κ = 0).                           (Q4)

A missing channel (``missing="skip"``) is removed exactly as in the covariance
forms: its row of H (or its output deviations) and innovation zeroed and its
rows and columns of R decoupled, so it moves neither x̂ nor S.

On well-conditioned problems these filters equal the covariance (Joseph) forms
to rounding (tested to 1e-10); they survive where the covariance forms lose
definiteness (P₀ = 10¹² I with R = 10⁻¹⁰ I; Stone Soup's covariance-stability
set-up, ``tests/test_sqrt_filters.py``). :func:`square_root` converts a filter.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.exceptions import HinfnavError, InputError
from .base import FilterState, StepOutput, available_channels, fill_missing
from .kalman import ExtendedKalmanFilter, KalmanCore
from .sigma_point import SigmaPointFilter

__all__ = ["tria", "chol_downdate", "factor", "SquareRootEKF", "SquareRootSigmaPointFilter", "square_root", "FORMS"]

#: The covariance forms of a filter: P propagated (Joseph update), or its Cholesky factor.
FORMS = ("joseph", "sqrt")


def tria(A: NDArray[np.float64]) -> NDArray[np.float64]:
    """Lower-triangular S (…, n, n) with positive diagonal and ``S Sᵀ = A Aᵀ``, for A (…, n, k), k ≥ n (by QR of Aᵀ)."""
    R = np.linalg.qr(np.swapaxes(A, -1, -2), mode="r")
    L = np.swapaxes(R, -1, -2)
    d = np.sign(np.diagonal(L, axis1=-2, axis2=-1))
    return L * np.where(d == 0, 1.0, d)[..., None, :]


def chol_downdate(L: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Lower-triangular L' with ``L' L'ᵀ = L Lᵀ − v vᵀ`` (L (…, n, n) with positive diagonal, v (…, n)).

    Raises ``numpy.linalg.LinAlgError`` when the result is not positive definite.
    """
    L, v = np.array(L, dtype=float), np.array(v, dtype=float)
    n = L.shape[-1]
    for k in range(n):
        Lkk, vk = L[..., k, k], v[..., k]
        r2 = Lkk * Lkk - vk * vk
        if not np.all(r2 > 0):
            raise np.linalg.LinAlgError("Cholesky downdate: the result is not positive definite")
        r = np.sqrt(r2)
        c, s = (r / Lkk)[..., None], (vk / Lkk)[..., None]
        L[..., k, k] = r
        col = (L[..., k + 1:, k] - s * v[..., k + 1:]) / c
        v[..., k + 1:] = c * v[..., k + 1:] - s * col
        L[..., k + 1:, k] = col
    return L


def factor(name: str, M: NDArray[np.float64]) -> NDArray[np.float64]:
    """A factor L with L Lᵀ = M of a (semi)definite covariance (Cholesky, or from eigh when only semidefinite)."""
    try:
        return np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        lam, V = np.linalg.eigh(M)
        if np.any(lam < -1e-12 * max(1.0, float(np.max(np.abs(lam))))):
            raise InputError(f"{name} must be positive semidefinite") from None
        return tria(V * np.sqrt(np.clip(lam, 0.0, None)))


def _outer(S):
    return S @ np.swapaxes(S, -1, -2)


def _masked_R_factor(R, mask):
    """Factor of R with the missing channels' rows and columns decoupled (identity), per run."""
    both = mask[:, :, None] & mask[:, None, :]
    R_used = np.where(both, R, 0.0) + np.eye(R.shape[-1]) * ~mask[:, None, :]
    return np.linalg.cholesky(R_used)


class SquareRootEKF(ExtendedKalmanFilter):
    """The extended Kalman filter in square-root form (Q1)–(Q2); parameters of :class:`ExtendedKalmanFilter`.

    Diagnostics: ``innovation`` and ``innovation_covariance`` (S_e S_eᵀ).
    """

    name = "sqrt_ekf"
    form = "sqrt"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.LQ = factor("Q", self.Q)
        self.LR = None if self.R is None else np.linalg.cholesky(self.R)

    def _start(self, xhat0, P0, runs):
        state = super()._start(xhat0, P0, runs)
        state.extra["S"] = np.linalg.cholesky(state.P)
        return state

    def _update(self, state, y):
        x, S = state.x, state.extra["S"]
        runs = x.shape[0]
        mask = available_channels(y) if self.missing == "skip" else None
        try:
            yhat, H = self.observe(x)
            y, mask = fill_missing(self.measurement, y, x, yhat, mask)
            nu = self.measurement.residual(y, yhat)
        except InputError as exc:
            raise HinfnavError(f"filter {self.name!r} stopped at step {state.k}: the estimate reached a singular "
                               f"point ({exc})") from None
        R_k = self.R if self.R_of_reading is None else self.R_of_reading(y)
        if mask is not None or R_k.ndim == 3:
            Rb = np.broadcast_to(R_k, (runs,) + R_k.shape[-2:])
            if mask is not None:
                if self.R_of_reading is not None:  # R(y) not finite on the channels it has: the reading is not used
                    both = mask[:, :, None] & mask[:, None, :]
                    mask = mask & np.all(np.isfinite(np.where(both, Rb, 0.0)), axis=(1, 2))[:, None]
                H = np.where(mask[:, :, None], np.broadcast_to(H, (runs,) + H.shape[-2:]), 0.0)
                nu = np.where(mask, nu, 0.0)
                LR = _masked_R_factor(Rb, mask)
            else:
                LR = np.linalg.cholesky(Rb)
        else:
            LR = self.LR
        m, n = nu.shape[-1], S.shape[-1]
        HS = H @ S
        lead = np.broadcast_shapes(HS.shape[:-2], LR.shape[:-2], S.shape[:-2])
        pre = np.zeros(lead + (m + n, m + n))
        pre[..., :m, :m] = LR
        pre[..., :m, m:] = HS
        pre[..., m:, m:] = S
        post = tria(pre)
        Se, Kbar, S_post = post[..., :m, :m], post[..., m:, :m], post[..., m:, m:]
        if Se.ndim == 2:
            w = np.linalg.solve(Se, nu.T).T
            dx = w @ Kbar.T
        else:
            w = np.linalg.solve(Se, nu[:, :, None])
            dx = (Kbar @ w)[:, :, 0]
        x_post = x + dx
        P_post, P_prior = _outer(S_post), _outer(S)
        diag = {"innovation": nu if mask is None else np.where(mask, nu, np.nan), "innovation_covariance": self._broadcast(_outer(Se), runs)}
        extra = {key: val for key, val in state.extra.items() if key not in self.transient_keys}
        extra["S"] = S_post
        new = FilterState(x=x_post, P=P_post, k=state.k, extra=dict(extra, prior=(x, P_prior)))
        if self.output == "filtered":
            return new, StepOutput(xhat=x_post, P=self._broadcast(P_post, runs), diagnostics=diag)
        return new, StepOutput(xhat=x, P=self._broadcast(P_prior, runs), diagnostics=diag)

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        S = state.extra["S"]
        t = state.k * self.dt
        if self.nonlinear_dynamics:
            F = np.asarray(self.system.jacobian(state.x, u if self.uses_input else None, t), dtype=float)
        else:
            F = self.F
        x = self.predict_mean(state.x, u, t)
        FS = F @ S
        LQ = np.broadcast_to(self.LQ, FS.shape[:-2] + self.LQ.shape)
        S_prior = tria(np.concatenate([FS, LQ], axis=-1))
        extra = {key: val for key, val in state.extra.items() if key not in self.transient_keys}
        extra["S"] = S_prior
        return FilterState(x=x, P=_outer(S_prior), k=state.k + 1, extra=extra)


class SquareRootSigmaPointFilter(SigmaPointFilter):
    """The unscented / cubature filter in square-root form (Q3)–(Q4); parameters of :class:`SigmaPointFilter`."""

    name = "sqrt_ukf"
    form = "sqrt"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if self.error_coordinates:
            raise InputError("the square-root sigma-point filter takes an additive state (not a quaternion's error "
                             "coordinates)")
        self.LQ = factor("Q", self.Q)
        self.LR = None if self.R is None else np.linalg.cholesky(self.R)
        self._pos = self.Wc >= 0
        self._sw = np.sqrt(np.abs(self.Wc))

    def _offsets(self, S):
        """Sigma-point offsets (runs, N, n) of factors S: ``±√(n+λ) S_{:,i}`` (and the centre 0)."""
        cols = np.sqrt(self.scale) * np.swapaxes(S, -1, -2)
        parts = ([np.zeros_like(cols[:, :1])] if self.rule == "unscented" else []) + [cols, -cols]
        return np.concatenate(parts, axis=1)

    def _tria_weighted(self, D, L_noise, k, what):
        """``tria`` of the weighted deviations D (runs, N, a) with the noise factor, downdated by negative weights."""
        d = D * self._sw[:, None]
        A = np.concatenate([np.swapaxes(d[:, self._pos], -1, -2),
                            np.broadcast_to(L_noise, (D.shape[0],) + L_noise.shape[-2:])], axis=-1)
        S = tria(A)
        try:
            for i in np.flatnonzero(~self._pos):
                S = chol_downdate(S, d[:, i])
        except np.linalg.LinAlgError:
            raise HinfnavError(f"filter {self.name!r} stopped at step {k}: the {what} covariance is not positive "
                               "definite after the negative-weight downdate (use the cubature rule or α, β with "
                               "non-negative weights)") from None
        return S

    def _start(self, xhat0, P0, runs):
        state = super()._start(xhat0, P0, runs)
        state.extra["S"] = np.linalg.cholesky(state.P)
        return state

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        runs, n = state.x.shape
        X = state.x[:, None, :] + self._offsets(state.extra["S"])
        N = X.shape[1]
        uu = np.repeat(np.asarray(u, dtype=float), N, axis=0) if self.uses_input else None
        Xf = self._propagate(X.reshape(runs * N, n), uu, state.k * self.dt).reshape(runs, N, n)
        x, dX = self._moments(Xf)
        S = self._tria_weighted(dX, self.LQ, state.k, "predicted")
        extra = dict(state.extra, S=S)
        return FilterState(x=x, P=_outer(S), k=state.k + 1, extra=extra)

    def _update(self, state, y):
        x, S = state.x, state.extra["S"]
        runs, n = x.shape
        mask = available_channels(y) if self.missing == "skip" else None
        dX = self._offsets(S)
        X = x[:, None, :] + dX
        y_mean, dY = self._predicted_outputs(X, x, state.k)
        y, mask = fill_missing(self.measurement, y, x, y_mean, mask)
        R_k = self.R if self.R_of_reading is None else self.R_of_reading(y)
        nu = self.measurement.residual(y, y_mean)
        if mask is not None:
            Rb = np.broadcast_to(R_k, (runs,) + R_k.shape[-2:])
            if self.R_of_reading is not None:
                both = mask[:, :, None] & mask[:, None, :]
                mask = mask & np.all(np.isfinite(np.where(both, Rb, 0.0)), axis=(1, 2))[:, None]
            dY = np.where(mask[:, None, :], dY, 0.0)
            nu = np.where(mask, nu, 0.0)
            LR = _masked_R_factor(Rb, mask)
        else:
            LR = self.LR if self.R_of_reading is None else np.linalg.cholesky(R_k)
        Sy = self._tria_weighted(dY, LR, state.k, "innovation")
        Pxy = self._cov(dX, dY)
        # K Sy Syᵀ = Pxy  ⇒  Kᵀ = Sy⁻ᵀ (Sy⁻¹ Pxyᵀ)
        K = np.swapaxes(np.linalg.solve(np.swapaxes(Sy, -1, -2), np.linalg.solve(Sy, np.swapaxes(Pxy, -1, -2))), -1, -2)
        x_post = x + (K @ nu[:, :, None])[:, :, 0]
        E = dX - dY @ np.swapaxes(K, -1, -2)  # dX_i − K dY_i
        KLR = K @ LR
        S_post = self._tria_weighted(E, KLR, state.k, "posterior")
        P_post, P_prior = _outer(S_post), _outer(S)
        diag = {"innovation": nu if mask is None else np.where(mask, nu, np.nan), "innovation_covariance": _outer(Sy)}
        new = FilterState(x=x_post, P=P_post, k=state.k, extra=dict(state.extra, S=S_post))
        if self.output == "filtered":
            return new, StepOutput(xhat=x_post, P=P_post, diagnostics=diag)
        return new, StepOutput(xhat=x, P=P_prior, diagnostics=diag)


def square_root(estimator: KalmanCore | SigmaPointFilter, *, name: str | None = None) -> SquareRootEKF | SquareRootSigmaPointFilter:
    """The square-root form of an :class:`~hinfnav.estimators.ExtendedKalmanFilter` or a
    :class:`~hinfnav.estimators.SigmaPointFilter`: same model, P₀, Q, R, options.

    Raises InputError for a filter without one here (Huber's weights, strong
    tracking's fading, error coordinates, the H∞ filters).
    """
    cls = type(estimator)
    if getattr(estimator, "strategies", ()):
        raise InputError(f"{estimator.name!r} is composed with the {' and '.join(estimator.strategies)} strategy: no "
                         "square-root form here")
    if isinstance(estimator, (SquareRootEKF, SquareRootSigmaPointFilter)):
        return estimator
    if isinstance(estimator, SigmaPointFilter) and cls is SigmaPointFilter:
        return SquareRootSigmaPointFilter(
            estimator.system, estimator.measurement, P0=estimator.P0, Q=estimator.Q,
            R=None if estimator.R_of_reading is not None else estimator.R, rule=estimator.rule,
            alpha=estimator.alpha, beta=estimator.beta, kappa=estimator.kappa, uses_input=estimator.uses_input,
            output=estimator.output, name=name or f"{estimator.name}_sqrt", missing=estimator.missing)
    if cls is ExtendedKalmanFilter:
        return SquareRootEKF(estimator.system, estimator.measurement, P0=estimator.P0, Q=estimator.Q,
                             R=None if estimator.R_of_reading is not None else estimator.R,
                             uses_input=estimator.uses_input, output=estimator.output,
                             name=name or f"{estimator.name}_sqrt", missing=estimator.missing)
    raise InputError(f"{cls.__name__} has no square-root form here: it is given for ExtendedKalmanFilter and "
                     "SigmaPointFilter (the Huber weights, fading factors, error-coordinate and H∞ filters keep "
                     "their covariance form)")
