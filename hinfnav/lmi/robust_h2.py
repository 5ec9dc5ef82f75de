"""The robust H2 (guaranteed-cost) LMI for a fixed filter, solved by cvxpy, certified by eigenvalues.

For ``Ā + H̄FĒ`` with ``FᵀF ≤ I`` it minimizes ``trace(B̄ᵀPB̄)`` subject to

    Ā_Δᵀ P Ā_Δ − P + C̄ᵀC̄ < 0   for every admissible F,

written as :func:`hinfnav.lmi.mixed_blocks.extended_h2_matrix` with the slack
equal to P (G = P, the plain Lyapunov form) and F removed by Lemma 2 of Sun et
al. (2011). For a constant F the H2 norm is then below ``sqrt(trace(B̄ᵀPB̄))``;
for a time-varying F that number bounds the asymptotic RMS of the output
under unit white noise. The returned ν is certified at the solver's P and λ:
:func:`hinfnav.analysis.schur_gamma` finds the smallest κ for which the
matrix with ``−κI`` on its output block is negative definite in float64, and
``ν² = κ · trace(B̄ᵀPB̄)``.

It serves the mixed synthesis (:mod:`hinfnav.design.mixed`) as an a-posteriori
certificate of the filter it returns: the synthesis couples the H2 and H∞
conditions through one slack G, this analysis gives the H2 condition its own
Lyapunov matrix for the filter found.
"""

import math
import dataclasses
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from ..analysis.certificates import schur_gamma
from .blocks import error_system_matrices
from .mixed_blocks import extended_h2_matrix
from .solve import LMIProblem

__all__ = ["robust_h2_bound"]


@dataclass(frozen=True, eq=False)
class H2Certificate:
    """Result of :func:`robust_h2_bound`.

    Attributes
    ----------
    nu : float
        Certified bound (``inf`` if none).
    lmi_nu : float
        The solver's ``sqrt(trace(B̄ᵀPB̄))``.
    P : ndarray or None
    lam : float
    kappa : float
        Level of the output block at which the LMI was certified.
    status : str
    calls : int
        Solver invocations it took (one per solver tried).
    """

    nu: float
    lmi_nu: float
    P: np.ndarray
    lam: float
    kappa: float
    status: str
    calls: int = 1


def _certify(Abar, Bbar, Cbar, Hbar, Ebar, P, lam):
    N = Abar.shape[0]
    GH = None if Hbar is None else P @ Hbar
    M0 = extended_h2_matrix(P, P, P @ Abar, Cbar, GH, Ebar, lam, 0.0)
    root_kappa, _ = schur_gamma(M0, np.arange(2 * N, 2 * N + Cbar.shape[0]))
    kappa = root_kappa**2
    nu2 = kappa * float(np.trace(Bbar.T @ P @ Bbar))
    return (math.sqrt(nu2 * (1.0 + 1e-12)) if np.isfinite(nu2) and nu2 >= 0 else float("inf")), kappa


def robust_h2_bound(Abar, Bbar, Cbar, Hbar=None, Ebar=None, solver=None, margin=1e-9, bound=1e6, accuracy=1e-8):
    """Certified upper bound of the worst-case H2 norm of ``C̄(zI − Ā − H̄FĒ)⁻¹B̄`` over ``FᵀF ≤ I``.

    Parameters
    ----------
    Abar : array_like, shape (N, N)
        Schur stable.
    Bbar : array_like, shape (N, k)
    Cbar : array_like, shape (l, N)
    Hbar : array_like, shape (N, r1), optional
    Ebar : array_like, shape (r2, N), optional
    solver : str, optional
        cvxpy solver; default CVXOPT, then Clarabel (the smaller certified
        bound is kept).
    margin : float, optional
        Strictness margin of the LMI.
    bound : float, optional
        ``P ≤ bound·I``.
    accuracy : float, optional
        Solver tolerances.

    Returns
    -------
    H2Certificate
    """
    Abar, Bbar, Cbar, Hbar, Ebar = error_system_matrices(Abar, Bbar, Cbar, Hbar, Ebar)
    best, calls = None, 0
    for slv in ("CVXOPT", "CLARABEL") if solver is None else (solver,):
        cert = _once(Abar, Bbar, Cbar, Hbar, Ebar, slv, margin, bound, accuracy)
        calls += 1
        if best is None or cert.nu < best.nu:
            best = cert
        if solver is None and np.isfinite(best.nu):
            break
    return dataclasses.replace(best, calls=calls)


def _once(Abar, Bbar, Cbar, Hbar, Ebar, solver, margin, bound, accuracy):
    N = Abar.shape[0]

    def build(t, free):
        P = cp.Variable((N, N), symmetric=True)
        lam = cp.Variable() if Hbar is not None else 0.0
        GH = None if Hbar is None else P @ Hbar
        M = extended_h2_matrix(P, P, P @ Abar, Cbar, GH, Ebar, lam, 1.0, bmat=cp.bmat)
        cons = [0.5 * (M + M.T) << -t * np.eye(M.shape[0]), P << bound * np.eye(N)]
        readout = lambda: {} if P.value is None else {
            "P": 0.5 * (P.value + P.value.T), "lam": float(lam.value) if Hbar is not None else 0.0}
        return cons, cp.trace(Bbar.T @ P @ Bbar), readout

    sol = LMIProblem(build, margin, accuracy, retry=False).solve(solver)
    if not sol.solved:
        return H2Certificate(float("inf"), float("nan"), None, float("nan"), float("nan"), f"{solver}: {sol.status}")
    nu, kappa = _certify(Abar, Bbar, Cbar, Hbar, Ebar, sol.P, sol.lam)
    return H2Certificate(nu, math.sqrt(max(sol.gamma2, 0.0)), sol.P, sol.lam, kappa, f"{solver}: {sol.status}")
