"""Shi & Wang (2018) with a high-fidelity truth: two-body + J2 motion of both spacecraft (issue 35, item 3).

The paper simulates "high-precision orbit dynamics" (采用高精度轨道动力学仿真2颗航天器的空间飞行轨迹, §3);
the reproduction's truth is the filters' own CW model, so the EKF is the Kalman filter of its truth and no
filter can beat it under Gaussian noise. Here the truth's deterministic part is replaced by the relative
motion of two spacecraft each integrated under two-body + J2 (the GRACE chapter's models,
:mod:`hinfnav.papers.grace2010.dynamics`, a declared crossing), the filters left unchanged (CW):

* the chaser on a circular orbit of radius (μ/n²)^{1/3} (the scenario's rate n under two-body), inclination
  :data:`INCLINATION_DEG` (a choice; the paper names none), ascending node at t = 0;
* the target at the scenario's x₀ relative to it, mapped to inertial by the inverse of the Hill-frame
  transformation (G2) (x radial, y along-track, z normal: the scenario's frame);
* both integrated by RK4 at the navigation period T = 0.4 s (:data:`SUBSTEPS` steps per T), the relative
  state read back in the chaser's Hill frame at every sample;
* the white disturbance acceleration and the maneuver enter as in the CW truth (their CW response is added:
  their size, 1e-4 m/s² and 0.1 m/s, keeps the response linear); the readings are taken again from this
  truth with the same measurement noise draws, so the two truths of a seed differ by the deterministic
  mismatch alone.
"""

from dataclasses import dataclass, fields
from functools import lru_cache

import numpy as np

from ...core.validation import as_int_at_least, as_real
from ...sim.truth import Truth, child_rngs, draw_noise, noise_models
from ..grace2010.dataset import hill_to_inertial, inertial_to_hill
from ..grace2010.dynamics import pair, rk4, two_body_j2
from .constants import MU_EARTH
from .scenario import Scenario

__all__ = ["HighFidelityScenario", "SUBSTEPS", "high_fidelity", "relative_trajectory"]

#: Inclination of the chaser's orbit, degrees (a choice: J2's differential effect depends on it).
INCLINATION_DEG = 45.0
#: RK4 steps per navigation period (0.4 s steps: the integration error over 1000 s is far below a millimetre).
SUBSTEPS = 1


def relative_trajectory(scenario, *, inclination_deg=INCLINATION_DEG, substeps=SUBSTEPS):
    """Noise-free relative state of the target in the chaser's Hill frame under two-body + J2, (n_steps + 1, 6).

    Cached per (x₀, n, T, steps, inclination, substeps): a read-only array.
    """
    inc = float(as_real("inclination_deg", inclination_deg))
    substeps = as_int_at_least("substeps", substeps, 1)
    return _trajectory(tuple(float(v) for v in scenario.x0), float(scenario.n), float(scenario.dt),
                       int(scenario.n_steps), inc, substeps)


@lru_cache(maxsize=8)
def _trajectory(x0, n, dt, n_steps, inclination_deg, substeps):
    inc = np.radians(inclination_deg)
    r0 = (MU_EARTH / n**2) ** (1.0 / 3.0)
    rc = np.array([r0, 0.0, 0.0])
    vc = np.sqrt(MU_EARTH / r0) * np.array([0.0, np.cos(inc), np.sin(inc)])
    rd, vd = hill_to_inertial(rc, vc, np.array(x0))
    X = np.concatenate([rc, vc, rd, vd])
    f = pair(two_body_j2)
    states = np.empty((n_steps + 1, 12))
    states[0] = X
    for k in range(n_steps):
        X = rk4(f, X, k * dt, dt / substeps, substeps)
        states[k + 1] = X
    out = inertial_to_hill(states[:, :3], states[:, 3:6], states[:, 6:9], states[:, 9:12])
    out.setflags(write=False)
    return out


def high_fidelity(scenario, **changes):
    """The :class:`HighFidelityScenario` with every setting of ``scenario`` (a :class:`.scenario.Scenario`)."""
    values = {f.name: getattr(scenario, f.name) for f in fields(Scenario)}
    values.update(changes)
    return HighFidelityScenario(**values)


@dataclass(frozen=True, eq=False)
class HighFidelityScenario(Scenario):
    """The scenario with the two-body + J2 truth of the module docstring; the filters still see CW.

    Attributes
    ----------
    inclination_deg : float
        Of the chaser's orbit (:data:`INCLINATION_DEG`).
    """

    inclination_deg: float = INCLINATION_DEG

    def nominal_high_fidelity(self):
        """:func:`relative_trajectory` of this scenario (noise-free, no maneuver)."""
        return relative_trajectory(self, inclination_deg=self.inclination_deg)

    def simulate_truth(self, *, maneuver=False, noise="gaussian", measurement_noise=None, runs=1, seed=0, first_run=0):
        """The CW truth of the same draws with its noise-free part replaced by the two-body + J2 one."""
        cw = super().simulate_truth(maneuver=maneuver, noise=noise, measurement_noise=measurement_noise, runs=runs,
                                    seed=seed, first_run=first_run)
        x = cw.x - self.nominal_trajectory() + self.nominal_high_fidelity()
        model = self.truth_model()
        w_model, v_model = noise_models(noise, measurement_noise, self.dt)
        rngs = child_rngs(seed, as_int_at_least("runs", runs, 1), as_int_at_least("first_run", first_run, 0))
        _, v = draw_noise(w_model, v_model, rngs, model.n_steps + 1, model.system.n_noise, model.measurement.n_noise)
        settings = dict(cw.settings, truth="two-body + J2 (both spacecraft), CW noise response",
                        inclination_deg=self.inclination_deg)
        return Truth(t=cw.t, x=x, u=cw.u, y=model.measurement.measure(x, v), settings=settings, state=cw.state,
                     measurement=model.measurement)
