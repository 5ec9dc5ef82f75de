"""The one solve module of the LMI designs: a problem built once, one solver call path, one solution type.

:class:`SolverOptions` holds every solver choice of a synthesis (which
solvers, in which order, method, margins, tolerances, bisection, polishing,
state scaling) in one object, in the manner of dkpy's synthesis strategies.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import numbers
import time
import warnings
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable, Iterator

import cvxpy as cp
import numpy as np
import scs

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_int_at_least, as_positive
from .conditioning import NORMALIZE_THRESHOLD
from .forksafety import note_solve

__all__ = ["SOLVERS", "METHODS", "INFEASIBLE", "SolverOptions", "Solution", "LMIProblem", "run_solver",
           "watch_solves", "SolveWatch", "SCS_BUDGET_S", "solve_once", "solve_once_gamma"]

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
    state_scaling : {"balance", "units", "none"} or tuple of float
        Diagonal state-coordinate scaling: ``"balance"`` (default) balances
        A by powers of two; ``"units"`` first removes the state units
        (:func:`hinfnav.lmi.conditioning.unit_scaling`: the design does not
        depend on them; used by ``design --system``); a tuple gives the
        factors (rounded to powers of two).
    blocks : bool
        Pose LMI (20) of a decoupled plant (block-diagonal up to a
        permutation, :func:`hinfnav.analysis.structure.decoupled_blocks`)
        with block-diagonal variables, one small matrix inequality per block
        and a common λ and γ (default True: the same optimum as the full LMI,
        see :func:`lmi20_problem`; False: one matrix inequality of the whole
        plant, as before).
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
    blocks: bool = True

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
        if not isinstance(self.blocks, (bool, np.bool_)):
            raise InputError(f"blocks must be True or False; got {self.blocks!r}")
        if isinstance(self.state_scaling, str):
            as_choice("state_scaling", self.state_scaling, ("balance", "units", "none"))
        else:
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
    """What one solve of an LMI problem returns (every LMI design of hinfnav uses this one type).

    Attributes
    ----------
    status : str
        cvxpy's status, or ``"solver error (...)"``.
    gamma2 : float
        The level: the solver's minimum of γ² (minimisation), the level
        asked for (feasibility), NaN for the γ-free problem or no solution.
    values : dict
        The variables at the solution, by name (empty: no solution).
    margin : float
        Strictness margin t of ``M ≤ −t·I`` (feasibility: maximised).
    seconds : float
        Wall time of the solve(s).
    solver : str
    calls : int
        Solver invocations made (a retry at looser tolerances counts).
    """

    status: str
    gamma2: float
    values: dict = field(default_factory=dict)
    margin: float = float("nan")
    seconds: float = 0.0
    solver: str = ""
    calls: int = 0

    @property
    def solved(self) -> bool:
        """Whether the solver returned values for the variables."""
        return bool(self.values)

    def __getattr__(self, name: str) -> Any:
        values = self.__dict__.get("values") or {}
        if name in values:
            return values[name]
        if name in ("R", "S", "Abar_F", "Bbar_F", "Cbar_F"):
            return None  # LMI (20)'s variables when nothing was solved
        if name == "lam":
            return 0.0
        raise AttributeError(f"Solution has no value {name!r}")

    @classmethod
    def from_dict(cls, out: dict, solver: str) -> Solution:
        """The solution of a problem built in a single shot: :func:`solve_once`'s dict plus the values read into it."""
        head = ("status", "gamma2", "seconds", "calls", "margin")
        values = {k: v for k, v in out.items() if k not in head}
        return cls(out["status"], out["gamma2"], values, out.get("margin", float("nan")), out["seconds"], solver,
                   out.get("calls", 1))

    def as_dict(self) -> dict:
        """``status``, ``gamma2``, ``seconds``, and when solved ``margin`` and the values (a flat dict)."""
        out = {"status": self.status, "gamma2": self.gamma2, "seconds": self.seconds}
        if self.solved:
            out["margin"] = self.margin
            out.update(self.values)
        return out


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


#: Seconds of SCS solver time a design watched by :func:`watch_solves` may spend in all (issue 36: ``design
#: --system examples/two_mass_spring_30pct.toml --form observer --solver SCS`` made SCS solves for 181 s wall; with
#: this budget the design returns the best point certified within it, or says the budget ran out).
SCS_BUDGET_S = 60.0


@dataclass
class SolveWatch:
    """What :func:`watch_solves` watches: per-solver time budgets, time spent, calls, and a callback.

    Attributes
    ----------
    budget : dict
        Seconds of solver time allowed per solver name (a solver not named
        has no budget).
    spent : dict
        Seconds spent so far per solver.
    calls : int
        Solver invocations so far (all solvers).
    on_call : callable or None
        ``on_call(watch, solver, status, seconds)`` after each invocation
        (a progress bar).
    """

    budget: dict = field(default_factory=dict)
    spent: dict = field(default_factory=dict)
    calls: int = 0
    on_call: Callable | None = None
    exhausted: list = field(default_factory=list)

    def remaining(self, solver: str) -> float:
        """Seconds left for ``solver`` (inf: no budget)."""
        if solver not in self.budget:
            return math.inf
        return self.budget[solver] - self.spent.get(solver, 0.0)


_WATCH: contextvars.ContextVar = contextvars.ContextVar("hinfnav_solve_watch", default=None)


@contextlib.contextmanager
def watch_solves(budget: dict | None = None, on_call: Callable | None = None) -> Iterator[SolveWatch]:
    """Context manager: every :func:`run_solver` call inside is counted, timed and held to a time budget.

    ``budget={"SCS": 60}``: SCS's ``time_limit_secs`` of each solve is at
    most what is left of the budget, and once it is used up SCS is not
    called again (the solve reports ``"solver error (the SCS time budget
    ... is used up)"``, the design loop goes on with what it has: the best
    certified point, or a :class:`~hinfnav.core.exceptions.CertificationError`
    naming the budget). The command line's ``design`` runs inside one with
    :data:`SCS_BUDGET_S`.
    """
    watch = SolveWatch(dict(budget or {}), {}, 0, on_call)
    token = _WATCH.set(watch)
    try:
        yield watch
    finally:
        _WATCH.reset(token)


#: SCS's status value for a solve stopped by Ctrl-C (SCS_SIGINT in SCS's glbopts.h; cvxpy maps it to a solver error).
SCS_SIGINT = -5


@contextlib.contextmanager
def _scs_interrupts() -> Iterator[None]:
    """While inside, an SCS solve that SCS stopped on Ctrl-C raises KeyboardInterrupt (cvxpy calls ``scs.solve``)."""
    original = scs.solve

    def solve(*args: Any, **kwargs: Any) -> Any:
        out = original(*args, **kwargs)
        if out.get("info", {}).get("status_val") == SCS_SIGINT:
            raise KeyboardInterrupt
        return out

    scs.solve = solve
    try:
        yield
    finally:
        scs.solve = original


#: Exceptions a cvxpy solve may raise on a hard LMI (CVXOPT raises ArithmeticError from inside LAPACK).
SOLVER_ERRORS = (cp.error.SolverError, ArithmeticError, ValueError, np.linalg.LinAlgError)


def run_solver(prob: cp.Problem, solver: str, accuracy: float | None = None, retry: bool | tuple = True
               ) -> tuple[str, float, int]:
    """Solve one cvxpy problem: the only place where hinfnav calls a solver.

    ``accuracy=None`` uses the solver's own defaults. Otherwise the
    tolerances of :func:`solver_kwargs`; a solver that raises (CVXOPT's
    residuals often stall near 1e-7 and it stops with a singular KKT
    matrix) is asked once more with 100x looser tolerances when ``retry``
    is True, or once per factor when ``retry`` is a tuple of factors
    (``(100, 1000)``: 100x, then 1000x looser).

    Returns
    -------
    status : str
        cvxpy's status, or ``"solver error (...)"``.
    seconds : float
    calls : int
        Solver invocations (1 + the number of retries used).
    """
    watch = _WATCH.get()
    start = time.perf_counter()
    factors = (100.0,) if retry is True else tuple(retry or ())
    tries = (None,) if accuracy is None else (accuracy,) + tuple(f * accuracy for f in factors)
    status, calls = None, 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for acc in tries:
            kwargs = {} if acc is None else solver_kwargs(solver, acc)
            if watch is not None and solver in watch.budget:
                left = watch.remaining(solver)
                if left <= 0.5:
                    watch.exhausted.append(solver)
                    status = (f"solver error (the {solver} time budget of {watch.budget[solver]:g} s for this design is "
                              "used up)")
                    break
                if solver == "SCS":
                    kwargs["time_limit_secs"] = min(kwargs.get("time_limit_secs", SCS_TIME_LIMIT_S), left)
            calls += 1
            t0 = time.perf_counter()
            # SCS catches Ctrl-C itself (its own SIGINT handler during a solve) and reports a solver error, so a
            # design would go on to its next solve: its "interrupted" status is turned back into KeyboardInterrupt
            # (issue 36), which stops the command as anywhere else
            hold = _scs_interrupts() if solver == "SCS" else contextlib.nullcontext()
            try:
                with hold:
                    prob.solve(solver=solver, **kwargs)
                status = str(prob.status)
            except SOLVER_ERRORS as exc:
                status = f"solver error ({exc})"
            finally:
                if watch is not None:
                    watch.spent[solver] = watch.spent.get(solver, 0.0) + time.perf_counter() - t0
                    watch.calls += 1
            if not status.startswith("solver error"):
                break
    seconds = time.perf_counter() - start
    if watch is not None and watch.on_call is not None:
        watch.on_call(watch, solver, status, seconds)
    return status, seconds, calls


def solve_once(cons: list, level: Any, solver: str, accuracy: float | None, t: Any = None,
               gamma2: float | None = None) -> dict[str, Any]:
    """One :func:`run_solver` call (no retry) of a problem built in a single shot: minimise or maximise the margin.

    ``gamma2=None``: minimise ``level`` (a cvxpy expression, γ²) subject to
    ``cons``; otherwise maximise the margin variable ``t`` of ``cons`` at the
    fixed level ``gamma2``, with ``t ≤ 1e-3·min(1, γ²)`` (as
    :class:`LMIProblem`). The variables of ``cons`` hold the solution.

    Returns
    -------
    dict
        ``status`` (cvxpy's, or ``"solver error (...)"``), ``gamma2`` (the
        solver's minimum, or ``gamma2``; NaN without a solution),
        ``seconds`` and ``calls`` (solver invocations: 1).
    """
    if gamma2 is None:
        prob = cp.Problem(cp.Minimize(level), cons)
    else:
        prob = cp.Problem(cp.Maximize(t), list(cons) + [t <= 1e-3 * min(1.0, float(gamma2))])
    status, seconds, calls = run_solver(prob, solver, accuracy, retry=False)
    if status.startswith("solver error"):
        g2 = float("nan")
    elif gamma2 is None:
        g2 = float(level.value) if level.value is not None else float("nan")
    else:
        g2 = float(gamma2)
    return {"status": status, "gamma2": g2, "seconds": seconds, "calls": calls}


def solve_once_gamma(cons: list, g2: Any, solver: str, accuracy: float | None) -> dict[str, Any]:
    """:func:`solve_once` minimising γ² = ``g2``, reporting ``gamma`` = √max(γ², 0) (NaN without a solution)."""
    out = solve_once(cons, g2, solver, accuracy)
    level = out.pop("gamma2")
    out["gamma"] = float(np.sqrt(max(level, 0.0))) if not math.isnan(level) else float("nan")
    return out


class LMIProblem:
    """An LMI problem in a level γ², built once, solved in three ways.

    ``build(t, free)`` returns ``(constraints, level, readout)``: the
    constraints with the strictness margin ``t`` (a number, or a cvxpy
    variable), the expression of the level (γ², or ``tr W`` for H2; ``None``
    when ``free``) and a function returning the variables' values as a dict.
    The three problems, each built on first use and then kept (cvxpy
    re-solves a built problem without canonicalising it again):

    * ``solve(solver)``: minimise the level subject to the constraints at
      ``t = margin``;
    * ``solve(solver, gamma2=x)``: feasibility at level ``≤ x`` (a cvxpy
      Parameter), maximising t up to ``1e-3·min(1, x)`` (an interior point,
      which certifies well; a cap near the natural scale of the LMIs makes
      the solvers fail or report "unbounded");
    * ``solve(solver, gamma2="free")``: the same for the γ-free part
      (``build(t, True)``).

    ``calls`` counts every solver invocation of the problem; ``retry`` is
    that of :func:`run_solver`.
    """

    def __init__(self, build: Any, margin: float = 1e-8, accuracy: float | None = 1e-8,
                 retry: bool | tuple = True) -> None:
        self._build, self.margin, self.accuracy, self.retry = build, margin, accuracy, retry
        self._problems: dict = {}
        self.calls = 0
        self.seconds = 0.0

    def _problem(self, kind):
        if kind not in self._problems:
            if kind == "min":
                cons, level, readout = self._build(self.margin, False)
                self._problems[kind] = (cp.Problem(cp.Minimize(level), cons), level, None, None, readout)
            else:
                t = cp.Variable()
                cons, level, readout = self._build(t, kind == "free")
                gpar, cap = cp.Parameter(nonneg=True), cp.Parameter(nonneg=True)
                extra = [t <= cap] if kind == "free" else [level <= gpar, t <= cap]
                self._problems[kind] = (cp.Problem(cp.Maximize(t), cons + extra), t, gpar, cap, readout)
        return self._problems[kind]

    def solve(self, solver: str, gamma2: float | str | None = None) -> Solution:
        """Minimise (``gamma2=None``), or maximise the margin at a level (a number) or γ-free (``"free"``)."""
        kind = "min" if gamma2 is None else ("free" if isinstance(gamma2, str) else "level")
        prob, var, gpar, cap, readout = self._problem(kind)
        if kind == "level":
            gpar.value = float(gamma2)
            cap.value = 1e-3 * min(1.0, float(gamma2))
        elif kind == "free":
            cap.value = 1e-3
        status, seconds, calls = run_solver(prob, solver, self.accuracy, self.retry)
        self.calls += calls
        self.seconds += seconds
        values = readout() if not status.startswith("solver error") else {}
        if kind == "min":
            level = float(var.value) if values and var.value is not None else float("nan")
            margin = self.margin
        else:
            level = float(gamma2) if kind == "level" else float("nan")
            margin = float(var.value) if values and var.value is not None else float("nan")
        return Solution(status, level, values, margin, seconds, solver, calls)
