"""Continuous-time H∞ norm by the Hamiltonian bisection of Boyd, Balakrishnan & Kabamba (1989), in numpy.

For a Hurwitz ``A`` and ``G(s) = C (sI − A)⁻¹ B + D``, ``‖G‖∞ < γ`` (with
``σ̄(D) < γ``) iff the Hamiltonian matrix

    H(γ) = [[A + B R⁻¹ Dᵀ C,          B R⁻¹ Bᵀ          ],
            [−Cᵀ (I + D R⁻¹ Dᵀ) C,   −(A + B R⁻¹ Dᵀ C)ᵀ ]],   R = γ² I − Dᵀ D,

has no eigenvalue on the imaginary axis. Bisection on γ between the
largest sampled gain and an upper bound gives the norm to a relative
tolerance. Independent of SLICOT and of any LMI: the certificate of a
continuous-time robust analysis (:mod:`hinfnav.lmi.continuous`) is checked
against it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError

__all__ = ["hinf_norm_continuous"]


def _has_imaginary_eig(A, B, C, D, g, tol):
    R = g * g * np.eye(D.shape[1]) - D.T @ D
    Ri = np.linalg.inv(R)
    Ah = A + B @ Ri @ D.T @ C
    H = np.block([[Ah, B @ Ri @ B.T], [-C.T @ (np.eye(C.shape[0]) + D @ Ri @ D.T) @ C, -Ah.T]])
    lam = np.linalg.eigvals(H)
    return bool(np.any(np.abs(lam.real) < tol * max(1.0, np.abs(lam).max())))


def hinf_norm_continuous(A: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike | None = None,
                         rtol: float = 1e-9) -> float:
    """``‖C (sI − A)⁻¹ B + D‖∞`` of a continuous-time system (``inf`` when A is not Hurwitz).

    Parameters
    ----------
    A, B, C, D : array_like
        Shapes (n, n), (n, m), (p, n), (p, m); D defaults to 0.
    rtol : float
        Relative accuracy of the bisection.
    """
    A, B, C = (np.atleast_2d(np.asarray(M, dtype=float)) for M in (A, B, C))
    D = np.zeros((C.shape[0], B.shape[1])) if D is None else np.atleast_2d(np.asarray(D, dtype=float))
    n = A.shape[0]
    if A.shape != (n, n) or B.shape[0] != n or C.shape[1] != n or D.shape != (C.shape[0], B.shape[1]):
        raise InputError(f"A, B, C, D do not fit: shapes {A.shape}, {B.shape}, {C.shape}, {D.shape}")
    if not np.all(np.linalg.eigvals(A).real < 0):
        return float("inf")
    poles = np.linalg.eigvals(A)
    w = np.concatenate([[0.0], np.abs(poles)])
    lo = max(np.linalg.norm(C @ np.linalg.solve(1j * x * np.eye(n) - A, B) + D, 2) for x in w)
    lo = max(lo, np.linalg.norm(D, 2), 1e-300)
    hi = 2.0 * lo
    while _has_imaginary_eig(A, B, C, D, hi, 1e-10):
        hi *= 2.0
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if _has_imaginary_eig(A, B, C, D, mid, 1e-10):
            lo = mid
        else:
            hi = mid
    return float(hi)
