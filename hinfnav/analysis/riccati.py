"""Riccati limits and stationary error covariances of linear filters.

* :func:`steady_state_kalman`: the stationary Kalman filter of
  ``x⁺ = A x + w``, ``y = C x + v`` (discrete algebraic Riccati equation):
  no estimator that sees only y has a smaller error covariance, so it is the
  accuracy limit printed beside every accuracy table of the workbook.
* :func:`stationary_lti_error_covariance`: the stationary covariance of the
  error of a fixed LTI filter (12) on a stable linear truth (a discrete
  Lyapunov equation on the error system (13)).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import HinfnavError, InputError, UnstablePlantError
from ..core.linalg import as_covariance, spectral_radius
from ..core.validation import as_matrix
from .error_system import error_system_matrices

__all__ = ["steady_state_kalman", "stationary_lti_error_covariance"]


def steady_state_kalman(A: ArrayLike, C: ArrayLike, Q: ArrayLike, R: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Steady-state Kalman filter of ``x⁺ = A x + w``, ``y = C x + v``.

    Parameters
    ----------
    A : array_like, shape (n, n)
    C : array_like, shape (m, n)
    Q : array_like, shape (n, n)
        Covariance of w per step, positive semidefinite.
    R : array_like, shape (m, m)
        Covariance of v, positive definite.

    Returns
    -------
    P_predicted : ndarray, shape (n, n)
        A priori covariance P(k|k−1), the stabilizing solution of
        ``P = A P Aᵀ − A P Cᵀ (C P Cᵀ + R)⁻¹ C P Aᵀ + Q``.
    P_filtered : ndarray, shape (n, n)
        A posteriori covariance ``P − P Cᵀ (C P Cᵀ + R)⁻¹ C P``.
    gain : ndarray, shape (n, m)
        Filter gain ``P Cᵀ (C P Cᵀ + R)⁻¹`` of the update
        x̂(k|k) = x̂(k|k−1) + gain (y(k) − C x̂(k|k−1)).

    Raises
    ------
    InputError
        For bad shapes or covariances, or when the DARE has no stabilizing
        solution ((A, C) not detectable).
    """
    A = as_matrix("A", A)
    n = A.shape[0]
    if A.shape != (n, n):
        raise InputError(f"A must be square; got shape {A.shape}")
    C = as_matrix("C", C, (None, n))
    m = C.shape[0]
    Q = as_covariance("Q", Q, n, definite=False)
    R = as_covariance("R", R, m, definite=True)
    try:
        P = scipy.linalg.solve_discrete_are(A.T, C.T, Q, R)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise InputError(f"the Riccati equation has no stabilizing solution for this (A, C, Q, R): {exc}") from None
    P = 0.5 * (P + P.T)
    S = C @ P @ C.T + R
    gain = np.linalg.solve(S, C @ P).T
    Pf = P - gain @ S @ gain.T
    Pf = 0.5 * (Pf + Pf.T)
    residual = A @ Pf @ A.T + Q - P
    if np.max(np.abs(residual)) > 1e-8 * max(1.0, np.max(np.abs(P))):
        raise HinfnavError(f"the Riccati solution is inaccurate (residual {np.max(np.abs(residual)):.3g})")
    return P, Pf, gain




def stationary_lti_error_covariance(A_t: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike, A_F: ArrayLike,
                                    B_F: ArrayLike, C_F: ArrayLike, *, K_truth: ArrayLike | None = None,
                                    input_matrix: ArrayLike | None = None, K: ArrayLike | None = None) -> NDArray[np.float64]:
    """Stationary covariance of the error of the LTI filter (12) on a stable linear truth.

    The truth ``x(k+1) = A_t x(k) + B w(k)``, ``y = C x + D v`` (w, v white,
    unit variance) and the filter ``x_f(k+1) = A_F x_f + B_F y [+ C_F⁻¹ G (u −
    K C_F x_f)]`` (the known-input correction of
    :class:`hinfnav.estimators.LTIFilter`, told the applied ``u = K_truth x``)
    form a linear system driven by white noise; its stationary covariance
    solves a discrete Lyapunov equation.

    Parameters
    ----------
    A_t : array_like, shape (n, n)
        The truth's transition (closed loop where a controller acts), Schur stable.
    B : array_like, shape (n, p)
    C : array_like, shape (m, n)
    D : array_like, shape (m, q)
    A_F, B_F, C_F : array_like
        The filter; ``C_F`` square and invertible (the whole state estimated).
    K_truth : array_like, shape (m_u, n), optional
        The applied input ``u = K_truth x`` (zero input when None).
    input_matrix : array_like, shape (n, m_u), optional
        G of the known-input correction; with ``K`` switches it on.
    K : array_like, shape (m_u, n), optional
        The gain the filter assumed.

    Returns
    -------
    ndarray, shape (n, n)
        Stationary covariance of ``e(k) = x(k) − C_F x_f(k)``.

    Raises
    ------
    UnstablePlantError
        The truth is not Schur stable (its state has no stationary covariance).
    InputError
        Bad shapes, a singular C_F, or an unstable filter.
    """
    A_t = as_matrix("A_t", A_t)
    n = A_t.shape[0]
    B = as_matrix("B", B, (n, None))
    C = as_matrix("C", C, (None, n))
    D = as_matrix("D", D, (C.shape[0], None))
    A_F = as_matrix("A_F", A_F, (n, n))
    B_F = as_matrix("B_F", B_F, (n, C.shape[0]))
    C_F = as_matrix("C_F", C_F, (n, n))
    if np.linalg.cond(C_F) > 1e12:
        raise InputError("C_F must be invertible (the filter estimates the whole state)")
    rho = spectral_radius(A_t)
    if rho >= 1:
        raise UnstablePlantError(
            f"the truth x(k+1) = A x(k) + B w(k) is not Schur stable (spectral radius {rho:.6f}); "
            "its state, and the error of a filter without exact observer form, has no stationary covariance"
        )
    if (input_matrix is None) != (K is None):
        raise InputError("input_matrix and K must be given together to use the known thrust")
    m_u = 0
    if K_truth is not None:
        K_truth = as_matrix("K_truth", K_truth, (None, n))
        m_u = K_truth.shape[0]
    A_eff = A_F.copy()
    M_u_gain = np.zeros((n, m_u))
    if input_matrix is not None:
        G = as_matrix("input_matrix", input_matrix, (n, None))
        K_F = as_matrix("K", K, (G.shape[1], n))
        if K_truth is None:
            K_truth, m_u = np.zeros((G.shape[1], n)), G.shape[1]
        M = np.linalg.solve(C_F, G)
        A_eff = A_F - M @ K_F @ C_F
        M_u_gain = M
    if K_truth is None:
        K_truth = np.zeros((0, n))
    rho_f = spectral_radius(A_eff)
    if rho_f >= 1:
        raise InputError(f"A_F (with the input correction, if any) must be Schur stable; spectral radius {rho_f:.6f}")
    # The error system (13)-(14); the known input u = K_truth x enters the filter like an
    # extra measurement channel: B_F C + M K_truth = [B_F, M] [C; K_truth], noise [D; 0].
    Aa, Ba, Ca = error_system_matrices(
        A_t, B, np.vstack([C, K_truth]), np.vstack([D, np.zeros((K_truth.shape[0], D.shape[1]))]), np.eye(n),
        A_eff, np.hstack([B_F, M_u_gain]), C_F,
    )
    Sigma = scipy.linalg.solve_discrete_lyapunov(Aa, Ba @ Ba.T)
    cov = Ca @ Sigma @ Ca.T
    return 0.5 * (cov + cov.T)
