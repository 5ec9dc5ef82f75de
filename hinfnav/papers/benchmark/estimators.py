"""The benchmark's generic estimators: eight filters built from any scenario's declared Kalman model.

A scenario that offers the ``"kalman"`` model (:class:`~hinfnav.estimators.registry.Offers`) has
``kalman_model()``: its system (a LinearSystem or a dynamics model), its measurement model, the filters'
P₀, whether they are told the applied input, and two scales of an unknown input (``input_rate_max``, a bound
on its rate, input unit/s, and ``input_std0``, its initial σ). On it:

==================  =====================================================================================
``model_ekf``       :class:`~hinfnav.estimators.ExtendedKalmanFilter` (Q = B Bᵀ, R = D Dᵀ)
``model_ukf``       its sigma-point version (:meth:`~hinfnav.estimators.SigmaPointFilter.from_ekf`)
``model_hbf``       its Huber version (:meth:`~hinfnav.estimators.HuberFilter.from_ekf`, γ = 1.345)
``model_stekf``     strong tracking (:class:`~hinfnav.estimators.kalman.StrongTrackingEKF`, ρ = 0.95, β = 1)
``model_stkf``      Huang et al. (2017)'s Student-t filter (:class:`~hinfnav.estimators.variational.StudentTFilter`;
                    ω = ν = 5, N = 10, τ = 1e-8, the paper's choices)
``model_vbakf``     Särkkä & Nummenmaa (2009)'s noise-adaptive VB filter
                    (:class:`~hinfnav.estimators.variational.NoiseAdaptiveFilter`; ρ = 1, N = 5, R the prior)
``model_mckf``      Chen et al. (2017)'s maximum-correntropy filter
                    (:class:`~hinfnav.estimators.correntropy.CorrentropyFilter`; σ = 2, ε = 1e-6)
``model_adaptive``  the unknown input as a random walk whose noise follows its estimated rate
                    (:class:`~hinfnav.estimators.augmented.AugmentedInputAdaptiveKF`; linear dynamics):
                    Q = ḟ_max² T, base Q/100, ε with Q/100 (ε ḟ_max)² = Q, memory m = 50 steps —
                    the rule of :mod:`hinfnav.papers.attitude2018.chaser`, not tuned on any truth
==================  =====================================================================================

and, for paper 002's attitude scenario (quaternion error: the five above do not fit it), ``attitude_hbf``:
its AEKF with the Huber update (:class:`~hinfnav.estimators.attitude.AttitudeHuberEKF`, Q = 1e-14 I₃ as the
paper's best AEKF, γ = 1.345), and ``attitude_ukf``: the sigma-point filter on the same model in the error
coordinates (δθ, δω, δT) (the USQUE-type form (U6) of :mod:`hinfnav.estimators.sigma_point`; per-step
process noise ``Δt Γ Q Γᵀ`` with the AEKF's Q = 1e-14 I₃, as the AEKF's prediction), so that scenario has a
sigma-point and a Huber filter beside its AEKF, ASTEKF and AAEKF.
"""

import numpy as np

from ...core.exceptions import InputError
from ...estimators.attitude import AttitudeHuberEKF
from ...estimators.augmented import AugmentedInputAdaptiveKF
from ...estimators.correntropy import CorrentropyFilter
from ...estimators.huber_filter import HuberFilter
from ...estimators.kalman import ExtendedKalmanFilter, StrongTrackingEKF
from ...estimators.registry import Requires, register_estimator
from ...estimators.sigma_point import SigmaPointFilter
from ...estimators.variational import NoiseAdaptiveFilter, StudentTFilter
from ...systems.attitude import AttitudeSystem
from ..attitude2018.constants import PAPER_Q_BEST_AEKF
from ..attitude2018.filters import torque_density
from ..attitude2018.scenario import Scenario as AttitudeScenario
from ..shi2018.campaign import kalman_model as shi_kalman_model
from ..shi2018.scenario import Scenario as ShiScenario

__all__ = ["build_generic", "build_attitude_hbf", "build_attitude_ukf"]

#: Name → (kind, description).
GENERIC = {
    "model_ekf": ("ekf", "EKF of the scenario's declared Kalman model"),
    "model_ukf": ("ukf", "unscented (sigma-point) filter of the scenario's declared Kalman model"),
    "model_hbf": ("hbf", "Huber-based filter of the scenario's declared Kalman model"),
    "model_stekf": ("stekf", "strong-tracking EKF of the scenario's declared Kalman model"),
    "model_adaptive": ("adaptive", "Kalman filter with the unknown input as a rate-adapted random walk"),
    "model_stkf": ("stkf", "Student-t variational filter (Huang et al. 2017) of the scenario's declared Kalman model"),
    "model_vbakf": ("vbakf", "variational-Bayes noise-adaptive filter (Sarkka & Nummenmaa 2009) of the scenario's "
                             "declared Kalman model"),
    "model_mckf": ("mckf", "maximum-correntropy Kalman filter (Chen et al. 2017) of the scenario's declared Kalman "
                           "model"),
}

#: The robust variants of the Kalman model's EKF built through their ``from_ekf``.
_FROM_EKF = {"ukf": SigmaPointFilter, "hbf": HuberFilter, "stkf": StudentTFilter, "vbakf": NoiseAdaptiveFilter,
             "mckf": CorrentropyFilter}


def _model(scenario):
    model = getattr(scenario, "kalman_model", None)
    if callable(model):
        return model()
    if isinstance(scenario, ShiScenario):  # the paper's own scenario object (not the campaign's): the same model
        return shi_kalman_model(scenario)
    raise InputError(f"scenario {type(scenario).__name__} offers no kalman_model()")


def build_generic(scenario, kind, **options):
    """One of the eight filters of the module table on ``scenario``'s Kalman model (``options`` to its class)."""
    m = _model(scenario)
    system, meas, P0 = m["system"], m["measurement"], m["P0"]
    name = f"model_{kind}"
    if kind == "stekf":
        options.setdefault("rho", 0.95)
        options.setdefault("beta", 1.0)
        return StrongTrackingEKF(system, meas, P0=P0, uses_input=m["uses_input"], name=name, **options)
    if kind == "adaptive":
        T, rate = system.dt, m["input_rate_max"]
        q = rate**2 * T
        n_u = system.n_input
        return AugmentedInputAdaptiveKF(system, meas, Q_input=q / 100 * np.eye(n_u), P0=P0,
                                        P0_input=m["input_std0"] ** 2 * np.eye(n_u), epsilon=10.0 / rate,
                                        memory_steps=50, name=name, **options)
    ekf = ExtendedKalmanFilter(system, meas, P0=P0, uses_input=m["uses_input"], name="model_ekf",
                               **(options if kind == "ekf" else {}))
    if kind == "ekf":
        return ekf
    return _FROM_EKF[kind].from_ekf(ekf, name=name, **options)


def _builder(kind):
    def build(scenario, **options):
        return build_generic(scenario, kind, **options)

    build.__name__ = f"build_model_{kind}"
    return build


def _has_model(scenario):
    return callable(getattr(scenario, "kalman_model", None)) or isinstance(scenario, ShiScenario)


for _name, (_kind, _text) in GENERIC.items():
    register_estimator(_name, _builder(_kind), fits=_has_model, description=_text,
                       requires=Requires(error_form="additive", model="kalman", linear=_kind == "adaptive"))


def build_attitude_hbf(scenario, *, Q=PAPER_Q_BEST_AEKF, gamma=1.345, **options):
    """Paper 002's AEKF with Huber's M-estimation as its update (see the module docstring)."""
    if not isinstance(scenario, AttitudeScenario):
        raise InputError(f"scenario must be a paper 002 (attitude2018) Scenario; got {type(scenario).__name__}")
    return AttitudeHuberEKF(scenario.system(), scenario.measurement, P0=scenario.P0, Q=torque_density(Q), gamma=gamma,
                            name="attitude_hbf", **options)


register_estimator("attitude_hbf", build_attitude_hbf, fits=lambda scenario: isinstance(scenario, AttitudeScenario),
                   description="paper 002's AEKF with the Huber update (gamma = 1.345)",
                   requires=Requires(error_form="quaternion", measurement=("star_vectors",), input=True,
                                     model="attitude2018"))


def build_attitude_ukf(scenario, *, Q=PAPER_Q_BEST_AEKF, **options):
    """Paper 002's attitude model under the sigma-point filter (see the module docstring); ``options`` to
    :class:`~hinfnav.estimators.SigmaPointFilter` (``rule``, ``alpha``…)."""
    if not isinstance(scenario, AttitudeScenario):
        raise InputError(f"scenario must be a paper 002 (attitude2018) Scenario; got {type(scenario).__name__}")
    system = scenario.system()
    G = AttitudeSystem.noise_input()
    return SigmaPointFilter(system, scenario.measurement, P0=scenario.P0, Q=system.dt * G @ torque_density(Q) @ G.T,
                            uses_input=True, name="attitude_ukf", **options)


register_estimator("attitude_ukf", build_attitude_ukf, fits=lambda scenario: isinstance(scenario, AttitudeScenario),
                   description="paper 002's attitude model under the sigma-point (unscented) filter, Q = 1e-14 I3",
                   requires=Requires(error_form="quaternion", measurement=("star_vectors",), input=True,
                                     model="attitude2018"))
