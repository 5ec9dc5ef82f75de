"""Huber's M-estimation as §1.2 of Shi & Wang (2018) uses it, step by step, for the notebook.

The paper's (6)–(15) are lost; they are rebuilt from Karlgaard & Schaub
(2007): the measurement and the prior as one regression (7)–(8)
``y = M x + ξ`` with ``y = S⁻¹[z; x̂⁻]``, ``M = S⁻¹[H; I]``,
``S Sᵀ = blockdiag(R, P⁻)``; Huber's cost (9)–(11), (14)
``ρ(ζ) = ζ²/2`` for ``|ζ| ≤ γ``, ``γ|ζ| − γ²/2`` otherwise; the iterative
(IRLS) solution (12)–(13) with weights ``ψ(ζ) = min(1, γ/|ζ|)``; the
covariance (15) ``(MᵀΨM)⁻¹``. The filter itself uses
:func:`hinfnav.estimators.huber_update` (IRLS with exact Newton steps); these helpers
show the plain IRLS iteration on one update.
"""

from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_positive

__all__ = ["huber_rho", "huber_psi", "whitened_regression", "IrlsPath", "irls_path", "huber_efficiency"]


def huber_rho(zeta, gamma=1.345):
    """Huber's cost (14): ``ζ²/2`` for ``|ζ| ≤ γ``, ``γ|ζ| − γ²/2`` otherwise (elementwise)."""
    gamma = as_positive("gamma", gamma)
    a = np.abs(np.asarray(zeta, dtype=float))
    return np.where(a <= gamma, 0.5 * a * a, gamma * a - 0.5 * gamma**2)


def huber_psi(zeta, gamma=1.345):
    """The IRLS weight ``ψ(ζ) = ρ'(ζ)/ζ``: 1 for ``|ζ| ≤ γ``, ``γ/|ζ|`` otherwise (elementwise)."""
    gamma = as_positive("gamma", gamma)
    a = np.abs(np.asarray(zeta, dtype=float))
    return np.where(a <= gamma, 1.0, gamma / np.maximum(a, gamma))


def whitened_regression(x_prior, P_prior, z, H, R):
    """``(M, y)`` of (7)–(8) for one update: ``M = S⁻¹[H; I]``, ``y = S⁻¹[z; x̂⁻]``, S the Cholesky factors."""
    x_prior, z = np.asarray(x_prior, dtype=float), np.asarray(z, dtype=float)
    P_prior, H, R = (np.asarray(a, dtype=float) for a in (P_prior, H, R))
    if x_prior.ndim != 1 or z.ndim != 1 or H.shape != (z.size, x_prior.size):
        raise InputError(f"x_prior (n,), z (m,) and H (m, n) must agree; got {x_prior.shape}, {z.shape}, {H.shape}")
    try:
        S_R, S_P = np.linalg.cholesky(R), np.linalg.cholesky(P_prior)
    except np.linalg.LinAlgError:
        raise InputError("R and P_prior must be symmetric positive definite") from None
    M = np.vstack([np.linalg.solve(S_R, H), np.linalg.solve(S_P, np.eye(x_prior.size))])
    y = np.concatenate([np.linalg.solve(S_R, z), np.linalg.solve(S_P, x_prior)])
    return M, y


@dataclass(frozen=True, eq=False)
class IrlsPath:
    """Iterates of plain IRLS (12)–(13) on one regression.

    Attributes
    ----------
    x : ndarray, shape (iterations + 1, n)
        ``x[0]`` is least squares (the Kalman update).
    cost : ndarray, shape (iterations + 1,)
        Huber cost ``Σ ρ(M x − y)`` at each iterate.
    weights : ndarray, shape (iterations + 1, m + n)
        ψ at each iterate.
    """

    x: np.ndarray
    cost: np.ndarray
    weights: np.ndarray


def irls_path(M, y, gamma=1.345, iterations=20):
    """Plain IRLS from least squares: ``x_{j+1} = (MᵀΨ_j M)⁻¹ MᵀΨ_j y`` with ``Ψ_j = diag ψ(M x_j − y)``."""
    gamma = as_positive("gamma", gamma)
    iterations = as_int_at_least("iterations", iterations, 1)
    M, y = np.asarray(M, dtype=float), np.asarray(y, dtype=float)
    x = np.linalg.lstsq(M, y, rcond=None)[0]
    xs, costs, ws = [x], [], []
    for j in range(iterations + 1):
        zeta = M @ x - y
        w = huber_psi(zeta, gamma)
        costs.append(float(np.sum(huber_rho(zeta, gamma))))
        ws.append(w)
        if j == iterations:
            break
        x = np.linalg.solve(M.T @ (w[:, None] * M), M.T @ (w * y))
        xs.append(x)
    return IrlsPath(x=np.array(xs), cost=np.array(costs), weights=np.array(ws))


def huber_efficiency(gamma=1.345):
    """Asymptotic efficiency of Huber's location estimate at the Gaussian: ``(2Φ(γ) − 1)² / E[ψ_H(ζ)²]``.

    ``ψ_H(ζ) = ρ'(ζ)`` is the clipped residual; 0.950 at γ = 1.345 (Huber 1964).
    """
    gamma = as_positive("gamma", gamma)
    p = 2 * norm.cdf(gamma) - 1
    second = p - 2 * gamma * norm.pdf(gamma) + 2 * gamma**2 * norm.sf(gamma)
    return float(p**2 / second)
