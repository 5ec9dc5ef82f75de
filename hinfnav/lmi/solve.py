"""One cvxpy solve of LMI (20), and the solver strategy object.

:class:`SolverOptions` holds every solver choice of a synthesis (which
solvers, in which order, method, margins, tolerances, bisection, polishing,
state scaling) in one object, in the manner of dkpy's synthesis strategies.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import time
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import cvxpy as cp
import numpy as np

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_int_at_least, as_positive
from .blocks import gamma_index, lmi20_matrix, observer_lmi_matrix
from .conditioning import NORMALIZE_THRESHOLD
from .forksafety import note_solve

if TYPE_CHECKING:
    from .conditioning import Prepared

__all__ = ["SOLVERS", "METHODS", "INFEASIBLE", "SolverOptions", "Solution", "solve_lmi"]

#: Solvers the synthesis accepts (cvxpy names).
SOLVERS = ("CLARABEL", "CVXOPT", "SCS")

#: How γ is searched: ``"auto"`` minimizes and bisects when needed.
METHODS = ("auto", "minimize", "bisection")

INFEASIBLE = ("infeasible", "infeasible_inaccurate")


@dataclass(frozen=True)
class SolverOptions:
    """Every solver choice of a robust filter synthesis, in one object.

    Attributes
    ----------
    solvers : tuple of str
        Solvers tried in order (cvxpy names from :data:`SOLVERS`). Default:
        CVXOPT, then Clarabel (fallback when CVXOPT certifies nothing): the
        fastest solver that certifies first (issue 21: on Sun et al.
        (2011)'s model at δ̄ = 0.05 about 0.17 s of CPU for CVXOPT alone,
        certificate included, against 0.36 s for Clarabel, which also stops
        "optimal_inaccurate" at a γ 1e-5 above CVXOPT's). SCS, a first-order
        method, is slow and inaccurate on these LMIs.
    method : {"auto", "minimize", "bisection"}
        ``"auto"``: minimize γ² directly, and bisect on γ with maximum-margin
        feasibility problems when that does not certify or certifies a γ more
        than ``rtol`` above the solver's.
    margin : float
        Strictness margin of (20) in the scaled problem, as ``−margin·I``.
    accuracy : float
        Solver tolerances (gap and feasibility).
    rtol : float
        Relative accuracy of the bisection on γ, and the acceptable excess of
        the certified γ over the solver's γ.
    max_bisection : int
        Largest number of bisection steps per solver.
    polish : bool
        After a certified solution, also minimize with the remaining solvers
        and keep the smallest certified γ (default False: before issue 21 the
        default chain was Clarabel then a CVXOPT polish, and CVXOPT's design
        won at every δ̄ of Sun et al. (2011)'s sweep, general and observer
        form, so CVXOPT alone returns the same filters at a third of the cost).
    state_scaling : {"balance", "none"} or tuple of float
        Diagonal state-coordinate scaling (rounded to powers of two).
    normalize_above : float
        Scale of the noise block (B, D) or of the output block (L) above
        which it is normalised by a power of two before solving, and the
        normalisation undone exactly
        (:func:`hinfnav.lmi.conditioning.normalize`; default
        :data:`~hinfnav.lmi.conditioning.NORMALIZE_THRESHOLD`, 0: always,
        ``inf``: never).
    """

    solvers: tuple = ("CVXOPT", "CLARABEL")
    method: str = "auto"
    margin: float = 1e-8
    accuracy: float = 1e-8
    rtol: float = 1e-4
    max_bisection: int = 40
    polish: bool = False
    state_scaling: object = "balance"
    normalize_above: float = NORMALIZE_THRESHOLD

    def __post_init__(self):
        solvers = self.solvers
        if isinstance(solvers, str):
            solvers = (solvers,)
        checked = []
        for slv in solvers:
            if not isinstance(slv, str):
                raise InputError(f"solver must be a string, one of {', '.join(SOLVERS)}; got {slv!r}")
            checked.append(as_choice("solver", slv.upper(), SOLVERS))
        if not checked:
            raise InputError("solvers must name at least one solver")
        object.__setattr__(self, "solvers", tuple(checked))
        object.__setattr__(self, "method", as_choice("method", self.method, METHODS))
        object.__setattr__(self, "margin", as_positive("margin", self.margin))
        object.__setattr__(self, "accuracy", as_positive("accuracy", self.accuracy))
        object.__setattr__(self, "rtol", as_positive("rtol", self.rtol))
        object.__setattr__(self, "max_bisection", as_int_at_least("max_bisection", self.max_bisection, 1))
        if not isinstance(self.polish, (bool, np.bool_)):
            raise InputError(f"polish must be True or False; got {self.polish!r}")
        if not isinstance(self.state_scaling, str):
            object.__setattr__(self, "state_scaling", tuple(float(v) for v in np.ravel(self.state_scaling)))
        na = self.normalize_above
        if isinstance(na, bool) or not isinstance(na, numbers.Real) or math.isnan(na) or na < 0:
            raise InputError(f"normalize_above must be a number >= 0 (inf: never normalise); got {na!r}")
        object.__setattr__(self, "normalize_above", float(na))

    @classmethod
    def only(cls, solver: str | None, **changes: Any) -> SolverOptions:
        """Options that use one solver only (``None``: the default chain)."""
        if solver is None:
            return cls(**changes)
        return cls(solvers=(solver,), **changes)


@dataclass
class Solution:
    status: str
    gamma2: float
    R: np.ndarray = None
    S: np.ndarray = None
    Abar_F: np.ndarray = None
    Bbar_F: np.ndarray = None
    Cbar_F: np.ndarray = None
    lam: float = 0.0
    margin: float = float("nan")
    seconds: float = 0.0


#: Seconds one SCS solve may take (SCS's ``time_limit_secs``): SCS on LMI (20) otherwise runs for minutes
#: (issue 22: ``design --solver SCS`` past 60 s); what it returns is certified independently all the same.
SCS_TIME_LIMIT_S = 20.0


def solver_kwargs(solver, accuracy):
    note_solve(solver)  # called before every solve: refuses a solve that would hang after fork (issue 36)
    if solver == "CLARABEL":
        return {"tol_gap_abs": accuracy, "tol_gap_rel": accuracy, "tol_feas": accuracy, "max_iter": 400}
    if solver == "CVXOPT":
        return {"abstol": accuracy, "reltol": accuracy, "feastol": accuracy, "max_iters": 400}
    if solver == "SCS":
        return {"eps_abs": accuracy * 10, "eps_rel": accuracy * 10, "max_iters": 200000, "time_limit_secs": SCS_TIME_LIMIT_S}
    return {}


def solve_lmi(P: Prepared, solver: str, margin: float, accuracy: float, gamma2: float | None = None,
              bound: float = 1e8) -> Solution:
    """One cvxpy solve of LMI (20) on prepared data (internal).

    When ``P`` is normalised (:func:`hinfnav.lmi.conditioning.normalize`),
    the solver sees the normalised data, and ``gamma2`` and the returned
    solution are in the units of the original data: ``γ'² = γ²/(νρ)²`` is
    solved for, and ``R, S, Ā_F, B̄_F, λ`` come back multiplied by ν²,
    ``C̄_F`` by ν and γ² by (νρ)² (exact, powers of two); the margin is the
    normalised problem's (its sign is what matters).

    ``gamma2=None``: minimize γ² subject to (20) ≤ −margin·I (Corollary 1).
    ``gamma2`` a number: feasibility at that level, maximizing the margin t
    in (20) ≤ −t·I up to a cap (an interior point, which certifies well).
    ``gamma2="free"``: the same for the γ-free part of (20) (its rows and
    columns without −γ²I); it is feasible iff (20) is for some finite γ.
    The solution's ``gamma2`` is then NaN (the certificate finds γ).

    With ``P.form == "observer"`` the equality constraints
    ``Ā_F = S A + B̄_F C`` and ``C̄_F = −L`` (in the scaled coordinates of
    ``P``) are eliminated by substitution, and the LMI is posed in its
    congruent form :func:`observer_lmi_matrix` (variables X = R − S, S,
    B̄_F, λ), on which the solvers converge (on (20) with the substitution
    they stop with numerical errors near the optimum).
    """
    if not P.normalized:
        return _solve_once(P, solver, margin, accuracy, gamma2, bound)
    g = P.nu * P.rho
    level = gamma2 if gamma2 is None or isinstance(gamma2, str) else float(gamma2) / g**2
    sol = _solve_once(P, solver, margin, accuracy, level, bound)
    if sol.R is None:
        return dataclasses.replace(sol, gamma2=sol.gamma2 * g**2)
    k = P.nu**2
    return dataclasses.replace(
        sol,
        gamma2=sol.gamma2 * g**2,
        R=sol.R * k,
        S=sol.S * k,
        Abar_F=sol.Abar_F * k,
        Bbar_F=sol.Bbar_F * k,
        Cbar_F=sol.Cbar_F * P.nu,
        lam=sol.lam * k,
    )


def _solve_once(P, solver, margin, accuracy, gamma2, bound):
    n, p = P.B.shape
    m = P.C.shape[0]
    q = P.D.shape[1]
    l = P.L.shape[0]
    observer = P.form == "observer"
    # (variables created in the same order as before the observer option: identical general-form problems)
    X = cp.Variable((n, n), symmetric=True)  # R in the general form, R − S in the observer form
    S = cp.Variable((n, n), symmetric=True)
    AbF = None if observer else cp.Variable((n, n))
    BbF = cp.Variable((n, m))
    CbF = None if observer else cp.Variable((l, n))
    lam = cp.Variable() if P.H is not None else 0.0
    if gamma2 is None:
        g = cp.Variable()
    elif isinstance(gamma2, str):
        g = 0.0
    else:
        g = float(gamma2)
    if observer:
        R = X + S
        M = observer_lmi_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, X, S, BbF, lam, g, bmat=cp.bmat)
    else:
        R = X
        M = lmi20_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, R, S, AbF, BbF, CbF, lam, g, bmat=cp.bmat)
    if isinstance(gamma2, str):
        keep = np.setdiff1d(np.arange(M.shape[0]), gamma_index(n, p, q))
        M = M[keep, :][:, keep]
    N = M.shape[0]
    Msym = 0.5 * (M + M.T)
    # R ≤ bound·I bounds every variable when (20) holds (S < R, ‖Ā_F‖² ≤ ‖R‖‖S‖, λ‖E‖² < ‖R‖, ...)
    box = [R << bound * np.eye(n)]
    if gamma2 is None:
        t = margin
        prob = cp.Problem(cp.Minimize(g), [Msym << -margin * np.eye(N)] + box)
    else:
        # the margin is capped: with a cap near the natural scale of (20) (its −I and −γ²I blocks) the
        # solvers (CVXOPT above all) often fail or report "unbounded"
        cap = 1e-3 * min(1.0, 1.0 if isinstance(gamma2, str) else float(gamma2))
        t = cp.Variable()
        prob = cp.Problem(cp.Maximize(t), [Msym << -t * np.eye(N), t <= cap] + box)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # a solver that cannot reach the requested accuracy (CVXOPT's residuals often stall near 1e-7 and it
        # stops with a singular KKT matrix) is asked again with 100x looser tolerances
        for acc in (accuracy, 100.0 * accuracy):
            try:
                prob.solve(solver=solver, **solver_kwargs(solver, acc))
                break
            except (cp.error.SolverError, ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
                error = exc  # CVXOPT raises ArithmeticError from inside LAPACK on near-singular steps
        else:
            return Solution(f"solver error ({error})", float("nan"), seconds=time.perf_counter() - start)
    seconds = time.perf_counter() - start
    status = str(prob.status)
    if X.value is None or S.value is None:
        return Solution(status, float("nan"), seconds=seconds)
    sym = lambda Y: 0.5 * (Y + Y.T)
    S_val = sym(S.value)
    if observer:
        R_val = S_val + sym(X.value)
        Abar, Cbar = S_val @ P.A + BbF.value @ P.C, -P.L.copy()
    else:
        R_val = sym(X.value)
        Abar, Cbar = AbF.value.copy(), CbF.value.copy()
    if gamma2 is None:
        gval = float(g.value)
    elif isinstance(gamma2, str):
        gval = float("nan")
    else:
        gval = float(gamma2)
    tval = margin if gamma2 is None else float(t.value)
    return Solution(
        status,
        gval,
        R_val,
        S_val,
        Abar,
        BbF.value.copy(),
        Cbar,
        float(lam.value) if P.H is not None else 0.0,
        tval,
        seconds,
    )


