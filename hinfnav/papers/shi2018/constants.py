"""What Shi & Wang (2018) print, and the documented choices that replace what the extraction lost.

The paper's equations (1)–(22), Table 1 (sensor errors, 3σ) and Table 2
(results) are lost. What survives and is used here: T = 0.4 s (§3), γ =
1.345 (§1.2), the mixture (23) with ε = 0.6 and σ₂ = 2σ₁ (§3.2), the target's
maneuver at t = 500 s, 0.1 m/s away from the chaser along x (§3.3), and the
Gaussian-case accuracies HBF 2.03 m / 0.04 m/s, EKF 3.59 m / 0.11 m/s
(§3.1). Every other number here is a choice, said so where it is defined.
"""

import numpy as np

__all__ = [
    "CITATION",
    "PAPER_RESULTS",
    "PAPER_CLAIMS",
    "MU_EARTH",
    "R_EARTH_M",
    "ALTITUDE_M",
    "ORBITAL_RATE",
    "DT_S",
    "DURATION_S",
    "WINDOW_S",
    "GAMMA",
    "MIXTURE_EPS",
    "MIXTURE_RATIO",
    "MANEUVER_TIME_S",
    "MANEUVER_DV_MPS",
    "RELATIVE_ORBIT",
    "initial_state",
    "INITIAL_ESTIMATE_ERROR",
    "P0_STD",
    "CALIBRATION_TARGET",
    "CALIBRATED_SENSOR_ERRORS",
]

CITATION = (
    "Shi Changyong, Wang Xiang, \"Huber-based filtering in relative navigation of non-cooperative spacecraft\" "
    "(Huber-based滤波在非合作航天器相对导航中的应用), Aerospace Control (航天控制) 2018 no. 5"
)

#: The only numbers of the results that survive (§3.1, Gaussian sensor errors of Table 1).
#: The statistic behind them is not stated.
PAPER_RESULTS = {
    "gaussian": {"hbf": {"pos_m": 2.03, "vel_mps": 0.04}, "ekf": {"pos_m": 3.59, "vel_mps": 0.11}},
}

#: The paper's claims without numbers (Table 2 and Figs 3–6 are lost).
PAPER_CLAIMS = {
    "gaussian": "HBF errors smaller and smoother than the EKF's (Figs 3-4): 2.03 m / 0.04 m/s against 3.59 m / 0.11 m/s",
    "mixture": "under the Gaussian mixture (23), eps = 0.6, sigma2 = 2 sigma1, the HBF navigates better than the EKF "
               "(Table 2, lost)",
    "maneuver": "target maneuver at t = 500 s, 0.1 m/s away along x: the EKF senses the velocity change faster, the "
                "HBF with some delay but more smoothly, and its final accuracy is still higher (Figs 5-6)",
}

#: Earth's gravitational parameter, m³/s² (WGS-84).
MU_EARTH = 3.986004418e14
#: Earth's equatorial radius, m (WGS-84).
R_EARTH_M = 6378137.0
#: Chaser orbit altitude, m: a choice ("circular low orbit"; the paper names none).
ALTITUDE_M = 500e3
#: Orbital rate n of the chaser's circular orbit, rad/s (1.1068e-3, period 5677 s).
ORBITAL_RATE = float(np.sqrt(MU_EARTH / (R_EARTH_M + ALTITUDE_M) ** 3))

#: Navigation period T, s (§3).
DT_S = 0.4
#: Simulated time, s: a choice (the maneuver at 500 s needs time on both sides; 2500 steps).
DURATION_S = 1000.0
#: Window of the accuracy statistic, s: a choice, after the initial transient (filter time constant ~30 s).
WINDOW_S = (200.0, 1000.0)

#: Huber threshold γ (§1.2: "usually 1.345").
GAMMA = 1.345
#: Mixture (23): weight ε of the wide component (§3.2).
MIXTURE_EPS = 0.6
#: Mixture (23): σ₂/σ₁ (§3.2), reading N(0, σ) as N(mean, standard deviation).
MIXTURE_RATIO = 2.0

#: Target maneuver (§3.3): time, s, and velocity change away from the chaser along x, m/s.
MANEUVER_TIME_S = 500.0
MANEUVER_DV_MPS = 0.1

#: The target's relative orbit about the chaser, a choice: a drift-free (closed) CW orbit
#: x = A cos nt, y = y_c − 2A sin nt, z = B sin nt, in the chaser's orbital frame
#: (x radial, y along-track, z orbit normal). Ranges 2.1–3.0 km over the run.
RELATIVE_ORBIT = {"A_m": 500.0, "y_c_m": 3000.0, "B_m": 300.0}


def initial_state(n=ORBITAL_RATE, A_m=500.0, y_c_m=3000.0, B_m=300.0):
    """Initial relative state of the closed CW orbit above, (m, m/s): (A, y_c, 0, 0, −2An, Bn)."""
    return np.array([A_m, y_c_m, 0.0, 0.0, -2.0 * A_m * n, B_m * n])


#: Initial estimate error x̂₀ − x₀ of both filters, (m, m/s): a choice, within one σ of P₀.
INITIAL_ESTIMATE_ERROR = np.array([20.0, -30.0, 20.0, 0.2, 0.2, -0.1])
#: Initial standard deviations of both filters, (m, m/s): a choice.
P0_STD = np.array([50.0, 50.0, 50.0, 0.5, 0.5, 0.5])

#: What the sensor errors are calibrated to: the EKF's Gaussian-case accuracy (§3.1),
#: read as the RMS over the window and over the three axes (see :mod:`.calibration`).
CALIBRATION_TARGET = {"pos_m": 3.59, "vel_mps": 0.11}

#: The sensor errors (1σ) that give the EKF the target accuracy in the Kalman (Riccati) sense,
#: from :func:`hinfnav.papers.shi2018.calibrate_sensor_errors` (rounded to 5 digits; the test
#: suite recomputes them). Range and line-of-sight angles are tied by σ_ρ = ρ₀ σ_α (isotropic
#: converted-position noise at the initial range ρ₀); the accelerometer error is the white
#: disturbance acceleration per sample. Table 1 gives 3σ values: multiply by 3 (94.1 m, 1.77°,
#: 0.077 m/s²).
CALIBRATED_SENSOR_ERRORS = {"sigma_range_m": 31.359, "sigma_angle_rad": 0.0103108, "sigma_accel_mps2": 0.0256677}
