"""Certificates of linear matrix inequalities, evaluated in float64 without a solver.

The level γ at which an LMI, evaluated at given variables, is negative
definite (:func:`schur_gamma`, :func:`certify_negative_definite`): a
rounding-aware eigenvalue test. The discrete bounded real lemma matrix
(Lemma 1, with the norm-bounded uncertainty of Lemma 2) is built by
:func:`brl_matrix`; the solver that searches for its variables lives in
:mod:`hinfnav.lmi`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

__all__ = ["certify_negative_definite", "schur_gamma", "LMICertificate", "brl_matrix", "brl_blocks"]


def _sym(M):
    return 0.5 * (M + M.T)


def certify_negative_definite(M: ArrayLike, rel_tol: float = 1e-13) -> tuple[bool, float]:
    """Rounding-aware test that a symmetric float64 matrix is negative definite.

    Parameters
    ----------
    M : array_like, shape (N, N)
        Matrix as evaluated in float64 (its symmetric part is tested).
    rel_tol : float, optional
        Required margin relative to ``‖M‖₂``. The computed eigenvalues of a
        symmetric matrix are within about ``N · 1.1e-16 · ‖M‖₂`` of the exact
        ones (LAPACK ``syevd`` backward stability), and forming M in float64
        adds an error of the same order; for N up to ~100 the default keeps a
        safety factor of about 10 over both, so a largest eigenvalue below
        ``−rel_tol ‖M‖₂`` is negative for the exact matrix too.

    Returns
    -------
    ok : bool
    max_eig : float
        Largest eigenvalue.
    """
    M = _sym(np.asarray(M, dtype=float))
    eig = np.linalg.eigvalsh(M)
    scale = max(np.max(np.abs(eig)), np.finfo(float).tiny)
    return bool(eig[-1] < -rel_tol * scale), float(eig[-1])


def schur_gamma(M0: ArrayLike, gamma_index: ArrayLike, rel_tol: float = 1e-13) -> tuple[float, dict[str, Any]]:
    """Smallest γ for which ``M0 − γ² P_G`` is negative definite.

    ``P_G`` is the coordinate projection onto the rows/columns
    ``gamma_index`` (the ``−γ² I`` blocks of an LMI such as (17) or (20)).
    By the Schur complement (Lemma 3), ``M(γ) < 0`` iff ``M_OO < 0`` and
    ``γ² > λ_max(M0_GG + M_GO (−M_OO)⁻¹ M_OG)``, O being the other indices.
    The value is then confirmed by a direct eigenvalue test of ``M(γ)`` at a
    level raised by the smallest relative step (1e-10, 1e-9, ..., 1e-3) that
    passes :func:`certify_negative_definite`.

    Parameters
    ----------
    M0 : array_like, shape (N, N)
        The LMI matrix evaluated with γ² = 0.
    gamma_index : array_like of int
        Indices carrying ``−γ²``.
    rel_tol : float, optional
        Margin of the eigenvalue tests (see :func:`certify_negative_definite`).

    Returns
    -------
    gamma : float
        Certified level (``inf`` if no level makes the matrix negative
        definite in float64, i.e. ``M_OO`` is not negative definite).
    info : dict
        ``max_eig_OO`` (largest eigenvalue of ``M_OO``), ``gamma_schur``
        (the Schur-complement value before the confirming step), ``step``.
    """
    M0 = _sym(np.asarray(M0, dtype=float))
    N = M0.shape[0]
    G = np.asarray(gamma_index, dtype=int)
    O = np.setdiff1d(np.arange(N), G)
    MOO = M0[np.ix_(O, O)]
    ok, max_oo = certify_negative_definite(MOO, rel_tol)
    info = {"max_eig_OO": max_oo, "gamma_schur": float("inf"), "step": float("nan")}
    if not ok:
        return float("inf"), info
    try:
        Lc = np.linalg.cholesky(-MOO)
    except np.linalg.LinAlgError:
        return float("inf"), info
    X = scipy.linalg.solve_triangular(Lc, M0[np.ix_(O, G)], lower=True)
    Q = _sym(M0[np.ix_(G, G)] + X.T @ X)
    g2 = max(float(np.linalg.eigvalsh(Q)[-1]), 0.0)
    info["gamma_schur"] = float(np.sqrt(g2))
    diag = np.zeros(N)
    diag[G] = 1.0
    for step in 10.0 ** np.arange(-12.0, -2.0, 0.5):
        level = g2 * (1.0 + step) + step * np.finfo(float).eps ** 0.5
        if certify_negative_definite(M0 - level * np.diag(diag), rel_tol)[0]:
            info["step"] = float(step)
            return float(np.sqrt(level)), info
    return float("inf"), info


@dataclass(frozen=True, eq=False)
class LMICertificate:
    """Result of :func:`robust_bounded_real_lmi`.

    Attributes
    ----------
    gamma : float
        Level certified by the eigenvalue test at the returned ``P``, ``lam``
        (``inf`` if none).
    lmi_gamma : float
        Level the solver reached.
    P : ndarray, shape (N, N)
        Lyapunov matrix of Lemma 1 (in the caller's coordinates).
    lam : float
        Multiplier λ = 1/ε of Lemma 2 (0 without uncertainty).
    status : str
        Solver status.
    """

    gamma: float
    lmi_gamma: float
    P: np.ndarray
    lam: float
    status: str


def brl_matrix(Abar: ArrayLike, Bbar: ArrayLike, Cbar: ArrayLike, P: ArrayLike, gamma2: float, Hbar: ArrayLike | None = None,
               Ebar: ArrayLike | None = None, lam: float = 0.0) -> NDArray[np.float64]:
    """The matrix of the bounded real lemma (17), or of its robust form (26).

    Without ``Hbar``: Lemma 1, (17)::

        [ −P   PĀ    PB̄     0  ]
        [  *  −P     0      C̄ᵀ ]
        [  *   *    −γ²I    0  ]
        [  *   *     *     −I  ]

    With ``Hbar``, ``Ebar`` and ``lam`` = λ = 1/ε: the same with
    ``−P + λĒᵀĒ`` in block (2, 2) and a last block row/column
    ``[PH̄; 0; 0; 0; −λI]`` — (26), the form Lemmas 2–3 turn (17) into for
    ``Ā + H̄FĒ`` with ``FᵀF ≤ I``.

    Parameters
    ----------
    Abar : ndarray, shape (N, N)
    Bbar : ndarray, shape (N, k)
    Cbar : ndarray, shape (l, N)
    P : ndarray, shape (N, N)
    gamma2 : float
        γ².
    Hbar : ndarray, shape (N, r1), optional
    Ebar : ndarray, shape (r2, N), optional
    lam : float, optional

    Returns
    -------
    ndarray, shape (2N + k + l [+ r1],) * 2
        Negative definite iff the bound holds with this P (and λ).
    """
    return brl_blocks(
        np.asarray(Abar, float), np.asarray(Bbar, float), np.asarray(Cbar, float),
        None if Hbar is None else np.asarray(Hbar, float), None if Ebar is None else np.asarray(Ebar, float),
        np.asarray(P, float), float(lam), float(gamma2), np.block,
    )


def brl_blocks(Abar: NDArray[np.float64], Bbar: NDArray[np.float64], Cbar: NDArray[np.float64], Hbar: NDArray[np.float64] | None, Ebar: NDArray[np.float64] | None,
               P: Any, lam: Any, g: Any, lib: Callable[..., Any]) -> Any:
    """LMI (17), with the uncertainty eliminated by Lemmas 2–3 when Hbar is given."""
    N = Abar.shape[0]
    nin = Bbar.shape[1]
    nout = Cbar.shape[0]
    Z = np.zeros
    rows = [
        [-P, P @ Abar, P @ Bbar, Z((N, nout))],
        [(P @ Abar).T, -P, Z((N, nin)), Cbar.T],
        [(P @ Bbar).T, Z((nin, N)), -g * np.eye(nin), Z((nin, nout))],
        [Z((nout, N)), Cbar, Z((nout, nin)), -np.eye(nout)],
    ]
    if Hbar is not None:
        r1 = Hbar.shape[1]
        rows[1][1] = -P + lam * (Ebar.T @ Ebar)
        extra = [P @ Hbar, Z((N, r1)), Z((nin, r1)), Z((nout, r1))]
        for row, blk in zip(rows, extra):
            row.append(blk)
        rows.append([(P @ Hbar).T, Z((r1, N)), Z((r1, nin)), Z((r1, nout)), -lam * np.eye(r1)])
    return lib(rows)


