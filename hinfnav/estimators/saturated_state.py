"""Algorithms 2 and 3 of Yang et al. (2020): the saturated-measurement and the fused extended-state filters.

See :mod:`hinfnav.estimators.extended_state` for the model and Algorithm 1 (the module docstring there
describes all three): :class:`SaturatedExtendedStateFilter` is Algorithm 2 on independent axes
``X = [r, ṙ, f]`` with the truncated-normal update (23), (29)-(30), (33)-(34);
:class:`FusedExtendedStateFilter` is Algorithm 3, the fusion (38)-(43) of Algorithms 1 and 2.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..analysis.truncated import truncated_normal_moments
from ..core.exceptions import InputError
from ..core.linalg import as_covariance
from ..core.validation import as_choice, as_positive, as_vector
from ..systems.linear import LinearSystem
from ..systems.measurements import LinearMeasurement, Saturated
from ..systems.state import StateSpec
from .base import Estimator, FilterState, StepOutput
from .correction import drop_missing, joseph_covariance, kalman_gain
from .extended_state import ExtendedStateKalmanFilter, check_steady_tol
from .steady import freeze_gain

__all__ = ["SaturatedExtendedStateFilter", "FusedExtendedStateFilter"]

#: How Algorithm 2 treats a clipped reading: truncated-normal update (L1), skip the update (L3), never clipped (L2).
MODES = ("truncated", "skip", "ideal")
#: Readings of the fused covariance (39): symmetric part, as printed (not symmetric), block (no r/v-f terms).
FUSED_COVARIANCES = ("symmetric", "printed", "block")


def _axis_arrays(name, value, shape):
    arr = np.asarray(value, dtype=float)
    try:
        arr = np.broadcast_to(arr, shape).copy()
    except ValueError:
        raise InputError(f"{name} must broadcast to shape {shape}; got {arr.shape}") from None
    if np.any(np.isnan(arr)):
        raise InputError(f"{name} must not contain NaN")
    return arr


class SaturatedExtendedStateFilter(Estimator):
    """Algorithm 2 on independent axes ``X = [r, ṙ, f]``, batched over runs and axes.

    Parameters
    ----------
    A_d : array_like, shape (n_axes, 3, 3)
    B_d : array_like, shape (n_axes, 3)
        Input (force) column; the increment enters the third state.
    C : array_like, shape (n_axes, 3)
        ``y = C X + D(u + w) + d`` (11)-(13).
    D : array_like, shape (n_axes,)
    R, S : array_like, shape (n_axes,)
        Variances of d and of the input noise w per step.
    q : array_like, shape (n_axes,)
        Increment bounds ``E G² ≤ q``.
    P0 : array_like, shape (3, 3) or (n_axes, 3, 3)
    lower, upper : array_like, shape (n_axes,)
        Sensor range (14).
    dt : float
    mode : {"truncated", "skip", "ideal"}
        L1 (Algorithm 2), L3 (no update on a clipped reading), L2 (never clipped).
    state : StateSpec, optional
        Of the estimate ``[r (n_axes), ṙ (n_axes), f (n_axes)]``.
    measurement_labels, measurement_units : sequence of str, optional
        Of the saturated readings.
    theta : float or array_like, optional
        Default θ* per axis: ``√(4 q / tr P0)``.
    steady_tol : float, optional
    name : str
    """

    name = "saturated_eskf"
    uses_input = True

    def __init__(self, A_d: ArrayLike, B_d: ArrayLike, C: ArrayLike, D: ArrayLike, *, R: ArrayLike, S: ArrayLike,
                 q: ArrayLike, P0: ArrayLike, lower: ArrayLike, upper: ArrayLike, dt: float, mode: str = "truncated",
                 state: StateSpec | None = None, measurement_labels: Sequence[str] | None = None,
                 measurement_units: Sequence[str] | None = None, theta: ArrayLike | None = None,
                 steady_tol: float | None = None, name: str | None = None, missing: str = "refuse") -> None:
        A_d = np.asarray(A_d, dtype=float)
        if A_d.ndim != 3 or A_d.shape[1:] != (3, 3):
            raise InputError(f"A_d must have shape (n_axes, 3, 3); got {A_d.shape}")
        na = A_d.shape[0]
        self.n_axes = na
        self.A = _axis_arrays("A_d", A_d, (na, 3, 3))
        self.Bu = _axis_arrays("B_d", B_d, (na, 3))
        self.C = _axis_arrays("C", C, (na, 3))
        self.Dff = _axis_arrays("D", D, (na,))
        self.Rv = _axis_arrays("R", R, (na,))
        self.Sv = _axis_arrays("S", S, (na,))
        self.q = _axis_arrays("q", q, (na,))
        self.Reff = self.Rv + self.Dff**2 * self.Sv
        if min(self.Rv.min(), self.Sv.min(), self.q.min()) < 0 or np.any(self.Reff <= 0):
            raise InputError("R, S and q must be >= 0 and R + D^2 S > 0 on every axis")
        P0 = _axis_arrays("P0", P0, (na, 3, 3))
        for a in range(na):
            P0[a] = as_covariance("P0", P0[a], 3, definite=True)
        self.P0 = P0
        self.lower = _axis_arrays("lower", lower, (na,))
        self.upper = _axis_arrays("upper", upper, (na,))
        if np.any(self.lower >= self.upper):
            raise InputError("lower must be < upper on every axis")
        self.mode = as_choice("mode", mode, MODES)
        self.Q1 = 4.0 * self.q[:, None, None] * np.diag([0.0, 0.0, 1.0])
        self.Q2 = self.Sv[:, None, None] * np.einsum("ai,aj->aij", self.Bu, self.Bu)
        if theta is None:
            tr = np.trace(P0, axis1=1, axis2=2)
            if np.any(self.q <= 0):
                raise InputError("theta* = sqrt(4 q / tr P0) needs q > 0 on every axis: give theta explicitly")
            self.theta = np.sqrt(4.0 * self.q / tr)
        else:
            self.theta = _axis_arrays("theta", theta, (na,))
            if np.any(self.theta <= 0):
                raise InputError("theta must be > 0")
        self.Qtheta = (1.0 + 1.0 / self.theta)[:, None, None] * self.Q1 + self.Q2
        self.steady_tol = check_steady_tol(steady_tol)
        # the generic views: a 3 n_axes state [r, ṙ, f] and a saturated linear measurement
        Phi = np.zeros((3 * na, 3 * na))
        Gam = np.zeros((3 * na, na))
        Cm = np.zeros((na, 3 * na))
        for a in range(na):
            idx = np.arange(3) * na + a
            Phi[np.ix_(idx, idx)] = self.A[a]
            Gam[idx, a] = self.Bu[a]
            Cm[a, idx] = self.C[a]
        if state is None:
            labels = [f"{c}{a}" for c in ("r", "v", "f") for a in range(na)]
            state = StateSpec(labels=labels, units=[""] * (3 * na))
        system = LinearSystem(Phi, Gam, np.zeros((3 * na, 1)), as_positive("dt", dt), state, name="per-axis [r, v, f]")
        meas = Saturated(LinearMeasurement(Cm, np.diag(np.sqrt(self.Reff)), labels=measurement_labels,
                                           units=measurement_units), self.lower, self.upper)
        super().__init__(system, meas, name=name, missing=missing)
        self._Ccol = self.C[..., None]  # (axes, 3, 1)
        self._Crow = self.C[:, None, :]  # (axes, 1, 3): H of each axis
        self._Rcol = self.Reff[:, None, None]  # (axes, 1, 1): R of each axis
        self._AT = np.swapaxes(self.A, -1, -2)  # Aᵀ per axis (a view)
        self._inflate = (1.0 + self.theta)[:, None, None]  # 1 + θ per axis

    # -- array kernels (runs, n_axes, 3) -------------------------------------------------

    def to_full(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """(runs, n_axes, 3) → (runs, 3 n_axes) in the order [r, ṙ, f]."""
        return np.swapaxes(X, 1, 2).reshape(X.shape[0], -1)

    def from_full(self, x: ArrayLike) -> NDArray[np.float64]:
        """(runs, 3 n_axes) → (runs, n_axes, 3)."""
        return np.swapaxes(np.asarray(x, dtype=float).reshape(-1, 3, self.n_axes), 1, 2).copy()

    def full_covariance(self, P: NDArray[np.float64]) -> NDArray[np.float64]:
        """(runs, n_axes, 3, 3) → (runs, 3 n_axes, 3 n_axes) (block diagonal over axes)."""
        na = self.n_axes
        out = np.zeros((P.shape[0], 3, na, 3, na))
        for a in range(na):
            out[:, :, a, :, a] = P[:, a]
        return out.reshape(P.shape[0], 3 * na, 3 * na)

    def prior_covariance(self, P: NDArray[np.float64]) -> NDArray[np.float64]:
        """``(1+θ) A P Aᵀ + (1+1/θ) Q₁ + Q₂`` per axis."""
        return self._inflate * (self.A @ P @ self._AT) + self.Qtheta

    def flags(self, y: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Which readings sit at a bound (never in ``ideal`` mode)."""
        if self.mode == "ideal":
            return np.zeros(np.shape(y), dtype=bool)
        return (y <= self.lower) | (y >= self.upper)

    def kernel_update(self, X: NDArray[np.float64], P: NDArray[np.float64], y: NDArray[np.float64], u_feed: NDArray[np.float64], cache: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
                      sat: NDArray[np.bool_] | None = None, skip: NDArray[np.bool_] | None = None,
                      missing: NDArray[np.bool_] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
        """One measurement update on arrays ``X`` (runs, n_axes, 3), ``P`` (runs, n_axes, 3, 3).

        ``y``, ``u_feed`` (runs, n_axes): readings and the input they contain. ``cache = (K, P_post)`` of a
        converged recursion is used when no reading is clipped; ``sat`` (default :meth:`flags`) marks the
        clipped readings, ``skip`` (default ``mode == "skip"``, per run or per reading) those to skip rather
        than replace by the truncated moments; ``missing`` (runs, n_axes) marks readings that are not there
        (NaN; their gain is 0, so the update keeps the prediction, exactly). Returns
        ``(X, P, innovation, flags, K)``.
        """
        yhat = (X[..., None, :] @ self._Ccol)[..., 0, 0] + self.Dff * u_feed
        if missing is not None and missing.any():
            y = np.where(missing, yhat, y)
            sat = (self.flags(y) if sat is None else sat) & ~missing
            skip = (self.mode == "skip") if skip is None else skip
            skip = np.reshape(skip, np.shape(skip) + (1,) * (missing.ndim - np.ndim(skip))) | missing
            sat = sat | missing  # handled as skipped readings
            cache = None
        sat = self.flags(y) if sat is None else sat
        any_sat = sat.any()
        if cache is not None and not any_sat:
            K, P_post = cache
            innov = y - yhat
            return X + K * innov[..., None], P_post, innov, sat, K
        Kc, P_post, Sy = kalman_gain(P, self._Crow, self._Rcol, symmetrize=False)  # (J1)-(J2) per axis
        K, Sy = Kc[..., 0], Sy[..., 0, 0]
        modified = False
        y_eff = y
        extra_var = None
        if any_sat:
            skip = (self.mode == "skip") if skip is None else skip
            skip_sat = sat & np.reshape(skip, np.shape(skip) + (1,) * (sat.ndim - np.ndim(skip)))
            trunc = sat & ~skip_sat
            y_eff = np.array(y, dtype=float, copy=True)
            if trunc.any():
                below = y <= self.lower
                lo = np.where(below, -np.inf, self.upper)
                hi = np.where(below, self.lower, np.inf)
                m, v = truncated_normal_moments(yhat[trunc], Sy[trunc], lo[trunc], hi[trunc], check=False)
                y_eff[trunc] = m
                extra_var = np.zeros_like(Sy)
                extra_var[trunc] = v
            if skip_sat.any():  # keep the prediction on a skipped reading
                K = np.where(skip_sat[..., None], 0.0, K)
                modified = True
        innov = y_eff - yhat
        X_post = X + K * innov[..., None]
        if modified:  # (J2) with the gain of the readings used
            P_post = joseph_covariance(P, K[..., :, None], self._Crow, self._Rcol, symmetrize=False)
        if extra_var is not None:
            P_post = P_post + extra_var[..., None, None] * (K[..., :, None] * K[..., None, :])
        return X_post, P_post, innov, sat, K

    def kernel_predict(self, X: NDArray[np.float64], P: NDArray[np.float64] | None, u: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
        """``X⁻ = A X + B u`` (Ĝ = 0: f̄ = 0) and the prior covariance, per axis."""
        Xp = (self.A @ X[..., None])[..., 0] + self.Bu * u[..., None]
        return Xp, (None if P is None else self.prior_covariance(P))

    # -- the step contract ---------------------------------------------------------------

    def _start(self, xhat0, P0, runs):
        x0 = as_vector("xhat0", xhat0, self.n_state)
        X = np.broadcast_to(self.from_full(x0[None]), (runs, self.n_axes, 3)).copy()
        P = self.P0 if P0 is None else self.from_full_cov(P0)
        P = np.broadcast_to(P, (runs, self.n_axes, 3, 3)).copy()
        return FilterState(x=X, P=P, extra={"u_feed": np.zeros((runs, self.n_axes)), "steady": None})

    def feed_input(self, state: FilterState, u: ArrayLike) -> FilterState:
        """The state with the input ``u_k`` (runs, n_axes) that the next reading contains through ``D u_k``."""
        u = self._check_feed_input(state, u)
        return FilterState(x=state.x, P=state.P, k=state.k, extra=dict(state.extra, u_feed=u), phase=state.phase)

    def from_full_cov(self, P0: ArrayLike) -> NDArray[np.float64]:
        """A full (3 n_axes)² covariance → its per-axis blocks (cross-axis terms are dropped)."""
        P0 = as_covariance("P0", P0, self.n_state, definite=True)
        na = self.n_axes
        return np.stack([P0[np.ix_(np.arange(3) * na + a, np.arange(3) * na + a)] for a in range(na)])

    def _update(self, state, y):
        y = np.asarray(y, dtype=float)
        steady = state.extra.get("steady")
        cache = None if steady is None or "K" not in steady else (steady["K"], steady["P_post"])
        miss = np.isnan(y) if self.missing == "skip" else None
        if miss is not None and miss.any():
            X, P, innov, sat, K = self.kernel_update(state.x, state.P, y, state.extra["u_feed"], missing=miss)
            sat = sat & ~miss
            innov = np.where(miss, np.nan, innov)
            steady = None if steady is None else {key: v for key, v in steady.items() if key not in ("K", "P_post")}
        else:
            X, P, innov, sat, K = self.kernel_update(state.x, state.P, y, state.extra["u_feed"], cache)
        if steady is not None and sat.any():
            steady = None  # a clipped reading: the covariance depends on the data again
        elif steady is not None and "K" not in steady:
            steady = dict(steady, K=K, P_post=P)
        diag = {"innovation": innov, "saturated": sat, "theta": self.theta * np.ones(sat.shape)}
        extra = dict(state.extra, steady=steady)
        new = FilterState(x=X, P=P, k=state.k, extra=extra)
        return new, StepOutput(xhat=self.to_full(X), P=self.full_covariance(P), diagnostics=diag)

    def _predict(self, state, u):
        u = np.asarray(u, dtype=float)
        steady = state.extra.get("steady")
        X, P = self.kernel_predict(state.x, None if steady is not None else state.P, u)
        extra = dict(state.extra, u_feed=np.zeros_like(u))
        if steady is not None:
            P = steady["P_prior"]
        else:
            steady = freeze_gain(self.steady_tol, state.k, extra, P_prior=P)
        extra["steady"] = steady
        return FilterState(x=X, P=P, k=state.k + 1, extra=extra)


class FusedExtendedStateFilter(Estimator):
    """Algorithm 3: Algorithm 1 on the whole system fused with Algorithm 2 on the drag-free axes.

    Parameters
    ----------
    alg1 : ExtendedStateKalmanFilter
        On the full extended state, measurement Y (first channels).
    alg2 : SaturatedExtendedStateFilter
        On the drag-free axes, measurement the accelerometer (last channels).
    indices : array_like, shape (3 n_axes,)
        Where Algorithm 2's ``[r, ṙ, f]`` sit in Algorithm 1's state (the rows of Γ, (35)).
    input_indices : array_like, shape (n_axes,)
        Which of the inputs u Algorithm 2 receives.
    covariance : {"symmetric", "printed", "block"}
        Reading of the fused covariance (39): its symmetric part, as printed
        (rows of P₁ for r, ṙ and of P₂ for f: not symmetric), or block
        diagonal (r, ṙ from P₁, f from P₂, no cross terms).
    steady_tol : float, optional
        Freeze both gains once both recursions have converged (and no reading is clipped).
    name : str
    """

    name = "fused_eskf"
    uses_input = True

    def __init__(self, alg1: ExtendedStateKalmanFilter, alg2: SaturatedExtendedStateFilter, *, indices: Sequence[int],
                 input_indices: Sequence[int], covariance: str = "symmetric", steady_tol: float | None = None,
                 name: str | None = None, missing: str = "refuse") -> None:
        if not isinstance(alg1, ExtendedStateKalmanFilter):
            raise InputError(f"alg1 must be an ExtendedStateKalmanFilter; got {type(alg1).__name__}")
        if not isinstance(alg2, SaturatedExtendedStateFilter):
            raise InputError(f"alg2 must be a SaturatedExtendedStateFilter; got {type(alg2).__name__}")
        na = alg2.n_axes
        idx = np.asarray(indices, dtype=int)
        if idx.shape != (3 * na,) or idx.min() < 0 or idx.max() >= alg1.n_state or len(set(idx)) != idx.size:
            raise InputError(f"indices must be {3 * na} distinct state indices of alg1; got {indices!r}")
        uidx = np.asarray(input_indices, dtype=int)
        if uidx.shape != (na,) or uidx.min() < 0 or uidx.max() >= alg1.n_input:
            raise InputError(f"input_indices must be {na} input indices of alg1; got {input_indices!r}")
        self.alg1, self.alg2, self.idx, self.uidx = alg1, alg2, idx, uidx
        self._f_idx = idx[2 * na:]  # where Algorithm 2's f sits in Algorithm 1's state
        self._fused_rc = np.zeros((alg1.n_state, alg1.n_state), dtype=bool)  # the rows and columns (40)-(43) replace
        self._fused_rc[idx, :] = True
        self._fused_rc[:, idx] = True
        self.covariance = as_choice("fused covariance", covariance, FUSED_COVARIANCES)
        self.steady_tol = check_steady_tol(steady_tol)
        blocks = idx.reshape(3, na).T  # (axes, 3): [r_a, v_a, f_a]
        self._axis_idx = blocks  # Algorithm 2's [r, ṙ, f] of each axis in Algorithm 1's state
        self._rr, self._cc = blocks[:, :, None], blocks[:, None, :]
        n = alg1.n_state
        m1 = alg1.measurement.n_meas
        C2 = np.zeros((na, n))
        C2[np.arange(na)[:, None], blocks] = alg2.C
        Cm = np.vstack([alg1.measurement.H, C2])
        D = np.zeros((m1 + na, alg1.measurement.n_noise + na))
        D[:m1, : alg1.measurement.n_noise] = alg1.measurement.D
        D[m1:, alg1.measurement.n_noise:] = np.diag(np.sqrt(alg2.Reff))
        meas = Saturated(LinearMeasurement(Cm, D, labels=alg1.measurement.labels + alg2.measurement.labels,
                                           units=alg1.measurement.units + alg2.measurement.units),
                         np.r_[np.full(m1, -np.inf), alg2.lower],
                         np.r_[np.full(m1, np.inf), alg2.upper])
        super().__init__(alg1.system, meas, name=name, missing=missing)
        self._m1 = m1

    def fuse(self, x1: NDArray[np.float64], P1: NDArray[np.float64], X2: NDArray[np.float64], P2: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(38)-(43): returns the fused ``(x1, P1, X2, P2)`` (new arrays)."""
        x1, Xo = self._fuse_mean(x1, X2)
        Po = P1[:, self._rr, self._cc]  # (runs, axes, 3, 3), a new array
        Po[..., 2, :] = P2[..., 2, :]
        if self.covariance == "symmetric":
            Po = 0.5 * (Po + np.swapaxes(Po, -1, -2))
        elif self.covariance == "block":
            Po[..., :2, 2] = 0.0
            Po[..., 2, :2] = 0.0
        P1 = np.where(self._fused_rc, 0.0, P1)  # a copy with the rows and columns of idx zeroed
        P1[:, self._rr, self._cc] = Po
        return x1, P1, Xo, Po

    def _start(self, xhat0, P0, runs):
        s1 = self.alg1._start(xhat0, P0, runs)
        x0 = np.asarray(xhat0, dtype=float)
        s2 = self.alg2._start(x0[self.idx], None if P0 is None else np.asarray(P0)[np.ix_(self.idx, self.idx)], runs)
        P1 = np.broadcast_to(s1.P, (runs,) + s1.P.shape[-2:]).copy()
        return FilterState(x=s1.x, P=P1, extra={"X2": s2.x, "P2": s2.P, "u_feed": s2.extra["u_feed"], "steady": None})

    def feed_input(self, state: FilterState, u: ArrayLike) -> FilterState:
        """The state with the input u_k (runs, n_input) whose drag-free part the next accelerometer reading contains."""
        return self._feed_input(state, self._check_feed_input(state, u))

    def feed_input_unchecked(self, state: FilterState, u: NDArray[np.float64]) -> FilterState:
        """:meth:`feed_input` without its checks: ``u`` a finite float (runs, n_input) array (see
        :meth:`~hinfnav.estimators.base.Estimator.update_unchecked`)."""
        return self._feed_input(state, u)

    def _feed_input(self, state: FilterState, u: NDArray[np.float64]) -> FilterState:
        """:meth:`feed_input`'s hook, ``u`` already checked."""
        return FilterState(x=state.x, P=state.P, k=state.k, extra=dict(state.extra, u_feed=u[:, self.uidx]),
                           phase=state.phase)

    def _update(self, state, y):
        x1, P1, X2, P2 = state.x, state.P, state.extra["X2"], state.extra["P2"]
        steady = state.extra["steady"]
        a1, m1 = self.alg1, self._m1
        innov1 = y[:, :m1] - x1 @ a1.measurement.H.T
        miss = np.isnan(y) if self.missing == "skip" else None
        if miss is not None and not miss.any():
            miss = None
        if miss is not None and miss.all():  # no reading at all: the prediction is the estimate (no fusion either)
            innov2, sat = np.full((y.shape[0], y.shape[1] - m1), np.nan), np.zeros(X2.shape[:2], dtype=bool)
        elif miss is not None:  # this step's gains without the missing channels (exact); the frozen gains kept aside
            X2, P2, innov2, sat, _ = self.alg2.kernel_update(X2, P2, y[:, m1:], state.extra["u_feed"],
                                                             missing=miss[:, m1:])
            sat, innov2 = sat & ~miss[:, m1:], np.where(miss[:, m1:], np.nan, innov2)
            P1m, H1, R1, used = drop_missing(P1, a1.measurement.H, a1.R, innov1, ~miss[:, :m1])
            K1, P1p = a1.gain(P1m, H1, R1)
            x1 = x1 + (K1 @ used[..., None])[..., 0] if K1.ndim == 3 else x1 + used @ K1.T
            x1, P1, X2, P2 = self.fuse(x1, np.broadcast_to(P1p, P1.shape), X2, P2)
            if steady is not None:
                steady = None if sat.any() else {k: v for k, v in steady.items() if not k.endswith("post")
                                                 and k not in ("K1", "K2")}
        else:
            cache2 = None if steady is None or "K2" not in steady else (steady["K2"], steady["P2_post"])
            X2, P2, innov2, sat, K2 = self.alg2.kernel_update(X2, P2, y[:, m1:], state.extra["u_feed"], cache2)
            if cache2 is not None and not sat.any():
                K1 = steady["K1"]
                x1 = x1 + (K1 @ innov1[..., None])[..., 0]
                x1, X2 = self._fuse_mean(x1, X2)
                P1, P2 = steady["P1_post"], steady["P2_post"]
            else:
                K1, P1p = a1.gain(P1)
                x1 = x1 + (K1 @ innov1[..., None])[..., 0]
                x1, P1, X2, P2 = self.fuse(x1, P1p, X2, P2)
                if steady is not None:
                    steady = None if sat.any() else dict(steady, K1=K1, K2=K2, P1_post=P1, P2_post=P2)
        th1, th2 = self._thetas(x1.shape[0])
        diag = {"innovation": np.concatenate([innov1, innov2], axis=1), "saturated": sat, "theta": th1,
                "theta_alg2": th2}
        extra = dict(state.extra, X2=X2, P2=P2, steady=steady)
        return FilterState(x=x1, P=P1, k=state.k, extra=extra), StepOutput(xhat=x1, P=P1, diagnostics=diag)

    def _thetas(self, runs):
        """θ* of both algorithms as (runs,) and (runs, n_axes) arrays (read-only, made once per batch size)."""
        if getattr(self, "_theta_runs", None) != runs:
            th1 = np.full(runs, self.alg1.theta)
            th2 = np.broadcast_to(self.alg2.theta, (runs, self.alg2.n_axes)).copy()
            th1.setflags(write=False)
            th2.setflags(write=False)
            self._theta_runs, self._theta_arrays = runs, (th1, th2)
        return self._theta_arrays

    def _fuse_mean(self, x1, X2):
        """(38), (40), (42): r, ṙ of Algorithm 1 and f of Algorithm 2, written into both."""
        x1 = x1.copy()
        x1[:, self._f_idx] = X2[:, :, 2]
        return x1, x1[:, self._axis_idx]  # (runs, axes, 3), a new array

    def _predict(self, state, u):
        u = np.asarray(u, dtype=float)
        a1 = self.alg1
        x1 = a1.predict_mean(state.x, u, state.k * a1.dt)  # Algorithm 1's hook (with the nominal increment (9))
        u2 = u[:, self.uidx]
        steady = state.extra["steady"]
        extra = dict(state.extra, u_feed=np.zeros(u2.shape))
        if steady is not None:
            X2, _ = self.alg2.kernel_predict(state.extra["X2"], None, u2)
            P1, P2 = steady["P1_prior"], steady["P2_prior"]
        else:
            P1 = a1.predict_covariance(state.P, state)
            X2, P2 = self.alg2.kernel_predict(state.extra["X2"], state.extra["P2"], u2)
            steady = freeze_gain(self.steady_tol, state.k, extra, P1_prior=P1, P2_prior=P2)
        extra.update(X2=X2, P2=P2, steady=steady)
        return FilterState(x=x1, P=P1, k=state.k + 1, extra=extra)
