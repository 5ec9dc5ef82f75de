"""numba-compiled mean prediction of the two-body (+ J2) EKF (imported on demand by :class:`.filters.PairPrediction`).

One state's version of :meth:`.filters.PairPrediction.f`, with the NumPy
functions' arithmetic: the Hill state x̂ and the chief's tabulated state at
t = kΔt give the deputy's inertial state (inverse of (G2), ``hill_to_inertial``),
both spacecraft go through one RK4 step of Δt under (D1) or (D1)+(D2)
(``rk4``, ``pair``, ``two_body_j2``), and the deputy returns to the chief's
Hill frame (G2) (``inertial_to_hill``). The Jacobian is Hill's Φ (the filter
propagates its covariance with Φ).

``p = (Δt, μ, J2 (0 for two-body), R_E, n_chief, Φ (36, row by row), r_c (3 n_chief), v_c (3 n_chief))``.
"""

import numpy as np
from numba import njit

from ...systems.compiled_functions import DYNAMICS_JACOBIAN_SIGNATURE, DYNAMICS_SIGNATURE

__all__ = ["pair_prediction_f", "pair_prediction_jacobian"]

_OPTS = {"cache": True, "error_model": "numpy"}
_PHI = 5  # offset of Φ in p


@njit(**_OPTS)
def _cross(a, b):
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(**_OPTS)
def _norm(a):
    return np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit(**_OPTS)
def _basis(r, v):
    """Rows x̂, ŷ, ẑ of the Hill frame and its rate |h|/|r|² (``hill_basis``)."""
    h = _cross(r, v)
    xh = r / _norm(r)
    zh = h / _norm(h)
    yh = _cross(zh, xh)
    M = np.empty((3, 3))
    M[0], M[1], M[2] = xh, yh, zh
    return M, _norm(h) / (r[0] * r[0] + r[1] * r[1] + r[2] * r[2])


@njit(**_OPTS)
def _derivative(X, mu, j2, radius):
    """(D1) (+ (D2) when j2 ≠ 0) of the chief (X[:6]) and the deputy (X[6:])."""
    out = np.empty(12)
    for o in (0, 6):
        r = X[o:o + 3]
        r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
        s = r2 * np.sqrt(r2)
        z2 = r[2] ** 2 / r2
        k = -1.5 * j2 * mu * radius**2 / (r2 * r2 * np.sqrt(r2))
        for i in range(3):
            out[o + i] = X[o + 3 + i]
            a = -mu * r[i] / s
            if j2 != 0.0:
                a += k * r[i] * ((3.0 if i == 2 else 1.0) - 5 * z2)
            out[o + 3 + i] = a
    return out


@njit(DYNAMICS_SIGNATURE, **_OPTS)
def pair_prediction_f(x, u, t, p):
    """The Hill state one step later through the nonlinear pair model (see the module docstring)."""
    dt, mu, j2, radius, n_chief = p[0], p[1], p[2], p[3], int(p[4])
    k = int(np.round(t / dt))
    if k < 0 or k >= n_chief:  # beyond the chief's table: NaN (the NumPy path raises its IndexError)
        return np.full(6, np.nan)
    r0 = _PHI + 36
    rc = p[r0 + 3 * k:r0 + 3 * k + 3]
    vc = p[r0 + 3 * n_chief + 3 * k:r0 + 3 * n_chief + 3 * k + 3]
    M, w = _basis(rc, vc)
    wv = np.zeros(3)
    wv[2] = w
    rho, drho = x[:3], x[3:6]
    dv = drho + _cross(wv, rho)
    X = np.empty(12)
    for i in range(3):
        X[i], X[3 + i] = rc[i], vc[i]
        sr, sv = 0.0, 0.0
        for j in range(3):
            sr += M[j, i] * rho[j]
            sv += M[j, i] * dv[j]
        X[6 + i], X[9 + i] = rc[i] + sr, vc[i] + sv
    k1 = _derivative(X, mu, j2, radius)
    k2 = _derivative(X + 0.5 * dt * k1, mu, j2, radius)
    k3 = _derivative(X + 0.5 * dt * k2, mu, j2, radius)
    k4 = _derivative(X + dt * k3, mu, j2, radius)
    X = X + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    M, w = _basis(X[:3], X[3:6])
    out = np.empty(6)
    for i in range(3):
        sr, sv = 0.0, 0.0
        for j in range(3):
            sr += M[i, j] * (X[6 + j] - X[j])
            sv += M[i, j] * (X[9 + j] - X[3 + j])
        out[i], out[3 + i] = sr, sv
    wv[2] = w
    c = _cross(wv, out[:3])
    for i in range(3):
        out[3 + i] -= c[i]
    return out


@njit(DYNAMICS_JACOBIAN_SIGNATURE, **_OPTS)
def pair_prediction_jacobian(x, u, t, p):
    """Hill's Φ (the covariance's propagation)."""
    return p[_PHI:_PHI + 36].copy().reshape((6, 6))
