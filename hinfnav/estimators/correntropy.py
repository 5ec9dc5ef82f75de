"""The maximum-correntropy Kalman filter (MCKF) as a correction of the Kalman core.

Chen, Liu, Zhao & Principe (2017), "Maximum correntropy Kalman filter",
Automatica 76, 70–77, Algorithm (steps 1–6). The prediction is the Kalman
filter's, ``x̂⁻ = F x̂``, ``P⁻ = F P Fᵀ + Q``. With the Cholesky factors
``P⁻ = B_p B_pᵀ``, ``R = B_r B_rᵀ`` the prior and the reading are one whitened
regression ``D = W x + e`` with ``D = B⁻¹[x̂⁻; y]``, ``W = B⁻¹[I; H]``,
``B = blockdiag(B_p, B_r)``; instead of its least squares the MCKF maximises the
correntropy ``Σ G_σ(e_i)``, ``G_σ(e) = exp(−e²/(2σ²))``, by the fixed point
(t = 1, 2 …, from x̂₀ = x̂⁻)

.. math::

    \\tilde e = D - W \\hat x_{t-1}, \\quad
    C_x = \\operatorname{diag}(G_\\sigma(\\tilde e_1 … \\tilde e_n)), \\quad
    C_y = \\operatorname{diag}(G_\\sigma(\\tilde e_{n+1} … \\tilde e_{n+m})),

    \\tilde P = B_p C_x^{-1} B_p^T, \\quad \\tilde R = B_r C_y^{-1} B_r^T, \\quad
    \\tilde K = \\tilde P H^T (H \\tilde P H^T + \\tilde R)^{-1}, \\quad
    \\hat x_t = \\hat x^- + \\tilde K \\nu_k,

stopped when ``‖x̂_t − x̂_{t−1}‖ / ‖x̂_{t−1}‖ ≤ ε`` (or after ``max_iter``
iterations); then ``P = (I − K̃H) P⁻ (I − K̃H)ᵀ + K̃ R K̃ᵀ`` (step 6). As σ → ∞
every weight is 1 and the MCKF is the Kalman filter. The implementation works in
the correction δ = x − x̂⁻ (``ẽ_x = −B_p⁻¹ δ``, ``ẽ_y = B_r⁻¹(ν − H δ)``), which is
the same regression; on a nonlinear measurement H and ν are the EKF's.

A weight G_σ below :data:`WEIGHT_FLOOR` (a residual of more than ~21 σ) is taken
at the floor, so that C⁻¹ stays finite (the paper's C⁻¹ is infinite there; the
reading or prior entry is then all but ignored either way).

Diagnostics: ``weights`` (runs, n + m) the final diag(C_x, C_y),
``iterations``, ``converged`` and ``innovation_covariance`` (the nominal
``H P⁻ Hᵀ + R``, for the NIS).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..core.validation import as_int_at_least, as_nonnegative, as_positive
from .correction import joseph_covariance
from .kalman import ExtendedKalmanFilter
from .variational import DataDependentCorrection, _from_ekf, _prior_per_run, _swap, relative_change

if TYPE_CHECKING:
    from .base import FilterState

__all__ = ["CorrentropyCorrection", "CorrentropyFilter"]

#: Smallest kernel weight G_σ(e) used (see the module docstring).
WEIGHT_FLOOR = 1e-100


class CorrentropyCorrection(DataDependentCorrection):
    """Mixin: the maximum-correntropy correction (Chen et al. 2017) on a filter of the Kalman core.

    Keyword parameters ``sigma`` (kernel bandwidth σ on the whitened residuals, > 0),
    ``tol`` ε (≥ 0) and ``max_iter`` (≥ 1). See the module docstring.
    """

    def __init__(self, *args: Any, sigma: float = 2.0, tol: float = 1e-6, max_iter: int = 100, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.sigma = as_positive("sigma", sigma)
        self.tol = as_nonnegative("tol", tol)
        self.max_iter = as_int_at_least("max_iter", max_iter, 1)

    def correct(self, x: NDArray[np.float64], P: NDArray[np.float64], H: NDArray[np.float64],
                innovation: NDArray[np.float64], state: FilterState,
                R: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """The kernel-weighted fixed point of the module docstring; returns ``(x⁺, P⁺, diagnostics)`` (P per run)."""
        R = self.R if R is None else R
        runs, P, n, x_ref = _prior_per_run(x, P, innovation)
        Bp = np.linalg.cholesky(P)
        Br = np.linalg.cholesky(R)
        HT = _swap(H)
        two_s2 = 2.0 * self.sigma**2
        dx = np.zeros((runs, n))
        K_fin = np.zeros((runs, n, innovation.shape[1]))
        weights = np.ones((runs, n + innovation.shape[1]))
        active = np.ones(runs, dtype=bool)
        iters = np.zeros(runs, dtype=int)
        for _ in range(self.max_iter):
            ex = np.linalg.solve(Bp, -dx[..., None])[..., 0]
            ey = np.linalg.solve(Br, (innovation - (H @ dx[..., None])[..., 0])[..., None])[..., 0]
            cx = np.maximum(np.exp(-ex**2 / two_s2), WEIGHT_FLOOR)
            cy = np.maximum(np.exp(-ey**2 / two_s2), WEIGHT_FLOOR)
            Pt = (Bp / cx[:, None, :]) @ _swap(Bp)
            Rt = (Br / cy[:, None, :]) @ _swap(Br)
            PHT = Pt @ HT
            K = _swap(np.linalg.solve(H @ PHT + Rt, _swap(PHT)))
            dx_new = (K @ innovation[..., None])[..., 0]
            change = relative_change(dx_new, dx, None if x_ref is None else x_ref + dx - dx_new)
            dx = np.where(active[:, None], dx_new, dx)
            K_fin = np.where(active[:, None, None], K, K_fin)
            weights = np.where(active[:, None], np.concatenate([cx, cy], axis=1), weights)
            iters = iters + active
            active = active & ~(change <= self.tol)
            if not active.any():
                break
        P_post = joseph_covariance(P, K_fin, H, R, symmetrize=False)
        return self.inject(x, dx), P_post, {"weights": weights, "iterations": iters, "converged": ~active,
                                            "innovation_covariance": H @ P @ HT + R}


class CorrentropyFilter(CorrentropyCorrection, ExtendedKalmanFilter):
    """Chen et al. (2017)'s maximum-correntropy Kalman filter on the step contract (see the module docstring).

    Parameters
    ----------
    system, measurement, P0, Q, R, uses_input, output, name, missing
        As for :class:`~hinfnav.estimators.ExtendedKalmanFilter`.
    sigma : float
        Kernel bandwidth σ (> 0) on the whitened residuals (Cholesky-whitened, so
        dimensionless); large σ gives the Kalman filter.
    tol : float
        ε, the relative-change stopping threshold (≥ 0; Chen et al. use 1e-6).
    max_iter : int
        The most fixed-point iterations per update (≥ 1).
    """

    name = "mckf"

    @classmethod
    def from_ekf(cls, ekf: ExtendedKalmanFilter, *, name: str | None = None, **options: Any) -> CorrentropyFilter:
        """The MCKF version of an :class:`~hinfnav.estimators.ExtendedKalmanFilter` (same model, Q, R, P₀)."""
        return _from_ekf(cls, ekf, name or cls.name, options)
