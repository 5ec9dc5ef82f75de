"""Small linear-algebra helpers shared by every layer.

Nothing here knows about a paper, a system or an estimator: spectral radius,
symmetric part, covariance checks, zero-order-hold discretization.
"""

import numpy as np
import scipy.linalg

from .exceptions import InputError
from .validation import as_choice, as_matrix, as_positive

__all__ = ["spectral_radius", "sym", "as_covariance", "discretize"]


def spectral_radius(A):
    """Largest eigenvalue modulus of a square matrix (Schur stable iff < 1)."""
    A = np.asarray(A, dtype=float)
    if A.size == 0:
        return 0.0
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def sym(M):
    """Symmetric part ``(M + Mᵀ)/2``."""
    M = np.asarray(M, dtype=float)
    return 0.5 * (M + M.T)


def as_covariance(name, value, n, definite):
    """Return ``value`` as a symmetric ``n × n`` covariance, checking its sign.

    Parameters
    ----------
    name : str
        Parameter name used in error messages.
    value : array_like, shape (n, n)
    n : int
    definite : bool
        Require positive definiteness (True) or only semidefiniteness.

    Raises
    ------
    InputError
        Wrong shape, not symmetric, or an eigenvalue of the wrong sign.
    """
    M = as_matrix(name, value, (n, n))
    scale = max(float(np.max(np.abs(M))), np.finfo(float).tiny)
    if not np.allclose(M, M.T, rtol=0, atol=1e-10 * scale):
        raise InputError(f"{name} must be symmetric (a covariance matrix)")
    M = 0.5 * (M + M.T)
    low = float(np.min(np.linalg.eigvalsh(M)))
    if definite and low <= 0:
        raise InputError(f"{name} must be positive definite; its smallest eigenvalue is {low:.3g}")
    if not definite and low < -1e-12 * scale:
        raise InputError(f"{name} must be positive semidefinite; its smallest eigenvalue is {low:.3g}")
    return M


def discretize(Ac, Gc, dt, method="exact"):
    """Discretize ``ẋ = Ac x + Gc u`` with a zero-order hold on ``u``.

    Parameters
    ----------
    Ac : array_like, shape (n, n)
    Gc : array_like, shape (n, m)
    dt : float
        Sampling time T, s.
    method : {"exact", "euler"}
        ``"euler"``: ``(I + T Ac, T Gc)``.
        ``"exact"``: ``(e^{Ac T}, ∫₀ᵀ e^{Ac s} ds Gc)``.

    Returns
    -------
    Ad : ndarray, shape (n, n)
    Gd : ndarray, shape (n, m)

    Notes
    -----
    The two agree to first order in T; the Euler error is
    ``T² Ac²/2 + O(T³)`` (tested in ``tests/test_systems.py``).
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
