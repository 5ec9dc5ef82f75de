"""Paper 002's three gyroless attitude filters as one EKF: AEKF, ASTEKF, AAEKF.

All three estimate ``x = [q, ω, T_d]`` of :class:`~hinfnav.systems.attitude.AttitudeSystem`
from star-sensor vectors (:class:`~hinfnav.systems.attitude.StarSensorVectors`),
with the disturbance torque T_d as augmented random-walk state (A5), and
differ in one hook each (:mod:`hinfnav.estimators.adaptive`):

``AttitudeAEKF``
    the augmented EKF (paper 002 §2.1): prediction with Φ = e^{FΔt},
    ``P⁻ = Φ P Φᵀ + Δt Γ Q Γᵀ``, Joseph-form update;
``AttitudeASTEKF``
    strong tracking: ``P⁻ = Λ^{1/2} Φ P Φᵀ Λ^{1/2} + Δt Γ Q Γᵀ`` with the
    multiple fading factors of Zhou, Xi & Zhang (1991) (§2.3);
``AttitudeAAEKF``
    the torque's noise density follows its estimated rate over the last m
    steps, ``Q(t_k) = Q(t₀) F[ε κ(t_k)]`` (§2.2).

**Error coordinates** (documented choice). The filters carry the quaternion
itself but their covariance lives in the 9 error coordinates
(δθ, δω, δT) with ``δq = q ⊗ q̂⁻¹ ≈ [δθ/2, 1]`` — the reduced, multiplicative
representation of Lefferts, Markley & Shuster (1982), paper 002's reference
[3] for the filter's form. The correction is applied as ``q̂ ← δq(δθ) ⊗ q̂``,
which keeps q̂ a unit quaternion; the fading factors λᵢ are per error
coordinate (n = 9). The control torque T_c is known to the filters (the
``u`` argument); the wheel momentum is the system's h.
"""

import numpy as np

from ..core.exceptions import InputError
from ..systems.attitude import TORQUE, AttitudeSystem, StarSensorVectors
from .adaptive import RateAdaptive, StrongTracking
from .augmented import AugmentedEKF
from .huber_filter import HuberCorrection

__all__ = ["AttitudeAAEKF", "AttitudeAEKF", "AttitudeASTEKF", "AttitudeHuberEKF", "AttitudeHuberSTEKF"]


class AttitudeAEKF(AugmentedEKF):
    """Augmented EKF of gyroless attitude (paper 002 §2.1), batched over runs.

    Parameters
    ----------
    system : AttitudeSystem
        The filter's model (``disturbance`` must be None: the torque is the
        random-walk state).
    measurement : StarSensorVectors
    P0 : array_like, shape (9, 9)
        Initial covariance in error coordinates (rad², (rad/s)², (N·m)²).
    Q : float or array_like, shape (3, 3)
        Density of the torque's random walk, (N·m)²/s; a number ε means ε I₃
        (paper 002: Q = ε I₃, best AEKF ε = 1e-14, ASTEKF 1e-16).
    R : array_like, shape (3k, 3k), optional
        Measurement covariance (default the sensor's σ² I).
    output : {"filtered", "predicted"}
    name : str
    """

    name = "aekf"

    def __init__(self, system, measurement, *, P0, Q, R=None, output="filtered", name=None, missing="refuse"):
        if not isinstance(system, AttitudeSystem):
            raise InputError(f"system must be a hinfnav AttitudeSystem; got {type(system).__name__}")
        if system.disturbance is not None:
            raise InputError("system must be the filter's model (disturbance=None): the torque is estimated, not given")
        if not isinstance(measurement, StarSensorVectors):
            raise InputError(f"measurement must be StarSensorVectors; got {type(measurement).__name__}")
        Q = np.asarray(Q, dtype=float)
        if Q.ndim == 0:
            Q = float(Q) * np.eye(3)
        super().__init__(system, measurement, n_cov=9, aug_input=AttitudeSystem.noise_input(), P0=P0, Q=Q, R=R,
                         uses_input=True, output=output, name=name, missing=missing)

    def initial_internal(self, xhat0):
        x = xhat0.copy()
        norm = np.linalg.norm(x[:4])
        if norm == 0:
            raise InputError("xhat0 must start with a non-zero quaternion [q1, q2, q3, q4] (scalar last)")
        x[:4] /= norm
        return x

    def propagate_mean(self, x, u):
        return self.system.predict_mean(x, u)

    def transition(self, x, u):
        return self.system.transition(x)

    def observe(self, x):
        b = self.measurement.function(x)  # h(x̂) once: the Jacobian's blocks are [b̂_i×]
        return b, self.measurement.error_jacobian_at(b)

    def inject(self, x, dx):
        return self.system.inject(x, dx)

    def report(self, x):
        return x

    def augmented(self, x):
        return x[:, TORQUE]


class AttitudeASTEKF(StrongTracking, AttitudeAEKF):
    """Augmented strong-tracking EKF (paper 002 §2.3): :class:`AttitudeAEKF` with fading factors.

    Extra parameters ``rho`` (forgetting factor, 0.95), ``beta`` (weakening
    factor ≥ 1, 1.0) and ``a`` (9 prior weights ≥ 1, all 1); see
    :class:`~hinfnav.estimators.adaptive.StrongTracking`.
    """

    name = "astekf"


class AttitudeAAEKF(RateAdaptive, AttitudeAEKF):
    """Augmented adaptive EKF (paper 002 §2.2): :class:`AttitudeAEKF` with ``Q(t_k) = Q(t₀) F[ε κ(t_k)]``.

    Extra parameters ``memory_steps`` (m steps), ``epsilon`` (ε, s/(N·m)) and
    ``floor``; ``Q`` is Q(t₀). See :class:`~hinfnav.estimators.adaptive.RateAdaptive`.
    """

    name = "aaekf"


class AttitudeHuberEKF(HuberCorrection, AttitudeAEKF):
    """:class:`AttitudeAEKF` whose correction is Huber's M-estimation (Karlgaard & Schaub 2007).

    Extra parameters ``gamma``, ``tol``, ``max_iter``; see
    :class:`~hinfnav.estimators.huber_filter.HuberCorrection`. The regression
    is solved for the 9 error coordinates and injected as the AEKF's
    correction (multiplicative for the quaternion).
    """

    name = "huber_aekf"


class AttitudeHuberSTEKF(HuberCorrection, StrongTracking, AttitudeAEKF):
    """Huber correction with strong tracking on the attitude filter (both mixins on :class:`AttitudeAEKF`)."""

    name = "huber_astekf"
