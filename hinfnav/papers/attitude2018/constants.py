"""Paper 002: every number it prints, transcribed once, and the documented choices that fill what it lost.

"基于星敏感器的卫星姿态估计方法研究" (Research on satellite attitude estimation based
on star sensors), Navigation Positioning and Timing (导航定位与授时) 2018 no. 1,
pp. 42–47 (authors lost in the extraction). What survives and what is rebuilt
is listed in notebook 20 and in ``/work/shared/REFERENCE.md``.
"""

import numpy as np

__all__ = [
    "ALTITUDE_M",
    "CITATION",
    "DEFAULT_AA",
    "DEFAULT_DT",
    "DEFAULT_EULER0_DEG",
    "DEFAULT_HOLD_DAMPING",
    "DEFAULT_HOLD_NATURAL_FREQ",
    "DEFAULT_J",
    "DEFAULT_P0_STD",
    "DEFAULT_REFERENCES",
    "DEFAULT_ST",
    "EARTH_RADIUS_M",
    "HARMONICS",
    "MU_EARTH_M3_S2",
    "PAPER_OMEGA_E_DEG_S",
    "PAPER_Q_ASTEKF",
    "PAPER_Q_BEST_AEKF",
    "PAPER_R",
    "Q_SWEEP",
    "SIGNS",
    "T0_NM",
    "orbit_rate",
    "orbital_period",
    "torque_periods",
]

CITATION = (
    "\"Research on satellite attitude estimation based on star sensors\" (基于星敏感器的卫星姿态估计方法研究), "
    "Navigation Positioning and Timing (导航定位与授时) 2018 no. 1, pp. 42-47 (authors lost in the extraction)"
)

# -- printed in the paper ------------------------------------------------------------

#: ω_e printed for a 650 km circular orbit, deg/s.
PAPER_OMEGA_E_DEG_S = 0.06148839356680
#: Orbit altitude, m.
ALTITUDE_M = 650e3
#: Amplitude T_dx0 = T_dy0 = T_dz0 of the disturbance torque, N·m.
T0_NM = 1e-5
#: Frequencies of T_d in multiples of ω_e: ω_φ = 6 ω_e, ω_θ = 4 ω_e, ω_ψ = 8 ω_e.
HARMONICS = np.array([6.0, 4.0, 8.0])
#: Signs of T_d = [−T₀ sin 6ω_e t, T₀ sin 4ω_e t, −T₀ sin 8ω_e t].
SIGNS = np.array([-1.0, 1.0, -1.0])
#: Star-sensor noise covariance per reference vector, R = 1e-10 I₃.
PAPER_R = 1e-10
#: The AEKF's best torque noise density (Figs 8–9), Q = 1e-14 I₃, (N·m)²/s.
PAPER_Q_BEST_AEKF = 1e-14
#: The ASTEKF's noise density (Figs 8–9), Q = 1e-16 I₃, (N·m)²/s.
PAPER_Q_ASTEKF = 1e-16

# -- reconstructed constants ------------------------------------------------------------

#: Mean Earth radius, m. With μ below it reproduces the printed ω_e to 1e-10 relative.
EARTH_RADIUS_M = 6371.0e3
#: Gravitational parameter, m³/s² (3.986006e14, the value of Chinese textbooks such as
#: 章仁为 1998, the paper's ref. [10]; 3.986004418e14 would give ω_e 2e-7 lower).
MU_EARTH_M3_S2 = 3.986006e14
#: The Q sweep of the reproduction: one value per decade from 1e-18 to 1e-10, (N·m)²/s.
Q_SWEEP = tuple(10.0 ** k for k in range(-18, -9))


def orbit_rate(altitude_m=ALTITUDE_M, radius_m=EARTH_RADIUS_M, mu=MU_EARTH_M3_S2):
    """Mean motion ``ω_e = √(μ / (R_E + h)³)`` of a circular orbit, rad/s."""
    return float(np.sqrt(mu / (radius_m + altitude_m) ** 3))


def orbital_period(altitude_m=ALTITUDE_M):
    """Orbital period ``2π/ω_e``, s (5854.76 s at 650 km)."""
    return 2.0 * np.pi / orbit_rate(altitude_m)


def torque_periods(altitude_m=ALTITUDE_M):
    """Periods of the three torque components, s (975.8, 1463.7, 731.8 at 650 km)."""
    return orbital_period(altitude_m) / HARMONICS


# -- documented choices for what the paper lost -----------------------------------------------

#: Inertia of a 100 kg-class three-axis stabilized small satellite, kg·m² (the printed J is lost).
DEFAULT_J = np.diag([15.0, 12.0, 10.0])
#: Sampling time of the star sensor and the filters, s (lost; 1 Hz star-sensor output).
DEFAULT_DT = 1.0
#: Reference vectors C_I in the orbital frame: two orthogonal stars (the paper needs two non-parallel).
DEFAULT_REFERENCES = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
#: True initial attitude, 3-2-1 Euler angles (φ, θ, ψ), deg; the filters start at q = [0, 0, 0, 1].
DEFAULT_EULER0_DEG = np.array([0.5, -0.5, 0.5])
#: Initial standard deviations of the filters: attitude (rad), rate (rad/s), torque (N·m).
DEFAULT_P0_STD = np.array([np.radians(1.0)] * 3 + [1e-3] * 3 + [2 * T0_NM] * 3)
#: Attitude-hold law T_c = −J(ω_n² δθ + 2ζω_n ω) on the true state: natural frequency, rad/s.
DEFAULT_HOLD_NATURAL_FREQ = 0.02
#: Damping ratio of the attitude-hold law.
DEFAULT_HOLD_DAMPING = 0.7
#: Strong-tracking defaults: forgetting factor ρ, weakening factor β (Zhou, Xi & Zhang 1991 use ρ = 0.95).
DEFAULT_ST = {"rho": 0.95, "beta": 1.0}
#: AAEKF defaults: memory m of the rate estimate (steps), Q(t₀) (N·m)²/s, floor. ε is set by :func:`default_epsilon`.
DEFAULT_AA = {"memory_steps": 60, "Q0": PAPER_Q_ASTEKF, "floor": 1.0}
