"""Paper 002's estimators by name, registered for the notebooks, the studies and the contract tests.

=================================  ====================================================
name                               estimator
=================================  ====================================================
``aekf``                           augmented EKF, Q = 1e-14 I₃ (paper: its best)
``astekf``                         augmented strong-tracking EKF, Q = 1e-16 I₃
                                   (paper), ρ = 0.95, β = 1, aᵢ = 1
``aaekf``                          augmented adaptive EKF, Q(t₀) = 1e-16 I₃,
                                   ε = :func:`~.scenario.default_epsilon`, m = 60
``ekf_augmented_thrust``           Sun 2011's chaser: the unknown thrust as a
                                   random-walk state (:mod:`.chaser`)
``ekf_augmented_thrust_st``        … with strong tracking
``ekf_augmented_thrust_adaptive``  … with the rate-adapted thrust noise
=================================  ====================================================

The first three fit paper 002's :class:`~.scenario.Scenario` only, the last
three Sun 2011's scenario only.
"""

import numpy as np

from ...core.exceptions import InputError
from ...estimators.attitude import AttitudeAAEKF, AttitudeAEKF, AttitudeASTEKF
from ...estimators.registry import Requires, register_estimator
from ..sun2011.scenario import Scenario as ChaserScenario
from .chaser import build_augmented_thrust
from .constants import DEFAULT_AA, DEFAULT_ST, PAPER_Q_ASTEKF, PAPER_Q_BEST_AEKF
from .scenario import Scenario, default_epsilon

__all__ = [
    "ATTITUDE_FILTERS",
    "CHASER_FILTERS",
    "build_aaekf",
    "build_aekf",
    "build_astekf",
    "build_attitude_filter",
    "torque_density",
]

ATTITUDE_FILTERS = ("aekf", "astekf", "aaekf")
CHASER_FILTERS = ("ekf_augmented_thrust", "ekf_augmented_thrust_st", "ekf_augmented_thrust_adaptive")


def torque_density(Q):
    """The torque noise density as a matrix: a number ε → ε I₃; a 1-D array → one ε I₃ per run (B, 3, 3)."""
    Q = np.asarray(Q, dtype=float)
    if Q.ndim == 0:
        return float(Q) * np.eye(3)
    if Q.ndim == 1:
        return Q[:, None, None] * np.eye(3)
    return Q


def _check(scenario):
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a paper 002 (attitude2018) Scenario; got {type(scenario).__name__}")


def build_aekf(scenario, Q=PAPER_Q_BEST_AEKF, *, name="aekf", **options):
    """The AEKF on ``scenario`` with torque noise density Q ((N·m)²/s; a number, or one per run)."""
    _check(scenario)
    return AttitudeAEKF(scenario.system(), scenario.measurement, P0=scenario.P0, Q=torque_density(Q), name=name,
                        **options)


def build_astekf(scenario, Q=PAPER_Q_ASTEKF, *, rho=DEFAULT_ST["rho"], beta=DEFAULT_ST["beta"], a=None, name="astekf",
                 **options):
    """The ASTEKF on ``scenario`` (ρ, β may be one value per run)."""
    _check(scenario)
    return AttitudeASTEKF(scenario.system(), scenario.measurement, P0=scenario.P0, Q=torque_density(Q), rho=rho,
                          beta=beta, a=a, name=name, **options)


def build_aaekf(scenario, Q0=DEFAULT_AA["Q0"], *, epsilon=None, memory_steps=DEFAULT_AA["memory_steps"],
                floor=DEFAULT_AA["floor"], name="aaekf", **options):
    """The AAEKF on ``scenario``: Q(t₀) = Q0 I₃, ε (default :func:`default_epsilon`; may be one per run), m = memory_steps."""
    _check(scenario)
    epsilon = default_epsilon(Q0=float(np.max(Q0)), omega_e=scenario.omega_e) if epsilon is None else epsilon
    return AttitudeAAEKF(scenario.system(), scenario.measurement, P0=scenario.P0, Q=torque_density(Q0),
                         epsilon=epsilon, memory_steps=memory_steps, floor=floor, name=name, **options)


_BUILDERS = {"aekf": build_aekf, "astekf": build_astekf, "aaekf": build_aaekf}


def build_attitude_filter(scenario, name, **options):
    """One of :data:`ATTITUDE_FILTERS` by name."""
    if name not in _BUILDERS:
        raise InputError(f"unknown attitude filter {name!r}; choose one of: {', '.join(_BUILDERS)}")
    return _BUILDERS[name](scenario, **options)


_DESCRIPTIONS = {
    "aekf": "paper 002: augmented EKF of gyroless attitude, torque as random-walk state (Q = 1e-14 I3)",
    "astekf": "paper 002: augmented strong-tracking EKF (multiple fading factors, Q = 1e-16 I3)",
    "aaekf": "paper 002: augmented adaptive EKF (torque noise from its estimated rate)",
    "ekf_augmented_thrust": "Sun 2011 chaser: EKF with the unknown thrust as random-walk state (paper 002's idea)",
    "ekf_augmented_thrust_st": "Sun 2011 chaser: thrust-augmented EKF with strong tracking",
    "ekf_augmented_thrust_adaptive": "Sun 2011 chaser: thrust-augmented EKF with rate-adapted thrust noise",
}


def _attitude_fits(scenario):
    return isinstance(scenario, Scenario)


def _chaser_fits(scenario):
    return isinstance(scenario, ChaserScenario)


def _chaser_builder(variant):
    def build(scenario, **options):
        return build_augmented_thrust(scenario, variant=variant, **options)

    build.__name__ = f"build_augmented_thrust_{variant}"
    return build


for _name in ATTITUDE_FILTERS:
    register_estimator(_name, _BUILDERS[_name], fits=_attitude_fits, description=_DESCRIPTIONS[_name],
                       requires=Requires(error_form="quaternion", measurement=("star_vectors",), input=True, model="attitude2018"))
for _name, _variant in zip(CHASER_FILTERS, ("plain", "st", "adaptive")):
    register_estimator(_name, _chaser_builder(_variant), fits=_chaser_fits, description=_DESCRIPTIONS[_name],
                       requires=Requires(model="sun2011", linear=True))
