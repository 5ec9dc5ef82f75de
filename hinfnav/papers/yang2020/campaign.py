"""Yang et al. (2020) as a campaign scenario: the three drag-free axes read by the saturated accelerometers.

:class:`CampaignScenario` is the scenario's linear truth ``"dragfree"``
(:class:`~.scenario.LinearTruth`: the states [r, ṙ, F_Dsc] of the three
translational axes, the accelerometers clipped at ±6e-6 m/s² (11), the linear
ADRC law u = K x on the true state), so Algorithm 2 and its variants build on
it unchanged. Its condition is the initial disturbance (``disturbance``,
N: −3e-3 keeps the accelerometers inside their range, −12.8e-3 saturates
them); its settings the loop length ``n_steps`` (steps of h = 0.1 s).

The truth is linear (simulated by :func:`hinfnav.sim.simulate_truth`); the
readings are not (clipped). Its bound is that of the *unclipped* accelerometers
with the truth's noise covariances (:meth:`CampaignScenario.bound_problem`):
a clipped reading is a function of the unclipped one, so no estimator of the
clipped readings can do better than the best one of the unclipped readings
(for Gaussian noise, the Kalman filter); the bound is tight without clipping.
"""

from dataclasses import dataclass

import numpy as np

from ...campaign.registry import register_scenario
from ...analysis.pcrb import measurement_information
from ...estimators.registry import Offers
from ...noise import make_noise
from .constants import P0_DIAGONAL
from .scenario import LinearTruth, Scenario

__all__ = ["CampaignScenario", "OFFERS"]

#: Additive error, the saturated accelerometers of the drag-free axes, the applied force known, linear dynamics.
OFFERS = Offers(error_form="additive", measurement="saturated_accelerometer", input=True, linear=True,
                models=("yang2020", "kalman"))


@dataclass(frozen=True)
class CampaignScenario(LinearTruth):
    """The drag-free axes of a yang2020 :class:`~.scenario.Scenario` as a campaign scenario (module docstring)."""

    offers = OFFERS

    @property
    def P0(self):
        """Initial covariance of the filters: 0.01 on the diagonal (Section 3)."""
        return P0_DIAGONAL * np.eye(9)

    def truth_model(self, disturbance=-3e-3):
        """The linear truth of the drag-free axes with initial disturbance ``disturbance`` (N)."""
        return self.parent.truth_model("dragfree", disturbance=disturbance)

    def kalman_model(self):
        """The generic filters' model: the truth's system, the unclipped accelerometers, the applied force known."""
        model = self.truth_model()
        return {"system": model.system, "measurement": model.measurement.model, "P0": self.P0, "uses_input": True,
                "input_rate_max": float(np.sqrt(self.parent.q[3]) / self.parent.dt), "input_std0": 1e-2}

    def bound_problem(self, conditions, noise):
        """The bound's model: x⁺ = Φ x + B w (the input known), unclipped y = C x + D v, the initial state known.

        The truth starts from one fixed state, so the bound's prior is that state (P₀ = 0): the recursion is
        the Kalman covariance from zero, a strict bound at every step for every estimator (which does not know
        x₀); it rises towards the steady-state Riccati limit, which it has not reached within these runs
        (the accelerometers see the displacement only through the slow test-mass spring).
        """
        model = self.truth_model(**conditions)
        system, meas = model.system, model.measurement.model
        return {"kind": "pcrb", "F": system.Phi, "H": meas.H, "Q": system.B @ system.B.T,
                "Lambda": measurement_information(meas.D, make_noise(noise)), "P0": np.zeros((9, 9)),
                "states": lambda x: x}


def campaign_scenario(n_steps=20_000):
    """The campaign scenario ``yang2020``: the drag-free axes over ``n_steps`` steps of 0.1 s (default 2000 s)."""
    return CampaignScenario(Scenario(n_steps=n_steps), "dragfree")


register_scenario("yang2020", campaign_scenario,
                  description="Yang et al. 2020: the three drag-free axes with the saturated accelerometers")
