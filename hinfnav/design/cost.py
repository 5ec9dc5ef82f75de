"""How long an LMI design will take, said before it starts, and a progress bar while it runs (issue 36 item 5).

The cost model is fitted to ``benchmarks/bench_design_scale.py`` (k stacked
copies of Sun et al. (2011)'s chaser, norm-bounded, the default solver chain,
CPU seconds on the project's 2 shared cores, issue 31's table)::

    states   CPU s
       6      0.35
      12     13.96
      18     98.5

A least-squares line through (log n, log t) gives ``t ≈ c · n^a`` with
``a = 5.2`` and ``c = 2.9e-5`` s (within 20 % of each point). A polytope is
one LMI block per vertex and, with a parameter-dependent Lyapunov matrix,
one matrix variable per vertex: the model multiplies by the vertex count V
(common Lyapunov matrix) or by ``V^1.5`` (parameter-dependent), an
extrapolation that ``examples/two_mass_spring_30pct.toml`` (4 states, 2
vertices, 4 augmented for the observer form) bounds from above. SCS is held
to :data:`hinfnav.lmi.solve.SCS_BUDGET_S` by the command line, so its
estimate is that budget at most. The estimate is a guide (a factor of 2 on
a loaded machine), not a limit; a run above :data:`DESIGN_LIMIT_S` is
refused up front unless asked for.
"""

from __future__ import annotations

import contextlib
import math
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from ..core.exceptions import InputError, SynthesisError
from ..io.progress import bar_disabled
from ..lmi.solve import SCS_BUDGET_S, watch_solves

__all__ = ["COST_EXPONENT", "COST_SCALE_S", "DESIGN_LIMIT_S", "SHOW_ABOVE_S", "estimate_design_seconds",
           "system_size", "design_progress"]

#: Exponent a of the fitted cost ``c · n^a`` (see the module docstring).
COST_EXPONENT = 5.2
#: Factor c (CPU seconds) of the fitted cost.
COST_SCALE_S = 2.9e-5
#: A design estimated above this many seconds is refused up front (``limit=`` / ``--time-limit`` raise it).
DESIGN_LIMIT_S = 3600.0
#: The estimate and the bar are shown for designs estimated above this many seconds.
SHOW_ABOVE_S = 5.0


def estimate_design_seconds(n: int, vertices: int = 1, lyapunov: str = "common", solver: str | None = None) -> float:
    """Estimated CPU seconds of one LMI design with ``n`` states (see the module docstring for the fit).

    Parameters
    ----------
    n : int
        Plant states (the observer form of a polytope augments them; pass the augmented count).
    vertices : int
        Vertices of a polytope (1: norm-bounded or nominal).
    lyapunov : {"common", "parameter-dependent"}
    solver : str, optional
        ``"SCS"``: at most the budget :data:`~hinfnav.lmi.solve.SCS_BUDGET_S`.
    """
    t = COST_SCALE_S * float(n) ** COST_EXPONENT
    v = max(int(vertices), 1)
    t *= v ** 1.5 if lyapunov == "parameter-dependent" and v > 1 else v
    if solver is not None and str(solver).upper() == "SCS":
        t = min(max(t, 1.0), SCS_BUDGET_S)
    return t


def system_size(system: Any, lyapunov: str | None = None, form: str = "general") -> tuple[int, int, str]:
    """``(n, vertices, lyapunov)`` of a system read from a file, as the design will see it."""
    verts = getattr(system, "vertices", None)
    if verts is not None:
        v0 = verts[0]
        A = v0[0] if isinstance(v0, tuple) else v0.A  # a ContinuousPolytope's vertices are (A, B, C, D, L)
        n, v = np.shape(A)[0], len(verts)
        lyap = lyapunov or "parameter-dependent"
    else:
        n = system.A.shape[0]
        r = 0 if getattr(system, "H", None) is None else system.H.shape[1]
        lyap = lyapunov or "common"
        v = 2 ** min(r, 20) if lyap == "parameter-dependent" and r else 1
    if form == "observer" and v > 1:
        n = 2 * n  # augmented with the states the uncertainty reads (at most n)
    return n, v, lyap


@contextlib.contextmanager
def design_progress(estimate_s: float, *, progress: bool = True, limit_s: float | None = DESIGN_LIMIT_S,
                    what: str = "design", stream: Any = None) -> Iterator[Any]:
    """Context manager around a design: refuse it above ``limit_s``, else say its estimate and show a bar.

    The bar's total is the estimate in seconds; it advances with the wall
    time (every second, and at each solver call counted by
    :func:`hinfnav.lmi.solve.watch_solves`, which also holds SCS to
    :data:`~hinfnav.lmi.solve.SCS_BUDGET_S`) and shows the calls and the
    last status. Nothing is printed for a design estimated under
    :data:`SHOW_ABOVE_S`, except a note when a solver's budget ran out
    (after the design, on ``stream``).
    """
    stream = sys.stderr if stream is None else stream
    if limit_s is not None and estimate_s > limit_s:
        raise InputError(f"{what}: estimated {estimate_s:.3g} s (cost model of hinfnav.design.cost, fitted to "
                         f"benchmarks/bench_design_scale.py) exceeds the limit of {limit_s:g} s; raise it "
                         "(--time-limit SECONDS, or limit_s=) if you mean it")
    show = progress and estimate_s >= SHOW_ABOVE_S
    if show:
        print(f"{what}: estimated {_human(estimate_s)} (cost model fitted to benchmarks/bench_design_scale.py; "
              "a factor of 2 either way on a loaded machine)", file=stream, flush=True)
    bar = tqdm(total=max(round(estimate_s), 1), disable=bar_disabled(show), desc=what, unit="s", file=stream,
               bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} s est. {postfix}")
    start = time.perf_counter()
    lock, stop = threading.Lock(), threading.Event()

    def advance():
        with lock:
            elapsed = time.perf_counter() - start
            bar.total = max(bar.total, math.ceil(elapsed))  # past the estimate: the total follows the elapsed time
            bar.n = min(elapsed, bar.total)
            bar.refresh()

    def on_call(watch, solver, status, seconds):
        with lock:
            bar.set_postfix_str(f"{watch.calls} solver calls, last {solver}: {status[:40]}", refresh=False)
        advance()

    def tick():
        while not stop.wait(1.0):
            advance()

    ticker = threading.Thread(target=tick, name="hinfnav-design-progress", daemon=True)
    if not bar.disable:
        ticker.start()
    try:
        with watch_solves({"SCS": SCS_BUDGET_S}, on_call) as watch:
            try:
                yield watch
            except SynthesisError as exc:
                if "SCS" not in watch.spent:
                    raise
                # SCS (first-order, loose) is the likely cause: say so and what to use instead, in the same line
                raise type(exc)(f"{exc} [SCS ran {watch.spent['SCS']:.0f} s of its {SCS_BUDGET_S:g} s budget and its "
                                "points did not certify: SCS is a first-order solver, loose on these LMIs; use "
                                "--solver CLARABEL or CVXOPT (the default chain)]") from None
    finally:
        stop.set()
        if ticker.is_alive():
            ticker.join()
        bar.close()
    for slv in dict.fromkeys(watch.exhausted):
        print(f"note: the {slv} time budget of {watch.budget[slv]:g} s was used up; the design is the best point "
              f"certified within it (CLARABEL or CVXOPT certify tighter, faster)", file=stream, flush=True)


def _human(seconds: float) -> str:
    if seconds < 120:
        return f"~{seconds:.0f} s"
    if seconds < 7200:
        return f"~{seconds / 60:.0f} min"
    return f"~{seconds / 3600:.1f} h"
