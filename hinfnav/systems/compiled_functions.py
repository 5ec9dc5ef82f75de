"""numba-compiled f, h and Jacobians of the package's own models (imported on demand: it imports numba).

The signatures are those of :mod:`hinfnav.systems.compiled` (one state, C-contiguous float64 arrays, the
model's parameters in ``p``); each function is the NumPy model's equations written for one state:

* :func:`constant_turn_f`, :func:`constant_turn_jacobian` — (CT1) of
  :class:`~hinfnav.systems.ConstantTurn`, ``p = (T,)``;
* :func:`linear_f`, :func:`linear_jacobian` — ``Φ x + Γ u`` of a
  :class:`~hinfnav.systems.LinearSystem`, ``p = (n, n_u, Φ row by row, Γ row by row)``;
* :func:`linear_h`, :func:`linear_h_jacobian` — ``H x`` of a
  :class:`~hinfnav.systems.LinearMeasurement`, ``p = (m, n, H row by row)``;
* :func:`range_bearing_h`, :func:`range_bearing_jacobian` — (P1)-(P2) of
  :class:`~hinfnav.systems.RangeBearing`, ``p = (n, i, j, o_x, o_y)``;
* :func:`range_angles_h`, :func:`range_angles_jacobian` — range, azimuth,
  elevation of :class:`~hinfnav.systems.RangeAzimuthElevation`, ``p = (n, C_bl row by row)``;
* :func:`plain_residual` (``y − ŷ``) and :func:`angles_residual` (``y − ŷ``
  with the channels 1: wrapped to (−π, π], as
  :func:`~hinfnav.systems.measurements.wrap_angle`).

A singular point (zero range) gives inf or NaN, which the kernel hands back to
the NumPy path (that raises its own error there).
"""

import numpy as np
from numba import njit, types

__all__ = ["DYNAMICS_SIGNATURE", "DYNAMICS_JACOBIAN_SIGNATURE", "MEASUREMENT_SIGNATURE",
           "MEASUREMENT_JACOBIAN_SIGNATURE", "RESIDUAL_SIGNATURE", "angles_residual", "constant_turn_f",
           "constant_turn_jacobian", "linear_f", "linear_h", "linear_h_jacobian", "linear_jacobian",
           "plain_residual", "range_angles_h", "range_angles_jacobian", "range_bearing_h", "range_bearing_jacobian"]

VEC = types.float64[::1]
MAT = types.float64[:, ::1]
#: f(x, u, t, p) -> x_next
DYNAMICS_SIGNATURE = VEC(VEC, VEC, types.float64, VEC)
#: jacobian(x, u, t, p) -> ∂f/∂x
DYNAMICS_JACOBIAN_SIGNATURE = MAT(VEC, VEC, types.float64, VEC)
#: h(x, p) -> y
MEASUREMENT_SIGNATURE = VEC(VEC, VEC)
#: jacobian(x, p) -> ∂h/∂x
MEASUREMENT_JACOBIAN_SIGNATURE = MAT(VEC, VEC)
#: residual(y, yhat, p) -> y − ŷ
RESIDUAL_SIGNATURE = VEC(VEC, VEC, VEC)

_OPTS = {"cache": True, "error_model": "numpy"}


# -- residuals -------------------------------------------------------------------------------

@njit(RESIDUAL_SIGNATURE, **_OPTS)
def plain_residual(y, yhat, p):
    """``y − ŷ``."""
    return y - yhat


@njit(**_OPTS)
def _wrap(a):
    """:func:`~hinfnav.systems.measurements.wrap_angle` of one angle."""
    if a > -np.pi and a <= np.pi:
        return a
    return np.pi - np.mod(np.pi - a, 2 * np.pi)


@njit(RESIDUAL_SIGNATURE, **_OPTS)
def angles_residual(y, yhat, p):
    """``y − ŷ`` with channels 1: (the angles) wrapped to (−π, π]."""
    d = y - yhat
    for i in range(1, d.size):
        d[i] = _wrap(d[i])
    return d


# -- constant turn -----------------------------------------------------------------------------

@njit(**_OPTS)
def _turn(w, T):
    """``(s, c, ds/dω, dc/dω, cos ωT, sin ωT)`` of :func:`~hinfnav.systems.dynamics._turn_coefficients`."""
    a = w * T
    s = T * np.sinc(a / np.pi)
    c = T * np.sin(0.5 * a) * np.sinc(0.5 * a / np.pi)
    a2 = a * a
    if abs(a) < 1e-2:
        ds = (-a / 3.0 + a * a2 / 30.0 - a * a2 * a2 / 840.0) * T * T
        dc = (0.5 - a2 / 8.0 + a2 * a2 / 144.0) * T * T
    else:
        ds = (a * np.cos(a) - np.sin(a)) / a**2 * T * T
        dc = (a * np.sin(a) - 1.0 + np.cos(a)) / a**2 * T * T
    return s, c, ds, dc, np.cos(w * T), np.sin(w * T)


@njit(DYNAMICS_SIGNATURE, **_OPTS)
def constant_turn_f(x, u, t, p):
    """(CT1) of one state (x, y, vx, vy, ω); ``p = (T,)``."""
    vx, vy, w = x[2], x[3], x[4]
    s, c, _, _, cw, sw = _turn(w, p[0])
    out = np.empty(5)
    out[0] = x[0] + s * vx - c * vy
    out[1] = x[1] + c * vx + s * vy
    out[2] = cw * vx - sw * vy
    out[3] = sw * vx + cw * vy
    out[4] = w
    return out


@njit(DYNAMICS_JACOBIAN_SIGNATURE, **_OPTS)
def constant_turn_jacobian(x, u, t, p):
    """∂f/∂x of (CT1), (5, 5); ``p = (T,)``."""
    vx, vy, w, T = x[2], x[3], x[4], p[0]
    s, c, ds, dc, cw, sw = _turn(w, T)
    J = np.zeros((5, 5))
    J[0, 0] = J[1, 1] = J[4, 4] = 1.0
    J[0, 2], J[0, 3], J[0, 4] = s, -c, ds * vx - dc * vy
    J[1, 2], J[1, 3], J[1, 4] = c, s, dc * vx + ds * vy
    J[2, 2], J[2, 3], J[2, 4] = cw, -sw, -T * (sw * vx + cw * vy)
    J[3, 2], J[3, 3], J[3, 4] = sw, cw, T * (cw * vx - sw * vy)
    return J


# -- linear dynamics and measurement -------------------------------------------------------------

@njit(DYNAMICS_SIGNATURE, **_OPTS)
def linear_f(x, u, t, p):
    """``Φ x (+ Γ u)``; ``p = (n, n_u, Φ, Γ)`` (u of length 0: no input)."""
    n, nu = int(p[0]), int(p[1])
    out = np.empty(n)
    g0 = 2 + n * n
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += p[2 + i * n + j] * x[j]
        if u.size:
            for j in range(nu):
                s += p[g0 + i * nu + j] * u[j]
        out[i] = s
    return out


@njit(DYNAMICS_JACOBIAN_SIGNATURE, **_OPTS)
def linear_jacobian(x, u, t, p):
    """Φ; ``p`` as :func:`linear_f`."""
    n = int(p[0])
    return p[2:2 + n * n].copy().reshape((n, n))


@njit(MEASUREMENT_SIGNATURE, **_OPTS)
def linear_h(x, p):
    """``H x``; ``p = (m, n, H)``."""
    m, n = int(p[0]), int(p[1])
    out = np.empty(m)
    for i in range(m):
        s = 0.0
        for j in range(n):
            s += p[2 + i * n + j] * x[j]
        out[i] = s
    return out


@njit(MEASUREMENT_JACOBIAN_SIGNATURE, **_OPTS)
def linear_h_jacobian(x, p):
    """H; ``p`` as :func:`linear_h`."""
    m, n = int(p[0]), int(p[1])
    return p[2:2 + m * n].copy().reshape((m, n))


# -- range and bearing (planar) ---------------------------------------------------------------------

@njit(MEASUREMENT_SIGNATURE, **_OPTS)
def range_bearing_h(x, p):
    """(P1) ``(|d|, atan2(d_y, d_x))``, d = position − origin; ``p = (n, i, j, o_x, o_y)``."""
    dx, dy = x[int(p[1])] - p[3], x[int(p[2])] - p[4]
    out = np.empty(2)
    out[0] = np.hypot(dx, dy)
    out[1] = np.arctan2(dy, dx)
    return out


@njit(MEASUREMENT_JACOBIAN_SIGNATURE, **_OPTS)
def range_bearing_jacobian(x, p):
    """(P2), (2, n); ``p`` as :func:`range_bearing_h` (inf or NaN at zero range)."""
    i, j = int(p[1]), int(p[2])
    dx, dy = x[i] - p[3], x[j] - p[4]
    r2 = dx * dx + dy * dy
    r = np.sqrt(r2)
    J = np.zeros((2, int(p[0])))
    J[0, i], J[0, j] = dx / r, dy / r
    J[1, i], J[1, j] = -dy / r2, dx / r2
    return J


# -- range, azimuth, elevation --------------------------------------------------------------------

@njit(**_OPTS)
def _sensor_position(x, p):
    pb = np.empty(3)
    for i in range(3):
        pb[i] = p[1 + 3 * i] * x[0] + p[2 + 3 * i] * x[1] + p[3 + 3 * i] * x[2]
    return pb


@njit(MEASUREMENT_SIGNATURE, **_OPTS)
def range_angles_h(x, p):
    """``(ρ, α, β)`` of the position x[:3] in the sensor frame ``C_bl x``; ``p = (n, C_bl)``."""
    pb = _sensor_position(x, p)
    out = np.empty(3)
    out[0] = np.sqrt(pb[0] * pb[0] + pb[1] * pb[1] + pb[2] * pb[2])
    out[1] = np.arctan2(pb[1], pb[0])
    out[2] = np.arctan2(-pb[2], np.hypot(pb[0], pb[1]))
    return out


@njit(MEASUREMENT_JACOBIAN_SIGNATURE, **_OPTS)
def range_angles_jacobian(x, p):
    """∂(ρ, α, β)/∂x, (3, n); ``p`` as :func:`range_angles_h` (inf or NaN on the sensor's z axis)."""
    pb = _sensor_position(x, p)
    rho2 = pb[0] * pb[0] + pb[1] * pb[1] + pb[2] * pb[2]
    h2 = pb[0] ** 2 + pb[1] ** 2
    rho, h = np.sqrt(rho2), np.sqrt(h2)
    Jb = np.empty((3, 3))
    for k in range(3):
        Jb[0, k] = pb[k] / rho
    Jb[1, 0], Jb[1, 1], Jb[1, 2] = -pb[1] / h2, pb[0] / h2, 0.0
    Jb[2, 0] = pb[2] * pb[0] / (h * rho2)
    Jb[2, 1] = pb[2] * pb[1] / (h * rho2)
    Jb[2, 2] = -h / rho2
    J = np.zeros((3, int(p[0])))
    for a in range(3):
        for b in range(3):
            s = 0.0
            for k in range(3):
                s += Jb[a, k] * p[1 + 3 * k + b]
            J[a, b] = s
    return J
