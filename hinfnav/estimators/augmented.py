"""One EKF with augmented random-walk states, and its use on a linear system with unknown inputs.

:class:`AugmentedEKF` is the EKF shared by paper 002's three filters (AEKF,
ASTEKF, AAEKF) and by their transfer to the chaser. It works in *error
coordinates* (dimension ``n_cov``, the covariance's), whose last ``n_aug``
coordinates are augmented states β with ``β̇ = n_β``, E[n_β n_βᵀ] = Q δ(t−τ):

* prediction  ``x̂(k+1|k) = f(x̂(k|k), u_k)``,
  ``P(k+1|k) = Φ P Φᵀ + Q_d``, ``Q_d = Q_base + Δt Γ Q Γᵀ``   (E1)
  (paper 002: Φ = e^{FΔt}, P⁻ = ΦPΦᵀ + ΔtΓQΓᵀ);
* update (Joseph form) ``K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹``, ``δx = K γ``,
  ``P = (I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ``, x̂ ← inject(x̂⁻, δx)   (E2).

It is a :class:`~hinfnav.estimators.kalman.KalmanCore`: the update (E2),
the deferred prior, the missing channels and the report are the core's one
``_update``, shared with :class:`~hinfnav.estimators.ExtendedKalmanFilter`;
this class supplies the prediction (E1) in error coordinates.
A subclass supplies the model (hooks ``initial_internal``, ``propagate_mean``,
``transition``, ``observe``, ``inject``, ``report``, ``report_covariance``,
``augmented``); the ideas of :mod:`hinfnav.estimators.adaptive` override
``complete_prior`` (strong tracking; the same hook as on
:class:`~hinfnav.estimators.ExtendedKalmanFilter`) or ``process_noise``
(adaptive).

:class:`AugmentedInputKF` wraps a :class:`~hinfnav.systems.LinearSystem`
``x(k+1) = Φ x + Γ u + B w`` whose input u is *unknown* to the filter and is
estimated as random-walk states: ``[x; u](k+1) = [[Φ, Γ], [0, I]] [x; u]``.
It reports the system's state (so it fits the system's scenarios and the
contract suite); the input estimate is in the diagnostics
(``input_estimate``). With a linear measurement and no data-dependent idea,
its covariance is shared by every run.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import as_covariance, congruence
from ..core.validation import as_choice
from .adaptive import RateAdaptive, StrongTracking
from .base import FilterState
from .huber_filter import HuberCorrection
from .kalman import OUTPUTS, KalmanCore

if TYPE_CHECKING:
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["AugmentedEKF", "AugmentedInputAdaptiveKF", "AugmentedInputHuberSTKF", "AugmentedInputKF",
           "AugmentedInputSTKF"]


class AugmentedEKF(KalmanCore):
    """EKF in error coordinates with augmented random-walk states (E1)–(E2); see the module docstring.

    Parameters
    ----------
    system, measurement
        The model (the subclass reads what it needs).
    n_cov : int
        Dimension of the error coordinates (and of P).
    aug_input : ndarray, shape (n_cov, n_aug)
        Γ: how the augmented states' noise enters the error coordinates.
    P0 : array_like, shape (n_cov, n_cov)
        Default initial covariance (positive definite).
    Q : array_like, shape (n_aug, n_aug) or (runs, n_aug, n_aug)
        Noise density of the augmented states (unit²/s), applied as Δt Γ Q Γᵀ.
        With a leading axis, one density per run (a parameter sweep batched
        as runs): the filter then runs exactly that many runs.
    base_noise : array_like, shape (n_cov, n_cov), optional
        Per-step process noise of the other coordinates (zero).
    R : array_like, optional
        Measurement covariance (default the model's D Dᵀ).
    uses_input : bool
    output : {"filtered", "predicted"}
    name : str
    missing : {"refuse", "skip"}
        A NaN channel: an InputError, or removed exactly at that step
        (:func:`~hinfnav.estimators.correction.drop_missing`).
    """

    name = "augmented ekf"
    linear_model = False
    defers_prior = True
    refuse_nonfinite = True

    def __init__(self, system: Any, measurement: MeasurementModel, *, n_cov: int, aug_input: int, P0: ArrayLike,
                 Q: ArrayLike, base_noise: ArrayLike | None = None, R: ArrayLike | None = None, uses_input: bool = False,
                 output: str = "filtered", name: str | None = None, missing: str = "refuse") -> None:
        super().__init__(system, measurement, name=name, missing=missing)
        self.n_cov = int(n_cov)
        self.E = np.asarray(aug_input, dtype=float)
        if self.E.ndim != 2 or self.E.shape[0] != self.n_cov:
            raise InputError(f"aug_input must have shape ({self.n_cov}, n_aug); got {self.E.shape}")
        self.n_aug = self.E.shape[1]
        Q = np.asarray(Q, dtype=float)
        if Q.ndim == 3:
            self.Q = np.stack([as_covariance(f"Q[{i}]", Qi, self.n_aug, definite=False) for i, Qi in enumerate(Q)])
            self.Q.setflags(write=False)
        else:
            self.Q = as_covariance("Q", Q, self.n_aug, definite=False)
        self.base_noise = (np.zeros((self.n_cov, self.n_cov)) if base_noise is None
                           else as_covariance("base_noise", base_noise, self.n_cov, definite=False))
        self.R = as_covariance("R", measurement.R if R is None else R, measurement.n_meas, definite=True)
        self.P0 = as_covariance("P0", P0, self.n_cov, definite=True)
        if not isinstance(uses_input, (bool, np.bool_)):
            raise InputError(f"uses_input must be True or False; got {uses_input!r}")
        self.uses_input = bool(uses_input)
        self.output = as_choice("output", output, OUTPUTS)
        self.Qd = self.base_noise + self.dt * self.E @ self.Q @ self.E.T

    @property
    def parameter_runs(self) -> int | None:
        """Number of runs a per-run parameter fixes (Q, or an idea's ρ, β, ε), or None."""
        sizes = {self.Q.shape[0]} if self.Q.ndim == 3 else set()
        for key in ("rho", "beta", "epsilon"):
            val = getattr(self, key, None)
            if isinstance(val, np.ndarray):
                sizes.add(val.size)
        if len(sizes) > 1:
            raise InputError(f"per-run parameters must all have the same number of runs; got {sorted(sizes)}")
        return sizes.pop() if sizes else None

    @property
    def shares_covariance(self) -> bool:
        """True when P and the gain do not depend on the data (linear model, no adaptive idea, one Q)."""
        return self.linear_model and not self.data_dependent_covariance and self.parameter_runs is None

    # -- model hooks (subclasses) ------------------------------------------------

    def initial_internal(self, xhat0: NDArray[np.float64]) -> NDArray[np.float64]:
        """Internal state from the reported prior estimate, shape (n_x,)."""
        raise NotImplementedError

    def propagate_mean(self, x: NDArray[np.float64], u: NDArray[np.float64] | None) -> NDArray[np.float64]:
        """``f(x̂, u)`` for a batch, shape (runs, n_x)."""
        raise NotImplementedError

    def transition(self, x: NDArray[np.float64], u: NDArray[np.float64] | None) -> NDArray[np.float64]:
        """Φ of the error coordinates at the posterior, (n_cov, n_cov) or (runs, n_cov, n_cov)."""
        raise NotImplementedError

    def inject(self, x: NDArray[np.float64], dx: NDArray[np.float64]) -> NDArray[np.float64]:
        """The internal state corrected by ``dx`` (error coordinates)."""
        raise NotImplementedError

    def report(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The estimate reported in the system's coordinates, (runs, system.n)."""
        raise NotImplementedError

    def augmented(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The augmented states' estimate, (runs, n_aug)."""
        raise NotImplementedError

    # -- idea hooks (see hinfnav.estimators.adaptive) ---------------------------------

    def process_noise(self, state: FilterState) -> tuple[NDArray[np.float64], dict[str, Any]]:
        """``(Q_d, extra)`` for the step from ``state`` (E1); constant here."""
        return self.Qd, {}

    def update_diagnostics(self, x_post: NDArray[np.float64]) -> dict[str, Any]:
        """The augmented states' estimate after the update, ``input_estimate`` (runs, n_aug)."""
        return {"input_estimate": self.augmented(x_post)}

    # -- the step contract ---------------------------------------------------------------

    def _start(self, xhat0, P0, runs):
        if self.parameter_runs is not None and runs != self.parameter_runs:
            raise InputError(f"runs must equal the number of per-run parameter values ({self.parameter_runs}); got {runs}")
        return super()._start(xhat0, P0, runs)

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        Qd, e_noise = self.process_noise(state)
        Phi = self.transition(state.x, u)
        x = self.propagate_mean(state.x, u)
        PhiPPhiT = congruence(Phi, state.P)
        extra = {k: v for k, v in state.extra.items() if k not in self.transient_keys}
        extra.update(e_noise, PhiPPhiT=PhiPPhiT, Qd=Qd)
        return FilterState(x=x, P=PhiPPhiT + Qd, k=state.k + 1, extra=extra)


class AugmentedInputKF(AugmentedEKF):
    """Kalman filter of a linear system whose unknown input is estimated as random-walk states.

    Parameters
    ----------
    system : LinearSystem
        Φ, Γ (the unknown input u enters through Γ), B (Q = B Bᵀ), dt, state.
    measurement : MeasurementModel
        On the system's n states (linear or not).
    Q_input : array_like, shape (m_u, m_u)
        Noise density of the input's random walk, (input unit)²/s; per step
        Δt Q_input.
    P0 : array_like, shape (n, n) or (n + m_u, n + m_u)
        Initial covariance of the state (then ``P0_input`` completes it) or of
        the augmented state.
    P0_input : array_like, shape (m_u, m_u), optional
        Initial covariance of the input estimate (required with an n × n P0).
    Q : array_like, shape (n, n), optional
        State process noise per step (default ``system.Q``).
    R, output, name
        As in :class:`AugmentedEKF`.

    Notes
    -----
    The input u_k is held over [t_k, t_{k+1}) as in the truth, so the
    augmented model ``x(k+1) = Φ x + Γ û`` is exact for a constant input; the
    filter is not told the applied input (``uses_input`` is False).
    """

    name = "augmented input kf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "augmented"

    def __init__(self, system: LinearSystem, measurement: MeasurementModel, *, Q_input: ArrayLike, P0: ArrayLike,
                 P0_input: ArrayLike | None = None, Q: ArrayLike | None = None, R: ArrayLike | None = None, output: str = "filtered",
                 name: str | None = None, missing: str = "refuse") -> None:
        for attr in ("Phi", "Gamma"):
            if not hasattr(system, attr):
                raise InputError(f"system must be a hinfnav LinearSystem (with Phi, Gamma); got {type(system).__name__}")
        n, m = system.n, system.n_input
        if m < 1:
            raise InputError("system has no input channel to estimate (Gamma has no columns)")
        P0 = np.asarray(P0, dtype=float)
        if P0.shape == (n, n):
            if P0_input is None:
                raise InputError(f"P0_input (initial covariance of the input estimate, {m}x{m}) is required with an {n}x{n} P0")
            P0 = np.block([[P0, np.zeros((n, m))], [np.zeros((m, n)), np.asarray(P0_input, dtype=float)]])
        base = np.zeros((n + m, n + m))
        base[:n, :n] = as_covariance("Q", system.Q if Q is None else Q, n, definite=False)
        E = np.vstack([np.zeros((n, m)), np.eye(m)])
        super().__init__(system, measurement, n_cov=n + m, aug_input=E, P0=P0, Q=Q_input, base_noise=base, R=R,
                         uses_input=False, output=output, name=name, missing=missing)
        self.Phi_a = np.block([[system.Phi, system.Gamma], [np.zeros((m, n)), np.eye(m)]])
        self._n = n
        self.linear_model = bool(measurement.linear)
        if self.linear_model:
            self._H = np.hstack([measurement.H, np.zeros((measurement.n_meas, m))])

    def initial_internal(self, xhat0: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.concatenate([xhat0, np.zeros(self.n_aug)])

    def propagate_mean(self, x: NDArray[np.float64], u: NDArray[np.float64] | None) -> NDArray[np.float64]:
        return x @ self.Phi_a.T

    def transition(self, x: NDArray[np.float64], u: NDArray[np.float64] | None) -> NDArray[np.float64]:
        return self.Phi_a

    def observe(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        xs = x[:, : self._n]
        yhat = self.measurement.function(xs)
        if self.linear_model:
            return yhat, self._H
        J = self.measurement.jacobian(xs)
        return yhat, np.concatenate([J, np.zeros(J.shape[:-1] + (self.n_aug,))], axis=-1)

    def inject(self, x: NDArray[np.float64], dx: NDArray[np.float64]) -> NDArray[np.float64]:
        return x + dx

    def report(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        return x[:, : self._n]

    def report_covariance(self, P: NDArray[np.float64]) -> NDArray[np.float64]:
        return P[..., : self._n, : self._n]

    def augmented(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        return x[:, self._n:]

    @property
    def H_augmented(self) -> np.ndarray | None:
        """``[H 0]``, the measurement matrix on the augmented state (a linear measurement), else None."""
        return getattr(self, "_H", None)


class AugmentedInputSTKF(StrongTracking, AugmentedInputKF):
    """:class:`AugmentedInputKF` with strong tracking (fading factors; ``rho``, ``beta``, ``a``)."""

    name = "augmented input stkf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "augmented"


class AugmentedInputAdaptiveKF(RateAdaptive, AugmentedInputKF):
    """:class:`AugmentedInputKF` whose input noise follows the input's estimated rate (``memory_steps``, ``epsilon``, ``floor``)."""

    name = "augmented input adaptive kf"


class AugmentedInputHuberSTKF(HuberCorrection, StrongTracking, AugmentedInputKF):
    """Huber × strong tracking: :class:`AugmentedInputSTKF` whose correction is Huber's M-estimation.

    Extra parameters ``gamma``, ``tol``, ``max_iter``
    (:class:`~hinfnav.estimators.huber_filter.HuberCorrection`) and ``rho``,
    ``beta``, ``a`` (:class:`~hinfnav.estimators.adaptive.StrongTracking`).
    """

    name = "augmented input huber stkf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "augmented"
