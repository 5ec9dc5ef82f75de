"""Hill relative motion of a chaser about a target on a circular orbit (Sun et al. 2011, Sections 1 and 4).

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

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import discretize
from ..core.validation import as_nonnegative, as_positive, as_real
from .linear import LinearSystem
from .measurements import LinearMeasurement
from .state import chaser_state_spec

__all__ = [
    "hill_matrices",
    "delta_A1",
    "uncertainty_structure",
    "uncertainty_F",
    "measurement_matrix",
    "hill_system",
    "position_measurement",
]

def hill_matrices(omega: float, mass: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
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
    if not math.isfinite(omega * omega):
        raise InputError(f"omega = {omega:g} rad/s is too large: ω² overflows")
    A0 = np.zeros((6, 6))
    A0[:3, 3:] = np.eye(3)
    A0[3, 0] = 3.0 * omega**2
    A0[3, 4] = 2.0 * omega
    A0[4, 3] = -2.0 * omega
    A0[5, 2] = -(omega**2)
    G0 = np.vstack([np.zeros((3, 3)), np.eye(3)]) / mass
    return A0, G0


def delta_A1(omega0: float, delta: float) -> NDArray[np.float64]:
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


def uncertainty_structure(omega0: float, delta_bar: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
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
    if not (math.isfinite(delta_bar * delta_bar) and math.isfinite(omega0 * (2 * delta_bar + delta_bar * delta_bar))):
        raise InputError(f"delta_bar = {delta_bar:g} is too large: ω₀(2δ̄ + δ̄²) overflows")
    E = np.zeros((6, 6))
    E[0, 0] = E[2, 2] = omega0 * (2 * delta_bar + delta_bar**2)
    E[3, 3] = E[4, 4] = omega0 * delta_bar
    return H, E


def uncertainty_F(delta: float, delta_bar: float) -> NDArray[np.float64]:
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


def measurement_matrix() -> NDArray[np.float64]:
    """The indirect position measurement ``C = [I₃ 0]`` of (8), shape (3, 6)."""
    return np.hstack([np.eye(3), np.zeros((3, 3))])




def hill_system(omega: float, mass: float, dt: float, B: ArrayLike, *, K: ArrayLike | None = None, discretization: str = "exact",
                name: str = "Hill relative motion") -> LinearSystem:
    """The Hill model (1)–(2) discretized with a zero-order hold, as a :class:`LinearSystem`.

    Parameters
    ----------
    omega : float
        Orbital rate of the target, rad/s.
    mass : float
        Chaser mass, kg.
    dt : float
        Sampling time, s.
    B : array_like, shape (6, p)
        Process-noise matrix (unit-variance w).
    K : array_like, shape (3, 6), optional
        State-feedback gain: with it the system is the closed loop
        ``Φ + Γ K`` with no input (a filter that assumes the law u = K x).
    discretization : {"exact", "euler"}

    Returns
    -------
    LinearSystem
        State (x, y, z, vx, vy, vz) in m and m/s; input thrust (Fx, Fy, Fz) in N.
    """
    A0, G0 = hill_matrices(omega, mass)
    Phi, Gamma = discretize(A0, G0, dt, discretization)
    info = {"omega": float(omega), "mass": float(mass), "discretization": discretization}
    if K is not None:
        Phi = Phi + Gamma @ np.asarray(K, dtype=float)
        Gamma = np.zeros((6, 0))
        return LinearSystem(Phi, Gamma, B, dt, chaser_state_spec(), name=name + " (closed loop u = Kx)", info=info)
    return LinearSystem(Phi, Gamma, B, dt, chaser_state_spec(), ("Fx", "Fy", "Fz"), ("N", "N", "N"), name=name, info=info)


def position_measurement(D: ArrayLike) -> LinearMeasurement:
    """The indirect position measurement (8), ``y = [I 0] x + D v``, as a :class:`LinearMeasurement`."""
    return LinearMeasurement(measurement_matrix(), D, ("x", "y", "z"), ("m", "m", "m"))
