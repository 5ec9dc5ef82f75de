"""The Huber-based filter (HBF): the extended Kalman filter with Huber's M-estimation as its update.

Karlgaard & Schaub (J. Guidance, Control, and Dynamics 30(3), 2007); Shi &
Wang (Aerospace Control 2018 no. 5), §1. The prediction is the EKF's,
``x̂⁻ = Φ x̂ (+ Γ u)``, ``P⁻ = Φ P Φᵀ + Q``. The update writes the
linearised measurement and the prior as one regression for the correction
``δ = x − x̂⁻``,

.. math::

    \\begin{bmatrix} \\nu_k \\\\ 0 \\end{bmatrix}
    = \\begin{bmatrix} H_k \\\\ I \\end{bmatrix} \\delta + e, \\qquad
    \\operatorname{cov}(e) = \\operatorname{blockdiag}(R_k, P^-),

with the innovation ``ν_k = y_k − h(x̂⁻)`` (the converted reading minus the
predicted position for the indirect measurement), whitens it and minimises
Huber's cost ``Σ ρ_γ(ζ_i)`` by :func:`~hinfnav.estimators.huber.huber_update`
(IRLS with exact Newton steps); ``x̂⁺ = x̂⁻ + δ`` and ``P⁺ = (MᵀΨM)⁻¹`` at the
converged weights Ψ. This is the same regression in ``x`` as in Karlgaard &
Schaub's ``[z; x̂⁻] = [H; I] x`` (shifting the unknown by x̂⁻ changes no
residual). When no whitened residual exceeds γ the update is the Kalman
update.

Diagnostics reported at each step (leading dimension runs): ``weights``
(the final Ψ, the first m for the measurement rows, the last n for the prior
rows), ``iterations`` and ``converged`` of the M-estimation, and the
``innovation``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_positive
from .huber import huber_correct, whitening
from .kalman import ExtendedKalmanFilter, StrongTrackingEKF

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["HuberCorrection", "HuberFilter", "HuberStrategy", "HuberStrongTrackingEKF", "huber_correct_error"]


def huber_correct_error(P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64],
                        innovation: NDArray[np.float64], *, gamma: float, tol: float, max_iter: int,
                        LRi: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
    """Huber M-estimation of the correction δx (the module docstring's regression); ``(δx, P⁺, diagnostics)``.

    P (n, n) or (runs, n, n) (made per run), H (m, n) or (runs, m, n), R (m, m) or (runs, m, m); ``LRi`` the
    whitening of a constant R (None: R whitened here). Diagnostics ``weights``, ``iterations``, ``converged``,
    ``innovation_covariance`` (H P⁻ Hᵀ + R).
    """
    if P.ndim == 2:
        P = np.broadcast_to(P, (innovation.shape[0],) + P.shape)
    dx, P_post, weights, iterations, converged = huber_correct(
        None, P, innovation, H, R, gamma=gamma, tol=tol, max_iter=max_iter, LRi=LRi)
    HT = np.swapaxes(H, -1, -2)
    S = H @ P @ HT + R  # innovation covariance of the prior (the Kalman start of the regression)
    return dx, P_post, {"weights": weights, "iterations": iterations, "converged": converged,
                        "innovation_covariance": S}


class HuberStrategy:
    """Huber's M-estimation as a correction *strategy*: composed onto any filter of the Kalman core
    (:func:`~hinfnav.estimators.strategies.compose`; ``correction="huber"``), whatever its moment rule.

    On the linearised rule it is :class:`HuberCorrection`'s correction, bitwise; on the sigma-point rule it
    runs on the statistical linearisation (M1) of :mod:`hinfnav.estimators.moments` (the Huber-based
    sigma-point filter of Karlgaard & Schaub 2007). Parameters as :class:`HuberFilter`'s.

    Parameters
    ----------
    gamma : float
        Huber threshold on the whitened residuals (> 0), 1.345 by default.
    tol : float
        Convergence tolerance of the M-estimation (> 0).
    max_iter : int
        Iterations per update (≥ 1).
    """

    name = "huber"

    def __init__(self, gamma: float = 1.345, tol: float = 1e-10, max_iter: int = 50) -> None:
        self.gamma = as_positive("gamma", gamma)
        self.tol = as_positive("tol", tol)
        self.max_iter = as_int_at_least("max_iter", max_iter, 1)

    def __repr__(self) -> str:
        return f"HuberStrategy(gamma={self.gamma}, tol={self.tol}, max_iter={self.max_iter})"

    def bind(self, estimator: Any) -> None:
        """Check that ``estimator`` can take this correction (none needed: R may depend on the reading)."""

    def correct_error(self, estimator: Any, P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64],
                      innovation: NDArray[np.float64], x: NDArray[np.float64] | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """``(δx, P⁺, diagnostics)`` of :func:`huber_correct_error` (P per run; the prior estimate x is not used)."""
        LRi = whitening(R) if R is estimator.R else None  # the constant R whitened as HuberCorrection does
        return huber_correct_error(P, H, R, innovation, gamma=self.gamma, tol=self.tol, max_iter=self.max_iter,
                                   LRi=LRi)


class HuberCorrection:
    """Mixin: Huber's M-estimation as the correction of any Kalman-type filter of the package.

    Put it first in the bases of a filter with the ``correct_error`` hook
    (:class:`~hinfnav.estimators.ExtendedKalmanFilter`,
    :class:`~hinfnav.estimators.AugmentedEKF` and their variants: strong
    tracking, the attitude filters). Keyword parameters ``gamma``, ``tol``,
    ``max_iter`` as in :class:`HuberFilter`. The weights make P depend on the
    data: every run carries its own covariance. Diagnostics: ``weights``,
    ``iterations``, ``converged``, ``innovation_covariance`` (H P⁻ Hᵀ + R).
    """

    data_dependent_covariance = True
    #: The correction is Huber's M-estimation (read by the compiled kernels).
    huber_correction = True

    def __init__(self, *args: Any, gamma: float = 1.345, tol: float = 1e-10, max_iter: int = 50, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.gamma = as_positive("gamma", gamma)
        self.tol = as_positive("tol", tol)
        self.max_iter = as_int_at_least("max_iter", max_iter, 1)
        self._LRi = None if self.R is None else whitening(self.R)  # constant R: whitened once

    @property
    def whitening_matrix(self) -> np.ndarray | None:
        """``L_R⁻¹`` of the constant R (:func:`~hinfnav.estimators.huber.whitening`), None when R depends on the
        reading."""
        return self._LRi

    @property
    def shares_covariance(self) -> bool:
        """Always False: the Huber weights, hence P, depend on the data."""
        return False

    def correct_error(self, P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64], innovation: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """Huber M-estimation of the correction δx; returns ``(δx, P⁺, diagnostics)`` (P per run)."""
        return huber_correct_error(P, H, R, innovation, gamma=self.gamma, tol=self.tol, max_iter=self.max_iter,
                                   LRi=self._LRi if R is self.R else None)


class HuberFilter(HuberCorrection, ExtendedKalmanFilter):
    """Huber-based filter on the step contract (see the module docstring).

    Parameters
    ----------
    system, measurement, P0, Q, R, uses_input, output, name
        As for :class:`~hinfnav.estimators.ExtendedKalmanFilter`.
    gamma : float
        Huber threshold γ on the whitened residuals (> 0); 1.345, "usually
        1.345" in Shi & Wang (2018) §1.2, gives 95 % efficiency at the Gaussian.
    tol : float
        Convergence tolerance of the M-estimation (> 0), on the whitened residuals.
    max_iter : int
        Iterations of the M-estimation per update (≥ 1).

    Notes
    -----
    The weights, hence the covariance, depend on the data, so every run
    carries its own covariance (no shared gain sequence as for the Kalman
    filter on a linear measurement).
    """

    name = "hbf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "kalman"

    def __init__(self, system: LinearSystem | DynamicsModel, measurement: MeasurementModel, *, P0: ArrayLike, Q: ArrayLike | None = None,
                 R: ArrayLike | None = None, gamma: float = 1.345, tol: float = 1e-10, max_iter: int = 50,
                 uses_input: bool = False, output: str = "filtered", name: str | None = None,
                 missing: str = "refuse") -> None:
        super().__init__(system, measurement, P0=P0, Q=Q, R=R, uses_input=uses_input, output=output, name=name,
                         missing=missing, gamma=gamma, tol=tol, max_iter=max_iter)

    @classmethod
    def from_ekf(cls, ekf: ExtendedKalmanFilter, *, gamma: float = 1.345, tol: float = 1e-10, max_iter: int = 50,
                 name: str | None = None) -> HuberFilter:
        """The Huber-based version of an :class:`~hinfnav.estimators.ExtendedKalmanFilter`.

        Same system, measurement, P₀, Q, R (or reading-dependent R), input
        use and output; only the update differs.
        """
        if not isinstance(ekf, ExtendedKalmanFilter):
            raise InputError(f"ekf must be a hinfnav ExtendedKalmanFilter; got {type(ekf).__name__}")
        return cls(ekf.system, ekf.measurement, P0=ekf.P0, Q=ekf.Q, R=ekf.R, gamma=gamma, tol=tol,
                   max_iter=max_iter, uses_input=ekf.uses_input, output=ekf.output,
                   name=name if name is not None else "hbf", missing=ekf.missing)


class HuberStrongTrackingEKF(HuberCorrection, StrongTrackingEKF):
    """Huber × strong tracking on the EKF core: fading factors (S1)–(S4) for the prior, Huber's M-estimation
    for the correction.

    Parameters of :class:`~hinfnav.estimators.StrongTrackingEKF` (``rho``,
    ``beta``, ``a``; R constant) and of :class:`HuberFilter` (``gamma``,
    ``tol``, ``max_iter``). Diagnostics of both (``fading``, ``weights`` …).
    """

    name = "huber_stekf"

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "kalman"
