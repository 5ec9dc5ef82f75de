"""The accuracy limit of Sun et al. (2011)'s scenario: steady-state Kalman (Riccati) error.

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

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...analysis.riccati import stationary_lti_error_covariance, steady_state_kalman
from ...core.exceptions import InputError
from ...core.validation import as_choice, as_matrix, as_real
from ...systems.hill import measurement_matrix
from .scenario import Scenario

__all__ = ["KalmanLimit", "kalman_limit", "lti_error_covariance"]


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

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the per-axis numbers (lists of floats) and settings."""
        return {
            "pos_m": self.pos_m.tolist(),
            "vel_mps": self.vel_mps.tolist(),
            "pos_m_predicted": self.pos_m_predicted.tolist(),
            "vel_mps_predicted": self.vel_mps_predicted.tolist(),
            "maneuver": self.maneuver,
            "discretization": self.discretization,
        }


def kalman_limit(scenario: Scenario, maneuver: bool = True, discretization: str = "exact") -> KalmanLimit:
    """Steady-state Kalman error of the scenario's stated white-noise model.

    Parameters
    ----------
    scenario : Scenario
        Uses T, ω₀ (δ = 0), mass, K, B and D.
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
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    if not isinstance(maneuver, (bool, np.bool_)):
        raise InputError(f"maneuver must be True or False; got {maneuver!r}")
    as_choice("discretization", discretization, ("exact", "euler"))
    if np.linalg.matrix_rank(scenario.D) < scenario.D.shape[0]:
        raise InputError("the scenario's D must have full row rank: the Kalman limit needs R = D Dᵀ positive definite "
                         f"(D has rank {np.linalg.matrix_rank(scenario.D)} of {scenario.D.shape[0]})")
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
    scenario: Scenario, A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike, *, maneuver: bool = True,
    input_matrix: ArrayLike | None = None, K: ArrayLike | None = None, delta: float = 0.0, discretization: str = "exact"
) -> NDArray[np.float64]:
    """Stationary error covariance of the LTI filter (12) on the closed loop.

    The truth ``x(k+1) = A_t x(k) + B w(k)``, ``A_t = Φ(δ) + Γ(δ) K`` with
    maneuver (``Φ(δ)`` without), ``y = C x + D v``, and the filter
    ``x_f(k+1) = A_F x_f(k) + B_F y(k) [+ C_F⁻¹ G (u(k) − K C_F x_f(k))]``
    (the known-input correction of :class:`hinfnav.estimators.LTIFilter`,
    with ``u = K x`` of the truth) form a linear system driven by white
    noise; its stationary covariance solves a discrete Lyapunov equation.

    Parameters
    ----------
    scenario : Scenario
        Gives B, D, K, T, ω₀ and the mass.
    A_F : array_like, shape (6, 6)
    B_F : array_like, shape (6, 3)
    C_F : array_like, shape (6, 6)
        The filter (12); C_F invertible.
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
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    if not isinstance(maneuver, (bool, np.bool_)):
        raise InputError(f"maneuver must be True or False; got {maneuver!r}")
    A_F = as_matrix("A_F", A_F, (6, 6))
    B_F = as_matrix("B_F", B_F, (6, 3))
    C_F = as_matrix("C_F", C_F, (6, 6))
    delta = as_real("delta", delta)
    Phi, Gamma = scenario.truth_matrices(delta, discretization)
    K_truth = scenario.K if maneuver else np.zeros_like(scenario.K)
    return stationary_lti_error_covariance(
        Phi + Gamma @ K_truth, scenario.B, measurement_matrix(), scenario.D, A_F, B_F, C_F,
        K_truth=K_truth, input_matrix=input_matrix, K=K,
    )
