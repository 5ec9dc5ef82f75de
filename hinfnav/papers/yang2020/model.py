"""The drag-free satellite: the 18-state model (1)-(5), its extended form (6)-(8), the per-axis model (10)-(13).

States (SI units), in the paper's order:

* plant (4): ``X_o = [φ_sc, φ̇_sc, r_rel, ṙ_rel, φ_rel, φ̇_rel]`` (18);
* extended (6): ``X = [φ_sc, φ̇_sc, T_Dsc, r_rel, ṙ_rel, F_Dsc, φ_rel, φ̇_rel, T_Dtm]`` (27);
* one drag-free axis (12): ``X = [r, ṙ, f]`` with the accelerometer
  ``y = C X + D(u + w) + d``, ``C = [K/m_tm, D_trans/m_tm, 1/m_sc]``, ``D = 1/m_sc`` (11).

Inputs ``u = [T_Csc, F_Csc, T_Ctm]`` (9), disturbances ``f = [T_Dsc, F_Dsc,
T_Dtm]`` (9), measurements ``Y = [φ_sc, r_rel, φ_rel]`` (9) plus the
accelerometer (3). Discretization is exact with a zero-order hold on
``u + w + f`` over h (8), (13); the extended discrete model is then
``A_d = [[Φ, Γ], [0, I]]`` (in the order [X_o, f]), ``B_d = [Γ; 0]`` and the
increment ``G_k = f_{k+1} − f_k`` enters through ``B_e``.
"""

from dataclasses import dataclass, field

import numpy as np

from ...core.linalg import discretize
from ...core.validation import as_choice, as_positive
from ...systems.state import StateSpec
from .constants import (
    D_ROT,
    D_TRANS,
    DISTURBANCE_AMPLITUDE,
    DISTURBANCE_MEAN,
    DISTURBANCE_PHASES,
    H,
    I_SC,
    I_TM,
    K_ROT,
    K_TRANS,
    M_SC,
    M_TM,
    OMEGA_D_PRINTED,
)

__all__ = [
    "DragFreeModel",
    "drag_free_model",
    "omega_d",
    "disturbance",
    "increment_bounds",
    "noise_std",
    "plant_state_spec",
    "extended_state_spec",
    "dragfree_state_spec",
    "DRAGFREE_INDICES",
    "MEASURED_INDICES",
]

_AX = ("x", "y", "z")
_ANG = ("pitch", "yaw", "roll")

#: Index in the augmented order [X_o (18), f (9)] of each extended state (paper's order (6)).
EXTENDED_FROM_AUGMENTED = np.array(
    [0, 1, 2, 3, 4, 5, 18, 19, 20, 6, 7, 8, 9, 10, 11, 21, 22, 23, 12, 13, 14, 15, 16, 17, 24, 25, 26]
)
#: Indices of (r_x, r_y, r_z, ṙ_x, ṙ_y, ṙ_z, F_x, F_y, F_z) in the extended state: the rows of Γ in (35).
DRAGFREE_INDICES = np.arange(9, 18)
#: Indices of the measured plant states (φ_sc, r_rel, φ_rel) in the 18-state X_o (C_o of (5)).
MEASURED_INDICES = np.array([0, 1, 2, 6, 7, 8, 12, 13, 14])


def _spec(groups_units, axis_names):
    labels, units, groups = [], [], {}
    for group, unit, names in groups_units:
        groups[group] = tuple(range(len(labels), len(labels) + 3))
        labels += [f"{group}_{a}" for a in names]
        units += [unit] * 3
    return StateSpec(labels=tuple(labels), units=tuple(units), groups=groups,
                     axis_names={g: axis_names[g] for g in groups})


def plant_state_spec():
    """Labels, units and groups of the 18-state plant (4)."""
    g = [("attitude", "rad", _ANG), ("rate", "rad/s", _ANG), ("displacement", "m", _AX),
         ("velocity", "m/s", _AX), ("rel_attitude", "rad", _ANG), ("rel_rate", "rad/s", _ANG)]
    return _spec(g, {name: names for name, _, names in g})


def extended_state_spec():
    """Labels, units and groups of the 27-state extended system (6)."""
    g = [("attitude", "rad", _ANG), ("rate", "rad/s", _ANG), ("T_Dsc", "N m", _ANG),
         ("displacement", "m", _AX), ("velocity", "m/s", _AX), ("F_Dsc", "N", _AX),
         ("rel_attitude", "rad", _ANG), ("rel_rate", "rad/s", _ANG), ("T_Dtm", "N m", _ANG)]
    return _spec(g, {name: names for name, _, names in g})


def dragfree_state_spec():
    """Labels, units and groups of the three drag-free axes of Algorithm 2: [r (3), ṙ (3), f (3)]."""
    g = [("displacement", "m", _AX), ("velocity", "m/s", _AX), ("F_Dsc", "N", _AX)]
    return _spec(g, {name: names for name, _, names in g})


def omega_d(reading="hz"):
    """ω_d in rad/s: ``"hz"`` reads the printed 1.2e-3 Hz as a frequency (2π·1.2e-3), ``"rad_s"`` as rad/s."""
    as_choice("omega_d reading", reading, ("hz", "rad_s"))
    return 2.0 * np.pi * OMEGA_D_PRINTED if reading == "hz" else OMEGA_D_PRINTED


def disturbance(t, w_d):
    """The disturbances of Table 2 at times ``t`` (s): ``[T_Dsc (N·m), F_Dsc (N), T_Dtm (N·m)]``, shape (..., 9).

    ``T_Dsc,i = F_Dsc,i = −12.8 + 7.7 sin(ω_d t + 2π(i−1)/3)`` (mN·m, mN) with
    the ``t`` restored in the 2nd and 3rd components; ``T_Dtm = 0``.
    """
    t = np.asarray(t, dtype=float)
    s = DISTURBANCE_MEAN + DISTURBANCE_AMPLITUDE * np.sin(w_d * t[..., None] + DISTURBANCE_PHASES)
    return np.concatenate([s, s, np.zeros_like(s)], axis=-1)


def increment_bounds(w_d, h=H):
    """Assumption 4's bounds ``q_i = (max |df_i/dt| h)²`` of the 9 disturbance increments, N² or (N·m)²."""
    rate = DISTURBANCE_AMPLITUDE * w_d
    return np.array([rate * h] * 6 + [0.0] * 3) ** 2


def noise_std(density, h=H, reading="one_sided"):
    """Per-step standard deviation of white noise given by an amplitude spectral density.

    Parameters
    ----------
    density : array_like
        Amplitude spectral density, unit/√Hz.
    h : float
        Sampling time, s.
    reading : {"one_sided", "two_sided", "per_sample"}
        ``one_sided``: σ² = ASD²/(2h) (a one-sided density over 0..1/(2h));
        ``two_sided``: σ² = ASD²/h; ``per_sample``: σ = the printed number.

    Returns
    -------
    ndarray
    """
    as_choice("noise reading", reading, ("one_sided", "two_sided", "per_sample"))
    h = as_positive("h", h)
    d = np.asarray(density, dtype=float)
    if reading == "one_sided":
        return d / np.sqrt(2.0 * h)
    if reading == "two_sided":
        return d / np.sqrt(h)
    return d.copy()


@dataclass(frozen=True, eq=False)
class DragFreeModel:
    """The drag-free satellite's matrices, continuous and discrete (see the module docstring).

    Attributes
    ----------
    A_o, B_o, C_o : ndarray
        (4)-(5): 18×18, 18×9, 9×18.
    Phi, Gamma : ndarray
        Exact ZOH discretization of (A_o, B_o) over h: 18×18, 18×9.
    A_d, B_d, B_e, C_d : ndarray
        Extended discrete model (8) in the paper's state order: 27×27,
        27×9, 27×9, 9×27.
    axis_A_d, axis_B_d, axis_C, axis_D : ndarray
        Per-axis model (13) for x, y, z: (3, 3, 3), (3, 3), (3, 3), (3,).
    accel_C : ndarray, shape (3, 18)
        The accelerometer's state part on the plant: ``(K_trans r + D_trans ṙ)/m_tm`` (11).
    h : float
    k_rot_sign : float
        +1 as printed in (3), −1 for a restoring K_rot and D_rot.
    """

    A_o: np.ndarray
    B_o: np.ndarray
    C_o: np.ndarray
    Phi: np.ndarray
    Gamma: np.ndarray
    A_d: np.ndarray
    B_d: np.ndarray
    B_e: np.ndarray
    C_d: np.ndarray
    axis_A_d: np.ndarray
    axis_B_d: np.ndarray
    axis_C: np.ndarray
    axis_D: np.ndarray
    accel_C: np.ndarray
    h: float
    k_rot_sign: float
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        for key in ("A_o", "B_o", "C_o", "Phi", "Gamma", "A_d", "B_d", "B_e", "C_d", "axis_A_d", "axis_B_d",
                    "axis_C", "axis_D", "accel_C"):
            getattr(self, key).setflags(write=False)


def _continuous(k_rot_sign):
    Z = np.zeros((3, 3))
    I3 = np.eye(3)
    Isc_inv = np.linalg.inv(I_SC)
    Itm_inv = np.linalg.inv(I_TM)
    A = np.block([
        [Z, I3, Z, Z, Z, Z],
        [Z, Z, Z, Z, Z, Z],
        [Z, Z, Z, I3, Z, Z],
        [Z, Z, -K_TRANS / M_TM, -D_TRANS / M_TM, Z, Z],
        [Z, Z, Z, Z, Z, I3],
        [Z, Z, Z, Z, k_rot_sign * Itm_inv @ K_ROT, k_rot_sign * Itm_inv @ D_ROT],
    ])
    B = np.block([[Z, Z, Z], [Isc_inv, Z, Z], [Z, Z, Z], [Z, -I3 / M_SC, Z], [Z, Z, Z], [-Isc_inv, Z, Itm_inv]])
    C = np.zeros((9, 18))
    C[np.arange(9), MEASURED_INDICES] = 1.0
    return A, B, C


def drag_free_model(*, h=H, k_rot_sign="printed"):
    """Build :class:`DragFreeModel` from Table 2.

    Parameters
    ----------
    h : float
        Sampling time, s (0.1 in the paper).
    k_rot_sign : {"printed", "restoring"}
        The sign of K_rot and D_rot in (3): ``+`` as printed, or ``−``.
    """
    h = as_positive("h", h)
    sign = {"printed": 1.0, "restoring": -1.0}[as_choice("k_rot_sign", k_rot_sign, ("printed", "restoring"))]
    A_o, B_o, C_o = _continuous(sign)
    Phi, Gamma = discretize(A_o, B_o, h)
    # extended (8) in the augmented order [X_o, f], then permuted to the paper's order (6)
    Ad_aug = np.block([[Phi, Gamma], [np.zeros((9, 18)), np.eye(9)]])
    Bd_aug = np.vstack([Gamma, np.zeros((9, 9))])
    Be_aug = np.vstack([np.zeros((18, 9)), np.eye(9)])
    p = EXTENDED_FROM_AUGMENTED
    A_d, B_d, B_e = Ad_aug[np.ix_(p, p)], Bd_aug[p], Be_aug[p]
    C_d = np.hstack([C_o, np.zeros((9, 9))])[:, p]
    # per-axis model (12)-(13): X = [r, v, f], the diagonal of K_trans, D_trans
    axA, axB, axC = np.empty((3, 3, 3)), np.empty((3, 3)), np.empty((3, 3))
    for a in range(3):
        k, d = K_TRANS[a, a] / M_TM, D_TRANS[a, a] / M_TM
        Ac = np.array([[0.0, 1.0, 0.0], [-k, -d, -1.0 / M_SC], [0.0, 0.0, 0.0]])
        Bc = np.array([[0.0], [-1.0 / M_SC], [0.0]])
        Ad, Bd = discretize(Ac, Bc, h)
        axA[a], axB[a] = Ad, Bd[:, 0]
        axC[a] = [k, d, 1.0 / M_SC]
    accel_C = np.zeros((3, 18))
    accel_C[:, 6:9] = K_TRANS / M_TM
    accel_C[:, 9:12] = D_TRANS / M_TM
    info = {"K_rot_eigenvalues": np.linalg.eigvalsh(K_ROT).tolist(),
            "max_unstable_rate_1_s": float(np.max(np.linalg.eigvals(A_o).real))}
    return DragFreeModel(A_o=A_o, B_o=B_o, C_o=C_o, Phi=Phi, Gamma=Gamma, A_d=A_d, B_d=B_d, B_e=B_e, C_d=C_d,
                         axis_A_d=axA, axis_B_d=axB, axis_C=axC, axis_D=np.full(3, 1.0 / M_SC), accel_C=accel_C,
                         h=h, k_rot_sign=sign, info=info)

