"""Conditioning of the synthesis LMIs: drop, balance and scale, all exactly undoable.

* zero columns of H and zero rows of E are dropped;
* the factorization ``ΔA = H F E`` is balanced channel by channel when F is
  diagonal, by one common scalar otherwise (:func:`prepare_uncertainty`);
* the state coordinates are scaled by powers of two (``x = Σ x̃``), so that
  scaling and unscaling are exact in floating point.
"""

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_matrix

__all__ = ["Prepared", "prepare_uncertainty", "prepare", "state_scaling", "pow2"]


def pow2(x):
    """Nearest power of two (exact scaling in floating point)."""
    return float(2.0 ** round(math.log2(x)))


@dataclass(frozen=True, eq=False)
class Prepared:
    """Scaled data of one synthesis problem (internal)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray
    H: np.ndarray  # balanced, zero columns dropped, state-scaled; None if nominal
    E: np.ndarray
    sigma: np.ndarray  # x = diag(sigma) x~
    H_balanced: np.ndarray  # balanced factors in the original state coordinates
    E_balanced: np.ndarray
    form: str = "general"  # "observer": Ā_F = S A + B̄_F C and C̄_F = −L (scaled data) are substituted


def prepare_uncertainty(H, E, structure="diagonal", tol=0.0):
    """Drop the zero columns of H / rows of E and balance the factorization.

    Parameters
    ----------
    H : ndarray, shape (n, r)
    E : ndarray, shape (r, n)
    structure : {"diagonal", "full"}
        ``"diagonal"``: F is diagonal (the paper's F_Δa, Section 4); pair j
        is dropped when column j of H or row j of E is zero, and balanced by
        its own power of two ``s_j ≈ sqrt(‖E_j‖/‖H_j‖)`` (``H diag(s) F
        diag(s)⁻¹ E = H F E`` because diagonal matrices commute). ``"full"``:
        F is any contraction; zero columns of H and zero rows of E are dropped
        independently and one common power of two balances ``‖H‖₂`` and ``‖E‖₂``.
    tol : float, optional
        Norms ≤ tol count as zero.

    Returns
    -------
    H_b : ndarray, shape (n, r1) or None
    E_b : ndarray, shape (r2, n) or None
        ``None`` when nothing uncertain is left (nominal design).
    keep : tuple of ndarray
        Indices of the kept columns of H and rows of E.

    Notes
    -----
    With per-column balancing LMI (20) bounds the error over the set
    ``{H diag(s) F̃ diag(s)⁻¹ E : ‖F̃‖ ≤ 1}``, which contains every diagonal
    contraction F but is not the set the paper's unbalanced LMI covers: the
    two bounds can differ (Lemma 2 with one λ is conservative for diagonal
    F, and the balancing changes by how much).
    """
    structure = as_choice("structure", structure, ("diagonal", "full"))
    H = as_matrix("H", H)
    E = as_matrix("E", E, (None, H.shape[0]))
    hn = np.linalg.norm(H, axis=0)
    en = np.linalg.norm(E, axis=1)
    if structure == "diagonal":
        if H.shape[1] != E.shape[0]:
            raise InputError(f"H has {H.shape[1]} columns but E has {E.shape[0]} rows")
        keep = np.flatnonzero((hn > tol) & (en > tol))
        if keep.size == 0:
            return None, None, (keep, keep)
        s = np.array([pow2(math.sqrt(en[j] / hn[j])) for j in keep])
        return H[:, keep] * s, E[keep, :] / s[:, None], (keep, keep)
    kh = np.flatnonzero(hn > tol)
    ke = np.flatnonzero(en > tol)
    if kh.size == 0 or ke.size == 0:
        return None, None, (kh, ke)
    Hk, Ek = H[:, kh], E[ke, :]
    s = pow2(math.sqrt(np.linalg.norm(Ek, 2) / np.linalg.norm(Hk, 2)))
    return Hk * s, Ek / s, (kh, ke)


def state_scaling(A, mode):
    """Powers of two σ_i for the coordinates ``x = diag(σ) x̃`` (internal).

    ``"balance"``: LAPACK gebal balancing (``scipy.linalg.matrix_balance``,
    no permutation) of the off-diagonal part of ``|A|``, so that the
    position (m) and velocity (m/s) couplings of the Hill model are of
    comparable size (for the paper's A: positions in units of 16 m). An
    array gives σ directly (rounded to powers of two); ``"none"``: σ = 1.
    """
    n = A.shape[0]
    if not isinstance(mode, str):
        sig = np.asarray(mode, dtype=float).ravel()
        if sig.shape != (n,) or not np.all(np.isfinite(sig)) or np.any(sig <= 0):
            raise InputError(f"state_scaling must be 'balance', 'none' or {n} positive numbers; got {mode!r}")
        return np.array([pow2(v) for v in sig])
    as_choice("state_scaling", mode, ("balance", "none"))
    M = np.abs(A - np.diag(np.diag(A)))
    if mode == "none" or not np.any(M):
        return np.ones(n)
    _, (sca, _) = scipy.linalg.matrix_balance(M, permute=False, separate=True)
    return np.array([pow2(v) for v in sca])


def prepare(system, structure, scaling, form="general"):
    H_b = E_b = None
    if system.H is not None:
        H_b, E_b, _ = prepare_uncertainty(system.H, system.E, structure)
    sigma = state_scaling(system.A, scaling)
    Si = 1.0 / sigma
    A = Si[:, None] * system.A * sigma[None, :]
    B = Si[:, None] * system.B
    C = system.C * sigma[None, :]
    L = system.L * sigma[None, :]
    H = E = None
    if H_b is not None:
        H = Si[:, None] * H_b
        E = E_b * sigma[None, :]
    return Prepared(A, B, C, system.D, L, H, E, sigma, H_b, E_b, form)


