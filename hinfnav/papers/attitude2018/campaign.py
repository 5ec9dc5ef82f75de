"""Paper 002's gyroless attitude problem as a campaign scenario: the periodic torque's amplitude T₀ a setting.

:class:`CampaignScenario` is the paper's :class:`~.scenario.Scenario` (its
filters build on it unchanged; ``T0`` and ``orbits`` are among its settings)
with what a campaign needs:

* ``truth_model(hold)``: the rigid body under T_d(t) with the attitude-hold law;
* no ``campaign_truth`` of its own: the campaign runner steps that truth
  (:meth:`~hinfnav.systems.attitude.AttitudeSystem.step`, RK4) by
  :func:`~hinfnav.sim.simulate_truth`, the star-sensor noise
  the campaign's ``noise`` (the truth has no process noise: T_d is given);
* ``bound_problem(conditions, noise)``: the posterior Cramér–Rao bound in the
  error coordinates (δθ, δω) of an estimator that knows T_d(t), the hold law
  and the prior N(x₀, P₀) of the filters (the torque error is then zero): F the
  error-dynamics transition e^{FΔt} at the true rate, H the star-sensor
  Jacobian in δθ, Q = 0 (the truth is deterministic between readings), Λ of
  the sensor noise. With Q = 0 the bound keeps falling as readings accumulate:
  it is what the readings allow with a known torque, not what a filter that
  models the torque as a random walk can reach.
"""

from dataclasses import dataclass

import numpy as np

from ...analysis.pcrb import measurement_information
from ...campaign.registry import register_scenario
from ...estimators.registry import Offers
from ...noise import make_noise
from ...systems.attitude import quat_from_rotvec, rotvec_from_quat
from .scenario import Scenario

__all__ = ["CampaignScenario", "OFFERS"]

#: Quaternion error, star-sensor vectors, the control torque known, nonlinear dynamics.
OFFERS = Offers(error_form="quaternion", measurement="star_vectors", input=True, linear=False,
                models=("attitude2018",))


@dataclass(frozen=True, eq=False)
class CampaignScenario(Scenario):
    """Paper 002's scenario for campaigns (see the module docstring); settings are the Scenario's."""

    offers = OFFERS

    def bound_problem(self, conditions, noise):
        """Ingredients of the posterior CRB on (δθ, δω) (see the module docstring); states as (rotation vector, ω)."""
        system, meas = self.system(truth=True), self.measurement

        def to_state(x):
            return np.concatenate([rotvec_from_quat(x[..., :4]), x[..., 4:7]], axis=-1)

        def full(z):
            return np.concatenate([quat_from_rotvec(z[..., :3]), z[..., 3:6], np.zeros(z.shape[:-1] + (3,))], axis=-1)

        def F(z):
            return system.transition(full(z))[..., :6, :6]

        def H(z):
            return meas.error_jacobian(full(z))[..., :6]

        v = make_noise(noise)
        return {"kind": "pcrb", "F": F, "H": H, "Q": np.zeros((6, 6)), "Lambda": measurement_information(meas.D, v),
                "P0": np.diag(self.P0_std[:6] ** 2), "states": to_state, "groups": {"attitude": (0, 1, 2),
                                                                                   "rate": (3, 4, 5)}}


register_scenario("attitude2018", CampaignScenario,
                  description="paper 002: gyroless star-sensor attitude under the periodic torque (amplitude T0)")
