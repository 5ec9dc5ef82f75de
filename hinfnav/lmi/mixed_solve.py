"""One cvxpy problem of the mixed H2/H∞ filter synthesis, compiled once and solved at many γ.

:class:`MixedProblem` poses, on prepared (balanced and scaled) data
(:func:`hinfnav.lmi.conditioning.prepare`),

    minimize  trace W  (= ν²)
    subject to  extended H2 LMIs (:func:`.mixed_blocks.extended_h2_matrix`,
                :func:`.mixed_blocks.h2_trace_matrix`)
                and, unless γ is None, the robust H∞ LMI at the level γ
                (``lyapunov="extended"``: :func:`.mixed_blocks.robust_extended_hinf_negative`;
                ``"common"``: LMI (20) itself, :func:`.blocks.lmi20_matrix`).

γ² is a cvxpy ``Parameter``: a Pareto front re-solves the same compiled
problem. Solutions are never trusted here; :mod:`hinfnav.design.mixed`
certifies them.
"""

from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from ..core.validation import as_choice
from .blocks import lmi20_matrix
from .mixed_blocks import extended_h2_matrix, robust_extended_hinf_negative, h2_trace_matrix, slack_products
from .solve import run_solver

__all__ = ["LYAPUNOV", "MixedProblem"]

#: How the H2 and H∞ conditions share their Lyapunov matrices.
LYAPUNOV = ("extended", "common")


@dataclass
class MixedSolution:
    """The solver's point (scaled coordinates; internal)."""

    status: str
    nu2: float
    X: np.ndarray = None
    Y: np.ndarray = None
    Z: np.ndarray = None
    Abar_F: np.ndarray = None
    Bbar_F: np.ndarray = None
    Cbar_F: np.ndarray = None
    P2: np.ndarray = None
    Pinf: np.ndarray = None
    lam2: float = 0.0
    lam_inf: float = 0.0
    W: np.ndarray = None
    seconds: float = 0.0
    calls: int = 0
    solver: str = ""

    @property
    def solved(self) -> bool:
        """Whether the solver returned a point."""
        return self.X is not None

    @property
    def gamma2(self) -> float:
        """The level this problem minimises, ν² (the name :func:`hinfnav.design.certify_loop.solve_and_certify` reads)."""
        return self.nu2


def _sym(M):
    return 0.5 * (M + M.T)


class MixedProblem:
    """The mixed H2/H∞ synthesis SDP on prepared data, γ² a parameter.

    Parameters
    ----------
    P : hinfnav.lmi.conditioning.Prepared
        Scaled plant and balanced uncertainty factors (general form only).
    hinf : bool
        Include the H∞ constraint (False: the robust H2 filter alone).
    lyapunov : {"extended", "common"}
        ``"extended"`` (default): one slack G, separate Lyapunov matrices
        P₂ and P∞ (de Oliveira, Geromel & Bernussou 2002). ``"common"``:
        ``G = P₂ = P∞ = [[R, S], [S, S]]``, LMI (20) for H∞ (the classical
        common-Lyapunov mixed design; kept to measure what the slack gains).
    margin : float
        Strictness of every LMI, as ``≤ −margin·I`` (``≥ margin·I``).
    bound : float
        ``P₂, P∞ ≤ bound·I`` (keeps the variables bounded). On Sun et al.
        (2011)'s scaled model the solutions have ``‖P‖ ≈ 10³``; 10⁶ leaves
        them free and starts CVXOPT nearer than (20)'s 10⁸ (about 20 % fewer
        iterations, same ν to 1e-7).
    """

    def __init__(self, P, *, hinf=True, lyapunov="extended", margin=1e-8, bound=1e6):
        self.lyapunov = as_choice("lyapunov", lyapunov, LYAPUNOV)
        self.hinf = bool(hinf)
        A, B, C, D, L, H, E = P.A, P.B, P.C, P.D, P.L, P.H, P.E
        n, p = B.shape
        m, q, l = C.shape[0], D.shape[1], L.shape[0]
        N, k = 2 * n, p + q
        eye = np.eye
        if self.lyapunov == "extended":
            X, Y, Z = cp.Variable((n, n)), cp.Variable((n, n)), cp.Variable((n, n))
        else:
            X, Y = cp.Variable((n, n), symmetric=True), cp.Variable((n, n), symmetric=True)
            Z = Y
        AbF, BbF, CbF = cp.Variable((n, n)), cp.Variable((n, m)), cp.Variable((l, n))
        W = cp.Variable((k, k), symmetric=True)
        lam2 = cp.Variable() if H is not None else 0.0
        sp = slack_products(A, B, C, D, L, H, E, X, Y, Z, AbF, BbF, CbF, bmat=cp.bmat)
        if self.lyapunov == "extended":
            P2 = cp.Variable((N, N), symmetric=True)
        else:
            P2 = sp["G"]  # = [[R, S], [S, S]], symmetric
        cons = []
        M2 = extended_h2_matrix(P2, sp["G"], sp["GA"], sp["Cbar"], sp["GH"], sp["Ebar"], lam2, 1.0, bmat=cp.bmat)
        cons.append(_sym(M2) << -margin * eye(M2.shape[0]))
        T = h2_trace_matrix(W, P2, sp["G"], sp["GB"], bmat=cp.bmat)
        cons.append(_sym(T) >> margin * eye(T.shape[0]))
        cons.append(_sym(P2) << bound * eye(N))
        self.gamma2 = cp.Parameter(nonneg=True, value=1.0) if self.hinf else None
        lam_inf, Pinf = 0.0, None
        if self.hinf:
            lam_inf = cp.Variable() if H is not None else 0.0
            if self.lyapunov == "extended":
                Pinf = cp.Variable((N, N), symmetric=True)
                Minf = robust_extended_hinf_negative(Pinf, sp["G"], sp["GA"], sp["GB"], sp["Cbar"], sp["GH"], sp["Ebar"],
                                            lam_inf, self.gamma2, bmat=cp.bmat)
                cons.append(_sym(Pinf) << bound * eye(N))
            else:
                Pinf = P2
                Minf = lmi20_matrix(A, B, C, D, L, H, E, X, Y, AbF, BbF, CbF, lam_inf, self.gamma2, bmat=cp.bmat)
            cons.append(_sym(Minf) << -margin * eye(Minf.shape[0]))
        self._vars = dict(X=X, Y=Y, Z=Z, AbF=AbF, BbF=BbF, CbF=CbF, W=W, P2=P2, Pinf=Pinf, lam2=lam2, lam_inf=lam_inf)
        self.problem = cp.Problem(cp.Minimize(cp.trace(W)), cons)

    def solve(self, gamma2, solver, accuracy=1e-8):
        """Solve at ``gamma2`` (ignored without the H∞ constraint) with one cvxpy solver.

        Returns
        -------
        MixedSolution
            ``nu2`` is the solver's trace W; the variables are None when the
            solver returned no point.
        """
        if self.hinf:
            self.gamma2.value = float(gamma2)
        status, seconds, calls = run_solver(self.problem, solver, accuracy)
        if status.startswith("solver error"):
            return MixedSolution(status, float("nan"), seconds=seconds, calls=calls, solver=solver)
        v = self._vars
        status = str(self.problem.status)
        if v["X"].value is None or v["W"].value is None:
            return MixedSolution(status, float("nan"), seconds=seconds, calls=calls, solver=solver)

        def val(x):
            if isinstance(x, float):
                return x
            out = np.asarray(x.value, dtype=float)
            return float(out) if out.ndim == 0 else out.copy()

        P2 = _sym(val(v["P2"]))
        Pinf = None if v["Pinf"] is None else _sym(val(v["Pinf"]))
        return MixedSolution(
            status,
            float(np.trace(val(v["W"]))),
            val(v["X"]),
            val(v["Y"]),
            val(v["Z"]),
            val(v["AbF"]),
            val(v["BbF"]),
            val(v["CbF"]),
            P2,
            Pinf,
            val(v["lam2"]),
            val(v["lam_inf"]),
            _sym(val(v["W"])),
            seconds,
            calls,
            solver,
        )
