"""A single-axis rigid spacecraft with one flexible appendage mode: an uncertain, marginally stable plant.

States ``x = [θ, ω, η, η̇]`` (rad·10⁻³ = mrad, mrad/s, modal units): the
rigid attitude and rate (a double integrator) and one appendage mode of
frequency Ω (rad/s) and damping ratio ζ, both excited by the disturbance
torque w (mN·m, inertia J in kg·m²)::

    θ̇ = ω,   ω̇ = (u + w)/J,   η̈ = −Ω² η − 2ζΩ η̇ + φ (u + w)/J,

the star tracker measuring the attitude at its mount, ``y = θ + σ η + v``
(mrad), and the estimated signal the rigid attitude ``z = θ``. The mode is
Schur stable and the integrators do not feed it, so the observer form
designs (:mod:`hinfnav.analysis.marginal`). Discretised by a zero-order hold
at ``dt`` (exact for piecewise-constant inputs); the discrete matrices are not
affine in (Ω, ζ), so the 4-corner polytope is an approximation whose
coverage :func:`hinfnav.systems.parametric.polytope_coverage` measures.

:func:`flexible_attitude_closed_loop`: the same plant under a PD attitude
loop ``u = −k_p θ − k_d ω`` (held over each sample): every vertex is Schur
stable, the uncertainty then reads the whole state.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from ..core.exceptions import InputError
from ..core.validation import as_positive
from .parametric import polytope_from_parameters
from .polytopic import PolytopicSystem
from .uncertain import UncertainSystem

__all__ = ["flexible_attitude_matrices", "flexible_attitude", "flexible_attitude_closed_loop"]


def flexible_attitude_matrices(freq_hz: float, damping: float, *, J: float = 1.0, phi: float = 0.5,
                               sigma: float = 0.3, noise_v: float = 0.1, dt: float | None = 0.1,
                               gains: tuple[float, float] | None = None) -> tuple[np.ndarray, ...]:
    """``(A, B, C, D, L)`` at one frequency (Hz) and damping; continuous when ``dt`` is None or 0.

    Parameters
    ----------
    freq_hz, damping : float
        Mode frequency Ω/2π (Hz) and damping ratio ζ.
    J, phi, sigma : float
        Inertia (kg·m²), modal participation of the torque, modal slope at the star tracker.
    noise_v : float
        Star-tracker noise scale (mrad per unit v).
    dt : float or None
        Sampling time, s (zero-order hold); None or 0: continuous-time matrices.
    gains : (k_p, k_d), optional
        Close the loop ``u = −k_p θ − k_d ω`` (u held over each sample when discrete).
    """
    W = 2 * np.pi * as_positive("freq_hz", freq_hz)
    if not damping >= 0:
        raise InputError(f"damping must be >= 0; got {damping!r}")
    as_positive("J", J)
    Ac = np.array([[0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1], [0, 0, -W * W, -2 * damping * W]], dtype=float)
    Bc = np.array([[0.0], [1.0 / J], [0.0], [phi / J]])
    C = np.array([[1.0, 0.0, sigma, 0.0]])
    D = np.array([[float(noise_v)]])
    L = np.array([[1.0, 0.0, 0.0, 0.0]])
    K = None if gains is None else np.array([[gains[0], gains[1], 0.0, 0.0]])
    if not dt:
        A = Ac if K is None else Ac - Bc @ K
        return A, Bc, C, D, L
    as_positive("dt", dt)
    Md = expm(np.block([[Ac, Bc], [np.zeros((1, 5))]]) * dt)  # zero-order hold of [A_c, B_c]
    A, B = Md[:4, :4], Md[:4, 4:]
    if K is not None:
        A = A - B @ K
    return A, B, C, D, L


def flexible_attitude(freq_hz: tuple[float, float] = (0.8, 1.2), damping: tuple[float, float] = (0.002, 0.01),
                      dt: float = 0.1, splits: int = 1, **kw) -> PolytopicSystem:
    """The polytope (corners of frequency × damping) of the open-loop plant at ``dt`` s.

    ``splits > 1`` cuts the frequency range into that many cells
    (:func:`~hinfnav.systems.parametric.polytope_from_parameters`).
    """
    def plant(f, z):
        return UncertainSystem(*flexible_attitude_matrices(f, z, dt=dt, **kw), dt=dt)

    return polytope_from_parameters(plant, {"f": freq_hz, "z": damping}, dt, {"f": splits})


def flexible_attitude_closed_loop(freq_hz: tuple[float, float] = (0.8, 1.2),
                                  damping: tuple[float, float] = (0.002, 0.01), dt: float = 0.1,
                                  gains: tuple[float, float] = (0.4, 0.9), splits: int = 1,
                                  **kw) -> PolytopicSystem:
    """The same polytope under the PD attitude loop ``u = −k_p θ − k_d ω`` (every vertex Schur stable)."""
    def plant(f, z):
        return UncertainSystem(*flexible_attitude_matrices(f, z, dt=dt, gains=gains, **kw), dt=dt)

    return polytope_from_parameters(plant, {"f": freq_hz, "z": damping}, dt, {"f": splits})
