"""The paper's scenario (Section 4), transcribed once.

Everything numeric that the paper prints lives here: ω₀, chaser mass, the
feedback gain K (from Gao, Yang & Shi 2009), the initial truth and filter
states, the noise matrices B and D, L, and the published filter
(A_F, B_F, C_F) designed at δ̄ = 0.05. What the paper does not print (the
sampling time, the run length, the error window) is a documented choice.
"""

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from .exceptions import InputError
from .models import (
    UncertainSystem,
    delta_A1,
    discretize,
    hill_matrices,
    measurement_matrix,
    uncertainty_structure,
)
from .validation import as_matrix, as_nonnegative, as_positive, as_real, as_vector

__all__ = [
    "Scenario",
    "PublishedFilter",
    "PAPER_K",
    "published_filter",
    "infer_sampling_time",
    "paper_scenario",
]

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
    """

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    delta_bar: float = 0.05


def published_filter():
    """The published filter matrices A_F, B_F, C_F of Section 4 (copies)."""
    return PublishedFilter(_PAPER_AF.copy(), _PAPER_BF.copy(), _PAPER_CF.copy())


def infer_sampling_time(A_F=None, B_F=None):
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


def _readonly(name, value, shape):
    arr = as_matrix(name, value, shape)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class Scenario:
    """Settings of one relative-navigation scenario; defaults are the paper's.

    Attributes
    ----------
    omega0 : float
        Nominal orbital rate of the target, rad/s (24 h orbit: 7.2722e-5).
    mass : float
        Chaser mass, kg (1000).
    dt : float
        Sampling time T, s. Not printed in the paper; 0.1 s is read off the
        published filter by :func:`infer_sampling_time`.
    K : ndarray, shape (3, 6)
        State-feedback gain of (3), u = K x, N per (m, m/s).
    x0 : ndarray, shape (6,)
        Initial relative state (600, 550, 1040, 0.02, −0.08, 0.03), m and m/s.
    xhat0 : ndarray, shape (6,)
        Initial state estimate of the filters (630, 520, 1000, 0, 0, 0).
    B : ndarray, shape (6, 6)
        Process-noise matrix diag(0.05, 0.05, 0.05, 0.001, 0.001, 0.001).
    D : ndarray, shape (3, 3)
        Measurement-noise matrix diag(0.1, 0.1, 0.1) (0.1 m accuracy).
    L : ndarray, shape (6, 6)
        Estimated signal z = L x; the identity (the whole state).
    delta_bar : float
        Uncertainty bound δ̄ of the design (0.05 for the published filter).
    duration_s : float
        Simulated time, s. Not printed in the paper; 1000 s covers the
        ~500 s thrust phase of Fig 6 and a steady part after it.
    rms_window_s : tuple of float
        Time window (start, end) of the RMS error, s. Starts at 100 s, after
        every filter's initial transient (the initial estimate is 30–40 m
        off) and inside the EKF's 500 s failure with maneuver.
    """

    omega0: float = 7.2722e-5
    mass: float = 1000.0
    dt: float = 0.1
    K: np.ndarray = field(default_factory=lambda: PAPER_K.copy())
    x0: np.ndarray = field(default_factory=lambda: np.array([600.0, 550.0, 1040.0, 0.02, -0.08, 0.03]))
    xhat0: np.ndarray = field(default_factory=lambda: np.array([630.0, 520.0, 1000.0, 0.0, 0.0, 0.0]))
    B: np.ndarray = field(default_factory=lambda: np.diag([0.05, 0.05, 0.05, 0.001, 0.001, 0.001]))
    D: np.ndarray = field(default_factory=lambda: np.diag([0.1, 0.1, 0.1]))
    L: np.ndarray = field(default_factory=lambda: np.eye(6))
    delta_bar: float = 0.05
    duration_s: float = 1000.0
    rms_window_s: tuple = (100.0, 1000.0)

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        set_("omega0", as_positive("omega0", self.omega0))
        set_("mass", as_positive("mass", self.mass))
        set_("dt", as_positive("dt", self.dt))
        set_("delta_bar", as_nonnegative("delta_bar", self.delta_bar))
        set_("duration_s", as_positive("duration_s", self.duration_s))
        set_("K", _readonly("K", self.K, (3, 6)))
        for name in ("x0", "xhat0"):
            v = as_vector(name, getattr(self, name), 6)
            v.setflags(write=False)
            set_(name, v)
        set_("B", _readonly("B", self.B, (6, None)))
        set_("D", _readonly("D", self.D, (3, None)))
        set_("L", _readonly("L", self.L, (None, 6)))
        try:
            start, end = (float(t) for t in self.rms_window_s)
        except (TypeError, ValueError):
            raise InputError(f"rms_window_s must be a pair (start, end) in seconds; got {self.rms_window_s!r}") from None
        if not (0 <= start < end <= self.duration_s):
            raise InputError(
                f"rms_window_s must satisfy 0 <= start < end <= duration_s = {self.duration_s}; got ({start}, {end})"
            )
        set_("rms_window_s", (start, end))
        if self.duration_s < self.dt:
            raise InputError(f"duration_s must be at least one sampling time dt = {self.dt}; got {self.duration_s}")

    def replace(self, **changes):
        """A copy with some settings changed (validated again)."""
        return dataclasses.replace(self, **changes)

    @property
    def n_steps(self):
        """Number of sampling intervals, ``round(duration_s / dt)``."""
        return int(round(self.duration_s / self.dt))

    @property
    def time(self):
        """Sample times ``t_k = k T``, shape (n_steps + 1,), s."""
        return np.arange(self.n_steps + 1) * self.dt

    def continuous_matrices(self, delta=0.0):
        """``(A₀(ω₀(1+δ)), G₀)`` of (2), shapes (6, 6) and (6, 3)."""
        delta = as_real("delta", delta)
        return hill_matrices(self.omega0 * (1.0 + delta), self.mass)

    def truth_matrices(self, delta=0.0, discretization="exact"):
        """Discrete truth model ``x(k+1) = Φ x(k) + Γ u(k)`` (open loop).

        Parameters
        ----------
        delta : float
            True orbital-rate error δ of (4), any real number > −1 (the
            truth is not bound by δ̄).
        discretization : {"exact", "euler"}

        Returns
        -------
        Phi : ndarray, shape (6, 6)
        Gamma : ndarray, shape (6, 3)
        """
        delta = as_real("delta", delta)
        if delta <= -1:
            raise InputError(f"delta must be > -1 (the orbital rate ω₀(1+δ) must be positive); got {delta}")
        A0, G0 = self.continuous_matrices(delta)
        return discretize(A0, G0, self.dt, discretization)

    def design_model(self, delta_bar=None):
        """The uncertain discrete closed-loop system ψ_d of (6)–(11).

        ``A = I + T(A₁ + G₀K)`` (Euler, as in the paper), ``H = T H_a`` and
        ``E = E_a`` of Section 4 (the zero columns of H_a / rows of E_a are
        kept here; the synthesis drops them), ``C = [I 0]``.

        Parameters
        ----------
        delta_bar : float, optional
            Uncertainty bound; defaults to ``self.delta_bar``. With 0 the
            system is returned without H and E (nominal design).

        Returns
        -------
        UncertainSystem
        """
        delta_bar = self.delta_bar if delta_bar is None else as_nonnegative("delta_bar", delta_bar)
        A1, G0 = hill_matrices(self.omega0, self.mass)
        A = np.eye(6) + self.dt * (A1 + G0 @ self.K)
        H = E = None
        if delta_bar > 0:
            Ha, Ea = uncertainty_structure(self.omega0, delta_bar)
            H, E = self.dt * Ha, Ea
        return UncertainSystem(A, self.B, measurement_matrix(), self.D, self.L, H, E, self.dt)

    def design_A(self, delta=0.0):
        """Euler closed-loop matrix with a given δ: ``I + T(A₁ + ΔA₁(δ) + G₀K)``."""
        A1, G0 = hill_matrices(self.omega0, self.mass)
        return np.eye(6) + self.dt * (A1 + delta_A1(self.omega0, delta) + G0 @ self.K)

    def input_matrix_design(self):
        """Input matrix of the Euler design model, ``T G₀``, shape (6, 3)."""
        _, G0 = hill_matrices(self.omega0, self.mass)
        return self.dt * G0


def paper_scenario(**changes):
    """The paper's scenario, optionally with some settings changed."""
    return Scenario(**changes)
