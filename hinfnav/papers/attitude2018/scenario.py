"""Paper 002's simulation scenario (§3): the satellite, its torque, its star sensor, the filters' start.

What the paper prints is in :mod:`.constants`; what it lost (J, Δt, the
reference vectors, the true initial state, the control torque, the run length)
is a documented choice here. The truth is the rigid body (A3)–(A4) driven by
the paper's torque T_d(t) and held near the orbital frame by an attitude-hold
law on the true state whose torque the filters are told (the paper's known
control torque T_c; no wheels, h = 0); the filters never see T_d.
"""

from dataclasses import dataclass, field

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_matrix, as_positive, as_vector
from ...sim.scenario import Scenario as BaseScenario
from ...sim.truth import TruthModel
from ...systems.attitude import (
    QUAT,
    RATE,
    AttitudeSystem,
    StarSensorVectors,
    quat_from_euler321,
    rotvec_from_quat,
)
from .constants import (
    ALTITUDE_M,
    DEFAULT_DT,
    DEFAULT_EULER0_DEG,
    DEFAULT_HOLD_DAMPING,
    DEFAULT_HOLD_NATURAL_FREQ,
    DEFAULT_J,
    DEFAULT_P0_STD,
    DEFAULT_REFERENCES,
    HARMONICS,
    PAPER_Q_ASTEKF,
    PAPER_Q_BEST_AEKF,
    PAPER_R,
    SIGNS,
    T0_NM,
    orbit_rate,
)

__all__ = ["AttitudeHold", "Scenario", "default_epsilon"]


class AttitudeHold:
    """Attitude-hold law on the true state, ``T_c = −J (ω_n² δθ + 2 ζ ω_n ω)``, vectorized over runs.

    δθ is the rotation vector of q (the orbital frame is the target attitude).
    It only keeps the body near the orbital frame, where paper 002 defines
    T_d; the filters are told T_c, so (to first order) their errors do not
    depend on it.
    """

    source = "truth"

    def __init__(self, J, natural_freq, damping):
        self.J = as_matrix("J", J, (3, 3))
        self.natural_freq = as_positive("natural_freq", natural_freq)
        self.damping = as_positive("damping", damping)
        self.name = "attitude hold"

    def __call__(self, x):
        x = np.asarray(x, dtype=float)
        wn, z = self.natural_freq, self.damping
        return -(wn**2 * rotvec_from_quat(x[..., QUAT]) + 2 * z * wn * x[..., RATE]) @ self.J.T


def default_epsilon(Q0=PAPER_Q_ASTEKF, Q_target=PAPER_Q_BEST_AEKF, T0=T0_NM, omega_e=None):
    """The AAEKF's compression factor ε, s/(N·m) (documented choice, not in the paper).

    Chosen so that the adapted density ``Q0 (ε κ)²`` reaches the paper's best
    AEKF value ``Q_target`` at the largest torque rate the paper's torque can
    have, ``T₀ · 8 ω_e``: ε = √(Q_target/Q0) / (8 T₀ ω_e) ≈ 1.17e8 s/(N·m).
    """
    omega_e = orbit_rate() if omega_e is None else omega_e
    return float(np.sqrt(Q_target / Q0) / (HARMONICS.max() * T0 * omega_e))


@dataclass(frozen=True, eq=False)
class Scenario(BaseScenario):
    """Paper 002's scenario; defaults are the paper's numbers and the documented choices.

    Attributes
    ----------
    J : ndarray, shape (3, 3)
        Inertia, kg·m² (lost; :data:`~.constants.DEFAULT_J`).
    dt : float
        Sampling time, s (lost; 1 s).
    altitude_m : float
        Circular-orbit altitude, m (650 km: ω_e = 0.06148839356680 °/s).
    T0 : float
        Torque amplitude, N·m (1e-5).
    references : ndarray, shape (k, 3)
        Star directions in the orbital frame (lost; x and z axes).
    R : float
        Star-sensor noise variance per component (1e-10).
    euler0_deg : ndarray, shape (3,)
        True initial 3-2-1 Euler angles, deg (lost; 0.5, −0.5, 0.5).
    rate0 : ndarray, shape (3,)
        True initial body rate, rad/s (lost; 0).
    P0_std : ndarray, shape (9,)
        Filters' initial standard deviations (rad, rad/s, N·m).
    hold_natural_freq, hold_damping : float
        Attitude-hold law (lost; 0.02 rad/s, 0.7).
    orbits : float
        Simulated length in orbital periods (2: every torque period repeats).
    """

    J: np.ndarray = field(default_factory=lambda: DEFAULT_J.copy())
    dt: float = DEFAULT_DT
    altitude_m: float = ALTITUDE_M
    T0: float = T0_NM
    references: np.ndarray = field(default_factory=lambda: DEFAULT_REFERENCES.copy())
    R: float = PAPER_R
    euler0_deg: np.ndarray = field(default_factory=lambda: DEFAULT_EULER0_DEG.copy())
    rate0: np.ndarray = field(default_factory=lambda: np.zeros(3))
    P0_std: np.ndarray = field(default_factory=lambda: DEFAULT_P0_STD.copy())
    hold_natural_freq: float = DEFAULT_HOLD_NATURAL_FREQ
    hold_damping: float = DEFAULT_HOLD_DAMPING
    orbits: float = 2.0

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)
        for key in ("dt", "altitude_m", "T0", "R", "hold_natural_freq", "hold_damping", "orbits"):
            set_(key, as_positive(key, getattr(self, key)))
        for key, shape in (("J", (3, 3)), ("references", (None, 3))):
            arr = as_matrix(key, getattr(self, key), shape)
            arr.setflags(write=False)
            set_(key, arr)
        for key, size in (("euler0_deg", 3), ("rate0", 3), ("P0_std", 9)):
            arr = as_vector(key, getattr(self, key), size)
            arr.setflags(write=False)
            set_(key, arr)
        if np.any(self.P0_std <= 0):
            raise InputError("P0_std must be > 0 in every error coordinate")
        if self.duration_s < 10 * self.dt:
            raise InputError(f"orbits must give at least 10 samples; got {self.duration_s} s at dt = {self.dt} s")

    # -- orbit and torque --------------------------------------------------------------

    @property
    def omega_e(self):
        """Orbit rate ω_e, rad/s."""
        return orbit_rate(self.altitude_m)

    @property
    def orbital_period(self):
        """2π/ω_e, s."""
        return 2 * np.pi / self.omega_e

    @property
    def frequencies(self):
        """Torque frequencies (6, 4, 8) ω_e, rad/s."""
        return HARMONICS * self.omega_e

    def torque(self, t):
        """``T_d(t) = [−T₀ sin 6ω_e t, T₀ sin 4ω_e t, −T₀ sin 8ω_e t]``, N·m; shape t.shape + (3,)."""
        t = np.asarray(t, dtype=float)
        return SIGNS * self.T0 * np.sin(np.multiply.outer(t, self.frequencies))

    def torque_rate(self, t):
        """``dT_d/dt``, N·m/s; shape t.shape + (3,)."""
        t = np.asarray(t, dtype=float)
        return SIGNS * self.T0 * self.frequencies * np.cos(np.multiply.outer(t, self.frequencies))

    # -- length and windows ---------------------------------------------------------------

    @property
    def duration_s(self):
        """Simulated time, ``orbits`` orbital periods rounded up to a sample, s."""
        return float(np.ceil(self.orbits * self.orbital_period / self.dt) * self.dt)

    @property
    def rms_window_s(self):
        """RMS window, s: the last orbit (after at least half the run for convergence).

        For the default two orbits: the second orbit, where every torque period repeats.
        """
        return (max(self.duration_s - self.orbital_period, 0.5 * self.duration_s), self.duration_s)

    # -- the objects the generic layers read ------------------------------------------------

    def system(self, truth=False):
        """The filters' model (torque a random walk) or, with ``truth=True``, the truth (torque T_d(t))."""
        return AttitudeSystem(self.J, self.dt, disturbance=self.torque if truth else None)

    @property
    def measurement(self):
        """Star-sensor vectors (A7) with R = σ² I, σ = √R."""
        return StarSensorVectors(self.references, np.sqrt(self.R))

    @property
    def controller(self):
        """The attitude-hold law on the true state."""
        return AttitudeHold(self.J, self.hold_natural_freq, self.hold_damping)

    @property
    def x0(self):
        """True initial state [q, ω, T_d(0)]."""
        q = quat_from_euler321(np.radians(self.euler0_deg))
        return np.concatenate([q, self.rate0, self.torque(0.0)])

    @property
    def xhat0(self):
        """Filters' initial state (paper): q = [0, 0, 0, 1], ω = 0, T_d = 0."""
        x = np.zeros(10)
        x[3] = 1.0
        return x

    @property
    def P0(self):
        """Filters' initial covariance in error coordinates, diag(P0_std²)."""
        return np.diag(self.P0_std**2)

    def truth_model(self, hold=True):
        """What the simulation layer needs (run with :func:`hinfnav.sim.simulate_truth`).

        Parameters
        ----------
        hold : bool
            Attitude-hold law on (default) or free drift (T_c = 0).
        """
        if not isinstance(hold, (bool, np.bool_)):
            raise InputError(f"hold must be True or False; got {hold!r}")
        return TruthModel(self.system(truth=True), self.measurement, self.x0, self.n_steps,
                          self.controller if hold else None, {"hold": bool(hold)})

    def short(self, orbits=0.25):
        """A shorter copy (tests and notebooks)."""
        return self.replace(orbits=orbits)

