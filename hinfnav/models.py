"""Relative-motion models of the paper, Sections 1 and 4.

The state is ``x = [x, y, z, ẋ, ẏ, ż]`` (m, m/s) in the target's orbital frame
(x radial, z along the orbit normal), the input is the chaser's thrust
``u = [Fx, Fy, Fz]`` (N).

Continuous model, Hill equations (1)–(2)::

    ẋ = A₀(ω) x + G₀ u,          u = K x   (3)

Orbital-rate uncertainty (4)–(5): ``ω = ω₀(1 + δ)``, so
``A₀(ω) = A₁ + ΔA₁(δ)`` with ``A₁ = A₀(ω₀)``.

Discrete design model (6), Euler: ``A = I + T(A₁ + G₀K)``, ``ΔA = T ΔA₁``.
The truth is simulated with the exact zero-order-hold discretization
(matrix exponential) unless Euler is asked for.

Norm-bounded structure (10)–(11) of Section 4: ``ΔA₁ = H_a F(δ) E_a`` with
``F(δ)ᵀF(δ) ≤ I`` for ``|δ| ≤ δ̄``.
"""

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .exceptions import InputError
from .validation import as_choice, as_matrix, as_nonnegative, as_positive, as_real

__all__ = [
    "N_STATE",
    "N_INPUT",
    "N_MEAS",
    "hill_matrices",
    "delta_A1",
    "uncertainty_structure",
    "uncertainty_F",
    "discretize",
    "measurement_matrix",
    "spectral_radius",
    "UncertainSystem",
]

N_STATE = 6
N_INPUT = 3
N_MEAS = 3


def hill_matrices(omega, mass):
    """Continuous Hill model (2).

    Parameters
    ----------
    omega : float
        Orbital rate of the target, rad/s.
    mass : float
        Chaser mass, kg.

    Returns
    -------
    A0 : ndarray, shape (6, 6)
        State matrix ``A₀(ω)`` of (2).
    G0 : ndarray, shape (6, 3)
        Input matrix ``G₀ = [0; I]/m`` of (2) (thrust in N to acceleration).
    """
    omega = as_real("omega", omega)
    mass = as_positive("mass", mass)
    A0 = np.zeros((6, 6))
    A0[:3, 3:] = np.eye(3)
    A0[3, 0] = 3.0 * omega**2
    A0[3, 4] = 2.0 * omega
    A0[4, 3] = -2.0 * omega
    A0[5, 2] = -(omega**2)
    G0 = np.vstack([np.zeros((3, 3)), np.eye(3)]) / mass
    return A0, G0


def delta_A1(omega0, delta):
    """The uncertain part ``ΔA₁(δ) = A₀(ω₀(1+δ)) − A₀(ω₀)`` of (5).

    Returns
    -------
    ndarray, shape (6, 6)
    """
    omega0 = as_positive("omega0", omega0)
    delta = as_real("delta", delta)
    dA = np.zeros((6, 6))
    dA[3, 0] = 3.0 * omega0**2 * (2 * delta + delta**2)
    dA[3, 4] = 2.0 * omega0 * delta
    dA[4, 3] = -2.0 * omega0 * delta
    dA[5, 2] = -(omega0**2) * (2 * delta + delta**2)
    return dA


def uncertainty_structure(omega0, delta_bar):
    """The matrices ``H_a`` and ``E_a`` of Section 4, as printed (6x6).

    Parameters
    ----------
    omega0 : float
        Nominal orbital rate ω₀, rad/s.
    delta_bar : float
        Uncertainty bound δ̄ ≥ 0 of (4).

    Returns
    -------
    H_a, E_a : ndarray, shape (6, 6)
        With ``ΔA₁(δ) = H_a F(δ) E_a`` (continuous time). The discrete
        uncertainty (6) is ``ΔA = (T H_a) F E_a``. Columns 1 and 5 of ``H_a``
        (and rows 1 and 5 of ``E_a``) are zero; the synthesis drops them.

    Notes
    -----
    ``F`` is built by :func:`uncertainty_F`. Entry ``(2δ + δ²/2δ̄ + δ̄²)`` of the
    printed ``F_Δa`` means ``(2δ + δ²)/(2δ̄ + δ̄²)``.
    """
    omega0 = as_positive("omega0", omega0)
    delta_bar = as_nonnegative("delta_bar", delta_bar)
    H = np.zeros((6, 6))
    H[3, 0] = 3.0 * omega0
    H[3, 4] = 2.0
    H[4, 3] = -2.0
    H[5, 2] = -omega0
    E = np.zeros((6, 6))
    E[0, 0] = E[2, 2] = omega0 * (2 * delta_bar + delta_bar**2)
    E[3, 3] = E[4, 4] = omega0 * delta_bar
    return H, E


def uncertainty_F(delta, delta_bar):
    """The uncertain matrix ``F_Δa(δ)`` of Section 4 (6x6, diagonal).

    Raises
    ------
    InputError
        If ``delta_bar`` is not positive or ``|delta| > delta_bar``.
    """
    delta = as_real("delta", delta)
    delta_bar = as_positive("delta_bar", delta_bar)
    if abs(delta) > delta_bar * (1 + 1e-12):
        raise InputError(f"delta must satisfy |delta| <= delta_bar = {delta_bar}; got {delta}")
    quad = (2 * delta + delta**2) / (2 * delta_bar + delta_bar**2)
    return np.diag([quad, 0.0, quad, delta / delta_bar, delta / delta_bar, 0.0])


def discretize(Ac, Gc, dt, method="exact"):
    """Discretize ``ẋ = Ac x + Gc u`` with a zero-order hold on ``u``.

    Parameters
    ----------
    Ac : array_like, shape (n, n)
    Gc : array_like, shape (n, m)
    dt : float
        Sampling time T, s.
    method : {"exact", "euler"}
        ``"euler"``: ``(I + T Ac, T Gc)``, the paper's (6).
        ``"exact"``: ``(e^{Ac T}, ∫₀ᵀ e^{Ac s} ds Gc)``.

    Returns
    -------
    Ad : ndarray, shape (n, n)
    Gd : ndarray, shape (n, m)

    Notes
    -----
    The two agree to first order in T; the Euler error is
    ``T² Ac²/2 + O(T³)`` (tested in ``tests/test_models.py``).
    """
    Ac = as_matrix("Ac", Ac)
    n = Ac.shape[0]
    if Ac.shape != (n, n):
        raise InputError(f"Ac must be square; got shape {Ac.shape}")
    Gc = as_matrix("Gc", Gc, (n, None))
    dt = as_positive("dt", dt)
    as_choice("discretization method", method, ("exact", "euler"))
    if method == "euler":
        return np.eye(n) + dt * Ac, dt * Gc
    m = Gc.shape[1]
    M = np.zeros((n + m, n + m))
    M[:n, :n] = Ac * dt
    M[:n, n:] = Gc * dt
    E = scipy.linalg.expm(M)
    return E[:n, :n], E[:n, n:]


def measurement_matrix():
    """The indirect position measurement ``C = [I₃ 0]`` of (8), shape (3, 6)."""
    return np.hstack([np.eye(3), np.zeros((3, 3))])


def spectral_radius(A):
    """Largest eigenvalue modulus of a square matrix."""
    return float(np.max(np.abs(np.linalg.eigvals(np.asarray(A, dtype=float)))))


@dataclass(frozen=True, eq=False)
class UncertainSystem:
    """The uncertain discrete system ψ_d of (9)–(11).

    ``x(k+1) = (A + H F E) x(k) + B w(k)``, ``y(k) = C x(k) + D v(k)``,
    ``z(k) = L x(k)``, with ``FᵀF ≤ I``.

    Attributes
    ----------
    A : ndarray, shape (n, n)
    B : ndarray, shape (n, p)
    C : ndarray, shape (m, n)
    D : ndarray, shape (m, q)
    L : ndarray, shape (l, n)
    H : ndarray, shape (n, r) or None
    E : ndarray, shape (r, n) or None
    dt : float
        Sampling time, s.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray
    H: np.ndarray = None
    E: np.ndarray = None
    dt: float = 1.0

    def __post_init__(self):
        A = as_matrix("A", self.A)
        n = A.shape[0]
        if A.shape != (n, n):
            raise InputError(f"A must be square; got shape {A.shape}")
        checked = {
            "A": A,
            "B": as_matrix("B", self.B, (n, None)),
            "C": as_matrix("C", self.C, (None, n)),
            "L": as_matrix("L", self.L, (None, n)),
        }
        checked["D"] = as_matrix("D", self.D, (checked["C"].shape[0], None))
        if (self.H is None) != (self.E is None):
            raise InputError("H and E must be given together (or both left out for a nominal system)")
        if self.H is not None:
            H = as_matrix("H", self.H, (n, None))
            checked["H"] = H
            checked["E"] = as_matrix("E", self.E, (H.shape[1], n))
        for key, value in checked.items():
            value.setflags(write=False)
            object.__setattr__(self, key, value)
        object.__setattr__(self, "dt", as_positive("dt", self.dt))

    @property
    def n(self):
        """State dimension."""
        return self.A.shape[0]

    def perturbed_A(self, F):
        """``A + H F E`` for a given uncertainty matrix ``F`` (shape (r, r))."""
        if self.H is None:
            return self.A.copy()
        F = as_matrix("F", F, (self.H.shape[1], self.E.shape[0]))
        return self.A + self.H @ F @ self.E
