"""The robust bounded real LMI for a fixed filter, solved by cvxpy (Lemmas 1–3).

Gives a certified upper bound of the worst-case H∞ norm over every
norm-bounded uncertainty for a given error system; the solution is checked by
:func:`hinfnav.analysis.certificates.schur_gamma`.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
from numpy.typing import ArrayLike

from ..analysis.certificates import LMICertificate, brl_blocks, schur_gamma
from ..core.linalg import sym
from .blocks import error_system_matrices
from .solve import LMIProblem

__all__ = ["robust_bounded_real_lmi"]


def robust_bounded_real_lmi(Abar: ArrayLike, Bbar: ArrayLike, Cbar: ArrayLike, Hbar: ArrayLike | None = None,
                            Ebar: ArrayLike | None = None, solver: str | None = None,
                            margin: float = 1e-9) -> LMICertificate:
    """Certified upper bound of ``‖C̄(zI − Ā − H̄FĒ)⁻¹B̄‖∞`` over ``FᵀF ≤ I``.

    Minimizes γ² subject to the bounded real lemma (Lemma 1, (17)), with the
    uncertainty ``Ā + H̄ F Ē`` removed by Lemma 2 and the Schur complement
    (Lemma 3), exactly as in the proof of Theorem 1 but for a fixed filter::

        [ −P   PĀ             PB̄     0    PH̄  ]
        [  *  −P + λĒᵀĒ       0      C̄ᵀ   0   ]
        [  *   *             −γ²I    0    0   ]  < 0
        [  *   *              *     −I    0   ]
        [  *   *              *      *   −λI  ]

    Without ``Hbar`` it is Lemma 1 alone (the nominal norm, up to solver
    accuracy). The returned ``gamma`` is certified by :func:`schur_gamma` at
    the solver's ``P`` and ``λ``, not taken from the solver.

    Parameters
    ----------
    Abar : array_like, shape (N, N)
    Bbar : array_like, shape (N, k)
    Cbar : array_like, shape (l, N)
    Hbar : array_like, shape (N, r1), optional
    Ebar : array_like, shape (r2, N), optional
    solver : str, optional
        cvxpy solver name; default: Clarabel and CVXOPT, the smaller
        certified bound is kept.
    margin : float, optional
        Strictness margin: the LMI is imposed as ``≤ −margin·I``.

    Returns
    -------
    LMICertificate
    """
    Abar, Bbar, Cbar, Hbar, Ebar = error_system_matrices(Abar, Bbar, Cbar, Hbar, Ebar)
    solvers = ("CLARABEL", "CVXOPT") if solver is None else (solver,)
    best = None
    for slv in solvers:
        cert = _robust_brl_once(Abar, Bbar, Cbar, Hbar, Ebar, slv, margin)
        if best is None or cert.gamma < best.gamma:
            best = cert
    return best


def _robust_brl_once(Abar, Bbar, Cbar, Hbar, Ebar, solver, margin):
    N = Abar.shape[0]

    def build(t, free):
        P = cp.Variable((N, N), symmetric=True)
        lam = cp.Variable() if Hbar is not None else 0.0
        g = cp.Variable()
        M = brl_blocks(Abar, Bbar, Cbar, Hbar, Ebar, P, lam, g, cp.bmat)
        readout = lambda: {} if P.value is None else {
            "P": sym(P.value), "lam": float(lam.value) if Hbar is not None else 0.0}
        return [0.5 * (M + M.T) << -t * np.eye(M.shape[0])], g, readout

    # the solver's own tolerances (as this certificate always had), one solve (no retry)
    sol = LMIProblem(build, margin, accuracy=None, retry=False).solve(solver)
    if not sol.solved:
        return LMICertificate(float("inf"), float("nan"), None, float("nan"), f"{solver}: {sol.status}")
    Pv, lamv = sol.P, sol.lam
    M0 = brl_blocks(Abar, Bbar, Cbar, Hbar, Ebar, Pv, lamv, 0.0, np.block)
    nin = Bbar.shape[1]
    gamma, _ = schur_gamma(M0, np.arange(2 * N, 2 * N + nin))
    return LMICertificate(gamma, float(np.sqrt(max(sol.gamma2, 0.0))), Pv, lamv, f"{solver}: {sol.status}")
