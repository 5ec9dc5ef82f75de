"""Sun et al. (2011): every number the paper prints, transcribed once.

ω₀, chaser mass and the feedback gain K (from Gao, Yang & Shi 2009) are in
:class:`~hinfnav.papers.sun2011.scenario.Scenario`'s defaults; here are the
gain, the published filter (A_F, B_F, C_F) designed at δ̄ = 0.05, Table 1,
the citation, and the documented choices that fill what the paper leaves out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ...core.validation import as_matrix

__all__ = [
    "CITATION",
    "PAPER_K",
    "PAPER_TABLE1",
    "DEFAULT_DELTA_BARS",
    "DEFAULT_P0_STD",
    "DEFAULT_SIGMA_RANGE",
    "DEFAULT_SIGMA_ANGLE",
    "PublishedFilter",
    "published_filter",
    "infer_sampling_time",
]

CITATION = (
    "Sun Zhao-wei, Deng Hong, Liu Hao, Zhong Wei-chao, \"Relative navigation algorithm for chaser satellite "
    "based on robust H-infinity filtering\", Journal of Astronautics 32(7):1462-1470, 2011, "
    "doi:10.3873/j.issn.1000-1328.2011.07.005"
)

#: Table 1 of the paper (None where it prints "—").
PAPER_TABLE1 = {
    "no_maneuver": {"ekf": {"pos_m": 0.04, "vel_mps": 0.001}, "hinf": {"pos_m": 0.2, "vel_mps": 0.8}},
    "maneuver": {"ekf": {"pos_m": None, "vel_mps": None}, "hinf": {"pos_m": 0.2, "vel_mps": 0.8}},
}

#: The δ̄ values of the design sweep (notebook 03).
DEFAULT_DELTA_BARS = (0.0, 0.01, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)

#: Default initial standard deviations of the EKF, (m, m, m, m/s, m/s, m/s).
#: The paper's initial estimate (630, 520, 1000, 0, 0, 0) is off the truth
#: (600, 550, 1040, 0.02, −0.08, 0.03) by (30, 30, 40) m and
#: (0.02, 0.08, 0.03) m/s; 50 m and 0.1 m/s put each of those inside one σ.
DEFAULT_P0_STD = np.array([50.0, 50.0, 50.0, 0.1, 0.1, 0.1])
#: Default range noise of the range/angle model, m (the paper's 0.1 m accuracy).
DEFAULT_SIGMA_RANGE = 0.1
#: Default angle noise of the range/angle model, rad: 0.1 m across the line of
#: sight at the initial range of ~1.3 km is ~1e-4 rad.
DEFAULT_SIGMA_ANGLE = 1e-4

#: Feedback gain K of (3), N per (m, m/s); Section 4, from Gao, Yang & Shi (2009).
PAPER_K = np.array(
    [
        [-2.2541, -0.0071, -0.0072, -22.3975, 2.3256, 1.9369],
        [-0.0104, -2.2493, -0.0055, 2.3259, -23.7456, 1.4544],
        [-0.0072, -0.0055, -2.2471, 1.9357, 1.4552, -24.2818],
    ]
)

_PAPER_AF = np.array(
    [
        [-0.6126, -0.0053, -0.0046, 0.1, -1.7e-6, -1.0e-6],
        [-0.0052, -0.6083, -0.0035, -1.5e-6, 0.1, -1.4e-6],
        [-0.0046, -0.0035, -0.6066, -1.5e-6, -5.6e-7, 0.1],
        [-6.1302, -0.0390, -0.0337, 0.9980, 1.1e-4, 8.2e-5],
        [-0.0385, -6.0991, -0.0259, 8.0e-5, 0.9979, 6.3e-5],
        [-0.0337, -0.0259, -6.0864, 8.3e-5, 6.4e-5, 0.9979],
    ]
)

_PAPER_BF = np.array(
    [
        [-1.6126, -0.0053, -0.0046],
        [-0.0052, -1.6083, -0.0035],
        [-0.0046, -0.0035, -1.6066],
        [-6.1300, -0.0390, -0.0337],
        [-0.0385, -6.0989, -0.0259],
        [-0.0337, -0.0259, -6.0862],
    ]
)

# Printed as 1e-6 x [...] with -1e6 on the diagonal, i.e. C_F ≈ -I.
_PAPER_CF = 1e-6 * np.array(
    [
        [-1e6, 0.0489, 0.0247, 6.3345, -5.4934, -4.3894],
        [0.0386, -1e6, 0.0418, -5.3662, 10.3349, -2.9326],
        [0.0420, 0.0148, -1e6, -4.5742, -2.9659, 11.3677],
        [-0.3164, 0.3131, 0.1588, -999960, -33.635, -28.487],
        [0.2469, -0.5593, 0.2630, -33.612, -999935, -19.564],
        [0.2712, 0.0939, -0.5821, -28.520, -19.572, -999927],
    ]
)


@dataclass(frozen=True, eq=False)
class PublishedFilter:
    """The filter (12) printed in Section 4 (δ̄ = 0.05, MATLAB LMI toolbox).

    Attributes
    ----------
    A_F : ndarray, shape (6, 6)
    B_F : ndarray, shape (6, 3)
    C_F : ndarray, shape (6, 6)
    delta_bar : float
        The uncertainty bound it was designed for, 0.05.
    dt : float
        The sampling time it was designed for, s: not printed, 0.1 s read off
        A_F and B_F by :func:`infer_sampling_time`.
    """

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    delta_bar: float = 0.05
    dt: float = 0.1


def published_filter() -> PublishedFilter:
    """The published filter matrices A_F, B_F, C_F of Section 4 (copies)."""
    return PublishedFilter(_PAPER_AF.copy(), _PAPER_BF.copy(), _PAPER_CF.copy())


def infer_sampling_time(A_F: ArrayLike | None = None, B_F: ArrayLike | None = None) -> tuple[float, float]:
    """Infer the sampling time T from the published filter.

    The paper never prints T. With the indirect measurement ``C = [I 0]``
    the filter only acts on position through ``B_F C``, so its first three
    rows keep the plant's structure ``A = I + T(A₁ + G₀K)``: the
    position-to-position block is ``I + B_F[:3]`` (because ``C_F ≈ −I`` the
    filter state is ``−x̂``) and the velocity-to-position block is ``T I``.
    T is read off the mean diagonal of ``A_F[:3, 3:]``; the consistency of the
    other block, ``A_F[:3, :3] − B_F[:3] = I``, is returned as a residual.

    Returns
    -------
    T : float
        Sampling time, s (0.1 for the published matrices).
    residual : float
        ``max |A_F[:3, :3] − B_F[:3, :] − I|`` (0 up to print rounding).
    """
    pub = published_filter()
    A_F = pub.A_F if A_F is None else as_matrix("A_F", A_F, (6, 6))
    B_F = pub.B_F if B_F is None else as_matrix("B_F", B_F, (6, 3))
    T = float(np.mean(np.diag(A_F[:3, 3:])))
    residual = float(np.max(np.abs(A_F[:3, :3] - B_F[:3, :] - np.eye(3))))
    return T, residual


