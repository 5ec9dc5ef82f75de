"""Fixed-interval (Rauch–Tung–Striebel) and fixed-lag smoothing of the Gaussian filters, batched over runs.

A forward pass of the filter records, at every sample t_k (k = 0 … N−1),
the posterior ``x̂(k|k), P(k|k)``, the prior ``x̂(k+1|k), P(k+1|k)`` and the
cross-covariance ``C_k = cov(x_k, x_{k+1} | y_0…y_k)``:

* Kalman / extended Kalman / Huber filter (:class:`~hinfnav.estimators.ExtendedKalmanFilter`
  and its subclasses with an additive state): ``C_k = P(k|k) F_kᵀ``, F_k = Φ or the
  dynamics model's Jacobian at x̂(k|k) (the one the filter propagates P with);
* sigma-point filter (:class:`~hinfnav.estimators.SigmaPointFilter`, unscented or
  cubature): ``C_k = Σ_i W_i^c (χ_i − x̂(k|k))(f(χ_i) − x̂(k+1|k))ᵀ`` over the filter's
  own sigma points (the unscented RTS smoother, Särkkä, IEEE TAC 53(3), 2008).

The backward pass (Rauch, Tung & Striebel, AIAA J. 3(8), 1965; Särkkä,
*Bayesian Filtering and Smoothing*, 2013, Thm 8.2 and Alg. 9.3) is, from
``x̂ˢ_{N−1} = x̂(N−1|N−1)``, ``Pˢ_{N−1} = P(N−1|N−1)``,

.. math::

    G_k &= C_k\\,P(k+1|k)^{-1}                                    && \\text{(S1)} \\\\
    \\hat x^s_k &= \\hat x(k|k) + G_k\\,(\\hat x^s_{k+1} - \\hat x(k+1|k)) && \\text{(S2)} \\\\
    P^s_k &= P(k|k) + G_k\\,(P^s_{k+1} - P(k+1|k))\\,G_k^T            && \\text{(S3)}

A **fixed-lag** smoother of lag L reports ``x̂(k | min(k+L, N−1))``: (S2)–(S3)
run back L steps from every end time j (all end times at once, so a lag costs
L vectorised steps); at ``L ≥ N−1`` it is the RTS smoother, with the same
arithmetic. ``missing="skip"`` needs nothing here: a skipped reading leaves
its posterior equal to its prior, which (S1)–(S3) then smooth.

**Filter–smoother consistency** (the orbit-determination check, e.g. Wright's
test of ODTK): under the filter's model, ``x̂(k|k) − x̂ˢ_k`` has covariance
``P(k|k) − Pˢ_k`` (the smoothed error is orthogonal to the difference), so
each ratio ``(x̂_i(k|k) − x̂ˢ_i(k)) / √(P_ii(k|k) − Pˢ_ii(k))`` should be
standard normal; ``|ratio| > 3`` flags a component whose filter and smoother
disagree more than their covariances allow (:func:`filter_smoother_consistency`).

**Not smoothed here.** The H∞ filters: their P (if any) is the Riccati bound
of a game, not an error covariance, so (S1)–(S3) have no meaning for them;
:func:`smooth` refuses them with an :class:`~hinfnav.core.exceptions.InputError`
saying so. The H∞ fixed-lag smoother of the recursive H∞ filter is
:func:`hinfnav.estimators.hinf_smoother.hinf_fixed_lag` (its game on the
lag-augmented state); a fixed-gain :class:`~hinfnav.estimators.LTIFilter` has no
such recursion, and the extended H∞ filter's is not built. Also refused:
filters whose prior is completed at the next reading (strong tracking's
fading factors, rate-adapted Q: ``defers_prior``) and filters on error
coordinates (quaternion attitude, augmented states), whose smoothing needs
the state's ⊟ map in (S2).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import HinfnavError, InputError
from ..core.validation import as_int_at_least
from .base import Estimator, check_estimator_inputs
from .kalman import KalmanCore
from .lti import LTIFilter
from .recursive_hinf import ExtendedHInfinityFilter, RecursiveHInfinityFilter
from .sigma_point import SigmaPointFilter

__all__ = ["FilterRecord", "SmoothedHistory", "filter_record", "record_inputs", "rts_smooth", "smooth", "filter_smoother_consistency"]


@dataclass(frozen=True, eq=False)
class FilterRecord:
    """What the backward pass needs from a forward pass (leading dimensions (runs, N) or, shared by every run, (N,)).

    Attributes
    ----------
    x_filt, P_filt : ndarray
        ``x̂(k|k)`` (runs, N, n) and ``P(k|k)`` (runs, N, n, n).
    x_pred, P_pred : ndarray
        ``x̂(k|k−1)`` and ``P(k|k−1)`` (index 0: the initial prior x̂₀, P₀).
    cross : ndarray
        ``C_k = cov(x_k, x_{k+1} | y_0…y_k)``, (runs, N−1, n, n) (or (N−1, n, n) when shared).
    state : StateSpec or None
    """

    x_filt: np.ndarray
    P_filt: np.ndarray
    x_pred: np.ndarray
    P_pred: np.ndarray
    cross: np.ndarray
    state: object = None

    @property
    def n_samples(self) -> int:
        return self.x_filt.shape[1]


@dataclass(frozen=True, eq=False)
class SmoothedHistory:
    """Smoothed histories of a batch of runs, with the filter's.

    Attributes
    ----------
    xhat : ndarray, shape (runs, N, n)
        Smoothed estimate: ``x̂(k|N−1)`` (RTS) or ``x̂(k|min(k+lag, N−1))``.
    P : ndarray, shape (runs, N, n, n)
        Its covariance (broadcast from one history when shared by every run).
    gain : ndarray, shape (runs, N−1, n, n)
        The smoother gains G_k (S1).
    record : FilterRecord
        The forward pass (filtered and predicted estimates and covariances).
    lag : int or None
        None for the fixed-interval (RTS) smoother.
    """

    xhat: np.ndarray
    P: np.ndarray
    gain: np.ndarray
    record: FilterRecord
    lag: int | None = None

    @property
    def x_filt(self) -> NDArray[np.float64]:
        """Filtered estimates x̂(k|k), (runs, N, n)."""
        return self.record.x_filt

    @property
    def P_filt(self) -> NDArray[np.float64]:
        """Filtered covariances P(k|k), (runs, N, n, n) (broadcast when shared by every run)."""
        P = self.record.P_filt
        return P if P.ndim == 4 else np.broadcast_to(P, (self.xhat.shape[0],) + P.shape)

    @property
    def state(self) -> Any:
        return self.record.state

    def consistency(self) -> dict[str, NDArray[np.float64]]:
        """:func:`filter_smoother_consistency` of this history."""
        return filter_smoother_consistency(self.x_filt, self.P_filt, self.xhat, self.P)


def _refuse(estimator: Any) -> None:
    """An InputError naming why ``estimator`` has no Gaussian smoother here (nothing when it has one)."""
    name = type(estimator).__name__
    if isinstance(estimator, RecursiveHInfinityFilter):
        raise InputError(
            f"{name} is an H∞ filter: its P is the Riccati bound of a game, not an error covariance, so the "
            "Rauch–Tung–Striebel recursion (which needs P(k|k), P(k+1|k) and their cross-covariance) does not apply; "
            "its H∞ fixed-lag smoother is hinfnav.estimators.hinf_smoother.hinf_fixed_lag(filter, y, u, xhat0, lag)")
    if isinstance(estimator, (LTIFilter, ExtendedHInfinityFilter)):
        raise InputError(
            f"{name} is an H∞ filter with no Gaussian smoother: its P (if any) is not an error covariance, so the "
            "Rauch–Tung–Striebel recursion does not apply, and an H∞ fixed-lag smoother needs the game's Riccati "
            "recursion on the lag-augmented state, which a fixed-gain (LMI-designed) filter does not have and the "
            "extended (linearised, data-dependent) filter has not been given here; build a "
            "RecursiveHInfinityFilter on the same linear model and use hinf_smoother.hinf_fixed_lag, or smooth with "
            "the Kalman/EKF, sigma-point or Huber filter")
    if isinstance(estimator, KalmanCore) and getattr(estimator, "strategies", ()):
        raise InputError(f"{name} is composed with the {' and '.join(estimator.strategies)} strategy: not smoothed "
                         "here; smooth the plain filter")
    if isinstance(estimator, SigmaPointFilter):
        if estimator.error_coordinates:
            raise InputError(f"{name} on a state with its own error (a quaternion) is not smoothed: (S2) needs the "
                             "state's ⊟ map; smooth an additive state")
        return
    if isinstance(estimator, KalmanCore):
        if getattr(estimator, "defers_prior", False):
            raise InputError(f"{name} completes its prior at the next reading (fading factors or adapted Q): its "
                             "P(k+1|k) is not the propagated covariance the RTS recursion assumes; smooth the plain "
                             "EKF or Huber filter")
        if type(estimator).inject is not KalmanCore.inject or estimator.n_cov != estimator.n_state \
                or type(estimator).report is not KalmanCore.report:
            raise InputError(f"{name} estimates in error coordinates (augmented or quaternion states): not smoothed; "
                             "smooth an additive state")
        if not hasattr(estimator, "F"):
            raise InputError(f"{name} has no transition model (F or a dynamics Jacobian) to smooth with")
        return
    raise InputError(f"{name} is not a Gaussian filter of the package (ExtendedKalmanFilter and its Huber variants, "
                     "SigmaPointFilter): no smoother")


def _cross_covariance(est: Estimator, state: Any, u: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """``C_k = cov(x_k, x_{k+1} | y_0…y_k)`` at the posterior ``state`` (before its prediction)."""
    if isinstance(est, SigmaPointFilter):
        runs, n = state.x.shape
        if "S" in state.extra and hasattr(est, "_offsets"):  # a square-root filter: its own factor
            dX = est._offsets(state.extra["S"])
        else:  # the filter's own sigma points about x̂(k|k)
            dX = est._points(state.P, state.k, "posterior")
        N = dX.shape[1]
        uu = np.repeat(np.asarray(u, dtype=float), N, axis=0) if est.uses_input else None
        Xf = est._propagate((state.x[:, None, :] + dX).reshape(runs * N, n), uu, state.k * est.dt).reshape(runs, N, n)
        _, dXf = est._moments(Xf)
        return est._cov(dX, dXf)
    P = state.P
    if est.nonlinear_dynamics:  # the Jacobian the EKF propagates P with, at x̂(k|k)
        F = np.asarray(est.system.jacobian(state.x, u if est.uses_input else None, state.k * est.dt), dtype=float)
        return (P if P.ndim == 3 else np.broadcast_to(P, (F.shape[0],) + P.shape)) @ np.swapaxes(F, -1, -2)
    return P @ est.F.T


def record_inputs(estimator: Estimator, y: ArrayLike, u: ArrayLike | None, xhat0: ArrayLike,
                  u_width: int = 0) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(y, u, x̂₀)`` of a routine over whole records (a smoother), checked by :func:`check_estimator_inputs`.

    ``u`` may be None for a filter that does not use its input: then it is zeros (runs, N, ``u_width``).
    Raises InputError for y not (runs, N, m), or for u None when the filter uses it.
    """
    y = np.asarray(y, dtype=float)
    if y.ndim != 3:
        raise InputError(f"y must have shape (runs, n_samples, n_meas); got {y.shape}")
    if u is None:
        if estimator.uses_input:
            raise InputError(f"filter {estimator.name!r} uses the applied input: u is needed")
        u = np.zeros(y.shape[:2] + (u_width,))
    return check_estimator_inputs(y, u, xhat0, estimator.n_state, estimator.measurement.n_meas,
                                  estimator.n_input if estimator.uses_input else None, estimator.missing)


def filter_record(estimator: Estimator, y: ArrayLike, u: ArrayLike | None, xhat0: ArrayLike,
                  P0: ArrayLike | None = None, *, predictor: Callable[[int], Estimator] | None = None) -> FilterRecord:
    """Run a Gaussian filter forward over (runs, N, m) readings and record what (S1)–(S3) need.

    ``u`` (runs, N, n_input) may be None for a filter that does not use it;
    ``xhat0`` is (n,) or one initial estimate per run (runs, n);
    ``predictor(k)``, when given, is the filter that predicts from t_k to
    t_{k+1} (a step of its own length, :mod:`hinfnav.estimators.timed`).
    Raises InputError for a filter with no smoother (see the module docstring).
    """
    _refuse(estimator)
    y_arr, u, x0 = record_inputs(estimator, y, u, xhat0)
    runs, N, _ = y_arr.shape
    state = estimator.start(x0, P0, runs)
    xf, Pf, xp, Pp, C = [], [], [state.x], [state.P], []
    for k in range(N):
        state, _ = estimator._update(state, y_arr[:, k])
        xf.append(state.x)
        Pf.append(state.P)
        if k < N - 1:
            step = estimator if predictor is None else predictor(k)
            try:
                C.append(_cross_covariance(step, state, u[:, k]))
            except np.linalg.LinAlgError:
                raise HinfnavError(f"filter {estimator.name!r}: posterior covariance at step {k} is not positive "
                                   "definite (no sigma points for the smoother)") from None
            state = step._predict(state, u[:, k])
            xp.append(state.x)
            Pp.append(state.P)
    stack = _stacker(runs)
    return FilterRecord(x_filt=np.stack(xf, axis=1), P_filt=stack(Pf), x_pred=np.stack(xp, axis=1), P_pred=stack(Pp),
                        cross=stack(C) if C else np.zeros((runs, 0) + Pf[0].shape[-2:]),
                        state=estimator.system.state)


def _stacker(runs):
    """Stack matrices over time: (N, n, n) when all are shared (2-D), else (runs, N, n, n)."""
    def stack(mats):
        if all(M.ndim == 2 for M in mats):
            return np.stack(mats)
        return np.stack([np.broadcast_to(M, (runs,) + M.shape[-2:]) for M in mats], axis=1)
    return stack


def _time_axis(a: NDArray[np.float64], matrix: bool) -> NDArray[np.float64]:
    """A record's array with the time axis first: (N, ..., n[, n]) (shared arrays are already so)."""
    shared = a.ndim == (3 if matrix else 2)
    return a if shared else np.moveaxis(a, 1, 0)


def _gains(rec: FilterRecord) -> NDArray[np.float64]:
    """G_k = C_k P(k+1|k)⁻¹ (S1), time axis first."""
    C = _time_axis(rec.cross, True)
    Pp = _time_axis(rec.P_pred, True)[1:]
    Pp, C = np.broadcast_arrays(Pp, C)
    try:  # P(k+1|k) is symmetric: G = (P⁻¹ Cᵀ)ᵀ
        return np.swapaxes(np.linalg.solve(Pp, np.swapaxes(C, -1, -2)), -1, -2)
    except np.linalg.LinAlgError:
        raise HinfnavError("smoother: a predicted covariance P(k+1|k) is singular (no smoother gain)") from None


def rts_smooth(rec: FilterRecord, lag: int | None = None) -> SmoothedHistory:
    """The backward pass (S1)–(S3) on a :class:`FilterRecord`: fixed interval (``lag`` None) or fixed lag."""
    N = rec.n_samples
    runs = rec.x_filt.shape[0]
    L = N - 1 if lag is None else min(as_int_at_least("lag", lag, 0), N - 1)
    G = _gains(rec)                                  # (N−1, [runs,] n, n)
    xf = np.moveaxis(rec.x_filt, 1, 0)               # (N, runs, n)
    xp = np.moveaxis(rec.x_pred, 1, 0)
    Pf = _time_axis(rec.P_filt, True)
    Pp = _time_axis(rec.P_pred, True)
    n = xf.shape[-1]
    shared = Pf.ndim == Pp.ndim == G.ndim == 3      # one covariance history for every run
    if not shared:
        Pf, Pp = (np.broadcast_to(A if A.ndim == 4 else A[:, None], (A.shape[0], runs, n, n)) for A in (Pf, Pp))
        G = np.broadcast_to(G if G.ndim == 4 else G[:, None], (N - 1, runs, n, n))
    xs, Ps = np.empty_like(xf), np.empty(Pf.shape)
    if lag is None:                                  # (S2)–(S3) from the end
        xs[-1], Ps[-1] = xf[-1], Pf[-1]
        for k in range(N - 2, -1, -1):
            Gk = G[k]
            xs[k] = xf[k] + (Gk @ (xs[k + 1] - xp[k + 1])[..., None])[..., 0]
            Pk = Pf[k] + Gk @ (Ps[k + 1] - Pp[k + 1]) @ np.swapaxes(Gk, -1, -2)
            Ps[k] = 0.5 * (Pk + np.swapaxes(Pk, -1, -2))
    else:                                            # every end time j at once, d = 0 … L steps back
        cx, cP = xf.copy(), Pf.copy()                # cx[j] = x̂(j−d | j), cP[j] its covariance
        for d in range(L + 1):
            if d == L:
                xs[:N - L], Ps[:N - L] = cx[L:], cP[L:]
                break
            xs[N - 1 - d], Ps[N - 1 - d] = cx[N - 1], cP[N - 1]
            i = np.arange(N - d - 1)                 # one step further back, for the end times j = i + d + 1
            j = i + d + 1
            Gi = G[i]
            Gx = Gi[:, None] if shared else Gi
            cx[j] = xf[i] + (Gx @ (cx[j] - xp[i + 1])[..., None])[..., 0]
            Pk = Pf[i] + Gi @ (cP[j] - Pp[i + 1]) @ np.swapaxes(Gi, -1, -2)
            cP[j] = 0.5 * (Pk + np.swapaxes(Pk, -1, -2))
    if shared:
        P_out, G_out = (np.broadcast_to(A, (runs,) + A.shape) for A in (Ps, G))
    else:
        P_out, G_out = np.moveaxis(Ps, 0, 1), np.moveaxis(G, 0, 1)
    return SmoothedHistory(xhat=np.moveaxis(xs, 0, 1), P=P_out, gain=G_out, record=rec, lag=lag)


def smooth(estimator: Estimator, y: ArrayLike, u: ArrayLike | None, xhat0: ArrayLike, P0: ArrayLike | None = None, *,
           lag: int | None = None) -> SmoothedHistory:
    """Filter a batch of records forward and smooth them backward.

    Parameters
    ----------
    estimator : ExtendedKalmanFilter, HuberFilter or SigmaPointFilter
        Any Gaussian filter of the package on an additive state (see the
        module docstring for those refused and why); ``missing="skip"`` works.
    y : array_like, shape (runs, N, n_meas)
    u : array_like, shape (runs, N, n_input), or None
    xhat0 : array_like, shape (n,) or (runs, n)
        Prior estimate of x(0), one for all runs or one per run.
    P0 : array_like, shape (n, n), optional
    lag : int, optional
        None: the fixed-interval (RTS) smoother ``x̂(k|N−1)``; L ≥ 0: the
        fixed-lag smoother ``x̂(k|min(k+L, N−1))`` (L = 0 is the filter).

    Returns
    -------
    SmoothedHistory
    """
    return rts_smooth(filter_record(estimator, y, u, xhat0, P0), lag=lag)


def filter_smoother_consistency(x_filt: ArrayLike, P_filt: ArrayLike, x_smooth: ArrayLike, P_smooth: ArrayLike, *,
                                threshold: float = 3.0, floor: float = 1e-12) -> dict[str, NDArray[np.float64]]:
    """The filter–smoother consistency test: ``(x̂_i(k|k) − x̂ˢ_i) / √(P_ii(k|k) − Pˢ_ii)`` per component.

    Parameters
    ----------
    x_filt, x_smooth : array_like, shape (..., n)
    P_filt, P_smooth : array_like, shape (..., n, n)
    threshold : float
        The bound on ``|ratio|`` (3: a standard-normal ratio exceeds it with
        probability 0.27 %).
    floor : float
        A variance difference below ``floor · P_ii(k|k)`` (e.g. the last
        sample, where filter and smoother coincide) gives NaN, not a ratio.

    Returns
    -------
    dict
        ``ratio`` (..., n); ``exceeds`` (..., n), ``|ratio| > threshold`` (False
        where NaN); ``fraction_exceeding`` (n,), over every finite ratio.
    """
    xf, xs = np.asarray(x_filt, dtype=float), np.asarray(x_smooth, dtype=float)
    Pf, Ps = np.asarray(P_filt, dtype=float), np.asarray(P_smooth, dtype=float)
    if xf.shape != xs.shape or Pf.shape[-2:] != (xf.shape[-1],) * 2 or Pf.shape != Ps.shape:
        raise InputError(f"x_filt {xf.shape}, x_smooth {xs.shape} must match and P_filt {Pf.shape}, P_smooth "
                         f"{Ps.shape} be their covariances")
    vf, vs = np.diagonal(Pf, axis1=-2, axis2=-1), np.diagonal(Ps, axis1=-2, axis2=-1)
    dv = vf - vs
    ok = dv > floor * np.abs(vf)
    ratio = np.where(ok, (xf - xs) / np.sqrt(np.where(ok, dv, 1.0)), np.nan)
    exceeds = np.abs(np.nan_to_num(ratio)) > threshold
    count = np.sum(np.isfinite(ratio).reshape(-1, xf.shape[-1]), axis=0)
    frac = np.sum(exceeds.reshape(-1, xf.shape[-1]), axis=0) / np.maximum(count, 1)
    return {"ratio": ratio, "exceeds": exceeds, "fraction_exceeding": frac}
