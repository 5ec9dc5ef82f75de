"""Extended-state filters on the step contract (Yang et al. 2020, after Bai, Xue, Huang & Fang 2018).

An unknown disturbance f is appended to the state, ``X_{k+1} = A_d X_k +
B_d(u_k + w_k) + B_e G_k`` with the increment ``G_k = f_{k+1} − f_k`` bounded
in mean square, ``E G_{k,i}² ≤ q_i`` (Assumption 4). Three filters:

* :class:`ExtendedStateKalmanFilter` — Algorithm 1: the Kalman filter whose
  covariance prediction bounds the unknown cross term by Young's inequality,
  ``P⁻ = (1+θ) A P Aᵀ + (1+1/θ) Q₁ + Q₂`` (15)-(19), ``Q₁ = 4 B_e (l diag q) B_eᵀ``,
  ``Q₂ = B_d S B_dᵀ``, ``θ = θ* = √(tr Q₁,₀ / tr P₀)``; the predicted increment
  is ``Ĝ = sat(f̄_{k+1} − f̄_k, ±√q)`` (9) from a nominal model f̄ (0 if none).
* :class:`SaturatedExtendedStateFilter` — Algorithm 2, independent axes
  ``X = [r, ṙ, f]`` batched: inside the sensor range the Kalman update (31)-(32)
  with ``S_y = C P⁻ Cᵀ + R + D² S`` (22), (27); on a clipped reading the
  measurement is replaced by the mean of the predicted normal ``N(ŷ⁻, S_y)``
  truncated to the half-line beyond the bound (23), (29), and the truncated
  variance (30) is added to the covariance (33)-(34), using
  :func:`hinfnav.analysis.truncated_normal_moments`. ``mode="skip"`` keeps the
  prediction on a clipped reading (the paper's L3), ``mode="ideal"`` never
  treats a reading as clipped (L2, fed the unclipped readings).
* :class:`FusedExtendedStateFilter` — Algorithm 3: both run, then the
  position and velocity of Algorithm 1 and the disturbance of Algorithm 2 are
  combined (38)-(39) and written back into both (40)-(43).

The saturated reading contains the input through ``D u`` (11): a loop hands
the filter the input held when the reading was taken with ``feed_input``
before ``update``; without it the reading is taken to exclude the input part.

Every filter can freeze its gains once the covariance recursion has
converged (``steady_tol``, :func:`hinfnav.estimators.steady.freeze_gain`;
``None``, the default, never freezes). A clipped reading unfreezes Algorithms 2, 3.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import as_covariance
from ..core.validation import as_matrix, as_positive, as_vector
from .base import FilterState, StepOutput, available_channels
from .correction import drop_missing, kalman_gain
from .steady import CHECK_EVERY, freeze_gain
from .kalman import ExtendedKalmanFilter


if TYPE_CHECKING:
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["ExtendedStateKalmanFilter", "theta_star", "check_steady_tol", "CHECK_EVERY"]

def theta_star(Q1, P0):
    """θ* = √(tr Q₁,₀ / tr P₀) of Algorithm 1; an :class:`InputError` if it is 0."""
    num, den = float(np.trace(Q1)), float(np.trace(P0))
    if num <= 0 or den <= 0:
        raise InputError(f"theta* = sqrt(tr Q1 / tr P0) needs tr Q1 > 0 and tr P0 > 0; got {num:.3g}, {den:.3g}: "
                         "give theta explicitly")
    return float(np.sqrt(num / den))


def check_steady_tol(steady_tol):
    """``steady_tol`` checked: None (never freeze) or a positive number."""
    return None if steady_tol is None else as_positive("steady_tol", steady_tol)


def predicted_increment(nominal, k, q_sqrt):
    """Ĝ_k = sat(f̄_{k+1} − f̄_k, ±√q) of (9)."""
    return np.clip(np.asarray(nominal(k + 1), float) - np.asarray(nominal(k), float), -q_sqrt, q_sqrt)


class ExtendedStateKalmanFilter(ExtendedKalmanFilter):
    """Algorithm 1: the extended-state Kalman filter with the θ-inflated prediction.

    Parameters
    ----------
    system : LinearSystem
        ``Phi = A_d``, ``Gamma = B_d`` of the extended system (8).
    measurement : MeasurementModel
        ``Y = C_d X + d`` (linear), R = E d dᵀ.
    P0 : array_like, shape (n, n)
    B_e : array_like, shape (n, l)
        Where the disturbance increments enter.
    q : array_like, shape (l,)
        Bounds ``E G_i² ≤ q_i`` (units of f squared), Assumption 4.
    S : array_like, shape (m_u, m_u), optional
        Input-noise covariance per step (``Q₂ = B_d S B_dᵀ``); default: the
        system's ``B Bᵀ`` is used as Q₂.
    R : array_like, optional
        Measurement-noise covariance (default: the measurement's).
    theta : float, optional
        Default θ* from Q₁ and P0.
    nominal : callable, optional
        ``nominal(k) -> f̄_k`` (shape (l,)); default f̄ = 0, so Ĝ = 0.
    steady_tol : float, optional
        Freeze the gain once P⁻ changes by less than this (relative) in one step.
    name : str
    """

    name = "eskf"

    def __init__(self, system: LinearSystem, measurement: MeasurementModel, *, P0: ArrayLike, B_e: ArrayLike,
                 q: ArrayLike, S: ArrayLike | None = None, R: ArrayLike | None = None, theta: float | None = None,
                 nominal: Callable[[int], ArrayLike] | None = None, steady_tol: float | None = None,
                 name: str | None = None, missing: str = "refuse") -> None:
        n = system.n
        self.B_e = as_matrix("B_e", B_e, (n, None))
        self.q = as_vector("q", q, self.B_e.shape[1])
        if np.any(self.q < 0):
            raise InputError("q (the increment bounds) must be >= 0")
        l = self.q.size
        self.Q1 = 4.0 * self.B_e @ (l * np.diag(self.q)) @ self.B_e.T
        if S is None:
            self.Q2 = system.Q
        else:
            S = as_covariance("S", S, system.n_input, definite=False)
            self.Q2 = system.Gamma @ S @ system.Gamma.T
        P0c = as_covariance("P0", P0, n, definite=True)
        self.theta = theta_star(self.Q1, P0c) if theta is None else as_positive("theta", theta)
        Q = (1.0 + 1.0 / self.theta) * self.Q1 + self.Q2
        super().__init__(system, measurement, P0=P0c, Q=0.5 * (Q + Q.T), R=R, uses_input=True, name=name,
                         missing=missing)
        if nominal is not None and not callable(nominal):
            raise InputError("nominal must be a callable k -> f_bar_k")
        self.nominal = nominal
        self.steady_tol = check_steady_tol(steady_tol)
        self._q_sqrt = np.sqrt(self.q)

    # -- the core's prediction hooks ------------------------------------------------------

    def predict_mean(self, x: NDArray[np.float64], u: NDArray[np.float64] | None, t: float = 0.0) -> NDArray[np.float64]:
        """``A_d X̂ + B_d u + B_e Ĝ_k`` (Algorithm 1), Ĝ_k of (9) from the nominal model at k = t / Δt (0 without one)."""
        x = super().predict_mean(x, u, t)
        if self.nominal is not None:
            x = x + predicted_increment(self.nominal, int(round(t / self.dt)), self._q_sqrt) @ self.B_e.T
        return x

    def predict_covariance(self, P: NDArray[np.float64], state: FilterState, F: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """``(1+θ) A P Aᵀ + (1+1/θ) Q₁ + Q₂`` (Algorithm 1), or the frozen prior once the recursion has converged
        (``state`` None: the formula)."""
        steady = None if state is None else state.extra.get("steady")
        if steady is not None:
            return steady["P_prior"]
        return (1.0 + self.theta) * (self.F @ P @ self.F.T) + self.Q

    def after_predict(self, state: FilterState, P: NDArray[np.float64]) -> dict[str, Any]:
        """The steady record (:func:`~hinfnav.estimators.steady.freeze_gain` on P⁻) and its check value."""
        steady = state.extra.get("steady")
        if steady is not None:
            return {"steady": steady}
        record = {"check_P_prior": state.extra.get("check_P_prior")}
        record["steady"] = freeze_gain(self.steady_tol, state.k, record, P_prior=P)
        return record

    def gain(self, P_prior: NDArray[np.float64], H: NDArray[np.float64] | None = None, R: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kalman gain and Joseph-form posterior for a prior covariance (shared or per run).

        ``H``, ``R`` default to the measurement's; :func:`~hinfnav.estimators.correction.kalman_gain`.
        """
        K, P_post, _ = kalman_gain(P_prior, self.measurement.H if H is None else H, self.R if R is None else R,
                                   symmetrize=False)
        return K, P_post

    def correct(self, x: NDArray[np.float64], P: NDArray[np.float64], H: NDArray[np.float64], innovation: NDArray[np.float64], state: FilterState,
                R: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        steady = state.extra.get("steady")
        if R is not None:  # missing channels: this step's gain, not the steady one
            K, P_post = self.gain(P, H, R)
        elif steady is not None and "K" in steady:
            K, P_post = steady["K"], steady["P_post"]
        else:
            K, P_post = self.gain(P)
            if steady is not None:
                steady.update(K=K, P_post=P_post)
        if K.ndim == 2:
            x_post = x + innovation @ K.T
        else:
            x_post = x + np.einsum("rij,rj->ri", K, innovation)
        return x_post, P_post, {"theta": np.full(x.shape[0], self.theta)}

    def _update(self, state, y):
        """As :meth:`ExtendedKalmanFilter._update`, without re-evaluating the (linear) measurement's Jacobian
        (a gated filter takes the core's update, where the gate screens the reading)."""
        if not self.measurement.linear or self.gate is not None:
            return super()._update(state, y)
        x, P = state.x, state.P
        H = self.measurement.H
        innovation = y - x @ H.T
        mask = available_channels(y) if self.missing == "skip" else None
        if mask is None:
            x_post, P_post, diag = self.correct(x, P, H, innovation, state)
        else:
            P, H_used, R_used, used = drop_missing(P, H, self.R, innovation, mask)
            x_post, P_post, diag = self.correct(x, P, H_used, used, state, R=R_used)
        diag["innovation"] = innovation
        new = FilterState(x=x_post, P=P_post, k=state.k, extra=dict(state.extra, prior=(x, P)))
        if self.output == "filtered":
            return new, StepOutput(xhat=x_post, P=P_post, diagnostics=diag)
        return new, StepOutput(xhat=x, P=P, diagnostics=diag)
