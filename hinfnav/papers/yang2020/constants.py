"""Yang et al. (2020): every number the paper prints, transcribed once.

Table 2 (system parameters), the simulation paragraph of Section 3 (sampling
time, noise densities, accelerometer range, actuator bounds, increment
bounds, initial estimates) and the controller gains, exactly as printed, with
the unit each value is used in. Where the print is ambiguous or wrong the
reading is a named choice (:data:`READINGS`) with its reason; the
alternatives stay available through :class:`~hinfnav.papers.yang2020.Scenario`.
"""

import numpy as np

__all__ = [
    "CITATION",
    "TABLE2",
    "M_TM",
    "M_SC",
    "I_TM",
    "I_SC",
    "K_TRANS",
    "D_TRANS",
    "K_ROT",
    "D_ROT",
    "DISTURBANCE_MEAN",
    "DISTURBANCE_AMPLITUDE",
    "DISTURBANCE_PHASES",
    "OMEGA_D_PRINTED",
    "H",
    "INPUT_NOISE_DENSITY",
    "SENSOR_NOISE_DENSITY",
    "ACCELEROMETER_NOISE_DENSITY",
    "ACCELEROMETER_RANGE",
    "ACTUATOR_BOUND",
    "P0_DIAGONAL",
    "NLPID_GAINS",
    "FAL_ALPHA",
    "FAL_DELTA",
    "PID_GAINS",
    "STEP_COMMAND",
    "STEP_ON",
    "STEP_OFF",
    "REQUIREMENT_ASD",
    "REQUIREMENT_BAND_HZ",
    "READINGS",
    "READING_REASONS",
]

CITATION = (
    "Yang Fei, Tan Shu-Ping, Xue Wen-Chao, Guo Jin, Zhao Yan-Long, \"Extended state filtering with "
    "saturation-constrained observations and active disturbance rejection control of position and attitude "
    "for drag-free satellites\", Acta Automatica Sinica 46(11):2337-2349, 2020, doi:10.16383/j.aas.c190515"
)

# ---------------------------------------------------------------------------
# Table 2 (SI units; the printed unit is in TABLE2 below)
# ---------------------------------------------------------------------------

#: Test-mass mass m_tm, kg.
M_TM = 1.0
#: Spacecraft mass m_sc, kg (printed "1 050 kg").
M_SC = 1050.0
#: Test-mass inertia I_tm, kg·m².
I_TM = 0.2667e-3 * np.eye(3)
#: Spacecraft inertia I_sc, kg·m².
I_SC = np.array([[200.0, 1.0, 2.0], [1.0, 2700.0, 1.0], [2.0, 1.0, 2650.0]])
#: Translational stiffness K_trans, N/m.
K_TRANS = np.array([[1.0, 0.039, 0.039], [0.039, 1.0, 0.039], [0.039, 0.039, 1.0]]) * 1e-6
#: Translational damping D_trans, used in N·s/m (printed "N·m·s/rad", a copy of D_rot's unit).
D_TRANS = 1.4e-11 * np.eye(3)
#: Rotational stiffness K_rot, N·m/rad (indefinite: eigenvalues 21e-9, -9e-9, -9e-9).
K_ROT = np.array([[1.0, 10.0, 10.0], [10.0, 1.0, 10.0], [10.0, 10.0, 1.0]]) * 1e-9
#: Rotational damping D_rot, N·m·s/rad.
D_ROT = 1.4e-11 * np.eye(3)
#: Constant part of T_Dsc (N·m) and F_Dsc (N): -12.8 mN·m, -12.8 mN.
DISTURBANCE_MEAN = -12.8e-3
#: Amplitude of the periodic part: 7.7 mN·m, 7.7 mN.
DISTURBANCE_AMPLITUDE = 7.7e-3
#: Phases of the three components: sin(ω_d t), sin(ω_d + 2π/3), sin(ω_d + 4π/3) as printed.
DISTURBANCE_PHASES = np.array([0.0, 2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0])
#: ω_d as printed: 1.2e-3 with the unit "Hz".
OMEGA_D_PRINTED = 1.2e-3

# ---------------------------------------------------------------------------
# Section 3, the simulation paragraph
# ---------------------------------------------------------------------------

#: Sampling and actuation period h, s.
H = 0.1
#: Input-noise densities of w_TCsc, w_FCsc, w_TCtm, printed "N·s⁻²/√Hz"; used in N·m/√Hz, N/√Hz, N·m/√Hz.
INPUT_NOISE_DENSITY = np.array([1e-8, 1e-8, 1e-15])
#: Displacement and attitude sensor noise density, m/√Hz (rad/√Hz for the attitudes).
SENSOR_NOISE_DENSITY = 1e-8
#: Accelerometer noise density, printed "m/√Hz"; used in m·s⁻²/√Hz.
ACCELEROMETER_NOISE_DENSITY = 1e-12
#: Accelerometer range [y_lower, y_upper], m/s².
ACCELEROMETER_RANGE = (-6e-6, 6e-6)
#: Actuator bounds ρ₁ = ρ₂ = ρ₃, printed "0.03 N" for all three (N·m for the torques).
ACTUATOR_BOUND = 0.03
#: Initial error covariance of Algorithms 1-3: diagonal, every entry 0.01 (initial estimates 0).
P0_DIAGONAL = 0.01

# ---------------------------------------------------------------------------
# Controller (Section 3)
# ---------------------------------------------------------------------------

#: NLPID gains (k_p, k_i, k_d) on fal(e_p), fal(e_i), fal(e_d) of each loop.
NLPID_GAINS = {
    "attitude": (0.001, 0.0001, 0.01),  # T_Csc0, per pitch/yaw/roll
    "dragfree": (0.5, 0.01, 1.9),  # F_Csc0, per x/y/z
    "relative_attitude": (0.0001, 0.0, 0.0021),  # T_Ctm0: no integral term printed
}
#: fal(e, α, δ) parameters: fal(e) ≡ fal(e, 0.5, 0.01).
FAL_ALPHA = 0.5
FAL_DELTA = 0.01
#: The tuned PID of the comparison (Fig 9): K_P, K_I, K_D on the drag-free loop.
PID_GAINS = (5.55, 0.0, 9.0)
#: Attitude step command φ_sc (pitch, yaw, roll), rad (printed "/rad"), from step 1e5, back to 0 at 2e5.
STEP_COMMAND = np.array([0.01, 0.02, 0.03])
STEP_ON = 100_000
STEP_OFF = 200_000

#: LISA Pathfinder requirement quoted for Fig 12, m·s⁻²/√Hz, over 1-30 mHz.
REQUIREMENT_ASD = 3e-14
REQUIREMENT_BAND_HZ = (1e-3, 30e-3)

#: Table 2 and the simulation paragraph as printed (value, printed unit, unit used).
TABLE2 = {
    "m_tm": {"value": M_TM, "printed_unit": "kg", "unit": "kg"},
    "m_sc": {"value": M_SC, "printed_unit": "kg", "unit": "kg"},
    "I_tm": {"value": I_TM.tolist(), "printed_unit": "kg·m²", "unit": "kg m^2"},
    "I_sc": {"value": I_SC.tolist(), "printed_unit": "kg·m²", "unit": "kg m^2"},
    "K_trans": {"value": K_TRANS.tolist(), "printed_unit": "N/m", "unit": "N/m"},
    "D_trans": {"value": D_TRANS.tolist(), "printed_unit": "N·m·s/rad", "unit": "N s/m"},
    "K_rot": {"value": K_ROT.tolist(), "printed_unit": "N·m/rad", "unit": "N m/rad"},
    "D_rot": {"value": D_ROT.tolist(), "printed_unit": "N·m·s/rad", "unit": "N m s/rad"},
    "T_Dsc": {"value": "-12.8 + 7.7 sin(w_d t), -12.8 + 7.7 sin(w_d + 2pi/3), -12.8 + 7.7 sin(w_d + 4pi/3)",
              "printed_unit": "mN·m", "unit": "N m (read with t in every component)"},
    "F_Dsc": {"value": "-12.8 + 7.7 sin(w_d t), -12.8 + 7.7 sin(w_d + 2pi/3), -12.8 + 7.7 sin(w_d + 4pi/3)",
              "printed_unit": "mN", "unit": "N (read with t in every component)"},
    "T_Dtm": {"value": 0.0, "printed_unit": "", "unit": "N m"},
    "omega_d": {"value": OMEGA_D_PRINTED, "printed_unit": "Hz", "unit": "Hz (omega_d = 2 pi 1.2e-3 rad/s)"},
    "h": {"value": H, "printed_unit": "s", "unit": "s"},
    "input_noise_density": {"value": INPUT_NOISE_DENSITY.tolist(), "printed_unit": "N·s⁻²/√Hz",
                            "unit": "N/sqrt(Hz) (N m/sqrt(Hz) for the torques)"},
    "sensor_noise_density": {"value": SENSOR_NOISE_DENSITY, "printed_unit": "m/√Hz",
                             "unit": "m/sqrt(Hz) (rad/sqrt(Hz) for attitudes)"},
    "accelerometer_noise_density": {"value": ACCELEROMETER_NOISE_DENSITY, "printed_unit": "m/√Hz",
                                    "unit": "m s^-2/sqrt(Hz)"},
    "accelerometer_range": {"value": list(ACCELEROMETER_RANGE), "printed_unit": "m·s⁻²", "unit": "m s^-2"},
    "actuator_bound": {"value": ACTUATOR_BOUND, "printed_unit": "N", "unit": "N (N m for the torques), |u_i| <= rho"},
    "P0_diagonal": {"value": P0_DIAGONAL, "printed_unit": "", "unit": "SI units of each state squared"},
    "nominal_disturbance": {"value": 0.0, "printed_unit": "", "unit": "f_bar = 0"},
    "increment_bound": {"value": "q_i = (max(df_i/dt) h)^2", "printed_unit": "", "unit": "N^2, (N m)^2"},
    "nlpid_gains": {"value": {k: list(v) for k, v in NLPID_GAINS.items()}, "printed_unit": "",
                    "unit": "fal(e, 0.5, 0.01)"},
    "pid_gains": {"value": list(PID_GAINS), "printed_unit": "", "unit": "K_P, K_I, K_D"},
    "step_command": {"value": STEP_COMMAND.tolist(), "printed_unit": "/rad", "unit": "rad",
                     "steps": [STEP_ON, STEP_OFF]},
    "requirement": {"value": REQUIREMENT_ASD, "printed_unit": "m·s⁻²·Hz^-1/2", "unit": "m s^-2/sqrt(Hz)",
                    "band_hz": list(REQUIREMENT_BAND_HZ)},
}

#: The ambiguities of the print, each with the reading used by default (first) and the alternatives.
READINGS = {
    "omega_d": ("hz", "rad_s"),
    "phase_time": ("with_t",),
    "noise": ("one_sided", "two_sided", "per_sample"),
    "k_rot_sign": ("printed", "restoring"),
    "fused_covariance": ("symmetric", "printed", "block"),
    "integral": ("off", "printed", "dt"),
    "residual": ("test_mass", "relative", "accelerometer"),
    "timing": ("posterior", "prior"),
}

#: Why each default reading was chosen (quoted in the notebooks and summary.json).
READING_REASONS = {
    "omega_d": "printed unit Hz: omega_d = 2*pi*1.2e-3 rad/s, period 833 s, inside the 1-30 mHz band; "
               "'rad_s' (period 5236 s, 0.19 mHz, below the band) is kept as the alternative",
    "phase_time": "the t missing in the 2nd and 3rd components is a typesetting loss: sin(omega_d + 2pi/3) "
                  "would add a dimensioned frequency to a phase and make two components constant",
    "noise": "densities are one-sided amplitude spectral densities (the LISA convention, and what "
             "scipy.signal.welch returns): per-step variance = ASD^2 / (2 h); 'two_sided' uses ASD^2 / h, "
             "'per_sample' uses the printed number as the per-step standard deviation",
    "k_rot_sign": "as printed (+K_rot, +D_rot in (3)); K_rot is indefinite so either sign leaves one "
                  "unstable relative-attitude mode, which the law (46) compensates",
    "fused_covariance": "Lambda1 P1 + Lambda2 P2 (39) is not symmetric; its symmetric part is used "
                        "('printed' keeps it as is, 'block' drops the (r, v)-f cross-covariances)",
    "integral": "the printed integral terms (e_i = sum of errors over steps, gains 0.0001 and 0.01) make the "
                "attitude and drag-free loops unstable in fal's linear region (Routh: 0.1*0.01 < 0.01 and "
                "19*5 < 1050*1); Section 3 says the ADRC of Fig 9 uses the tuned PID with K_I = 0, so the "
                "integral is off by default; 'printed' (sum) and 'dt' (h*sum) are run as studies",
    "timing": "the accelerometer is read at t_k just before the new command (the actuator still holds u_(k-1), "
              "the disturbance is f(t_k)) and u_k is computed from the filtered estimate, the usual discrete "
              "simulation loop; 'prior' takes (13) literally (the reading contains u_k), so u_k must come from the "
              "prior estimate and the disturbance compensation lags one step (residual up to h w_d 7.7 mN)",
    "residual": "Fig 12's 'non-conservative acceleration on the test mass': the coupling acceleration "
                "-(K_trans r + D_trans v)/m_tm (the accelerometer noise alone, 1e-12, exceeds 3e-14); "
                "'relative' is the true relative acceleration r'' the accelerometer senses, "
                "'accelerometer' its noisy reading",
}
