"""Continuous orbital dynamics ``ẋ = f(x, u, t)`` and a fixed-step RK4, for the GRACE study.

Small and local on purpose: each model keeps the ``f(x, u, t)`` signature (x of shape (..., n), u the
input or None, t in s) so that it can become a dynamics object of :mod:`hinfnav.systems` when those
exist. All in SI units.

* :func:`two_body` — absolute motion, ``r̈ = −μ r/|r|³`` (eq. D1);
* :func:`two_body_j2` — plus the J2 term (eq. D2)::

      a_J2 = −(3/2) J2 μ R_E² / |r|⁵ · (x (1 − 5z²/|r|²), y (1 − 5z²/|r|²), z (3 − 5z²/|r|²));

* :func:`hill_linear` — the Hill/CW model of paper 000, ``ẋ = A₀(ω) x`` (eq. (2) there);
* :func:`pair` — both spacecraft at once (12 states: chief, deputy), with either absolute model;
* :func:`rk4` — the classical fixed-step fourth-order Runge–Kutta.
"""

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_positive
from ...systems.hill import hill_matrices
from .constants import J2, MU_EARTH, R_EARTH_M

__all__ = ["two_body", "two_body_j2", "hill_linear", "pair", "rk4", "MODELS"]


def two_body(x, u=None, t=0.0, *, mu=MU_EARTH):
    """Two-body absolute dynamics (D1): ``x = (r, v)`` (..., 6), m and m/s; ``u`` an extra acceleration or None."""
    x = np.asarray(x, float)
    r = x[..., :3]
    r2 = np.sum(r * r, axis=-1, keepdims=True)
    a = -mu * r / (r2 * np.sqrt(r2))
    if u is not None:
        a = a + u
    return np.concatenate([x[..., 3:6], a], axis=-1)


def two_body_j2(x, u=None, t=0.0, *, mu=MU_EARTH, j2=J2, radius=R_EARTH_M):
    """Two-body plus J2 (D2), in a frame whose z axis is the Earth's rotation axis."""
    out = two_body(x, u, t, mu=mu)
    r = np.asarray(x, float)[..., :3]
    r2 = np.sum(r * r, axis=-1, keepdims=True)
    z2 = r[..., 2:3] ** 2 / r2
    k = -1.5 * j2 * mu * radius**2 / (r2 * r2 * np.sqrt(r2))
    a = k * r * np.concatenate([1 - 5 * z2, 1 - 5 * z2, 3 - 5 * z2], axis=-1)
    out[..., 3:6] += a
    return out


def hill_linear(omega):
    """The Hill/CW model ``f(x, u, t) = A₀(ω) x (+ [0; u])`` of paper 000, eq. (2) (u an acceleration, m/s²)."""
    A0, _ = hill_matrices(as_positive("omega", omega), 1.0)

    def f(x, u=None, t=0.0):
        out = np.asarray(x, float) @ A0.T
        if u is not None:
            out[..., 3:6] += u
        return out

    return f


def pair(absolute):
    """Chief and deputy together: ``x = (r_c, v_c, r_d, v_d)`` (..., 12) under one absolute model."""

    def f(x, u=None, t=0.0):
        x = np.asarray(x, float)
        out = absolute(x.reshape(x.shape[:-1] + (2, 6)), None, t)  # both spacecraft in one call
        if u is not None:
            out[..., 1, 3:] += u
        return out.reshape(x.shape)

    return f


#: Absolute models by name (the mismatch study and the nonlinear EKF use these).
MODELS = {"two_body": two_body, "two_body_j2": two_body_j2}


def rk4(f, x, t0, dt, steps=1, u=None):
    """Integrate ``ẋ = f(x, u, t)`` from ``t0`` over ``steps`` fixed steps of ``dt``, u held; returns x(t0 + steps·dt).

    Parameters
    ----------
    f : callable
        ``f(x, u, t)``, batched over the leading axes of x.
    x : array_like, shape (..., n)
    t0 : float
        s.
    dt : float
        Step, s (positive).
    steps : int
        Number of steps (≥ 1).
    u : array_like or None
    """
    dt = as_positive("dt", dt)
    steps = as_int_at_least("steps", steps, 1)
    x = np.asarray(x, float)
    if not np.all(np.isfinite(x)):
        raise InputError("x must be finite")
    t = float(t0)
    for _ in range(steps):
        k1 = f(x, u, t)
        k2 = f(x + 0.5 * dt * k1, u, t + 0.5 * dt)
        k3 = f(x + 0.5 * dt * k2, u, t + 0.5 * dt)
        k4 = f(x + dt * k3, u, t + dt)
        x = x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += dt
    return x
