"""Shi & Wang (2018) as a campaign scenario: the target's maneuver at 500 s, the mixture (23) as a setting.

:class:`CampaignScenario` is the paper's :class:`~.scenario.Scenario` (so its
filters build on it unchanged) with two more settings, ``eps`` and
``sigma2_ratio`` (ε and σ₂/σ₁ of the mixture (23)), and what a campaign needs:

* ``truth_model(maneuver)``: the Hill/CW system and the range/azimuth/elevation
  sensor (the generic truth model; the maneuver is an impulse it cannot carry);
* ``campaign_truth(conditions, noise, rngs)``: the truth of
  :meth:`~.scenario.Scenario.simulate_truth` drawn from the given per-run
  generators: the accelerometer disturbance w is Gaussian, the sensor noise v
  is the campaign's ``noise`` — ``"mixture"`` meaning the paper's contaminated
  mixture (23) with this scenario's ε and σ₂/σ₁ (variance ``(1−ε) + ε r²``
  times the sensor's, the filters being told σ₁), any other name that
  unit-variance noise; w first, then v, as :func:`hinfnav.sim.simulate_truth`;
  with maneuver the velocity impulse's response is added to the state;
* ``kalman_model()``: the direct range/angle model for the generic filters of
  the benchmark; ``bound_problem(conditions, noise)``: the ingredients of the
  posterior Cramér–Rao bound (linear dynamics, nonlinear sensor: no Riccati limit).
"""

from dataclasses import dataclass

import numpy as np

from ...analysis.pcrb import measurement_information
from ...core.exceptions import InputError
from ...core.validation import as_positive, as_real
from ...campaign.registry import register_scenario
from ...estimators.registry import Offers
from ...noise import MixtureNoise, make_noise
from ...sim.truth import Truth, TruthModel, draw_noise
from .constants import MIXTURE_EPS, MIXTURE_RATIO
from .scenario import ContaminatedNoise, Scenario

__all__ = ["CampaignScenario", "OFFERS", "kalman_model"]

#: Additive error, range/angle readings, the control acceleration known, linear (Hill/CW) dynamics.
OFFERS = Offers(error_form="additive", measurement="range_angle", input=True, linear=True, models=("shi2018", "kalman"))


def kalman_model(scenario):
    """The generic filters' model on a Shi & Wang :class:`~.scenario.Scenario`: Hill/CW with the known control
    acceleration, the direct range/angle sensor, the scenario's P₀; an unknown input of at most 1e-3 m/s³ in
    rate and 1e-3 m/s² at the start (documented choice, for the adaptive filter)."""
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Shi 2018 Scenario; got {type(scenario).__name__}")
    return {"system": scenario.system(), "measurement": scenario.sensor(), "P0": scenario.P0, "uses_input": True,
            "input_rate_max": 1e-3, "input_std0": 1e-3}


@dataclass(frozen=True, eq=False)
class CampaignScenario(Scenario):
    """Shi & Wang (2018)'s scenario with the mixture's ε and σ₂/σ₁ as settings (see the module docstring).

    Attributes
    ----------
    eps : float
        Weight ε of the wide component of (23), in [0, 1] (0.6).
    sigma2_ratio : float
        σ₂/σ₁ of (23), > 0 (2).
    """

    eps: float = MIXTURE_EPS
    sigma2_ratio: float = MIXTURE_RATIO

    offers = OFFERS

    def __post_init__(self):
        super().__post_init__()
        eps = as_real("eps", self.eps)
        if not 0.0 <= eps <= 1.0:
            raise InputError(f"eps must be in [0, 1]; got {self.eps}")
        object.__setattr__(self, "eps", eps)
        object.__setattr__(self, "sigma2_ratio", as_positive("sigma2_ratio", self.sigma2_ratio))

    def truth_model(self, maneuver=False):
        """System, sensor, x₀ and length; ``maneuver`` is recorded (the impulse is added by :meth:`campaign_truth`)."""
        if not isinstance(maneuver, (bool, np.bool_)):
            raise InputError(f"maneuver must be True or False; got {maneuver!r}")
        return TruthModel(self.system(), self.sensor(), self.x0, self.n_steps, None, {"maneuver": bool(maneuver)})

    def sensor_noise(self, noise):
        """The sensor's noise model for the campaign's ``noise`` name (``"mixture"``: (23) with ε, σ₂/σ₁)."""
        if noise == "mixture":
            return ContaminatedNoise(eps=self.eps, ratio=self.sigma2_ratio)
        return make_noise(noise, dt=self.dt) if noise == "colored" else make_noise(noise)

    def campaign_truth(self, conditions, noise, rngs):
        """Truth and readings of the runs whose generators are ``rngs`` (see the module docstring).

        Returns
        -------
        hinfnav.sim.Truth
        """
        model = self.truth_model(**conditions)
        system, sensor = model.system, model.measurement
        n1 = model.n_steps + 1
        w, v = draw_noise(make_noise("gaussian"), self.sensor_noise(noise), rngs, n1, system.n_noise, sensor.n_noise)
        x = np.empty((len(rngs), n1, system.n))
        x[:, 0] = model.x0
        drive = w @ system.B.T
        for k in range(n1 - 1):  # x(k+1) = Φ x(k) + B w(k) (the chaser coasts: u = 0)
            x[:, k + 1] = x[:, k] @ system.Phi.T + drive[:, k]
        if model.settings["maneuver"]:
            x += self.maneuver_response()
        settings = dict(model.settings, noise="gaussian", measurement_noise=self.sensor_noise(noise).name,
                        runs=len(rngs))
        return Truth(t=model.time, x=x, u=np.zeros((len(rngs), n1, system.n_input)), y=sensor.measure(x, v),
                     settings=settings, state=system.state, measurement=sensor)

    def kalman_model(self):
        """The generic filters' model (:func:`kalman_model`)."""
        return kalman_model(self)

    def bound_problem(self, conditions, noise):
        """Ingredients of the posterior CRB: F = Φ, H of the sensor, Q = B Bᵀ, Λ of the sensor noise, P₀ = 0.

        The truth starts from one fixed state (and the maneuver is a fixed impulse): the bound's prior is that
        state (P₀ = 0), which makes it a strict bound for every estimator, none of which knows it.

        Λ is ``j (D Dᵀ)⁻¹`` with j the Fisher information of the sensor's noise density
        (:func:`hinfnav.analysis.pcrb.measurement_information`); for the contaminated
        mixture, whose variance is ``s² = (1−ε) + ε r²``, that of the unit-variance mixture over s².
        """
        system, sensor = self.system(), self.sensor()
        v = self.sensor_noise(noise)
        if isinstance(v, ContaminatedNoise):
            Lam = measurement_information(sensor.D, MixtureNoise(eps=v.eps, ratio=v.ratio)) / v.variance
        else:
            Lam = measurement_information(sensor.D, v)
        return {"kind": "pcrb", "F": system.Phi, "H": sensor, "Q": system.B @ system.B.T, "Lambda": Lam,
                "P0": np.zeros((6, 6)), "states": lambda x: x}


register_scenario("shi2018", CampaignScenario,
                  description="Shi & Wang 2018: target relative motion, range/angle sensor, maneuver at 500 s, mixture (23)")
