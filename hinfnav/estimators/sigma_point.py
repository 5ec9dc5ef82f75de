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
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import HinfnavError, InputError, ModelFunctionError
from ..core.linalg import as_covariance, inv_spd
from ..core.validation import as_choice, as_nonnegative, as_positive, as_real, as_vector
from ..systems.attitude import quat_conjugate, quat_multiply, rotvec_from_quat
from ..systems.state import StateSpec
from .base import Estimator, FilterState, StepOutput, available_channels, fill_missing
from .gate import GateOption
from .kalman import OUTPUTS, ExtendedKalmanFilter

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["RULES", "SigmaPointFilter", "merwe_weights", "sigma_points"]

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


class SigmaPointFilter(GateOption, Estimator):
    """Unscented (or cubature) Kalman filter of any dynamics and measurement model (see the module docstring).

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
        self.rule = as_choice("rule", rule, RULES)
        self.alpha, self.beta, self.kappa = as_positive("alpha", alpha), as_nonnegative("beta", beta), as_real("kappa", kappa)
        if self.rule == "unscented":
            self.scale, self.Wm, self.Wc = merwe_weights(n, self.alpha, self.beta, self.kappa)
        else:
            self.scale, self.Wm = float(n), np.full(2 * n, 0.5 / n)
            self.Wc = self.Wm
        if not isinstance(uses_input, (bool, np.bool_)):
            raise InputError(f"uses_input must be True or False; got {uses_input!r}")
        self.uses_input = bool(uses_input)
        self.output = as_choice("output", output, OUTPUTS)

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

    # -- the transform -------------------------------------------------------------

    def _points(self, P, k, what):
        """Sigma-point offsets (runs, N, n_cov) of covariances P: (U1)/(U3) about zero."""
        try:
            return sigma_points(np.zeros(P.shape[:-1]), P, self.scale, center=self.rule == "unscented")
        except np.linalg.LinAlgError:
            raise HinfnavError(f"filter {self.name!r} stopped at step {k}: the {what} covariance is not positive "
                               "definite (no sigma points)") from None

    def _moments(self, X):
        """Weighted mean and deviations of state sigma points X (runs, N, n)."""
        mean = self.Wm @ X
        return mean, X - mean[:, None, :]

    def _inject(self, x, dx):
        """``x ⊞ δx``: x + δx, or the system's injection (``q ← δq(δθ) ⊗ q``, the rest added)."""
        return x + dx if not self.error_coordinates else self.system.inject(np.broadcast_to(x, dx.shape[:-1] + x.shape[-1:]), dx)

    def _difference(self, x, ref):
        """``x ⊟ ref``, the inverse of :meth:`_inject`: x − ref, or (U6) for a quaternion-first state."""
        if not self.error_coordinates:
            return x - ref
        ref = np.broadcast_to(ref, x.shape)
        dq = quat_multiply(x[..., :4], quat_conjugate(ref[..., :4]))
        return np.concatenate([rotvec_from_quat(dq), x[..., 4:] - ref[..., 4:]], axis=-1)

    def _propagate(self, X, u, t):
        if self.error_coordinates:
            return np.asarray(self.system.predict_mean(X, u))
        return np.asarray(self.system.f(X, u, t))

    @staticmethod
    def _without(mask, dY, R_k, innovation):
        """``(dY, R, ν)`` with the channels ``~mask`` removed exactly, as drop_missing does for the Kalman
        correction: their output deviations and innovation zeroed, their rows and columns of R decoupled (S block
        diagonal, K's column 0), so the rest of the update is the filter's without them (mask None: all kept)."""
        if mask is None:
            return dY, R_k, innovation
        both = mask[:, :, None] & mask[:, None, :]
        return (np.where(mask[:, None, :], dY, 0.0), np.where(both, R_k, 0.0) + np.eye(R_k.shape[-1]) * ~mask[:, None, :],
                np.where(mask, innovation, 0.0))

    def _cov(self, A, B):
        """``Σ W_i^c A_i B_iᵀ`` for deviations A (runs, N, a), B (runs, N, b)."""
        return np.swapaxes(A * self.Wc[:, None], -1, -2) @ B

    # -- the step contract -------------------------------------------------------------

    def _start(self, xhat0, P0, runs):
        P = self.P0 if P0 is None else as_covariance("P0", P0, self.n_cov, definite=True)
        x = np.broadcast_to(as_vector("xhat0", xhat0, self.n_state), (runs, self.n_state)).copy()
        if self.error_coordinates:  # the system's injection of a zero correction normalises (a unit quaternion)
            x = self._inject(x, np.zeros((runs, self.n_cov)))
        return FilterState(x=x, P=np.broadcast_to(P, (runs,) + P.shape).copy())

    def _predicted_outputs(self, X, x, k):
        """``(ȳ, dY)``: the weighted mean (runs, m) of h at the sigma points X (runs, N, n) and their deviations.

        The mean is taken about ``h(x̂⁻)`` (the first point for the unscented rule). A measurement function
        that refuses a point (InputError) stops the filter with a HinfnavError naming step ``k``.
        """
        runs, N, n = X.shape
        try:
            Y = self.measurement.function(X.reshape(runs * N, n)).reshape(runs, N, -1)
            ref = Y[:, 0] if self.rule == "unscented" else self.measurement.function(x)  # h(x̂⁻)
        except ModelFunctionError:  # a user model's own error, already naming its function
            raise
        except InputError as exc:
            raise HinfnavError(f"filter {self.name!r} stopped at step {k}: a sigma point reached a singular "
                               f"point of the measurement ({exc})") from None
        # differences of predicted outputs: the model's residual (angles wrapped), except for a converted
        # measurement, whose residual converts a reading (its predicted outputs are positions: plain differences)
        diff = np.subtract if hasattr(self.measurement, "convert") else self.measurement.residual
        y_mean = ref + self.Wm @ diff(Y, ref[:, None, :])
        return y_mean, diff(Y, y_mean[:, None, :])

    def _update(self, state, y):
        x, P = state.x, state.P
        runs, n = x.shape
        mask = available_channels(y) if self.missing == "skip" else None
        gate, count = self._gate, state.extra.get("gate_count")
        if gate is not None:  # a run recovering from rejections: its prior inflated before the points are drawn
            P = gate.inflate(P, count)
        dX = self._points(P, state.k, "prior")
        X = self._inject(x[:, None, :], dX)
        y_mean, dY = self._predicted_outputs(X, x, state.k)
        y, mask = fill_missing(self.measurement, y, x, y_mean, mask)  # a missing channel reads as predicted
        R_k = self.R if self.R_of_reading is None else self.R_of_reading(y)
        innovation = self.measurement.residual(y, y_mean)
        if mask is not None and self.R_of_reading is not None:
            # R(y) not finite on the channels it has: the reading is not used
            both = mask[:, :, None] & mask[:, None, :]
            mask = mask & np.all(np.isfinite(np.where(both, R_k, 0.0)), axis=(1, 2))[:, None]
        shown, raw = mask, innovation  # the channels the reading has (a rejected channel's innovation is reported)
        dY_u, R_u, nu_u = self._without(mask, dY, R_k, innovation)
        S = self._cov(dY_u, dY_u) + R_u
        d_gate = {}
        if gate is not None:
            avail = np.ones(innovation.shape, dtype=bool) if mask is None else mask
            rejected, d_gate, new_count = gate.decide(S, nu_u, avail, count)
            if rejected.any():
                mask = avail & ~rejected
                dY_u, R_u, nu_u = self._without(mask, dY, R_k, innovation)
                S = self._cov(dY_u, dY_u) + R_u
        dY, innovation = dY_u, nu_u
        Pxy = self._cov(dX, dY)
        K = Pxy @ inv_spd(S)
        x_post = self._inject(x, (K @ innovation[:, :, None])[:, :, 0])
        P_post = P - K @ S @ np.swapaxes(K, -1, -2)
        P_post = 0.5 * (P_post + np.swapaxes(P_post, -1, -2))
        diag = dict(d_gate, innovation=raw if shown is None else np.where(shown, raw, np.nan), innovation_covariance=S)
        extra = dict(state.extra)
        if gate is not None:
            extra["gate_count"] = new_count
        new = FilterState(x=x_post, P=P_post, k=state.k, extra=extra)
        if self.output == "filtered":
            return new, StepOutput(xhat=x_post, P=P_post, diagnostics=diag)
        return new, StepOutput(xhat=x, P=P, diagnostics=diag)

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        runs, n = state.x.shape
        X = self._inject(state.x[:, None, :], self._points(state.P, state.k, "posterior"))
        N = X.shape[1]
        uu = None
        if self.uses_input:
            u = np.asarray(u, dtype=float)
            uu = np.repeat(u, N, axis=0)
        t = state.k * self.dt
        Xf = self._propagate(X.reshape(runs * N, n), uu, t).reshape(runs, N, n)
        if not self.error_coordinates:
            x, dX = self._moments(Xf)
        else:  # (U6): deviations about the propagated centre, their weighted mean injected
            ref = Xf[:, 0] if self.rule == "unscented" else self._propagate(state.x, u, t)
            D = self._difference(Xf, ref[:, None, :])
            mean = self.Wm @ D
            x, dX = self._inject(ref, mean), D - mean[:, None, :]
        P = self._cov(dX, dX) + self.Q
        return FilterState(x=x, P=P, k=state.k + 1, extra=dict(state.extra))
