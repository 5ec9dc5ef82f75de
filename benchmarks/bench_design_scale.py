"""How the cost of a certified robust design grows with the number of states (issue 31).

Plants: k stacked copies of Sun et al. (2011)'s chaser at δ̄ = 0.05 (norm-bounded, ``structure="full"``: the
path of ``design --system``; one full contraction F couples all copies), n = 6k; the same with a different δ̄
per copy (``varied``: blocks that are not equal); and a dense random stable plant of the same size (seeded;
spectral radius 0.95, norm-bounded uncertainty of small gain ≈ 0.2). For each n it prints the CPU seconds of
each LMI route of :func:`hinfnav.design.synthesize` (unit-free scaling, certificate included): ``block`` (the
default: a decoupled plant's LMI (20) posed per block with a common λ and γ, the same optimum) and ``full``
(``SolverOptions(blocks=False)``: one matrix inequality of the whole plant), each with its number of solver calls
and certified γ, and beside them python-control's Riccati (slycot ``sb02od`` through ``control.dare``) for the
nominal a-priori H∞ filter Riccati equation of the same plant (no uncertainty, no certificate: the cost floor of
a Riccati design). On the dense plant the two LMI routes are the same (nothing decouples); only ``block`` is run.
A route whose predicted cost at the next n (from its fitted growth exponent) exceeds ``--budget`` CPU seconds is
skipped there ("skip"). The last lines fit the growth exponent ``t ∝ n^a`` per route. BLAS runs on one thread
(threadpoolctl): the CPU seconds are those of one core.

Run: ``python benchmarks/bench_design_scale.py [--sizes 6 12 18 24 48] [--budget 300]
[--plants chaser varied random] [--routes block full]`` (not a test; minutes).
"""

from __future__ import annotations

import argparse
import time

import control
import numpy as np
import scipy.linalg
from threadpoolctl import threadpool_limits

from hinfnav.design import SolverOptions, synthesize
from hinfnav.papers.sun2011 import Scenario
from hinfnav.systems.uncertain import UncertainSystem


def stacked_chasers(n: int, delta_bars=None) -> UncertainSystem:
    """``n / 6`` copies of Sun et al. (2011)'s design model, block-diagonal (δ̄ = 0.05 each, or one δ̄ per copy)."""
    k = n // 6
    models = [Scenario().design_model(d) for d in (delta_bars if delta_bars is not None else [0.05] * k)]
    bd = lambda name: scipy.linalg.block_diag(*[getattr(s, name) for s in models])
    return UncertainSystem(*(bd(name) for name in "ABCDLHE"), dt=models[0].dt)


def varied_chasers(n: int) -> UncertainSystem:
    """``n / 6`` chasers with δ̄ from 0.02 to 0.1 (blocks that are not equal)."""
    return stacked_chasers(n, np.linspace(0.02, 0.1, n // 6))


def dense_random(n: int, seed: int = 0) -> UncertainSystem:
    """A dense random stable plant: ρ(A) = 0.95, n/2 noise inputs and measurements, z = x, rank-2 uncertainty."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A *= 0.95 / max(abs(np.linalg.eigvals(A)))
    m = max(n // 2, 1)
    B, C = rng.standard_normal((n, m)) / np.sqrt(n), rng.standard_normal((m, n)) / np.sqrt(n)
    H, E = rng.standard_normal((n, 2)), rng.standard_normal((2, n))
    nominal = control.ss(A, H, E, 0, 1.0)
    g = control.linfnorm(nominal)[0]
    s = np.sqrt(0.2 / g)
    return UncertainSystem(A, B, C, 0.1 * np.eye(m), np.eye(n), H * s, E * s, dt=1.0)


def lmi_route(system, blocks=True):
    c0 = time.process_time()
    res = synthesize(system, structure="full", options=SolverOptions(state_scaling="units", blocks=blocks))
    return time.process_time() - c0, res.solver_calls, res.gamma


def riccati_floor(system, gamma_f):
    """python-control: the nominal a-priori H∞ filter Riccati at level γ_f (cost only)."""
    A, B, C, D, L = system.A, system.B, system.C, system.D, system.L
    c0 = time.process_time()
    Cc = np.vstack([C, L])
    R = scipy.linalg.block_diag(D @ D.T, -(gamma_f**2) * np.eye(L.shape[0]))
    try:
        control.dare(A.T, Cc.T, B @ B.T, R)
        ok = "ok"
    except Exception as exc:
        ok = type(exc).__name__
    return time.process_time() - c0, ok


def fit_exponent(ns, ts):
    pts = [(np.log(n), np.log(t)) for n, t in zip(ns, ts) if t is not None and t > 0]
    if len(pts) < 2:
        return float("nan")
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[6, 12, 18, 24, 48])
    ap.add_argument("--budget", type=float, default=300.0, help="CPU seconds one design may be predicted to take")
    ap.add_argument("--plants", nargs="+", default=["chaser", "random"], choices=list(PLANTS))
    ap.add_argument("--routes", nargs="+", default=["block", "full"], choices=["block", "full"])
    args = ap.parse_args()
    with threadpool_limits(1):
        synthesize(stacked_chasers(6), structure="full")  # warm-up: imports, cvxpy's first canonicalisation
        for plant in args.plants:
            make = PLANTS[plant]
            routes = args.routes if plant != "random" else ["block"]
            print(f"\n== {plant} plant ==")
            print(f"{'n':>4} " + " ".join(f"{r + ' CPU s':>12} {'calls':>5} {'certified γ':>12}" for r in routes)
                  + f" {'control.dare CPU s':>19}")
            fits = {r: ([], []) for r in routes}
            for n in args.sizes:
                system = make(n)
                cells = []
                for route in routes:
                    ns, ts = fits[route]
                    a = fit_exponent(ns, ts)
                    predicted = ts[-1] * (n / ns[-1]) ** (a if np.isfinite(a) else 6.0) if ts else 0.0
                    if predicted > args.budget:
                        cells.append(f"{'skip':>12} {'':>5} {'(~' + format(predicted, '.0f') + ' s)':>12}")
                        continue
                    try:
                        t, calls, g = lmi_route(system, route == "block")
                        ns.append(n)
                        ts.append(t)
                        cells.append(f"{t:12.2f} {calls:5d} {g:12.10f}")
                    except Exception as exc:
                        cells.append(f"{'failed':>12} {'':>5} {type(exc).__name__:>12}")
                tr, ok = riccati_floor(system, 10.0)
                print(f"{n:4d} " + " ".join(cells) + f" {tr:12.4f} ({ok})", flush=True)
            for route in routes:
                print(f"fitted growth exponent of the {route} route (t ∝ n^a over the sizes run): "
                      f"a = {fit_exponent(*fits[route]):.2f}")


PLANTS = {"chaser": stacked_chasers, "varied": varied_chasers, "random": dense_random}


if __name__ == "__main__":
    main()
