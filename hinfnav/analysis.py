"""Stationary error statistics of a fixed LTI filter, without simulation.

For the error system (13)–(15) driven by unit-variance white noise
τ = [w; v], the stationary covariance X of ξ = [x; x_f] solves the discrete
Lyapunov equation ``X = Ā X Āᵀ + B̄ B̄ᵀ``, and the error e = C̄ ξ has
covariance ``C̄ X C̄ᵀ``. Its diagonal is what a long simulation's per-axis
mean-square error tends to, so it is an independent check of the Monte Carlo
numbers and of the paper's Table 1.
"""

import numpy as np
import scipy.linalg

from .exceptions import UnstablePlantError
from .models import UncertainSystem, spectral_radius
from .validation import as_matrix

__all__ = ["error_system_matrices", "stationary_error_std"]


def error_system_matrices(system, A_F, B_F, C_F, A=None):
    """Matrices (Ā, B̄, C̄) of the error system (13)–(14).

    Parameters
    ----------
    system : UncertainSystem
    A_F, B_F, C_F : array_like
        Filter (12).
    A : array_like, optional
        Plant matrix to use instead of ``system.A`` (e.g. ``A + ΔA(δ)``).

    Returns
    -------
    Abar : ndarray, shape (2n, 2n)
    Bbar : ndarray, shape (2n, p + q)
    Cbar : ndarray, shape (l, 2n)
    """
    n = system.n
    A = system.A if A is None else as_matrix("A", A, (n, n))
    A_F = as_matrix("A_F", A_F, (n, n))
    B_F = as_matrix("B_F", B_F, (n, system.C.shape[0]))
    C_F = as_matrix("C_F", C_F, (system.L.shape[0], n))
    p, q = system.B.shape[1], system.D.shape[1]
    Abar = np.block([[A, np.zeros((n, n))], [B_F @ system.C, A_F]])
    Bbar = np.block([[system.B, np.zeros((n, q))], [np.zeros((n, p)), B_F @ system.D]])
    Cbar = np.hstack([system.L, -C_F])
    return Abar, Bbar, Cbar


def stationary_error_std(system, A_F, B_F, C_F, A=None):
    """Stationary standard deviation of each error component under unit white noise.

    Parameters
    ----------
    system : UncertainSystem
        E.g. ``Scenario().design_model()``.
    A_F, B_F, C_F : array_like
        Filter (12).
    A : array_like, optional
        Plant matrix (default ``system.A``).

    Returns
    -------
    ndarray, shape (l,)
        Per-component error standard deviation (m, m/s for the paper's L = I).

    Raises
    ------
    UnstablePlantError
        If the error system is not Schur stable (e.g. the unforced Hill model).
    """
    if not isinstance(system, UncertainSystem):
        raise TypeError(f"system must be an UncertainSystem; got {type(system).__name__}")
    Abar, Bbar, Cbar = error_system_matrices(system, A_F, B_F, C_F, A)
    rho = spectral_radius(Abar)
    if rho >= 1:
        raise UnstablePlantError(
            f"the error system is not Schur stable (spectral radius {rho:.6f} >= 1): it contains the plant state, "
            "so a stationary error covariance exists only for a stable plant (use the closed loop u = Kx)"
        )
    X = scipy.linalg.solve_discrete_lyapunov(Abar, Bbar @ Bbar.T)
    return np.sqrt(np.diag(Cbar @ X @ Cbar.T))
