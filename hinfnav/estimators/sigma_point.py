"""Sigma-point (unscented / cubature) Kalman filter on the step contract, batched over runs.

The filter carries the mean x̂ and covariance P of every run and replaces
the EKF's linearisations by the unscented transform: a set of sigma points
χ_i with weights W_i^m, W_i^c is drawn from (x̂, P), pushed through the
dynamics or measurement model, and their weighted mean and covariance are
those of the transformed variable. All runs' sigma points go through the
model in one call.

**Sigma points** (van der Merwe's scaled set; filterpy's ``MerweScaledSigmaPoints``):
with ``λ = α² (n + κ) − n`` and ``L Lᵀ = (n + λ) P`` (Cholesky),

* ``χ₀ = x̂``, ``χ_i = x̂ + L_{:,i}``, ``χ_{n+i} = x̂ − L_{:,i}`` (i = 1…n)   (U1)
* ``W₀^m = λ/(n+λ)``, ``W₀^c = W₀^m + 1 − α² + β``, ``W_i^m = W_i^c = 1/(2(n+λ))``   (U2)

The **cubature rule** (Arasaratnam & Haykin, IEEE TAC 54(6), 2009) is the
2n points ``x̂ ± √n L̃_{:,i}`` (``L̃ L̃ᵀ = P``) with equal weights 1/(2n) (U3)
(the scaled set with α = 1, β = 0, κ = 0 has the same points and a zero-weight
centre).

**Predict** (additive process noise): χ from (x̂(k|k), P(k|k)), ``χ⁻_i = f(χ_i, u_k, t_k)``,
``x̂⁻ = Σ W_i^m χ⁻_i``, ``P⁻ = Σ W_i^c (χ⁻_i − x̂⁻)(χ⁻_i − x̂⁻)ᵀ + Q``   (U4).

**Update** (additive measurement noise): χ redrawn from (x̂⁻, P⁻) (as filterpy
2.0 does after its predict), ``Y_i = h(χ_i)``, their mean
``ȳ = h(x̂⁻) + Σ W_i^m r(Y_i, h(x̂⁻))`` with r the measurement's ``residual``
(angles wrapped: a mean of angles that is correct across ±π, and the weighted
mean of the Y_i when nothing wraps), ``S = Σ W_i^c r(Y_i, ȳ) r(Y_i, ȳ)ᵀ + R``,
``P_xy = Σ W_i^c (χ_i − x̂⁻) r(Y_i, ȳ)ᵀ``, ``K = P_xy S⁻¹``, ``ν = r(y, ȳ)``,
``x̂ = x̂⁻ + K ν``, ``P = P⁻ − K S Kᵀ`` (symmetrised)   (U5).

The dynamics may be any model of :mod:`hinfnav.systems.dynamics` or a
:class:`~hinfnav.systems.LinearSystem` (on which, with a linear measurement,
the filter equals the Kalman filter: the transform is exact for linear maps).

**Quaternion states** (a state spec with its own ``error``, e.g.
:class:`~hinfnav.systems.attitude.AttitudeSystem`'s ``[q, ω, T]``): the
sigma points and P live in the error coordinates (δθ, δω, δT) (dimension
``state.n``, 9), as in the attitude EKF (Lefferts, Markley & Shuster 1982):
``χ_i = x̂ ⊞ δ_i`` with the system's ``inject`` (``q ← δq(δθ) ⊗ q``), the
propagated points are compared with the propagated centre χ⁻₀ by the inverse
map ``χ ⊟ χ⁻₀ = (rotvec(q ⊗ q₀⁻¹), ω − ω₀, T − T₀)``, and
``x̂⁻ = χ⁻₀ ⊞ Σ W_i^m (χ⁻_i ⊟ χ⁻₀)``, ``P⁻ = Σ W_i^c (d_i − d̄)(d_i − d̄)ᵀ + Q``
(U6) (a USQUE-type filter, Crassidis & Markley, JGCD 26(4), 2003, with the
rotation vector as attitude error). Q must then be given, per step, in error
coordinates (e.g. ``Δt Γ Q_c Γᵀ``).

Diagnostics at each step: ``innovation`` ν (runs, m) and
``innovation_covariance`` S (runs, m, m).

**On the Kalman core.** The transform is a *moment rule* (:class:`SigmaPointRule`,
:mod:`hinfnav.estimators.moments`): :class:`SigmaPointFilter` is
:class:`~hinfnav.estimators.kalman.KalmanCore` with this rule for its prediction (U4)/(U6) and for the moments
of the predicted reading (U5); the core does the rest (missing channels, the χ² gate, the deferred prior, the
report). So the ideas of the core apply to it as they are: Huber's correction and strong tracking's fading
(:func:`~hinfnav.estimators.strategies.compose`) read (U5)'s moments through the statistical linearisation (M1).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import HinfnavError, InputError, ModelFunctionError
from ..core.linalg import as_covariance, inv_spd
from ..core.validation import as_choice, as_nonnegative, as_positive, as_real, as_vector
from ..systems.attitude import quat_conjugate, quat_multiply, rotvec_from_quat
from ..systems.state import StateSpec
from .base import FilterState
from .correction import KalmanCorrection
from .kalman import OUTPUTS, ExtendedKalmanFilter, KalmanCore
from .moments import Moments, statistical_linearisation

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["RULES", "SigmaPointFilter", "SigmaPointRule", "merwe_weights", "sigma_points"]

#: Sigma-point rules: van der Merwe's scaled unscented set, or the spherical-radial cubature rule.
RULES = ("unscented", "cubature")


def merwe_weights(n, alpha, beta, kappa):
    """Scale and weights of (U2): ``(n + λ, W^m, W^c)``, each weight array of length 2n + 1."""
    lam = alpha * alpha * (n + kappa) - n
    if not n + lam > 0:
        raise InputError(f"alpha and kappa give n + λ = α²(n + κ) = {n + lam:g} <= 0; increase alpha or kappa")
    Wm = np.full(2 * n + 1, 0.5 / (n + lam))
    Wc = Wm.copy()
    Wm[0] = lam / (n + lam)
    Wc[0] = lam / (n + lam) + 1.0 - alpha * alpha + beta
    return n + lam, Wm, Wc


def sigma_points(x, P, scale, center=True):
    """Sigma points (U1)/(U3) of a batch: ``x`` (runs, n), ``P`` (runs, n, n) → (runs, 2n(+1), n).

    ``x ± L_{:,i}`` with ``L Lᵀ = scale · P``; the centre x first when ``center``.
    Raises ``numpy.linalg.LinAlgError`` if a P is not positive definite.
    """
    L = np.linalg.cholesky(scale * P)
    offsets = np.swapaxes(L, -1, -2)  # row i = column i of L
    parts = ([x[:, None, :]] if center else []) + [x[:, None, :] + offsets, x[:, None, :] - offsets]
    return np.concatenate(parts, axis=1)


def _without(mask, dY, R_k, innovation):
    """``(dY, R, ν)`` with the channels ``~mask`` removed exactly, as drop_missing does for the Kalman
    correction: their output deviations and innovation zeroed, their rows and columns of R decoupled (S block
    diagonal, K's column 0), so the rest of the update is the filter's without them (mask None: all kept)."""
    if mask is None:
        return dY, R_k, innovation
    both = mask[:, :, None] & mask[:, None, :]
    return (np.where(mask[:, None, :], dY, 0.0), np.where(both, R_k, 0.0) + np.eye(R_k.shape[-1]) * ~mask[:, None, :],
            np.where(mask, innovation, 0.0))


class SigmaPointRule:
    """The sigma-point moment rule: (U1)–(U3) points, (U4)/(U6) prediction, (U5) moments of the reading.

    Parameters
    ----------
    n : int
        Dimension of the covariance (the error coordinates).
    rule : {"unscented", "cubature"}
    alpha, beta, kappa : float
        Of the scaled unscented set (U2) (see :class:`SigmaPointFilter`).
    """

    #: The moments are drawn from P⁻ (the core redraws them from a completed or inflated prior)
    sigma_points = True

    def __init__(self, n: int, rule: str = "unscented", alpha: float = 1.0, beta: float = 2.0, kappa: float = 0.0) -> None:
        self.rule = as_choice("rule", rule, RULES)
        self.alpha, self.beta, self.kappa = as_positive("alpha", alpha), as_nonnegative("beta", beta), as_real("kappa", kappa)
        if self.rule == "unscented":
            self.scale, self.Wm, self.Wc = merwe_weights(n, self.alpha, self.beta, self.kappa)
        else:
            self.scale, self.Wm = float(n), np.full(2 * n, 0.5 / n)
            self.Wc = self.Wm

    @property
    def name(self) -> str:
        return self.rule

    def __repr__(self) -> str:
        return f"SigmaPointRule({self.rule!r}, alpha={self.alpha}, beta={self.beta}, kappa={self.kappa})"

    # -- the transform ----------------------------------------------------------------

    def points(self, core, P, k, what):
        """Sigma-point offsets (runs, N, n_cov) of covariances P: (U1)/(U3) about zero."""
        try:
            return sigma_points(np.zeros(P.shape[:-1]), P, self.scale, center=self.rule == "unscented")
        except np.linalg.LinAlgError:
            raise HinfnavError(f"filter {core.name!r} stopped at step {k}: the {what} covariance is not positive "
                               "definite (no sigma points)") from None

    def mean_deviations(self, X):
        """Weighted mean and deviations of state sigma points X (runs, N, n)."""
        mean = self.Wm @ X
        return mean, X - mean[:, None, :]

    def cov(self, A, B):
        """``Σ W_i^c A_i B_iᵀ`` for deviations A (runs, N, a), B (runs, N, b)."""
        return np.swapaxes(A * self.Wc[:, None], -1, -2) @ B

    def outputs(self, core, X, x, k):
        """``(ȳ, dY)``: the weighted mean (runs, m) of h at the sigma points X (runs, N, n) and their deviations.

        The mean is taken about ``h(x̂⁻)`` (the first point for the unscented rule). A measurement function
        that refuses a point (InputError) stops the filter with a HinfnavError naming step ``k``.
        """
        runs, N, n = X.shape
        meas = core.measurement
        try:
            Y = meas.function(X.reshape(runs * N, n)).reshape(runs, N, -1)
            ref = Y[:, 0] if self.rule == "unscented" else meas.function(x)  # h(x̂⁻)
        except ModelFunctionError:  # a user model's own error, already naming its function
            raise
        except InputError as exc:
            raise HinfnavError(f"filter {core.name!r} stopped at step {k}: a sigma point reached a singular "
                               f"point of the measurement ({exc})") from None
        # differences of predicted outputs: the model's residual (angles wrapped), except for a converted
        # measurement, whose residual converts a reading (its predicted outputs are positions: plain differences)
        diff = np.subtract if hasattr(meas, "convert") else meas.residual
        y_mean = ref + self.Wm @ diff(Y, ref[:, None, :])
        return y_mean, diff(Y, y_mean[:, None, :])

    # -- the rule's two uses by the core -------------------------------------------------

    def measurement_moments(self, core, x, P, k):
        """``Moments(ȳ, None, dX, dY)`` of the reading at the prior (x (runs, n_x), P (runs, n, n)) (U5)."""
        dX = self.points(core, P, k, "prior")
        X = core.inject(x[:, None, :], dX)
        y_mean, dY = self.outputs(core, X, x, k)
        return Moments(y_mean, None, dX, dY)

    def predict(self, core, state, u):
        """(U4), or (U6) in error coordinates: the prior of the next step (``P⁻ = Σ W^c dX dXᵀ + Q``; its two
        terms kept for the next reading when the core ``defers_prior``)."""
        if core.uses_input and u is None:
            raise InputError(f"filter {core.name!r} uses the applied input: predict needs u")
        runs, n = state.x.shape
        X = core.inject(state.x[:, None, :], self.points(core, state.P, state.k, "posterior"))
        N = X.shape[1]
        uu = None
        if core.uses_input:
            u = np.asarray(u, dtype=float)
            uu = np.repeat(u, N, axis=0)
        t = state.k * core.dt
        Xf = core.propagate_points(X.reshape(runs * N, n), uu, t).reshape(runs, N, n)
        if not core.error_coordinates:
            x, dX = self.mean_deviations(Xf)
        else:  # (U6): deviations about the propagated centre, their weighted mean injected
            ref = Xf[:, 0] if self.rule == "unscented" else core.propagate_points(state.x, u, t)
            D = core.difference(Xf, ref[:, None, :])
            mean = self.Wm @ D
            x, dX = core.inject(ref, mean), D - mean[:, None, :]
        extra = {key: val for key, val in state.extra.items() if key not in core.transient_keys}
        PhiPPhiT = self.cov(dX, dX)
        if core.defers_prior:  # Σ W^c dX dXᵀ and Q_d kept for complete_prior at the next reading
            Qd, e_noise = core.process_noise(state)
            extra.update(e_noise, PhiPPhiT=PhiPPhiT, Qd=Qd)
            P = PhiPPhiT + Qd
        else:
            P = PhiPPhiT + core.Q
        return FilterState(x=x, P=P, k=state.k + 1, extra=extra)

    def linearisation(self, P, mom, R, innovation, mask):
        """``(H̃, R̃, ν)`` of (M1) with the channels ``~mask`` removed, from the moments at the prior P."""
        dY, R_u, nu = _without(mask, mom.dY, R, innovation)
        S = self.cov(dY, dY) + R_u
        H, R_eff = statistical_linearisation(P, self.cov(mom.dX, dY), S)
        return H, R_eff, nu

    def screen(self, gate, mom, R, innovation, mask, count, P):
        """The χ² gate on (U5)'s S (the prior P already inflated); returns ``(P, mask, diagnostics, extra)`` as
        :meth:`~hinfnav.estimators.gate.ChiSquareGate.screen`."""
        dY, R_u, nu = _without(mask, mom.dY, R, innovation)
        S = self.cov(dY, dY) + R_u
        avail = np.ones(innovation.shape, dtype=bool) if mask is None else mask
        rejected, d_gate, new_count = gate.decide(S, nu, avail, count)
        if rejected.any():
            mask = avail & ~rejected
        return P, mask, d_gate, {"gate_count": new_count}

    def correct(self, core, x, P, mom, innovation, R, mask, state):
        """``(x⁺, P⁺, diagnostics)``: (U5) ``K = P_xy S⁻¹``, ``P⁺ = P⁻ − K S Kᵀ`` for the plain Kalman
        correction; any other correction (a composed strategy, a class's own ``correct_error``) on the
        statistical linearisation (M1) of the same moments."""
        dY, R_u, nu = _without(mask, mom.dY, R, innovation)
        S = self.cov(dY, dY) + R_u
        Pxy = self.cov(mom.dX, dY)
        if core.correction_rule is not None or type(core).correct_error is not KalmanCorrection.correct_error:
            H, R_eff = statistical_linearisation(P, Pxy, S)
            return core.correct(x, P, H, nu, state, R=R_eff)
        K = Pxy @ inv_spd(S)
        x_post = core.inject(x, (K @ nu[:, :, None])[:, :, 0])
        P_post = P - K @ S @ np.swapaxes(K, -1, -2)
        return x_post, 0.5 * (P_post + np.swapaxes(P_post, -1, -2)), {"innovation_covariance": S}


class SigmaPointFilter(KalmanCore):
    """Unscented (or cubature) Kalman filter of any dynamics and measurement model (see the module docstring):
    the Kalman core with the sigma-point moment rule (:class:`SigmaPointRule`).

    Parameters
    ----------
    system : LinearSystem or dynamics model
        ``f``, ``n``, ``dt``, ``state``, ``Q`` (see :mod:`hinfnav.systems.dynamics`).
    measurement : MeasurementModel
        h, R, residual (angles wrapped); a model with ``noise_covariance(y)``
        (a converted measurement) gives R_k per reading.
    P0 : array_like, shape (n, n)
        Default initial covariance (positive definite).
    Q : array_like, shape (n, n), optional
        Process-noise covariance per step (default the system's).
    R : array_like, shape (m, m), optional
        Measurement-noise covariance (default the measurement's).
    rule : {"unscented", "cubature"}
    alpha, beta, kappa : float
        Parameters of the scaled unscented set (U2), as filterpy's
        ``MerweScaledSigmaPoints(n, alpha, beta, kappa)``: 0 < α (spread,
        1 by default: the points at ±√(n+κ) σ), β ≥ 0 (2: optimal for a
        Gaussian prior), κ (0). Ignored by the cubature rule.
    uses_input : bool
        Propagate with the applied input u (True), or with none.
    output : {"filtered", "predicted"}
    name : str
    """

    name = "ukf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "sigma_point"
    #: P⁺ = P⁻ − K S Kᵀ symmetrised (U5)
    symmetric_posterior = True

    def __init__(self, system: LinearSystem | DynamicsModel, measurement: MeasurementModel, *, P0: ArrayLike, Q: ArrayLike | None = None,
                 R: ArrayLike | None = None, rule: str = "unscented", alpha: float = 1.0, beta: float = 2.0, kappa: float = 0.0,
                 uses_input: bool = False, output: str = "filtered", name: str | None = None,
                 missing: str = "refuse") -> None:
        super().__init__(system, measurement, name=name, missing=missing)
        #: True for a state with its own error (a quaternion): sigma points in error coordinates (U6)
        self.error_coordinates = type(system.state).error is not StateSpec.error
        if self.error_coordinates:
            if not (hasattr(system, "inject") and hasattr(system, "predict_mean")):
                raise InputError(f"the state of this system ({type(system.state).__name__}) has its own error: the "
                                 "system must give inject(x, dx) and predict_mean(x, u) (as AttitudeSystem does)")
            if Q is None:
                raise InputError("Q (process noise per step, in error coordinates) must be given for this system")
        elif not hasattr(system, "f"):
            raise InputError(f"system must be a dynamics model with f(x, u, t) (or a LinearSystem); "
                             f"got {type(system).__name__}")
        n, m = system.state.n, measurement.n_meas  # n: the error coordinates (the covariance's dimension)
        self.n_cov = n
        self.Q = as_covariance("Q", system.Q if Q is None else Q, n, definite=False)
        self.R_of_reading = getattr(measurement, "noise_covariance", None) if R is None else None
        self.R = (None if self.R_of_reading is not None
                  else as_covariance("R", measurement.R if R is None else R, m, definite=True))
        self.P0 = as_covariance("P0", P0, n, definite=True)
        self.moment_rule = SigmaPointRule(n, rule, alpha, beta, kappa)
        if not isinstance(uses_input, (bool, np.bool_)):
            raise InputError(f"uses_input must be True or False; got {uses_input!r}")
        self.uses_input = bool(uses_input)
        self.output = as_choice("output", output, OUTPUTS)

    # the rule's parameters, read by the compiled kernel, the square-root form and the smoothers

    @property
    def rule(self) -> str:
        """The sigma-point rule, "unscented" or "cubature"."""
        return self.moment_rule.rule

    @property
    def alpha(self) -> float:
        """α of (U2)."""
        return self.moment_rule.alpha

    @property
    def beta(self) -> float:
        """β of (U2)."""
        return self.moment_rule.beta

    @property
    def kappa(self) -> float:
        """κ of (U2)."""
        return self.moment_rule.kappa

    @property
    def scale(self) -> float:
        """n + λ of (U1) (n for the cubature rule)."""
        return self.moment_rule.scale

    @property
    def Wm(self) -> NDArray[np.float64]:
        """Mean weights W^m of (U2)."""
        return self.moment_rule.Wm

    @property
    def Wc(self) -> NDArray[np.float64]:
        """Covariance weights W^c of (U2)."""
        return self.moment_rule.Wc

    @property
    def shares_covariance(self) -> bool:
        """False: every run carries its own covariance (its sigma points depend on its estimate)."""
        return False

    @classmethod
    def from_ekf(cls, ekf: ExtendedKalmanFilter, *, name: str | None = None, **options: Any) -> SigmaPointFilter:
        """The sigma-point version of an :class:`~hinfnav.estimators.ExtendedKalmanFilter`.

        Same system, measurement, P₀, Q, R (or reading-dependent R), input use
        and output; ``options`` are the rule's (``rule``, ``alpha``, ``beta``, ``kappa``).
        """
        if not isinstance(ekf, ExtendedKalmanFilter):
            raise InputError(f"ekf must be a hinfnav ExtendedKalmanFilter; got {type(ekf).__name__}")
        return cls(ekf.system, ekf.measurement, P0=ekf.P0, Q=ekf.Q, R=ekf.R, uses_input=ekf.uses_input,
                   output=ekf.output, name=name if name is not None else "ukf", **options)

    # -- model hooks of the core ---------------------------------------------------------

    def inject(self, x: NDArray[np.float64], dx: NDArray[np.float64]) -> NDArray[np.float64]:
        """``x ⊞ δx``: x + δx, or the system's injection (``q ← δq(δθ) ⊗ q``, the rest added)."""
        return x + dx if not self.error_coordinates else self.system.inject(np.broadcast_to(x, dx.shape[:-1] + x.shape[-1:]), dx)

    def initial_internal(self, xhat0: NDArray[np.float64]) -> NDArray[np.float64]:
        """The prior estimate, normalised by the system's injection of a zero correction (a unit quaternion)."""
        x = as_vector("xhat0", xhat0, self.n_state)
        return self.inject(x[None, :], np.zeros((1, self.n_cov)))[0] if self.error_coordinates else x

    def difference(self, x: NDArray[np.float64], ref: NDArray[np.float64]) -> NDArray[np.float64]:
        """``x ⊟ ref``, the inverse of :meth:`inject`: x − ref, or (U6) for a quaternion-first state."""
        if not self.error_coordinates:
            return x - ref
        ref = np.broadcast_to(ref, x.shape)
        dq = quat_multiply(x[..., :4], quat_conjugate(ref[..., :4]))
        return np.concatenate([rotvec_from_quat(dq), x[..., 4:] - ref[..., 4:]], axis=-1)

    def propagate_points(self, X: NDArray[np.float64], u: NDArray[np.float64] | None, t: float) -> NDArray[np.float64]:
        """The dynamics at points X (a batch of states): ``f(X, u, t)``, or the system's ``predict_mean``."""
        if self.error_coordinates:
            return np.asarray(self.system.predict_mean(X, u))
        return np.asarray(self.system.f(X, u, t))

    def process_noise(self, state: FilterState) -> tuple[np.ndarray, dict[str, Any]]:
        """``(Q_d, extra)``: the constant :attr:`Q` (the additive process noise of (U4))."""
        return self.Q, {}

    # -- the transform, for the square-root form and the smoothers -----------------------------

    def _points(self, P, k, what):
        return self.moment_rule.points(self, P, k, what)

    def _moments(self, X):
        return self.moment_rule.mean_deviations(X)

    def _cov(self, A, B):
        return self.moment_rule.cov(A, B)

    def _propagate(self, X, u, t):
        return self.propagate_points(X, u, t)

    def _predicted_outputs(self, X, x, k):
        return self.moment_rule.outputs(self, X, x, k)

    # -- the step contract -------------------------------------------------------------

    def _predict(self, state, u):
        return self.moment_rule.predict(self, state, u)
