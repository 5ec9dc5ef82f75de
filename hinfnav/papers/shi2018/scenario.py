"""Shi & Wang (2018)'s scenario: a target drifting about a chaser in low orbit, seen by range and angles.

Rebuilt from what survives of §2–§3 (see :mod:`.constants` for every number
and whether it is the paper's or a choice):

* relative motion of the target with respect to the chaser by the Hill/CW
  equations (18)–(19) in the chaser's orbital frame (x radial, y
  along-track, z orbit normal; n the chaser's orbital rate), the chaser's
  control accelerations f known from an accelerometer (input u = f, here
  zero: the chaser coasts), white disturbance acceleration;
* the exact zero-order-hold discretisation at T = 0.4 s; the disturbance is
  an acceleration held over each step, ``B = Γ σ_a`` (the accelerometer's
  white error);
* range ρ, azimuth α (from the sensor X axis towards +Y) and elevation β
  (towards −Z) of the target, sensor frame = orbital frame, read with white
  noise of σ_ρ, σ_α = σ_β (Gaussian, or the mixture (23));
* the target's maneuver at 500 s: its velocity relative to the chaser
  changes by 0.1 m/s along x, away from the chaser. Neither filter models it.

The generic simulation (:func:`hinfnav.simulate`) runs this scenario without
the maneuver; :meth:`Scenario.simulate_truth` adds the maneuver to the same
noise draws.
"""

from dataclasses import dataclass, field

import numpy as np

from ...core.exceptions import InputError
from ...core.linalg import discretize
from ...core.validation import as_int_at_least, as_positive, as_real, as_vector
from ...noise import MixtureNoise
from ...sim.scenario import Scenario as BaseScenario
from ...sim.truth import Truth, TruthModel, child_rngs, draw_noise, noise_models, simulate_truth
from ...systems.hill import hill_matrices
from ...systems.linear import LinearSystem
from ...systems.measurements import ConvertedPosition, RangeAzimuthElevation
from ...systems.state import chaser_state_spec
from .constants import (
    CALIBRATED_SENSOR_ERRORS,
    DT_S,
    DURATION_S,
    INITIAL_ESTIMATE_ERROR,
    MANEUVER_DV_MPS,
    MANEUVER_TIME_S,
    ORBITAL_RATE,
    P0_STD,
    WINDOW_S,
    initial_state,
)

__all__ = ["Scenario", "ContaminatedNoise", "paper_scenario"]


class ContaminatedNoise(MixtureNoise):
    """The mixture (23) with its narrow component at the sensor's σ: ``(1−ε) N(0, 1) + ε N(0, r²)``.

    Paper 001 writes ``(1−ε) N(0, σ₁) + ε N(0, σ₂)`` with σ₂ = 2σ₁ and σ₁ the
    sensor error of Table 1, so the contamination *adds* variance: the
    filters, told σ₁, see noise of variance ``(1−ε) + ε r²`` times larger
    (2.8 with ε = 0.6, r = 2, reading N(0, σ) as a standard deviation; 1.6
    with r = √2, reading it as a variance). The draws are those of
    :class:`hinfnav.noise.MixtureNoise` (unit variance) scaled by
    ``√((1−ε) + ε r²)``: unlike the other noise models this one does not
    have unit variance, on purpose.

    Parameters
    ----------
    eps : float
        Weight of the wide component (0.6).
    ratio : float
        σ₂/σ₁ (2).
    """

    name = "contaminated"

    @property
    def variance(self):
        """Variance ``(1−ε) + ε r²`` of one sample (the narrow component has 1)."""
        return (1 - self.eps) + self.eps * self.ratio**2

    def _sample(self, rng, shape):
        return super()._sample(rng, shape) * np.sqrt(self.variance)


def _readonly_vector(name, value, n=6):
    v = as_vector(name, value, n)
    v.setflags(write=False)
    return v


@dataclass(frozen=True, eq=False)
class Scenario(BaseScenario):
    """Settings of Shi & Wang (2018)'s scenario as rebuilt here; defaults are the documented choices.

    Attributes
    ----------
    n : float
        Orbital rate of the chaser, rad/s (circular 500 km orbit: 1.1068e-3).
    dt : float
        Navigation period T, s (0.4, the paper's).
    duration_s : float
        Simulated time, s (1000).
    x0 : ndarray, shape (6,)
        Initial relative state of the target (m, m/s): a closed CW orbit,
        (500, 3000, 0, 0, −2An, Bn).
    xhat0 : ndarray, shape (6,)
        Initial estimate of both filters (default x0 + (20, −30, 20, 0.2, 0.2, −0.1)).
    P0 : ndarray, shape (6, 6)
        Initial covariance of both filters (default diag(50, 50, 50, 0.5, 0.5, 0.5)²).
    sigma_range : float
        Range error σ_ρ (1σ), m.
    sigma_angle : float
        Azimuth and elevation error σ_α = σ_β (1σ), rad.
    sigma_accel : float
        Accelerometer error / white disturbance acceleration per sample (1σ), m/s².
    maneuver_time_s, maneuver_dv_mps : float
        The target's maneuver: at this time its relative velocity changes by
        this much along x, away from the chaser.
    rms_window_s : (float, float)
        Window (start, end) of the accuracy statistic (the RMS error), s.
    """

    n: float = ORBITAL_RATE
    dt: float = DT_S
    duration_s: float = DURATION_S
    x0: np.ndarray = field(default_factory=initial_state)
    xhat0: np.ndarray = None
    P0: np.ndarray = field(default_factory=lambda: np.diag(P0_STD**2))
    sigma_range: float = CALIBRATED_SENSOR_ERRORS["sigma_range_m"]
    sigma_angle: float = CALIBRATED_SENSOR_ERRORS["sigma_angle_rad"]
    sigma_accel: float = CALIBRATED_SENSOR_ERRORS["sigma_accel_mps2"]
    maneuver_time_s: float = MANEUVER_TIME_S
    maneuver_dv_mps: float = MANEUVER_DV_MPS
    rms_window_s: tuple = WINDOW_S

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)
        for name in ("n", "dt", "duration_s", "sigma_range", "sigma_angle", "sigma_accel"):
            set_(name, as_positive(name, getattr(self, name)))
        if self.duration_s < self.dt:
            raise InputError(f"duration_s must be at least one sampling time dt = {self.dt}; got {self.duration_s}")
        set_("x0", _readonly_vector("x0", self.x0))
        if np.linalg.norm(self.x0[:3]) == 0:
            raise InputError("x0 must have a non-zero relative position (range and angles are undefined at zero)")
        xhat0 = self.x0 + INITIAL_ESTIMATE_ERROR if self.xhat0 is None else self.xhat0
        set_("xhat0", _readonly_vector("xhat0", xhat0))
        P0 = np.array(self.P0, dtype=float)
        if P0.shape != (6, 6) or not np.all(np.isfinite(P0)) or not np.allclose(P0, P0.T) \
                or np.linalg.eigvalsh(0.5 * (P0 + P0.T)).min() <= 0:
            raise InputError("P0 must be a symmetric positive definite 6x6 matrix")
        P0.setflags(write=False)
        set_("P0", P0)
        set_("maneuver_time_s", as_real("maneuver_time_s", self.maneuver_time_s))
        set_("maneuver_dv_mps", as_real("maneuver_dv_mps", self.maneuver_dv_mps))
        if not 0 < self.maneuver_time_s < self.duration_s:
            raise InputError(f"maneuver_time_s must lie inside the run (0, {self.duration_s}) s; got {self.maneuver_time_s}")
        set_("rms_window_s", self.checked_window("rms_window_s"))

    # -- time -----------------------------------------------------------------

    @property
    def maneuver_step(self):
        """Index k of the first sample after the maneuver (t_k ≥ maneuver_time_s)."""
        return int(np.ceil(self.maneuver_time_s / self.dt - 1e-9))

    # -- model ---------------------------------------------------------------------

    def system(self):
        """Hill/CW relative motion (18)–(19) with the control acceleration as input, T = dt.

        Returns
        -------
        LinearSystem
            State (x, y, z, vx, vy, vz) in m, m/s; input the measured control
            acceleration (fx, fy, fz) in m/s²; ``B = Γ σ_a``.
        """
        A, G = hill_matrices(self.n, 1.0)  # unit mass: the input is an acceleration
        Phi, Gamma = discretize(A, G, self.dt, "exact")
        return LinearSystem(Phi, Gamma, Gamma * self.sigma_accel, self.dt, chaser_state_spec(),
                            ("fx", "fy", "fz"), ("m/s²",) * 3, name="Hill/CW relative motion of the target",
                            info={"omega": self.n, "discretization": "exact"})

    def sensor(self, sigma_range=None, sigma_angle=None):
        """The range/azimuth/elevation sensor (the truth's, or one with other errors, 1σ)."""
        return RangeAzimuthElevation(6, self.sigma_range if sigma_range is None else sigma_range,
                                     self.sigma_angle if sigma_angle is None else sigma_angle)

    def filter_measurement(self, sigma_range=None, sigma_angle=None):
        """The indirect measurement (20)–(22) the filters use: readings converted to position, R_k = J R Jᵀ.

        ``sigma_range``, ``sigma_angle``: the sensor errors the filter is told
        (default the true ones).
        """
        return ConvertedPosition(self.sensor(sigma_range, sigma_angle))

    @property
    def measurement(self):
        """What is measured: the sensor's readings (ρ, α, β)."""
        return self.sensor()

    def sensor_errors(self):
        """The sensor errors as 1σ and as the 3σ of Table 1 (what the reproduction records)."""
        one = {"sigma_range_m": self.sigma_range, "sigma_angle_rad": self.sigma_angle,
               "sigma_accel_mps2": self.sigma_accel}
        return {"one_sigma": one, "three_sigma": {k: 3 * v for k, v in one.items()},
                "three_sigma_angle_deg": float(np.degrees(3 * self.sigma_angle))}

    # -- truth ---------------------------------------------------------------------

    def nominal_trajectory(self, maneuver=False):
        """Noise-free relative state at the sample times, shape (n_steps + 1, 6)."""
        Phi = self.system().Phi
        x = np.empty((self.n_steps + 1, 6))
        x[0] = self.x0
        for k in range(self.n_steps):
            x[k + 1] = Phi @ x[k]
        if maneuver:
            x = x + self.maneuver_response()
        return x

    def maneuver_dv(self):
        """The velocity change of the maneuver, shape (6,): ``(0, 0, 0, ±Δv, 0, 0)``, away from the chaser.

        "Away from the chaser along x" is the sign of the target's x at the
        maneuver time on the noise-free trajectory.
        """
        Phi = self.system().Phi
        x = np.linalg.matrix_power(Phi, self.maneuver_step) @ self.x0
        dv = np.zeros(6)
        dv[3] = self.maneuver_dv_mps * (1.0 if x[0] >= 0 else -1.0)
        return dv

    def maneuver_response(self):
        """The maneuver's effect on the state, ``Φ^(k−k_m) Δ`` for k ≥ k_m, shape (n_steps + 1, 6)."""
        Phi = self.system().Phi
        out = np.zeros((self.n_steps + 1, 6))
        d = self.maneuver_dv()
        for k in range(self.maneuver_step, self.n_steps + 1):
            out[k] = d
            d = Phi @ d
        return out

    def truth_model(self, maneuver=False):
        """What :mod:`hinfnav.sim` needs: system, sensor, x₀, length (no feedback: the chaser coasts).

        Parameters
        ----------
        maneuver : bool
            Must be False: the target's maneuver is an impulse that the
            generic truth model cannot carry; :meth:`simulate_truth` adds it.
        """
        if not isinstance(maneuver, (bool, np.bool_)):
            raise InputError(f"maneuver must be True or False; got {maneuver!r}")
        if maneuver:
            raise InputError("maneuver=True: the target's impulse is not part of the generic truth model; use "
                             "Scenario.simulate_truth(maneuver=True) or hinfnav.papers.shi2018.simulate_case")
        return TruthModel(self.system(), self.sensor(), self.x0, self.n_steps, None, {"maneuver": False})

    def simulate_truth(self, *, maneuver=False, noise="gaussian", measurement_noise=None, runs=1, seed=0, first_run=0):
        """Truth and readings, with or without the target's maneuver.

        Without maneuver this is :func:`hinfnav.sim.simulate_truth` on
        :meth:`truth_model`. With it, the same noise draws (run r from the
        r-th child generator of ``seed``, w first, then v) drive the state
        plus the maneuver's response, and the readings are taken again from
        that state with the same v: the two truths of one seed differ by the
        maneuver alone.

        Returns
        -------
        hinfnav.sim.Truth
        """
        if not isinstance(maneuver, (bool, np.bool_)):
            raise InputError(f"maneuver must be True or False; got {maneuver!r}")
        model = self.truth_model()
        truth = simulate_truth(model, noise=noise, measurement_noise=measurement_noise, runs=runs, seed=seed,
                               first_run=first_run)
        if not maneuver:
            return truth
        runs = as_int_at_least("runs", runs, 1)
        first_run = as_int_at_least("first_run", first_run, 0)
        w_model, v_model = noise_models(noise, measurement_noise, self.dt)
        rngs = child_rngs(seed, runs, first_run)
        _, v = draw_noise(w_model, v_model, rngs, model.n_steps + 1, model.system.n_noise, model.measurement.n_noise)
        x = truth.x + self.maneuver_response()
        settings = dict(truth.settings, maneuver=True, maneuver_time_s=self.maneuver_time_s,
                        maneuver_dv_mps=float(self.maneuver_dv()[3]))
        return Truth(t=truth.t, x=x, u=truth.u, y=model.measurement.measure(x, v), settings=settings,
                     state=truth.state, measurement=model.measurement)


def paper_scenario(**changes):
    """The scenario as rebuilt here, optionally with some settings changed."""
    return Scenario(**changes)
