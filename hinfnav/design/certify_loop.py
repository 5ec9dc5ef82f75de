"""The one solve → certify → tighten loop of the LMI designs, with its fallback order.

Every LMI design (norm-bounded LMI (20), polytopic extended LMIs (E1)/(E2))
hands this loop a list of *variants* of its problem (the data as prepared,
then rescaled data), each an :class:`hinfnav.lmi.LMIProblem` built once,
and a certificate function that never trusts the solver (float64 LMI test at
the returned filter, sampled norms). The loop returns certified candidates
and a log; it never returns an uncertified point.

Fallback order (stops as soon as a candidate is certified within ``rtol`` of
its solver's level, unless ``polish``):

1. minimise the level with each solver, on the first variant;
2. minimise with each solver on each further (rescaled) variant;
3. tighten: feasibility just above each solver level, lowest first, until one certifies (1e-4 … 1 relative,
   the level a cvxpy Parameter, the problem not rebuilt);
4. bisection on the level between the solver's level (a lower hint) and
   the best certified level (or the γ-free interior point, when the design
   has a γ-free problem), with each solver that gave a solution.

A design makes one solver call when the first minimisation certifies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable

__all__ = ["Candidate", "solve_and_certify"]


@dataclass
class Candidate:
    """A certified point: the certificate ``check`` (``.ok``, ``.gamma``), the solution and how it was found."""

    check: Any
    sol: Any
    solver: str
    how: str
    variant: int = 0
    level: float = float("nan")  # the solver's minimum the candidate descends from (NaN: bisection)


@dataclass
class Loop:
    """What :func:`solve_and_certify` did: candidates, log, statuses, γ-free verdicts, solver calls and time."""

    candidates: list = field(default_factory=list)
    log: list = field(default_factory=list)
    statuses: list = field(default_factory=list)
    verdicts: list = field(default_factory=list)
    hints: list = field(default_factory=list)
    calls: int = 0
    seconds: float = 0.0

    def best(self) -> Candidate | None:
        """The candidate of smallest certified level."""
        return min(self.candidates, key=lambda c: c.check.gamma, default=None)


def _level(sol):
    return math.sqrt(max(sol.gamma2, 0.0)) if math.isfinite(sol.gamma2) else float("nan")


def solve_and_certify(variants: list, solvers: list, certify: Callable, *, rtol: float = 1e-4,
                      max_bisection: int = 40, polish: bool = False, free: bool = False,
                      done: Callable | None = None, method: str = "auto", loop: Loop | None = None,
                      steps: tuple = (1e-4, 1e-3, 1e-2, 1e-1, 1.0)) -> Loop:
    """Run the fallback order of this module (see there) and return the :class:`Loop`.

    Parameters
    ----------
    variants : list of (str, callable)
        ``(name, solve)`` with ``solve(solver, gamma2)`` returning a
        :class:`hinfnav.lmi.Solution` in the units of the original data
        (``gamma2``: None to minimise, a level, or ``"free"``).
    solvers : list of str
    certify : callable
        ``certify(variant_index, sol)`` → a check with ``ok``, ``gamma``,
        ``reason`` (or None when ``sol`` has no values).
    free : bool
        The design has a γ-free problem (bisection's upper bracket when
        nothing certified).
    done : callable, optional
        ``done(loop)``: stop early (e.g. the certificate is tight enough).
    method : {"auto", "minimize", "bisection"}
        ``"minimize"``: steps 1–2 only; ``"bisection"``: steps 3–4 only.
    steps : tuple of float
        Relative steps above a solver's level tried in step 3.
    """
    loop = loop or Loop()
    log = loop.log

    def run(v, slv, level=None):
        sol = variants[v][1](slv, level)
        loop.calls += sol.calls
        loop.seconds += sol.seconds
        return sol, (certify(v, sol) if sol.solved else None)

    def accept(chk, sol, slv, how, v, level=float("nan")):
        loop.candidates.append(Candidate(chk, sol, slv, how, v, level))

    def finished():
        if done is not None and loop.candidates and done(loop):
            return True
        return False

    tight = False
    mins = []  # (variant, solver, solver level) of minimisations that solved
    if method != "bisection":
        for v, (name, _) in enumerate(variants):
            if v and loop.candidates:
                break  # rescaled data only when nothing certified on the data as prepared
            for slv in solvers:
                sol, chk = run(v, slv)
                loop.statuses.append((slv, sol.status))
                where = f" ({name})" if v else ""
                if chk is None:
                    log.append(f"{slv} minimize{where}: status {sol.status}, no solution")
                    continue
                g = _level(sol)
                mins.append((v, slv, g, sol.status))
                if slv != "SCS":
                    loop.hints.append(g)
                log.append(f"{slv} minimize{where}: status {sol.status}, solver γ = {g:.10g}, certified γ = "
                           f"{chk.gamma:.10g}: {chk.reason}")
                if chk.ok:
                    accept(chk, sol, slv, "minimize", v, g)
                    tight = tight or chk.gamma <= g * (1.0 + rtol)
                if loop.candidates and (tight or method == "minimize") and not polish:
                    return loop
            if loop.candidates and (tight or finished()) and not polish:
                return loop
        if method == "minimize" or (tight and polish):
            return loop
    # 3. tighten just above the best solver level
    for v, slv, g, _status in sorted(mins, key=lambda m: m[2]):
        if not g > 0 or (loop.best() is not None and loop.best().how == "bisection"):
            continue
        for step in steps:
            level = g * (1.0 + step)
            if loop.best() is not None and level >= loop.best().check.gamma:
                break
            sol, chk = run(v, slv, level**2)
            if chk is not None and sol.margin > 0 and chk.ok:
                log.append(f"{slv} feasibility at γ = {level:.10g}: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}")
                accept(chk, sol, slv, "bisection", v, g)
                break
            log.append(f"{slv} feasibility at γ = {level:.10g}: status {sol.status}, not certified")
            if not sol.solved and step >= 1e-3:
                break  # the solver gives no solution at all near its own optimum
    if loop.candidates and (finished() or loop.best().check.gamma <= min((m[2] for m in mins), default=math.inf) * (1 + 10 * rtol)):
        return loop
    # 4. bisection on the level
    for slv in solvers:
        lo_hint = min((m[2] for m in mins if m[1] == slv and m[3] == "optimal"), default=None)
        lo = 0.0 if lo_hint is None else lo_hint * (1.0 - 10.0 * rtol)
        best = loop.best()
        hi = None if best is None else best.check.gamma
        v = 0 if best is None else best.variant
        if hi is None and free:
            for v in range(len(variants)):
                sol, chk = run(v, slv, "free")
                name = "γ-free feasibility" + (f" ({variants[v][0]})" if v else "")
                if chk is None or not sol.margin > 0:
                    log.append(f"{slv} {name}: status {sol.status}, margin {sol.margin:.3g}: no interior point")
                    continue
                loop.verdicts.append("feasible" if math.isfinite(chk.gamma) else "interior point not certified")
                log.append(f"{slv} {name}: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
                if chk.ok:
                    sol.gamma2 = chk.gamma**2
                    accept(chk, sol, slv, "bisection", v)
                    hi = chk.gamma
                break
            else:
                loop.verdicts.append("infeasible")
                loop.statuses.append((slv, f"infeasible (status {sol.status}, γ-free part's largest margin "
                                           f"{sol.margin:.3g})"))
        if hi is None:
            continue
        if lo >= hi:
            lo = 0.0
        failures = 0
        for _ in range(max_bisection):
            if hi - lo <= rtol * hi:
                break
            mid = 0.5 * (lo + hi)
            sol, chk = run(v, slv, mid**2)
            if chk is None or not sol.margin > 0:
                log.append(f"{slv} feasibility at γ = {mid:.10g}: status {sol.status}, margin {sol.margin:.3g}: infeasible")
                lo = mid
                failures = failures + 1 if not math.isfinite(sol.margin) else 0
                if failures == 3:
                    log.append(f"{slv} bisection stopped: the solver gave no solution three times in a row")
                    break
                continue
            failures = 0
            log.append(f"{slv} feasibility at γ = {mid:.10g}: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
            if chk.ok and chk.gamma < hi:
                accept(chk, sol, slv, "bisection", v)
                hi = chk.gamma
            if not chk.ok or chk.gamma > mid:
                lo = mid
        if loop.candidates and not polish:
            break
    return loop
