"""Kalman filters on the step contract: the linear/extended Kalman filter, batched over runs.

:class:`ExtendedKalmanFilter` propagates a linear system (its Jacobian is Φ)
or any dynamics model (``n``, ``n_input``, ``dt``, ``state``, ``Q``,
``linear`` False, ``f(x, u, t)`` and ``jacobian(x, u, t)``: the Jacobian at
x̂(k|k) propagates P) and linearizes the measurement model at the prior estimate. It is one
class with small hooks that the variants override:

* :meth:`~ExtendedKalmanFilter.predict_covariance` — ``Φ P Φᵀ + Q``
  (strong tracking multiplies by fading factors);
* :meth:`~ExtendedKalmanFilter.correct` — the Joseph-form Kalman update
  (the Huber filter replaces it by an M-estimation);
* :meth:`~ExtendedKalmanFilter.measurement_covariance` — ``R_k``, constant
  unless the measurement's covariance depends on its reading (a converted
  range/angle measurement: ``J R Jᵀ`` at each reading);
* the system it is built on (augmented and extended-state filters append
  states to it).

With a linear measurement and one initial covariance for all runs the
covariance and gain do not depend on the data: P is then carried once (2-D)
and shared by every run, so a batch of R runs costs one covariance recursion.
The update follows filterpy's ``ExtendedKalmanFilter.update`` step for step
(Joseph form), which the test suite checks run by run.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import HinfnavError, InputError
from ..core.linalg import as_covariance, congruence
from ..core.validation import as_choice
from .base import Estimator, FilterState, StepOutput, available_channels, fill_missing
from .correction import KalmanCorrection, drop_missing

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["OUTPUTS", "ExtendedKalmanFilter"]

#: What ``update`` reports at t_k: x̂(k|k) or x̂(k|k−1).
OUTPUTS = ("filtered", "predicted")


class ExtendedKalmanFilter(KalmanCorrection, Estimator):
    """Extended Kalman filter of a linear system with any measurement model.

    Parameters
    ----------
    system : LinearSystem
        Φ, Γ, B (Q = B Bᵀ by default), dt, state labels.
    measurement : MeasurementModel
        h, its Jacobian, R = D Dᵀ by default, residual (angles wrapped).
    P0 : array_like, shape (n, n)
        Default initial covariance (positive definite); ``start`` may override it.
    Q : array_like, shape (n, n), optional
        Process-noise covariance per step (positive semidefinite).
    R : array_like, shape (m, m), optional
        Measurement-noise covariance (positive definite). Default: the
        measurement's ``R``, or, for a measurement whose covariance depends on
        its reading (one with ``noise_covariance(y)``, e.g.
        :class:`~hinfnav.systems.measurements.ConvertedPosition`), ``R_k``
        from each reading (see :meth:`measurement_covariance`).
    uses_input : bool
        Propagate with the applied input, ``Φ x̂ + Γ u`` (True), or ignore u.
    output : {"filtered", "predicted"}
        What ``update`` reports: x̂(k|k) (uses y_k) or x̂(k|k−1).
    name : str
    missing : {"refuse", "skip"}
        A NaN channel of a reading: an InputError, or not used at that step
        (removed exactly, :func:`~hinfnav.estimators.correction.drop_missing`;
        a reading without any channel leaves the prior as the estimate).
    """

    name = "ekf"
    symmetric_posterior = False

    def __init__(self, system: LinearSystem | DynamicsModel, measurement: MeasurementModel, *, P0: ArrayLike, Q: ArrayLike | None = None,
                 R: ArrayLike | None = None, uses_input: bool = False, output: str = "filtered", name: str | None = None,
                 missing: str = "refuse") -> None:
        super().__init__(system, measurement, name=name, missing=missing)
        n, m = system.n, measurement.n_meas
        self.Q = as_covariance("Q", system.Q if Q is None else Q, n, definite=False)
        #: R(y) of a measurement whose noise covariance depends on its reading (None: the constant R)
        self.R_of_reading = getattr(measurement, "noise_covariance", None) if R is None else None
        if self.R_of_reading is None:
            self.R = as_covariance("R" if R is not None else "R = D Dᵀ of the measurement's noise matrix D (give a D of "
                                   "full row rank, or R)", measurement.R if R is None else R, m, definite=True)
        else:
            self.R = None
        self.P0 = as_covariance("P0", P0, n, definite=True)
        if not isinstance(uses_input, (bool, np.bool_)):
            raise InputError(f"uses_input must be True or False; got {uses_input!r}")
        self.uses_input = bool(uses_input)
        self.output = as_choice("output", output, OUTPUTS)
        #: the dynamics model's f(x, u, t) and Jacobian propagate when the system says it is not linear
        self.nonlinear_dynamics = not getattr(system, "linear", True)
        if self.nonlinear_dynamics:
            if not (callable(getattr(system, "f", None)) and callable(getattr(system, "jacobian", None))):
                raise InputError(f"system {type(system).__name__} says it is not linear but has no f(x, u, t) and "
                                 "jacobian(x, u, t)")
        elif getattr(system, "Phi", None) is None:
            raise InputError(f"system must be a LinearSystem (with Phi) or a dynamics model (f, jacobian); got "
                             f"{type(system).__name__}")
        self.F = getattr(system, "Phi", None)
        self.Gamma = getattr(system, "Gamma", None)

    @property
    def shares_covariance(self) -> bool:
        """True when P and the gain do not depend on the data (linear measurement, constant R)."""
        return bool(self.measurement.linear) and self.R_of_reading is None and not self.nonlinear_dynamics

    # -- hooks ------------------------------------------------------------------

    def predict_mean(self, x: NDArray[np.float64], u: NDArray[np.float64] | None, t: float = 0.0) -> NDArray[np.float64]:
        """``Φ x̂ (+ Γ u)`` for a batch of estimates, or the dynamics model's ``f(x̂, u, t)`` (t the time of x̂, s)."""
        if self.nonlinear_dynamics:
            return self.system.f(x, u if self.uses_input else None, t)
        out = x @ self.F.T
        if self.uses_input:
            out = out + u @ self.Gamma.T
        return out

    def predict_covariance(self, P: NDArray[np.float64], state: FilterState, F: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """``F P Fᵀ + Q`` with F = Φ, or the dynamics model's Jacobian at x̂(k|k) ((n, n) or (runs, n, n))."""
        F = self.F if F is None else F
        if F.ndim == 3:
            return F @ P @ np.swapaxes(F, -1, -2) + self.Q
        return congruence(F, P) + self.Q

    def measurement_covariance(self, y: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """``R_k`` at this step: the measurement's ``noise_covariance(y_k)`` (runs, m, m) if it has one, else None.

        None means the constant :attr:`R` (and :meth:`correct` is called
        without an ``R`` argument, as before this hook existed).
        """
        return None if self.R_of_reading is None else self.R_of_reading(y)

    def correct(self, x: NDArray[np.float64], P: NDArray[np.float64], H: NDArray[np.float64], innovation: NDArray[np.float64], state: FilterState,
                R: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """The correction :meth:`correct_error` (Joseph form here, Huber's with the Huber mixin) applied to x.

        Returns ``(x⁺, P⁺, diagnostics)``; ``H`` is (m, n) when P is shared,
        (runs, m, n) otherwise; ``R`` is the step's covariance when it depends
        on the reading or on the missing channels (default the constant :attr:`R`).
        """
        dx, P_post, diag = self.correct_error(P, H, self.R if R is None else R, innovation)
        return x + dx, P_post, diag

    # -- the step contract --------------------------------------------------------

    def _start(self, xhat0, P0, runs):
        P = self.P0 if P0 is None else as_covariance("P0", P0, self.n_state, definite=True)
        x = np.broadcast_to(np.asarray(xhat0, dtype=float), (runs, self.n_state)).copy()
        if not self.shares_covariance:
            P = np.broadcast_to(P, (runs,) + P.shape).copy()
        return FilterState(x=x, P=P)

    def _update(self, state, y):
        x, P = state.x, state.P
        mask = available_channels(y) if self.missing == "skip" else None
        try:
            H = self.measurement.jacobian(x[0] if self.shares_covariance else x)
            yhat = self.measurement.function(x)
            # a missing channel reads as predicted (innovation 0; removed below)
            y, mask = fill_missing(self.measurement, y, x, yhat, mask)
            innovation = self.measurement.residual(y, yhat)
        except InputError as exc:
            raise HinfnavError(f"filter {self.name!r} stopped at step {state.k}: the estimate reached a singular point ({exc})") from None
        R_k = self.measurement_covariance(y, x)
        if mask is None:
            x_post, P_post, diag = self.correct(x, P, H, innovation, state, R=R_k)
        else:
            if R_k is not None:  # a reading-dependent R not finite on the channels it has: the reading is not used
                both = mask[:, :, None] & mask[:, None, :]
                mask = mask & np.all(np.isfinite(np.where(both, R_k, 0.0)), axis=(1, 2))[:, None]
            P, H_used, R_used, used = drop_missing(P, H, self.R if R_k is None else R_k, innovation, mask)
            x_post, P_post, diag = self.correct(x, P, H_used, used, state, R=R_used)
        diag = dict(diag, innovation=innovation if mask is None else np.where(mask, innovation, np.nan))
        new = FilterState(x=x_post, P=P_post, k=state.k, extra=dict(state.extra, prior=(x, P)))
        if self.output == "filtered":
            out = StepOutput(xhat=x_post, P=self._broadcast(P_post, x.shape[0]), diagnostics=diag)
        else:
            out = StepOutput(xhat=x, P=self._broadcast(P, x.shape[0]), diagnostics=diag)
        return new, out

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        if self.nonlinear_dynamics:  # the Jacobian at the posterior x̂(k|k), before the mean moves on
            t = state.k * self.dt
            F = np.asarray(self.system.jacobian(state.x, u if self.uses_input else None, t), dtype=float)
            P = self.predict_covariance(state.P, state, F=F)
            x = self.predict_mean(state.x, u, t)
        else:
            x = self.predict_mean(state.x, u)
            P = self.predict_covariance(state.P, state)
        extra = {key: val for key, val in state.extra.items() if key != "prior"}
        return FilterState(x=x, P=P, k=state.k + 1, extra=extra)

    def _broadcast(self, P, runs):
        return np.broadcast_to(P, (runs,) + P.shape) if P.ndim == 2 else P
