"""Kalman filters on the step contract: the linear/extended Kalman filter, batched over runs.

:class:`ExtendedKalmanFilter` propagates a linear system (its Jacobian is Φ)
or any dynamics model (``n``, ``n_input``, ``dt``, ``state``, ``Q``,
``linear`` False, ``f(x, u, t)`` and ``jacobian(x, u, t)``: the Jacobian at
x̂(k|k) propagates P) and linearizes the measurement model at the prior estimate. It is one
subclass of :class:`KalmanCore`, the one Kalman core whose single update
(``_update``) it shares with :class:`~hinfnav.estimators.AugmentedEKF`; the
variants override small hooks:

* :meth:`~ExtendedKalmanFilter.predict_covariance` — ``Φ P Φᵀ + Q``;
* :meth:`~ExtendedKalmanFilter.process_noise` and
  :meth:`~ExtendedKalmanFilter.complete_prior` — the hooks shared with
  :class:`~hinfnav.estimators.AugmentedEKF`: a filter whose class sets
  ``defers_prior`` keeps ``F P Fᵀ`` and ``Q`` from ``predict`` and completes
  P(k+1|k) when y(k+1) arrives, so the mixins of
  :mod:`hinfnav.estimators.adaptive` (strong tracking, rate-adapted noise)
  work on both cores, on a linear system or any dynamics model
  (:class:`StrongTrackingEKF`, :class:`RateAdaptiveEKF`);
* :meth:`~ExtendedKalmanFilter.predict_mean` — ``Φ x̂ + Γ u`` or ``f(x̂, u, t)``
  (Algorithm 1 adds its predicted disturbance increment, the GRACE filter
  propagates the mean through a two-body model), and
  :meth:`~KalmanCore.after_predict` — items kept after a prediction (a
  steady-gain freeze's record, :mod:`hinfnav.estimators.steady`);
* :meth:`~ExtendedKalmanFilter.correct` — the Joseph-form Kalman update
  (the Huber filter replaces it by an M-estimation);
* :meth:`~KalmanCore.carried` — items of a correction's diagnostics kept for
  the next reading (the noise-adaptive filter's α, β,
  :mod:`hinfnav.estimators.variational`); :attr:`~KalmanCore.gate` — a χ²
  innovation gate screening each reading before the correction
  (:mod:`hinfnav.estimators.gate`);
* :meth:`~ExtendedKalmanFilter.measurement_covariance` — ``R_k``, constant
  unless the measurement's covariance depends on its reading (a converted
  range/angle measurement: ``J R Jᵀ`` at each reading);
* the system it is built on (augmented and extended-state filters append
  states to it);
* :attr:`~KalmanCore.moment_rule` — how the moments of the predicted reading are computed
  (:mod:`hinfnav.estimators.moments`): linearised here (``observe``), the unscented transform for
  :class:`~hinfnav.estimators.sigma_point.SigmaPointFilter`; and the strategies
  :attr:`~KalmanCore.correction_rule` / :attr:`~KalmanCore.fading_rule` composed onto a built filter
  (:mod:`hinfnav.estimators.strategies`) in place of ``correct_error`` / ``complete_prior``.

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

from ..core.exceptions import HinfnavError, InputError, ModelFunctionError
from ..core.linalg import as_covariance, congruence
from ..core.validation import as_choice
from .adaptive import RateAdaptive, StrongTracking
from .base import Estimator, FilterState, StepOutput, available_channels, fill_missing
from .correction import KalmanCorrection, drop_missing
from .gate import GateOption
from .moments import LINEARISED

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["OUTPUTS", "ExtendedKalmanFilter", "KalmanCore", "RateAdaptiveEKF", "StrongTrackingEKF"]

#: What ``update`` reports at t_k: x̂(k|k) or x̂(k|k−1).
OUTPUTS = ("filtered", "predicted")

#: Keys of ``FilterState.extra`` that live from one step to the next only.
_TRANSIENT = ("prior", "PhiPPhiT", "Qd")


def _finite_reading_R(mask, R_k):
    """``mask`` without the runs whose reading-dependent R is not finite on the channels they have."""
    both = mask[:, :, None] & mask[:, None, :]
    return mask & np.all(np.isfinite(np.where(both, R_k, 0.0)), axis=(1, 2))[:, None]


class KalmanCore(GateOption, KalmanCorrection, Estimator):
    """The one Kalman core: hooks and the one update shared by every Kalman-type filter of the package.

    :class:`ExtendedKalmanFilter` (a linear system or a dynamics model) and
    :class:`~hinfnav.estimators.augmented.AugmentedEKF` (error coordinates
    with augmented states, the attitude filters) are its subclasses; they
    differ in the prediction and in the model hooks, never in the update.
    Hooks: ``observe`` (ŷ, H at the prior), ``inject`` (x̂ corrected by δx
    in error coordinates), ``report``/``report_covariance`` (what a step
    returns), ``correct``/``correct_error`` (the Joseph update (J1)-(J2), or
    Huber's), ``measurement_covariance`` (R_k), ``complete_prior`` (strong
    tracking), ``after_update``/``after_predict`` and the diagnostics hooks.
    """

    #: True when the covariance depends on the data (a mixin's Huber weights, fading factors …)
    data_dependent_covariance = False
    #: True when P(k+1|k) is completed at the next reading (:meth:`complete_prior`), e.g. by strong tracking
    defers_prior = False
    #: A non-finite correction or covariance is an error (HinfnavError naming the step) rather than carried on
    refuse_nonfinite = False
    #: Keys of ``FilterState.extra`` that live from one step to the next only
    transient_keys = _TRANSIENT
    #: R(y) of a measurement whose noise covariance depends on its reading (None: the constant R)
    R_of_reading = None
    #: How the moments of the predicted reading are computed (:mod:`hinfnav.estimators.moments`): linearised here,
    #: the unscented transform for :class:`~hinfnav.estimators.sigma_point.SigmaPointFilter`
    moment_rule = LINEARISED
    #: A correction strategy set by :func:`~hinfnav.estimators.strategies.compose` (None: the class's own
    #: ``correct_error``)
    correction_rule = None
    #: A prior-fading strategy set by :func:`~hinfnav.estimators.strategies.compose` (None: the class's own
    #: ``complete_prior``)
    fading_rule = None

    @property
    def strategies(self) -> tuple[str, ...]:
        """Names of the strategies composed onto this filter's class (empty: the class as written)."""
        return tuple(rule.name for rule in (self.correction_rule, self.fading_rule) if rule is not None)

    @property
    def n_cov(self) -> int:
        """Dimension of the error coordinates (and of P): the state's unless set otherwise (augmented states)."""
        return getattr(self, "_n_cov", None) or self.n_state

    @n_cov.setter
    def n_cov(self, value: int) -> None:
        self._n_cov = int(value)

    # -- model hooks ---------------------------------------------------------------

    def observe(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(ŷ, H)`` at the prior: ŷ (runs, m), H (m, n_cov) or (runs, m, n_cov)."""
        raise NotImplementedError

    def inject(self, x: NDArray[np.float64], dx: NDArray[np.float64]) -> NDArray[np.float64]:
        """The state corrected by ``dx`` (error coordinates); additive here."""
        return x + dx

    def initial_internal(self, xhat0: NDArray[np.float64]) -> NDArray[np.float64]:
        """The internal state of the prior estimate ``xhat0`` (n,): the estimate itself here."""
        return xhat0

    def report(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The estimate reported in the system's coordinates, (runs, system.n)."""
        return x

    def report_covariance(self, P: NDArray[np.float64]) -> NDArray[np.float64]:
        """The covariance reported with the estimate."""
        return P

    # -- idea hooks ----------------------------------------------------------------------

    def complete_prior(self, PhiPPhiT: NDArray[np.float64], Qd: NDArray[np.float64], state: FilterState, innovation: NDArray[np.float64], H: NDArray[np.float64],
                       mask: NDArray[np.bool_] | None = None) -> tuple[NDArray[np.float64], dict[str, Any], dict[str, Any]]:
        """``(P(k+1|k), diagnostics, extra)`` at the reading y(k+1): ``F P Fᵀ + Q_d`` here.

        Called only when :attr:`defers_prior` is set; ``innovation`` and ``H``
        are zero on the channels ``~mask`` a reading lacks (mask None: none).
        Strong tracking (:class:`~hinfnav.estimators.adaptive.StrongTracking`) overrides it; a composed fading
        strategy (:attr:`fading_rule`) replaces it.
        """
        if self.fading_rule is not None:
            return self.fading_rule.complete_prior(self, PhiPPhiT, Qd, state, innovation, H, mask=mask)
        return PhiPPhiT + Qd, {}, {}

    def initial_diagnostics(self, runs: int) -> dict[str, Any]:
        """Diagnostics every step reports, at their values before any prediction (a fading strategy's here)."""
        return {} if self.fading_rule is None else self.fading_rule.initial_diagnostics(self, runs)

    def step_diagnostics(self, state: FilterState) -> dict[str, Any]:
        """Diagnostics that depend on the prior ``state`` (none here)."""
        return {}

    def update_diagnostics(self, x_post: NDArray[np.float64]) -> dict[str, Any]:
        """Diagnostics that depend on the posterior estimate (none here)."""
        return {}

    def after_update(self, state: FilterState, x_post: NDArray[np.float64]) -> dict[str, Any]:
        """Extra items to keep after an update (none here)."""
        return {}

    def after_predict(self, state: FilterState, P: NDArray[np.float64]) -> dict[str, Any]:
        """Extra items to keep after a prediction to P(k+1|k) (none here; a gain freeze keeps its record)."""
        return {}

    def carried(self, diagnostics: dict[str, Any]) -> dict[str, Any]:
        """Items of the correction's diagnostics to keep in ``FilterState.extra`` for the next reading (none here;
        the noise-adaptive filter keeps its α, β)."""
        return {}

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
        R = self.R if R is None else R
        if self.correction_rule is not None:  # a composed correction strategy
            dx, P_post, diag = self.correction_rule.correct_error(self, P, H, R, innovation, x)
        else:
            dx, P_post, diag = self.correct_error(P, H, R, innovation)
        return self.inject(x, dx), P_post, diag

    # -- the step contract --------------------------------------------------------

    def _start(self, xhat0, P0, runs):
        """x̂ of every run at ``initial_internal(xhat0)``; P = P0 (the filter's default when None), one per run
        unless the covariance is shared."""
        if self.fading_rule is not None:
            self.fading_rule.check_runs(runs)
        P = self.P0 if P0 is None else as_covariance("P0", P0, self.n_cov, definite=True)
        x0 = self.initial_internal(np.asarray(xhat0, dtype=float))
        x = np.broadcast_to(x0, (runs, x0.size)).copy()
        if not self.shares_covariance or self._gate is not None:  # a gate's rejections depend on the data
            P = np.broadcast_to(P, (runs,) + P.shape).copy()
        return FilterState(x=x, P=P)

    def _update(self, state, y):
        """The one update of the Kalman core: moments of the predicted reading (the :attr:`moment_rule`),
        deferred prior, gate, correction, report."""
        x, P = state.x, state.P
        runs = x.shape[0]
        mask = available_channels(y) if self.missing == "skip" else None
        rule = self.moment_rule
        mom, y, mask, innovation = self._moments_at(rule, x, P, y, mask, state.k)
        H = mom.H
        R_k = self.measurement_covariance(y, x)
        R_full = self.R if R_k is None else R_k
        if rule.sigma_points and mask is not None and R_k is not None:
            mask = _finite_reading_R(mask, R_k)  # R(y) not finite on the channels it has: the reading is not used
        diag_prior = self.initial_diagnostics(runs)
        diag_prior.update(self.step_diagnostics(state))
        extra = {key: val for key, val in state.extra.items() if key not in self.transient_keys}
        if "PhiPPhiT" in state.extra:  # a deferred prior (defers_prior): completed with this reading
            if rule.sigma_points:  # the regression (M1) of the moments at the uncompleted prior
                H_0, _, used_0 = rule.linearisation(P, mom, R_full, innovation, mask)
            else:
                _, H_0, _, used_0 = drop_missing(P, H, R_full, innovation, mask)
            P, d_hook, e_hook = self.complete_prior(state.extra["PhiPPhiT"], state.extra["Qd"], state, used_0, H_0,
                                                    mask=mask)
            diag_prior.update(d_hook)
            extra.update(e_hook)
        if rule.sigma_points:
            if self._gate is not None:  # a run recovering from rejections: its prior inflated before the points
                P = self._gate.inflate(P, state.extra.get("gate_count"))
            if P is not state.P:  # the points redrawn from the completed (or inflated) prior
                mom, _, _, innovation = self._moments_at(rule, x, P, y, None, state.k)
        shown = mask  # the channels the reading has (a rejected channel's innovation is still reported)
        if self._gate is not None:
            if rule.sigma_points:
                P, mask, d_gate, e_gate = rule.screen(self._gate, mom, R_full, innovation, mask,
                                                      state.extra.get("gate_count"), P)
            else:
                P, mask, d_gate, e_gate = self._gate.screen(P, H, R_full, innovation, mask,
                                                            state.extra.get("gate_count"))
            diag_prior.update(d_gate)
            extra.update(e_gate)
        try:
            if rule.sigma_points:
                x_post, P_post, diag = rule.correct(self, x, P, mom, innovation, R_full, mask, state)
            elif mask is None:
                x_post, P_post, diag = self.correct(x, P, H, innovation, state, R=R_k)
            else:
                if R_k is not None:
                    mask = _finite_reading_R(mask, R_k)
                P, H_used, R_used, used = drop_missing(P, H, R_full, innovation, mask)
                x_post, P_post, diag = self.correct(x, P, H_used, used, state, R=R_used)
        except np.linalg.LinAlgError:
            if not self.refuse_nonfinite:
                raise
            x_post = P_post = np.array(np.nan)
        if self.refuse_nonfinite and not (np.all(np.isfinite(x_post)) and np.all(np.isfinite(P_post))):
            raise HinfnavError(f"filter {self.name!r} diverged at step {state.k}: its covariance or correction is not finite")
        extra.update(self.after_update(state, x_post))
        extra.update(self.carried(diag))
        diag = dict(diag_prior, **diag, innovation=innovation if shown is None else np.where(shown, innovation, np.nan))
        diag.update(self.update_diagnostics(x_post))
        new = FilterState(x=x_post, P=P_post, k=state.k, extra=dict(extra, prior=(x, P)))
        if self.output == "filtered":
            return new, StepOutput(xhat=self.report(x_post), P=self._broadcast(self.report_covariance(P_post), runs),
                                   diagnostics=diag)
        return new, StepOutput(xhat=self.report(x), P=self._broadcast(self.report_covariance(P), runs), diagnostics=diag)

    def _moments_at(self, rule, x, P, y, mask, k):
        """``(moments, y, mask, innovation)`` at the prior (x, P): a missing channel reads as predicted
        (innovation 0; removed at the correction)."""
        try:
            mom = rule.measurement_moments(self, x, P, k)
            if mask is not None:
                y, mask = fill_missing(self.measurement, y, x, mom.yhat, mask)
            innovation = self.measurement.residual(y, mom.yhat)
        except ModelFunctionError:  # a user model's own error, already naming its function
            raise
        except InputError as exc:
            raise HinfnavError(f"filter {self.name!r} stopped at step {k}: the estimate reached a singular point ({exc})") from None
        return mom, y, mask, innovation

    def _broadcast(self, P, runs):
        return np.broadcast_to(P, (runs,) + P.shape) if P.ndim == 2 else P


class ExtendedKalmanFilter(KalmanCore):
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

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "kalman"

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
        return (bool(self.measurement.linear) and self.R_of_reading is None and not self.nonlinear_dynamics
                and not self.data_dependent_covariance)

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
        return self.propagated_covariance(P, F) + self.Q

    def propagated_covariance(self, P: NDArray[np.float64], F: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """``F P Fᵀ`` without the process noise (F = Φ, or the dynamics model's Jacobian, (runs, n, n))."""
        F = self.F if F is None else F
        if F.ndim == 3:
            return F @ P @ np.swapaxes(F, -1, -2)
        return congruence(F, P)

    def observe(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(h(x̂⁻), H)``: H at one prior when the covariance is shared, else per run."""
        return self.measurement.function(x), self.measurement.jacobian(x[0] if self.shares_covariance else x)

    def process_noise(self, state: FilterState) -> tuple[NDArray[np.float64], dict[str, Any]]:
        """``(Q_d, extra)``: the process noise of the step from ``state`` (constant :attr:`Q` here)."""
        return self.Q, {}

    # -- the step contract --------------------------------------------------------

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        F = None
        t = state.k * self.dt
        if self.nonlinear_dynamics:  # the Jacobian at the posterior x̂(k|k), before the mean moves on
            F = np.asarray(self.system.jacobian(state.x, u if self.uses_input else None, t), dtype=float)
        x = self.predict_mean(state.x, u, t)
        extra = {key: val for key, val in state.extra.items() if key not in self.transient_keys}
        if self.defers_prior:  # F P Fᵀ and Q_d kept for complete_prior at the next reading
            PhiPPhiT = self.propagated_covariance(state.P, F)
            Qd, e_noise = self.process_noise(state)
            extra.update(e_noise, PhiPPhiT=PhiPPhiT, Qd=Qd)
            P = PhiPPhiT + Qd
        elif F is not None:
            P = self.predict_covariance(state.P, state, F=F)
        else:
            P = self.predict_covariance(state.P, state)
        extra.update(self.after_predict(state, P))
        return FilterState(x=x, P=P, k=state.k + 1, extra=extra)



class StrongTrackingEKF(StrongTracking, ExtendedKalmanFilter):
    """Strong-tracking EKF: :class:`ExtendedKalmanFilter` with multiple fading factors.

    On a linear system or any dynamics model; parameters of
    :class:`ExtendedKalmanFilter` and ``rho``, ``beta``, ``a`` of
    :class:`~hinfnav.estimators.adaptive.StrongTracking` ((S1)–(S4); R must
    be constant). Diagnostics ``fading`` (runs, n) and ``fading_c`` (runs,).
    """

    name = "stekf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "kalman"


class RateAdaptiveEKF(RateAdaptive, ExtendedKalmanFilter):
    """Rate-adapted process noise on :class:`ExtendedKalmanFilter` (R1)–(R2).

    On a linear system or any dynamics model; parameters of
    :class:`ExtendedKalmanFilter` and ``states``, ``memory_steps``, ``epsilon``,
    ``floor`` of :class:`~hinfnav.estimators.adaptive.RateAdaptive` (the
    diagonal entries of Q at ``states`` follow their states' estimated rate).
    Diagnostics ``q_adapted`` and ``input_rate`` (runs, len(states)).
    """

    name = "aekf_rate"
