"""The recursive (game-theoretic) H∞ filter of Simon (2006), a-priori form, on the step contract.

D. Simon, *Optimal State Estimation*, Wiley 2006, section 11.3: for
``x(k+1) = F x(k) + Γ u(k) + w(k)``, ``y(k) = H x(k) + v(k)`` and the
performance bound θ on the estimation error of ``z = L x`` weighted by S,

.. code-block:: text

    K_k     = P_k [I − θ S̄ P_k + HᵀR⁻¹H P_k]⁻¹ HᵀR⁻¹,          S̄ = Lᵀ S L
    x̂_{k+1} = F x̂_k + F K_k (y_k − H x̂_k) + Γ u_k
    P_{k+1} = F P_k [I − θ S̄ P_k + HᵀR⁻¹H P_k]⁻¹ Fᵀ + Q

which exists only while ``P_k⁻¹ − θ S̄ + HᵀR⁻¹H > 0``. With θ = 0 it is the
one-step Kalman predictor. The filter reports the a-priori estimate
``x̂_k = x̂(k|k−1)`` at t_k (like the LTI filter (12), a predictor).

Computation. With a factor ``P = C Cᵀ`` the push-through identity gives
``P [I + G P]⁻¹ = C N⁻¹ Cᵀ``, ``G = HᵀR⁻¹H − θ S̄``, ``N = I + Cᵀ G C =
Cᵀ(P⁻¹ + G)C``: the existence condition is ``N > 0`` (checked by a Cholesky
factorization at every step; its smallest eigenvalue is reported as the
``existence_margin`` diagnostic), ``K = C N⁻¹ Cᵀ HᵀR⁻¹`` and
``P⁺ = F C N⁻¹ Cᵀ Fᵀ + Q``. P and K do not depend on the data: one recursion
serves every run, and once ``‖P_{k+1} − P_k‖ ≤ 10⁻¹⁴ ‖P_k‖`` (Frobenius; the
package's one freeze, :func:`~hinfnav.estimators.steady.freeze_gain` with
rule (F2) checked every step, tolerance ``steady_tol``) the steady gain is
kept (:func:`hinfnav.analysis.steady_state_hinf` gives that
steady state directly).

filterpy's ``HInfinityFilter`` (2.0) is not this filter: it propagates P only
inside ``update`` (a ``predict`` without measurement leaves P where it was),
its gain ``F P L HᵀV⁻¹`` already contains F, and ``update`` adds that
correction to the *un-propagated* state, which ``predict`` then multiplies by
F again: its estimate after update and predict is ``F x̂ + F² K (y − H x̂)``
instead of ``F x̂ + F K (y − H x̂)``. With F = I the two coincide
(``tests/test_recursive_hinf.py`` checks both statements).

The *extended* H∞ filter (:class:`ExtendedHInfinityFilter`) is the same
recursion with a nonlinear measurement linearized at the prior estimate, as
the EKF does: with ``H_k = ∂h/∂x(x̂_k)`` and ``P̄_k = (P_k⁻¹ − θS̄ + H_kᵀR⁻¹H_k)⁻¹``,
Simon's gain is ``K_k = P̄_k H_kᵀ R⁻¹``, so

.. code-block:: text

    x̄_k     = x̂_k + P̄_k H_kᵀ R⁻¹ (y_k − h(x̂_k))                      (X1)
    x̂_{k+1} = Φ x̄_k + Γ u_k,      P_{k+1} = Φ P̄_k Φᵀ + Q              (X2)

which is the Kalman core's step (:class:`~hinfnav.estimators.ExtendedKalmanFilter`)
with the correction (X1) in place of the Joseph update; with a linear
measurement it is the filter above step for step, with θ = 0 the EKF.
P then depends on the data (H_k at each run's estimate): every run carries
its own, and the existence condition ``N_k > 0`` is checked per run.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..analysis.hinf_riccati import max_admissible_theta
from ..core.exceptions import HinfnavError, InputError
from ..core.linalg import as_covariance
from ..core.validation import as_choice, as_matrix, as_nonnegative
from .base import Estimator, FilterState, StepOutput
from .kalman import ExtendedKalmanFilter
from .steady import freeze_gain

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["RecursiveHInfinityFilter", "ExtendedHInfinityFilter",
           "STEADY_TOL"]

#: What the filter does when the existence condition fails.
ON_VIOLATION = ("raise", "flag")

#: What the extended filter does where the existence condition fails for a run: raise, or use θ = 0 at that step.
EXTENDED_ON_VIOLATION = ("raise", "kalman")

#: Default ``steady_tol``: relative change of P per step (Frobenius) below which the steady gain is kept.
STEADY_TOL = 1e-14


class RecursiveHInfinityFilter(Estimator):
    """Simon's a-priori recursive H∞ filter (see the module notes).

    Parameters
    ----------
    system : LinearSystem
        F = Φ, Γ (input), Q = B Bᵀ by default, dt, state labels.
    measurement : MeasurementModel
        Must be linear (``y = H x + D v``); R = D Dᵀ by default.
    theta : float
        Performance bound θ ≥ 0 (0: the Kalman predictor). Units: 1 / (units
        of S-weighted z)².
    P0 : array_like, shape (n, n)
        Default initial P (positive definite); ``start`` may override it.
    Q, R : array_like, optional
        Process- and measurement-noise covariances (Q ≥ 0, R > 0).
    L : array_like, shape (l, n), optional
        The estimated combination z = L x (default I).
    S : array_like, shape (l, l), optional
        Weight of its error (symmetric ≥ 0, default I); S̄ = Lᵀ S L.
    uses_input : bool
        Propagate with the applied input ``Γ u`` (True, default) or ignore it.
    on_violation : {"raise", "flag"}
        When ``P_k⁻¹ − θS̄ + HᵀR⁻¹H > 0`` fails at a step: raise an
        :class:`~hinfnav.core.exceptions.InputError` naming θ (default), or
        set ``existence_ok`` False in the diagnostics and go on with the
        same formulas (P may then lose definiteness).
    missing : {"refuse", "skip"}
        A NaN channel: an InputError, or its innovation set to 0 (the reading
        the filter predicts). The gain sequence does not depend on the data
        and is kept (documented choice: P then assumes the channel was read).
    name : str

    Notes
    -----
    Diagnostics of ``update``: ``innovation`` (runs, m), ``existence_margin``
    (runs,): smallest eigenvalue of ``N = Cᵀ(P⁻¹ − θS̄ + HᵀR⁻¹H)C``, and
    ``existence_ok`` (runs,).
    """

    name = "recursive_hinf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "recursive_hinf"

    def __init__(self, system: LinearSystem | DynamicsModel, measurement: MeasurementModel, *, theta: float, P0: ArrayLike,
                 Q: ArrayLike | None = None, R: ArrayLike | None = None, L: ArrayLike | None = None, S: ArrayLike | None = None, uses_input: bool = True,
                 on_violation: str = "raise", steady_tol: float | None = STEADY_TOL, name: str | None = None,
                 missing: str = "refuse") -> None:
        super().__init__(system, measurement, name=name, missing=missing)
        if not getattr(measurement, "linear", False) or measurement.H is None:
            raise InputError(f"measurement must be linear (y = H x + D v); got {type(measurement).__name__}")
        n, m = system.n, measurement.n_meas
        self.theta = as_nonnegative("theta", theta)
        self.F = np.asarray(system.Phi, dtype=float)
        self.Gamma = np.asarray(system.Gamma, dtype=float)
        self.H = np.asarray(measurement.H, dtype=float)
        self.Q = as_covariance("Q", system.Q if Q is None else Q, n, definite=False)
        self.R = as_covariance("R", measurement.R if R is None else R, m, definite=True)
        self.P0 = as_covariance("P0", P0, n, definite=True)
        self.L = np.eye(n) if L is None else as_matrix("L", L, (None, n))
        l = self.L.shape[0]
        self.S = np.eye(l) if S is None else as_covariance("S", S, l, definite=False)
        if not isinstance(uses_input, (bool, np.bool_)):
            raise InputError(f"uses_input must be True or False; got {uses_input!r}")
        self.uses_input = bool(uses_input)
        self.on_violation = as_choice("on_violation", on_violation, ON_VIOLATION)
        self.steady_tol = None if steady_tol is None else as_nonnegative("steady_tol", steady_tol)
        self._HtRi = np.linalg.solve(self.R, self.H).T  # Hᵀ R⁻¹
        W = self._HtRi @ self.H
        self.Sbar = self.L.T @ self.S @ self.L
        self._G = 0.5 * (W + W.T) - self.theta * 0.5 * (self.Sbar + self.Sbar.T)
        self._theta_max = None

    @property
    def HtRi(self) -> np.ndarray:
        """``Hᵀ R⁻¹`` (n, m)."""
        return self._HtRi

    @property
    def G_theta(self) -> np.ndarray:
        """``Hᵀ R⁻¹ H − θ S̄`` (symmetrised), the matrix of the recursion's ``N = I + Cᵀ G C``."""
        return self._G

    # -- the data-independent recursion --------------------------------------------

    def theta_max(self) -> float:
        """Largest θ with a steady state (:func:`hinfnav.analysis.max_admissible_theta`), cached."""
        if self._theta_max is None:
            self._theta_max = max_admissible_theta(self.F, self.H, self.Q, self.R, L=self.L, S=self.S)
        return self._theta_max

    def riccati_step(self, P: NDArray[np.float64], k: int = 0) -> tuple[NDArray[np.float64], NDArray[np.float64], float, bool]:
        """One step of the recursion: ``(K, P_next, margin, ok)`` (see the module notes)."""
        try:
            C = np.linalg.cholesky(P)
        except np.linalg.LinAlgError:
            lam, V = np.linalg.eigh(0.5 * (P + P.T))
            C = V * np.sqrt(np.clip(lam, 0.0, None))
        N = np.eye(P.shape[0]) + C.T @ self._G @ C
        N = 0.5 * (N + N.T)
        margin = float(np.linalg.eigvalsh(N)[0])
        try:
            Nc = np.linalg.cholesky(N)
            ok = True
            NiCt = np.linalg.solve(Nc.T, np.linalg.solve(Nc, C.T))  # N⁻¹ Cᵀ
        except np.linalg.LinAlgError:
            ok = False
            if self.on_violation == "raise":
                self._violation(k, margin)
            NiCt = np.linalg.solve(N, C.T)
        CNC = C @ NiCt
        CNC = 0.5 * (CNC + CNC.T)
        K = CNC @ self._HtRi
        P_next = self.F @ CNC @ self.F.T + self.Q
        return K, 0.5 * (P_next + P_next.T), margin, ok

    def _violation(self, k, margin):
        try:
            tmax = self.theta_max()
            hint = (f"the steady state admits theta < {tmax:.6g}" if np.isfinite(tmax)
                    else "every theta has a steady state; the violation comes from P0")
        except HinfnavError:
            hint = "even theta = 0 has no steady state ((F, H) not detectable?)"
        raise InputError(
            f"filter {self.name!r}: theta = {self.theta:g} violates the existence condition "
            f"P_k^-1 - theta*S̄ + H^T R^-1 H > 0 at step {k} (smallest eigenvalue of C^T(P^-1 - theta*S̄ + "
            f"H^T R^-1 H)C: {margin:.3g}); choose a smaller theta ({hint}) or a smaller P0"
        )

    # -- the step contract --------------------------------------------------------------

    def _start(self, xhat0, P0, runs):
        P = self.P0 if P0 is None else as_covariance("P0", P0, self.n_state, definite=True)
        x = np.broadcast_to(np.asarray(xhat0, dtype=float), (runs, self.n_state)).copy()
        return FilterState(x=x, P=P, extra={"steady": None})

    def _gain(self, P, k, steady):
        """``(K, P_next, margin, ok, steady)`` at step k; keeps the steady gain once P has converged."""
        if steady is not None:
            K, P_fixed, margin, ok = steady
            return K, P_fixed, margin, ok, steady
        K, P_next, margin, ok = self.riccati_step(P, k)
        if ok and freeze_gain(self.steady_tol, k, {"check_P": P}, every=1, rule="frobenius", P=P_next) is not None:
            steady = (K, P, margin, ok)
            P_next = P
        return K, P_next, margin, ok, steady

    def _update(self, state, y):
        y = np.asarray(y, dtype=float)
        runs = state.x.shape[0]
        K, P_next, margin, ok, steady = self._gain(state.P, state.k, state.extra.get("steady"))
        innovation = y - state.x @ self.H.T
        if self.missing == "skip":
            innovation = np.where(np.isnan(innovation), 0.0, innovation)  # a missing channel: its predicted reading
        diag = {
            "innovation": innovation,
            "existence_margin": np.full(runs, margin),
            "existence_ok": np.full(runs, ok),
        }
        extra = dict(state.extra, innovation=innovation, gain=K, P_next=P_next, steady=steady)
        new = FilterState(x=state.x, P=state.P, k=state.k, extra=extra)
        return new, StepOutput(xhat=state.x, P=np.broadcast_to(state.P, (runs,) + state.P.shape), diagnostics=diag)

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        if "gain" not in state.extra:
            raise InputError(f"filter {self.name!r}: predict needs an update first (the gain uses y_k)")
        FK = self.F @ state.extra["gain"]
        x = state.x @ self.F.T + state.extra["innovation"] @ FK.T
        if self.uses_input:
            x = x + np.asarray(u, dtype=float) @ self.Gamma.T
        extra = {"steady": state.extra.get("steady")}
        return FilterState(x=x, P=state.extra["P_next"], k=state.k + 1, extra=extra)


class ExtendedHInfinityFilter(ExtendedKalmanFilter):
    """Simon's a-priori H∞ filter with the measurement linearized at the prior estimate (module notes, (X1)–(X2)).

    Parameters
    ----------
    system, measurement, P0, Q, R, uses_input, name, missing
        As :class:`~hinfnav.estimators.ExtendedKalmanFilter` (any measurement model with a Jacobian).
    theta : float
        Performance bound θ ≥ 0 (0: the EKF), 1 / (units of z)².
    L, S : array_like, optional
        As :class:`RecursiveHInfinityFilter` (default I): S̄ = Lᵀ S L.
    output : {"predicted", "filtered"}
        What ``update`` reports: the a-priori estimate x̂_k of Simon's filter (default) or x̄_k of (X1).
    on_violation : {"raise", "kalman"}
        Where the existence condition fails for a run: stop with an InputError naming θ (default), or take that
        run's step with θ = 0 (the EKF's update; documented fallback: the game has no saddle point there), which
        ``existence_ok`` reports.

    Notes
    -----
    The existence condition ``P_k⁻¹ − θS̄ + H_kᵀR⁻¹H_k > 0`` is checked at every
    step for every run (``N = I + Cᵀ(H_kᵀR⁻¹H_k − θS̄)C > 0``, ``P_k = C Cᵀ``).
    With a linearized measurement it depends on the data, so a θ admissible
    at the initial geometry can fail in a run's transient. Diagnostics of
    ``update``: ``innovation``, ``innovation_covariance`` (``H_k P_k H_kᵀ + R``),
    ``existence_margin`` (runs,), the smallest eigenvalue of N, and ``existence_ok``.
    """

    name = "extended_hinf"
    symmetric_posterior = True

    def __init__(self, system: LinearSystem | DynamicsModel, measurement: MeasurementModel, *, theta: float,
                 P0: ArrayLike, Q: ArrayLike | None = None, R: ArrayLike | None = None, L: ArrayLike | None = None,
                 S: ArrayLike | None = None, uses_input: bool = True, output: str = "predicted",
                 on_violation: str = "raise", name: str | None = None, missing: str = "refuse") -> None:
        super().__init__(system, measurement, P0=P0, Q=Q, R=R, uses_input=uses_input, output=output, name=name,
                         missing=missing)
        if self.R is None:
            raise InputError(f"filter {self.name!r} needs a constant R (give R; the measurement's covariance "
                             "depends on its reading)")
        n = system.n
        self.theta = as_nonnegative("theta", theta)
        self.on_violation = as_choice("on_violation", on_violation, EXTENDED_ON_VIOLATION)
        self.L = np.eye(n) if L is None else as_matrix("L", L, (None, n))
        l = self.L.shape[0]
        self.S = np.eye(l) if S is None else as_covariance("S", S, l, definite=False)
        Sbar = self.L.T @ self.S @ self.L
        self.Sbar = 0.5 * (Sbar + Sbar.T)

    def correct_error(self, P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64],
                      innovation: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """(X1): ``(δx, P̄, diagnostics)`` batched (P, H, R shared or per run)."""
        HtRi = np.swapaxes(np.linalg.solve(R, H), -1, -2)  # Hᵀ R⁻¹, (…, n, m)
        G = HtRi @ H - self.theta * self.Sbar
        G = 0.5 * (G + np.swapaxes(G, -1, -2))
        C = np.linalg.cholesky(P)
        Ct = np.swapaxes(C, -1, -2)
        N = np.eye(P.shape[-1]) + Ct @ G @ C
        N = 0.5 * (N + np.swapaxes(N, -1, -2))
        margin = np.linalg.eigvalsh(N)[..., 0]
        ok = margin > 0
        if not np.all(ok):
            if self.on_violation == "raise":
                raise InputError(
                    f"filter {self.name!r}: theta = {self.theta:g} violates the existence condition "
                    f"P_k^-1 - theta*S̄ + H_k^T R^-1 H_k > 0 (smallest eigenvalue of N: {np.min(margin):.3g}); "
                    "choose a smaller theta or a smaller P0, or on_violation='kalman'")
            # "kalman": θ = 0 at this step on the runs that violate it (N = I + Cᵀ HᵀR⁻¹H C > 0 always)
            theta = self.theta * np.asarray(ok, dtype=float)[..., None, None]
            G = HtRi @ H - theta * self.Sbar
            N = np.eye(P.shape[-1]) + Ct @ (0.5 * (G + np.swapaxes(G, -1, -2))) @ C
            N = 0.5 * (N + np.swapaxes(N, -1, -2))
        Y = np.linalg.solve(np.linalg.cholesky(N), Ct)  # N_c⁻¹ Cᵀ
        P_post = np.swapaxes(Y, -1, -2) @ Y  # C N⁻¹ Cᵀ = P̄
        gain = P_post @ HtRi
        runs = innovation.shape[0]
        dx = innovation @ gain.T if gain.ndim == 2 else (gain @ innovation[..., None])[..., 0]
        Sk = H @ P @ np.swapaxes(H, -1, -2) + R
        diag = {"innovation_covariance": Sk if Sk.ndim == 3 else np.broadcast_to(Sk, (runs,) + Sk.shape),
                "existence_margin": np.broadcast_to(margin, (runs,)).copy(),
                "existence_ok": np.broadcast_to(ok, (runs,)).copy()}
        return dx, P_post, diag
