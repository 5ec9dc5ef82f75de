"""Variational-Bayes corrections of the Kalman core: the Student-t filter and the noise-adaptive filter.

Both are mixins that replace one hook of :class:`~hinfnav.estimators.kalman.KalmanCore`
(:meth:`~hinfnav.estimators.kalman.KalmanCore.correct`), as
:class:`~hinfnav.estimators.huber_filter.HuberCorrection` replaces ``correct_error``;
the prediction, the linearisation (an EKF's H at the prior), missing channels and
gates are the core's. Every quantity is batched over runs; a run whose fixed-point
iteration has converged is frozen while the others go on, so a batch gives each run's
numbers.

**Student-t filter** (Huang, Zhang, Li, Wu & Chambers 2017, "A novel robust Student's
t-based Kalman filter", IEEE TAES 53(3), Table I). Process and measurement noise are
Student-t with scale matrices Q, R and degrees of freedom ω (process) and ν
(measurement). The predicted density is approximated as St(x̂⁻, P⁻, ω) with the
nominal ``P⁻ = F P Fᵀ + Q`` and the likelihood as St(y; h(x), R, ν); each is a Gaussian
scale mixture with Gamma-distributed scales ξ (prior) and λ (likelihood), and the
variational iteration is, from q⁽⁰⁾(x) the prior (x̂⁽⁰⁾ = x̂⁻, P⁽⁰⁾ = P⁻; i = 0 … N−1),
first the scales given q⁽ⁱ⁾(x), then q⁽ⁱ⁺¹⁾(x) given the scales:

.. math::

    E^{(i+1)}[\\xi] = \\frac{\\omega + n}{\\omega + \\operatorname{tr}\\{A P^{-,-1}\\}}, \\quad
    A = (\\hat x^{(i)} - \\hat x^-)(\\cdot)^T + P^{(i)},

    E^{(i+1)}[\\lambda] = \\frac{\\nu + m}{\\nu + \\operatorname{tr}\\{B R^{-1}\\}}, \\quad
    B = (\\nu_k - H(\\hat x^{(i)} - \\hat x^-))(\\cdot)^T + H P^{(i)} H^T,

    \\tilde P = P^-/E^{(i+1)}[\\xi], \\quad \\tilde R = R/E^{(i+1)}[\\lambda], \\quad
    K = \\tilde P H^T (H \\tilde P H^T + \\tilde R)^{-1},

    \\hat x^{(i+1)} = \\hat x^- + K \\nu_k, \\quad P^{(i+1)} = \\tilde P - K H \\tilde P,

stopped after N iterations or when ``‖x̂⁽ⁱ⁺¹⁾ − x̂⁽ⁱ⁾‖ / ‖x̂⁽ⁱ⁺¹⁾‖ ≤ τ``; x̂(k|k) and
P(k|k) are the last iterate. The order matters: the VB fixed point is not unique
under an outlier, and starting from the prior (the scales first) lets the first
iteration already see the innovation (measured on :mod:`hinfnav.papers.benchmark.huang2017`:
the other order, the state first with E[ξ] = E[λ] = 1, lands on the fixed point that
keeps the outlier and gives a larger error). On a nonlinear measurement H is the EKF's Jacobian at the
prior and ``ν_k = y_k − h(x̂⁻)`` (Huang et al. treat the linear model; this is its
first-order extension, as the package's Huber filter is).

**Noise-adaptive filter** (Särkkä & Nummenmaa 2009, "Recursive noise adaptive Kalman
filtering by variational Bayesian approximations", IEEE TAC 54(3), eqs. of §III). The
measurement noise is N(0, Σ) with an unknown diagonal Σ = diag(σ²ᵢ), each σ²ᵢ
inverse-Gamma(αᵢ, βᵢ). Between readings the parameters fade, ``α⁻ = ρ α``,
``β⁻ = ρ β`` (ρ ∈ (0, 1], 1 = a constant Σ); at a reading ``α = α⁻ + 1/2`` and, from
β⁽⁰⁾ = β⁻, N times

.. math::

    \\hat\\Sigma = \\operatorname{diag}(\\beta^{(j)}/\\alpha), \\quad
    S = H P^- H^T + \\hat\\Sigma, \\quad K = P^- H^T S^{-1},

    \\hat x = \\hat x^- + K \\nu_k, \\quad P = P^- - K S K^T, \\quad
    \\beta^{(j+1)}_i = \\beta^-_i + \\tfrac12 (\\nu_k - H(\\hat x - \\hat x^-))_i^2 + \\tfrac12 (H P H^T)_{ii}.

The first reading uses α₀, β₀ themselves (the prior at t₀: the contract's ``start``
gives x̂(0|−1)); the default ``β₀ = α₀ diag(R)`` starts Σ̂ at the filter's nominal R.

Diagnostics (leading dimension runs): ``innovation_covariance`` (the nominal
``H P⁻ Hᵀ + R``, for the NIS), ``iterations``, and for the Student-t filter
``scale_prior`` E[ξ] and ``scale_measurement`` E[λ]; for the adaptive filter
``noise_variance`` (the estimated diag Σ, β/α).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_nonnegative, as_positive
from .kalman import ExtendedKalmanFilter

if TYPE_CHECKING:
    from .base import FilterState

__all__ = ["DataDependentCorrection", "StudentTCorrection", "StudentTFilter", "NoiseAdaptiveCorrection",
           "NoiseAdaptiveFilter", "relative_change"]


def _swap(M):
    return np.swapaxes(M, -1, -2)


def used_rows(H: NDArray[np.float64], runs: int) -> NDArray[np.bool_]:
    """(runs, m) mask of the rows of H that are used (a row the core zeroed for a missing or rejected channel is not)."""
    rows = np.any(H != 0.0, axis=-1)
    return np.broadcast_to(rows, (runs, H.shape[-2]))


def relative_change(dx_new: NDArray[np.float64], dx_old: NDArray[np.float64],
                    x_ref: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """``‖x̂⁽ⁱ⁺¹⁾ − x̂⁽ⁱ⁾‖ / ‖x̂⁽ⁱ⁺¹⁾‖`` per run with ``x̂ = x_ref + δ`` (the stopping rule of both papers);
    the absolute change ``‖δ⁽ⁱ⁺¹⁾ − δ⁽ⁱ⁾‖`` when ``x_ref`` is None (error coordinates of another size)."""
    step = np.linalg.norm(dx_new - dx_old, axis=-1)
    if x_ref is None:
        return step
    with np.errstate(divide="ignore", invalid="ignore"):
        return step / np.linalg.norm(x_ref + dx_new, axis=-1)


def _reference(x, P):
    """The prior estimate for the relative stopping rule, when it lives in the error coordinates of P."""
    return x if x.shape[-1] == P.shape[-1] else None


def _prior_per_run(x, P, innovation):
    """``(runs, P, n, x_ref)`` of an iterated correction: P broadcast to (runs, n, n), the stopping rule's reference."""
    runs = innovation.shape[0]
    P = np.broadcast_to(P, (runs,) + P.shape[-2:])
    return runs, P, P.shape[-1], _reference(x, P)


class DataDependentCorrection:
    """Mixin base of a correction whose weights or noise estimates, hence P, depend on the data."""

    data_dependent_covariance = True

    @property
    def shares_covariance(self) -> bool:
        """Always False: the correction's weights or noise estimates, hence P, depend on the data."""
        return False


class StudentTCorrection(DataDependentCorrection):
    """Mixin: Huang et al. (2017)'s variational Student-t update as the correction of a Kalman-type filter.

    Put it first in the bases of a filter of the Kalman core. Keyword parameters
    ``dof_process`` ω, ``dof_measurement`` ν (> 0), ``iterations`` N (≥ 1) and ``tol`` τ
    (≥ 0; 0: always N iterations). See the module docstring.
    """

    def __init__(self, *args: Any, dof_process: float = 5.0, dof_measurement: float = 5.0, iterations: int = 10,
                 tol: float = 1e-8, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.dof_process = as_positive("dof_process", dof_process)
        self.dof_measurement = as_positive("dof_measurement", dof_measurement)
        self.iterations = as_int_at_least("iterations", iterations, 1)
        self.tol = as_nonnegative("tol", tol)

    def correct(self, x: NDArray[np.float64], P: NDArray[np.float64], H: NDArray[np.float64],
                innovation: NDArray[np.float64], state: FilterState,
                R: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """The variational fixed point of the module docstring; returns ``(x⁺, P⁺, diagnostics)`` (P per run)."""
        R = self.R if R is None else R
        runs, P, n, x_ref = _prior_per_run(x, P, innovation)
        m_used = used_rows(H, runs).sum(axis=1)
        Pinv = np.linalg.inv(P)
        Rinv = np.linalg.inv(R)
        HT = _swap(H)
        e_xi, e_lam = np.ones(runs), np.ones(runs)
        dx = np.zeros_like(innovation, shape=(runs, n))  # x̂⁽⁰⁾ = x̂⁻, P⁽⁰⁾ = P⁻
        P_post = np.array(P)
        active = np.ones(runs, dtype=bool)
        iters = np.zeros(runs, dtype=int)
        omega, nu = self.dof_process, self.dof_measurement
        for _ in range(self.iterations):
            # q(ξ), q(λ) given q⁽ⁱ⁾(x) ...
            A = dx[:, :, None] * dx[:, None, :] + P_post
            e = innovation - (H @ dx[..., None])[..., 0]
            B = e[:, :, None] * e[:, None, :] + H @ P_post @ HT
            # tr(A P⁻⁻¹) = Σ_ij A_ij (P⁻⁻¹)_ji without forming the product
            xi_new = (omega + n) / (omega + np.einsum("rij,rji->r", A, np.broadcast_to(Pinv, A.shape)))
            lam_new = (nu + m_used) / (nu + np.einsum("rij,rji->r", B, np.broadcast_to(Rinv, B.shape)))
            # ... then q⁽ⁱ⁺¹⁾(x) given them
            Pt = P / xi_new[:, None, None]
            Rt = R / lam_new[:, None, None]
            PHT = Pt @ HT
            K = _swap(np.linalg.solve(H @ PHT + Rt, _swap(PHT)))
            dx_new = (K @ innovation[..., None])[..., 0]
            P_new = Pt - K @ H @ Pt
            change = relative_change(dx_new, dx, x_ref)
            dx = np.where(active[:, None], dx_new, dx)
            P_post = np.where(active[:, None, None], P_new, P_post)
            e_xi = np.where(active, xi_new, e_xi)
            e_lam = np.where(active, lam_new, e_lam)
            iters = iters + active
            active = active & ~(change <= self.tol)
            if not active.any():
                break
        S = H @ P @ HT + R
        return self.inject(x, dx), P_post, {"innovation_covariance": S, "iterations": iters,
                                            "scale_prior": e_xi, "scale_measurement": e_lam}


class StudentTFilter(StudentTCorrection, ExtendedKalmanFilter):
    """Huang et al. (2017)'s robust Student-t Kalman filter on the step contract (see the module docstring).

    Parameters
    ----------
    system, measurement, P0, Q, R, uses_input, output, name, missing
        As for :class:`~hinfnav.estimators.ExtendedKalmanFilter`; Q and R are the
        scale matrices of the Student-t process and measurement noise (the nominal
        covariances of the prediction ``F P Fᵀ + Q``).
    dof_process : float
        ω, degrees of freedom of the process noise (> 0; Huang et al. use 5).
    dof_measurement : float
        ν, degrees of freedom of the measurement noise (> 0; Huang et al. use 5).
    iterations : int
        N, the most fixed-point iterations per update (≥ 1; Huang et al. use 10).
    tol : float
        τ, the relative-change stopping threshold (≥ 0; 0 always runs N iterations).
    """

    name = "stkf"

    @classmethod
    def from_ekf(cls, ekf: ExtendedKalmanFilter, *, name: str | None = None, **options: Any) -> StudentTFilter:
        """The Student-t version of an :class:`~hinfnav.estimators.ExtendedKalmanFilter` (same model, Q, R, P₀)."""
        return _from_ekf(cls, ekf, name or cls.name, options)


def _from_ekf(cls, ekf, name, options):
    if not isinstance(ekf, ExtendedKalmanFilter):
        raise InputError(f"ekf must be a hinfnav ExtendedKalmanFilter; got {type(ekf).__name__}")
    return cls(ekf.system, ekf.measurement, P0=ekf.P0, Q=ekf.Q, R=ekf.R, uses_input=ekf.uses_input,
               output=ekf.output, name=name, missing=ekf.missing, **options)


class NoiseAdaptiveCorrection(DataDependentCorrection):
    """Mixin: Särkkä & Nummenmaa (2009)'s variational-Bayes update with an unknown diagonal R.

    Keyword parameters ``rho`` ρ ∈ (0, 1] (the fading of α, β between readings),
    ``iterations`` N (≥ 1), ``alpha0`` (> 0) and ``beta0`` ((m,) > 0; default
    ``alpha0 · diag(R)``). The posterior α, β are carried from reading to reading in
    ``FilterState.extra`` (keys ``vb_alpha``, ``vb_beta``; the core's :meth:`carried` hook).
    """

    def __init__(self, *args: Any, rho: float = 1.0, iterations: int = 5, alpha0: float = 1.0,
                 beta0: ArrayLike | None = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.rho = as_positive("rho", rho)
        if self.rho > 1.0:
            raise InputError(f"rho must be in (0, 1]; got {rho!r}")
        self.iterations = as_int_at_least("iterations", iterations, 1)
        self.alpha0 = as_positive("alpha0", alpha0)
        if self.R is None:
            raise InputError("the noise-adaptive filter needs a constant nominal R (its measurement's covariance "
                             "depends on the reading)")
        m = self.R.shape[0]
        beta0 = self.alpha0 * np.diag(self.R) if beta0 is None else np.asarray(beta0, dtype=float)
        if beta0.shape != (m,) or not np.all(np.isfinite(beta0)) or np.any(beta0 <= 0):
            raise InputError(f"beta0 must be {m} positive finite numbers (one per channel); got {beta0!r}")
        self.beta0 = beta0

    def carried(self, diagnostics: dict[str, Any]) -> dict[str, Any]:
        """α, β of this reading, kept for the next."""
        return {"vb_alpha": diagnostics["vb_alpha"], "vb_beta": diagnostics["vb_beta"]}

    def correct(self, x: NDArray[np.float64], P: NDArray[np.float64], H: NDArray[np.float64],
                innovation: NDArray[np.float64], state: FilterState,
                R: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        """The iteration of the module docstring; returns ``(x⁺, P⁺, diagnostics)`` (P per run)."""
        runs, m = innovation.shape
        P = np.broadcast_to(P, (runs,) + P.shape[-2:])
        used = used_rows(H, runs)
        if "vb_alpha" in state.extra:  # α⁻ = ρ α, β⁻ = ρ β: the parameters faded since the last reading
            alpha_prior, beta_prior = self.rho * state.extra["vb_alpha"], self.rho * state.extra["vb_beta"]
        else:
            alpha_prior = np.full((runs, m), self.alpha0)
            beta_prior = np.broadcast_to(self.beta0, (runs, m)).copy()
        alpha = alpha_prior + 0.5 * used
        beta = beta_prior
        HT = _swap(H)
        PHT = P @ HT
        HPHT = H @ PHT
        eye = np.eye(m)
        for _ in range(self.iterations):
            # a channel not used (missing or rejected) keeps its noise and has unit weight on its zero row
            sigma = np.where(used, beta / alpha, 1.0)
            S = HPHT + sigma[:, :, None] * eye
            K = _swap(np.linalg.solve(S, _swap(PHT)))
            dx = (K @ innovation[..., None])[..., 0]
            P_post = P - K @ S @ _swap(K)
            e = innovation - (H @ dx[..., None])[..., 0]
            beta = beta_prior + 0.5 * used * (e**2 + np.diagonal(H @ P_post @ HT, axis1=-2, axis2=-1))
        R_nom = self.R if R is None else R
        return self.inject(x, dx), P_post, {"innovation_covariance": HPHT + R_nom, "vb_alpha": alpha,
                                            "vb_beta": beta, "noise_variance": beta / alpha,
                                            "iterations": np.full(runs, self.iterations)}


class NoiseAdaptiveFilter(NoiseAdaptiveCorrection, ExtendedKalmanFilter):
    """Särkkä & Nummenmaa (2009)'s variational-Bayes adaptive Kalman filter (unknown diagonal R).

    Parameters
    ----------
    system, measurement, P0, Q, R, uses_input, output, name, missing
        As for :class:`~hinfnav.estimators.ExtendedKalmanFilter`; R is the nominal
        measurement covariance (its diagonal starts the estimate unless ``beta0`` is given).
    rho : float
        ρ ∈ (0, 1], the fading of the noise parameters between readings (1: constant noise).
    iterations : int
        N, fixed-point iterations per update (≥ 1).
    alpha0 : float
        α₀ (> 0), the shape of the initial inverse-Gamma densities.
    beta0 : array_like, shape (m,), optional
        β₀ (> 0); default ``alpha0 · diag(R)`` (Σ̂ starts at diag R).
    """

    name = "vbakf"

    @classmethod
    def from_ekf(cls, ekf: ExtendedKalmanFilter, *, name: str | None = None, **options: Any) -> NoiseAdaptiveFilter:
        """The noise-adaptive version of an :class:`~hinfnav.estimators.ExtendedKalmanFilter` (its R the nominal)."""
        return _from_ekf(cls, ekf, name or cls.name, options)
