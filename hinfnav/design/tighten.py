"""Tightening a certified robust H∞ design: a full Lyapunov matrix for a fixed filter, and the loose-bound test.

LMI (20) certifies a filter with the Lyapunov matrix of Theorem 1's change of
variables. With the filter fixed, the robust bounded real LMI of Lemmas 1–3
(:func:`hinfnav.lmi.robust_brl.robust_bounded_real_lmi`) searches over every
Lyapunov matrix of the error system (13)–(15) and one multiplier λ (Lemma 2)
and may certify a smaller level. For a general full-order filter at the
optimum of Corollary 1 the two agree (the change of variables is lossless);
for a structured filter (observer form) the level of (20) is that of a
restricted Lyapunov matrix, ``diag(R − S, S)`` in the coordinates (x, e).
"""

import numpy as np

from ..analysis.certificates import brl_blocks, schur_gamma
from ..analysis.error_system import error_system_matrices
from ..lmi.robust_brl import robust_bounded_real_lmi

__all__ = ["LOOSE_FACTOR", "full_lyapunov_gamma", "is_loose", "brl_solvers", "key"]

#: A certified γ above this multiple of the worst sampled norm counts as loose.
LOOSE_FACTOR = 2.0


def is_loose(gamma, sampled_norm, factor=LOOSE_FACTOR):
    """Whether a certified level is more than ``factor`` times the worst sampled H∞ norm."""
    return bool(gamma > factor * sampled_norm)


def full_lyapunov_gamma(P, A_F, B_F, C_F, solvers):
    """Certified level of a fixed filter with a full Lyapunov matrix (robust bounded real LMI).

    The error system (13)–(15) of the filter on the prepared data ``P``
    (state coordinates ``x = Σ x̃``, balanced H, E, noise and output
    normalised by ρ and ν when ``P`` is) is handed to
    :func:`~hinfnav.lmi.robust_brl.robust_bounded_real_lmi`; its Lyapunov
    matrix and λ are then scaled back exactly (powers of two: ``P = ν² P'``,
    ``λ = ν² λ'``) and the LMI of Lemmas 1–3 is re-evaluated with the
    original noise and output matrices, where the smallest γ making it
    negative definite is found by :func:`~hinfnav.analysis.schur_gamma`
    (eigenvalue-confirmed; tested after the exact diagonal congruence by
    ν and νρ, as in :func:`hinfnav.lmi.conditioning.lmi20_diagonal`). That γ bounds ``‖Ψ‖∞`` for every admissible F
    (Lemmas 1–3, (17), (26)).

    Parameters
    ----------
    P : hinfnav.lmi.Prepared
    A_F, B_F, C_F : ndarray
        The filter (12) in the plant's original state coordinates.
    solvers : sequence of str
        cvxpy solvers tried; the smallest certified level is kept.

    Returns
    -------
    gamma : float
        Certified level (``inf`` if no solver gave a certifiable point).
    lyapunov : ndarray, shape (2n, 2n) or None
        The Lyapunov matrix in the original coordinates ``(x, x_f)``.
    lam : float
        The multiplier λ of Lemma 2 (NaN if none).
    """
    sig = P.sigma
    AFs = A_F * sig[None, :] / sig[:, None]
    BFs = B_F / sig[:, None]
    CFs = C_F * sig[None, :]
    Q = P.unnormalized()
    Abar, Bbar, Cbar = error_system_matrices(Q.A, Q.B, Q.C, Q.D, Q.L, AFs, BFs, CFs)
    Bn, Cn = Bbar / P.rho, Cbar / P.nu  # the normalised error system (exact: powers of two)
    Hbar = Ebar = None
    if Q.H is not None:
        Hbar = np.vstack([Q.H, np.zeros_like(Q.H)])
        Ebar = np.hstack([Q.E, np.zeros_like(Q.E)])
    N, nin = Abar.shape[0], Bbar.shape[1]
    best = (float("inf"), None, float("nan"))
    for slv in solvers:
        cert = robust_bounded_real_lmi(Abar, Bn, Cn, Hbar, Ebar, solver=slv)
        if cert.P is None:
            continue
        Pl, lam = cert.P * P.nu**2, cert.lam * P.nu**2
        M0 = brl_blocks(Abar, Bbar, Cbar, Hbar, Ebar, Pl, lam, 0.0, np.block)
        # tested as diag(d) M0 diag(d), exact (powers of two): the LMI of the normalised system (d = 1 if none)
        d = np.concatenate([np.full(2 * N, 1.0 / P.nu), np.full(nin, 1.0 / (P.nu * P.rho)), np.ones(Cbar.shape[0]),
                            np.full(M0.shape[0] - 2 * N - nin - Cbar.shape[0], 1.0 / P.nu)])
        gamma, _ = schur_gamma(d[:, None] * M0 * d[None, :], np.arange(2 * N, 2 * N + nin))
        gamma *= P.nu * P.rho
        if gamma < best[0]:
            best = (gamma, Pl, lam)
    gamma, Pl, lam = best
    if Pl is not None:
        s2 = 1.0 / np.concatenate([sig, sig])
        Pl = s2[:, None] * Pl * s2[None, :]  # x̃ = Σ⁻¹ x: V = x̃ᵀ P x̃ = xᵀ Σ⁻¹ P Σ⁻¹ x
    return float(gamma), Pl, lam


def brl_solvers(solvers):
    """Solvers for the full-Lyapunov certificate: the interior-point ones chosen, else those given (internal)."""
    return [s for s in solvers if s != "SCS"] or list(solvers)


def key(P):
    """What identifies a prepared problem's scaling (internal)."""
    return (tuple(P.sigma), P.rho, P.nu)
