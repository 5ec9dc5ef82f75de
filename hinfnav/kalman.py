"""The accuracy limit: steady-state Kalman (Riccati) error of the paper's model.

With the noise model the simulation uses, x(k+1) = A x(k) + B w(k),
y(k) = C x(k) + D v(k) with white unit-variance w and v ((6), (8)), no
estimator that sees only y can have a smaller error covariance than the
Kalman filter's, and the Kalman filter's covariance converges to the
solution of the discrete algebraic Riccati equation (DARE). The per-axis
standard deviations of that solution are the accuracy limit printed next to
every accuracy table of the workbook.

For the paper's scenario (exact discretization, T = 0.1 s, B and D of
Section 4) the limit is, per axis:

=====================  =================  ==================
                       position, m        velocity, m/s
=====================  =================  ==================
no maneuver, filtered  0.0626             0.0224
no maneuver, predicted 0.0802             0.0224
maneuver, filtered     0.0625             0.0135 – 0.0139
maneuver, predicted    0.0801             0.0135 – 0.0139
=====================  =================  ==================

Table 1 of the paper gives the EKF without maneuver 0.04 m and 0.001 m/s:
0.64 and 0.045 times the filtered limit (0.0626 m, 0.0224 m/s), i.e. below
what any filter can reach on the stated noise model (whether Table 1's
number is per axis or the norm of the error vector, which would be √3 times
larger still). The velocity figure is even below the process noise the
model adds to the velocity at every step (0.001 m/s).

:func:`lti_error_covariance` gives the same kind of steady-state number for
a fixed LTI filter (12) when the plant is stable (the closed loop).
"""

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .exceptions import HinfnavError, InputError, UnstablePlantError
from .hinfnorm import error_system_matrices
from .models import measurement_matrix, spectral_radius
from .scenario import Scenario
from .validation import as_choice, as_matrix, as_real

__all__ = ["KalmanLimit", "steady_state_kalman", "kalman_limit", "lti_error_covariance"]


def _as_cov(name, value, n, definite):
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


def steady_state_kalman(A, C, Q, R):
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
    Q = _as_cov("Q", Q, n, definite=False)
    R = _as_cov("R", R, m, definite=True)
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


@dataclass(frozen=True, eq=False)
class KalmanLimit:
    """Steady-state Kalman accuracy of a scenario (see :func:`kalman_limit`).

    Attributes
    ----------
    pos_m, vel_mps : ndarray, shape (3,)
        Filtered (a posteriori, uses y(k)) per-axis error standard deviation,
        m and m/s.
    pos_m_predicted, vel_mps_predicted : ndarray, shape (3,)
        Predicted (a priori, uses y up to k−1) per-axis standard deviation,
        the one to compare with a predictor such as the LTI filter (12).
    P_filtered, P_predicted : ndarray, shape (6, 6)
        The covariance matrices.
    gain : ndarray, shape (6, 3)
        Steady-state Kalman gain of the update.
    A : ndarray, shape (6, 6)
        The state matrix the limit is computed for.
    maneuver : bool
    discretization : str
    """

    pos_m: np.ndarray
    vel_mps: np.ndarray
    pos_m_predicted: np.ndarray
    vel_mps_predicted: np.ndarray
    P_filtered: np.ndarray
    P_predicted: np.ndarray
    gain: np.ndarray
    A: np.ndarray
    maneuver: bool
    discretization: str

    def as_dict(self):
        """JSON-ready dict of the per-axis numbers (lists of floats) and settings."""
        return {
            "pos_m": self.pos_m.tolist(),
            "vel_mps": self.vel_mps.tolist(),
            "pos_m_predicted": self.pos_m_predicted.tolist(),
            "vel_mps_predicted": self.vel_mps_predicted.tolist(),
            "maneuver": self.maneuver,
            "discretization": self.discretization,
        }


def kalman_limit(scenario=None, maneuver=True, discretization="exact"):
    """Steady-state Kalman error of the scenario's stated white-noise model.

    Parameters
    ----------
    scenario : Scenario, optional
        The paper's by default. Uses T, ω₀ (δ = 0), mass, K, B and D.
    maneuver : bool
        True: the closed loop u = K x of (3), A = Φ + Γ K (a filter that
        knows the control law). False: free motion, A = Φ.
    discretization : {"exact", "euler"}
        (Φ, Γ) from ``scenario.truth_matrices(0.0, discretization)``;
        "exact" matches the truth simulation's default.

    Returns
    -------
    KalmanLimit

    Notes
    -----
    The model is (6) and (8) with white unit-variance w and v, so
    Q = B Bᵀ, R = D Dᵀ and C = [I 0] of (8); the limit is the DARE solution
    (:func:`steady_state_kalman`). It bounds every estimator that uses the
    measurements y (and, with maneuver, knowledge of the law u = Kx).

    With maneuver, a filter that is told the applied thrust u(k) as an
    exogenous input (:class:`hinfnav.ekf.EKF` with
    ``dynamics="applied_thrust"``) has the error dynamics of Φ whatever u is,
    so its steady state is the ``maneuver=False`` value (velocity 0.0224 m/s
    instead of 0.0135–0.0139 m/s). A filter could in principle beat both by
    reading K x(k) off the applied u(k) (the simulation's u is computed from
    the true state); that is an artefact of the idealized control loop, not
    an accuracy anyone can expect, and it is outside this limit.

    For the paper's numbers and the comparison with Table 1 see the module
    docstring: the paper's EKF (0.04 m, 0.001 m/s) is below this limit.
    """
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav.Scenario; got {type(scenario).__name__}")
    if not isinstance(maneuver, (bool, np.bool_)):
        raise InputError(f"maneuver must be True or False; got {maneuver!r}")
    as_choice("discretization", discretization, ("exact", "euler"))
    Phi, Gamma = scenario.truth_matrices(0.0, discretization)
    A = Phi + Gamma @ scenario.K if maneuver else Phi
    P, Pf, gain = steady_state_kalman(A, measurement_matrix(), scenario.B @ scenario.B.T, scenario.D @ scenario.D.T)
    sf, sp = np.sqrt(np.diag(Pf)), np.sqrt(np.diag(P))
    return KalmanLimit(
        pos_m=sf[:3],
        vel_mps=sf[3:],
        pos_m_predicted=sp[:3],
        vel_mps_predicted=sp[3:],
        P_filtered=Pf,
        P_predicted=P,
        gain=gain,
        A=A,
        maneuver=bool(maneuver),
        discretization=discretization,
    )


def lti_error_covariance(
    A_F, B_F, C_F, scenario=None, *, maneuver=True, input_matrix=None, K=None, delta=0.0, discretization="exact"
):
    """Stationary error covariance of the LTI filter (12) on the closed loop.

    The truth ``x(k+1) = A_t x(k) + B w(k)``, ``A_t = Φ(δ) + Γ(δ) K`` with
    maneuver (``Φ(δ)`` without), ``y = C x + D v``, and the filter
    ``x_f(k+1) = A_F x_f(k) + B_F y(k) [+ C_F⁻¹ G (u(k) − K C_F x_f(k))]``
    (the known-input correction of :class:`hinfnav.estimators.LTIFilter`,
    with ``u = K x`` of the truth) form a linear system driven by white
    noise; its stationary covariance solves a discrete Lyapunov equation.

    Parameters
    ----------
    A_F : array_like, shape (6, 6)
    B_F : array_like, shape (6, 3)
    C_F : array_like, shape (6, 6)
        The filter (12); C_F invertible.
    scenario : Scenario, optional
        The paper's by default (B, D, K, T, ω₀, mass).
    maneuver : bool
        Truth with u = K x (True) or u = 0 (False).
    input_matrix : array_like, shape (6, 3), optional
        G of the known-input correction (``scenario.input_matrix_design()``
        for the filters of the registry); with ``K`` switches it on.
    K : array_like, shape (3, 6), optional
        The gain the filter assumed.
    delta : float
        True orbital-rate error δ of (4) in the truth.
    discretization : {"exact", "euler"}
        Discretization of the truth.

    Returns
    -------
    ndarray, shape (6, 6)
        Stationary covariance of ``e(k) = x(k) − C_F x_f(k)``, the error of
        the estimate available at t_k (a prediction: it uses y up to k−1).
        ``sqrt(diag)`` gives the per-axis standard deviations.

    Raises
    ------
    UnstablePlantError
        If the truth is not Schur stable (always without maneuver: the
        unforced Hill model has eigenvalues on the unit circle, so x and
        hence the augmented state have no stationary covariance).
    InputError
        For bad shapes, a singular C_F, or an unstable filter.
    """
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav.Scenario; got {type(scenario).__name__}")
    if not isinstance(maneuver, (bool, np.bool_)):
        raise InputError(f"maneuver must be True or False; got {maneuver!r}")
    A_F = as_matrix("A_F", A_F, (6, 6))
    B_F = as_matrix("B_F", B_F, (6, 3))
    C_F = as_matrix("C_F", C_F, (6, 6))
    if np.linalg.cond(C_F) > 1e12:
        raise InputError("C_F must be invertible (the filter estimates the whole state)")
    delta = as_real("delta", delta)
    Phi, Gamma = scenario.truth_matrices(delta, discretization)
    K_truth = scenario.K if maneuver else np.zeros_like(scenario.K)
    A_t = Phi + Gamma @ K_truth
    rho = spectral_radius(A_t)
    if rho >= 1:
        raise UnstablePlantError(
            f"the truth x(k+1) = A x(k) + B w(k) is not Schur stable (spectral radius {rho:.6f}); "
            "its state, and the error of a filter without exact observer form, has no stationary covariance"
        )
    A_eff = A_F.copy()
    M_u_gain = np.zeros((6, 3))
    if (input_matrix is None) != (K is None):
        raise InputError("input_matrix and K must be given together to use the known thrust")
    if input_matrix is not None:
        G = as_matrix("input_matrix", input_matrix, (6, 3))
        K_F = as_matrix("K", K, (3, 6))
        M = np.linalg.solve(C_F, G)
        A_eff = A_F - M @ K_F @ C_F
        M_u_gain = M
    rho_f = spectral_radius(A_eff)
    if rho_f >= 1:
        raise InputError(f"A_F (with the input correction, if any) must be Schur stable; spectral radius {rho_f:.6f}")
    C, B, D = measurement_matrix(), scenario.B, scenario.D
    # The error system (13)-(14); the known thrust u = K_truth x enters the filter like an
    # extra measurement channel: B_F C + M K_truth = [B_F, M] [C; K_truth], noise [D; 0].
    Aa, Ba, Ca = error_system_matrices(
        A_t, B, np.vstack([C, K_truth]), np.vstack([D, np.zeros((3, D.shape[1]))]), np.eye(6),
        A_eff, np.hstack([B_F, M_u_gain]), C_F,
    )
    Sigma = scipy.linalg.solve_discrete_lyapunov(Aa, Ba @ Ba.T)
    cov = Ca @ Sigma @ Ca.T
    return 0.5 * (cov + cov.T)
