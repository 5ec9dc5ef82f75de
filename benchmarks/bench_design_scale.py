"""How the cost of a certified robust design grows with the number of states (issue 31).

Plants: k stacked copies of Sun et al. (2011)'s chaser at δ̄ = 0.05 (norm-bounded, ``structure="full"``: the
path of ``design --system``), n = 6k, and a dense random stable plant of the same size (seeded; spectral radius
0.95, norm-bounded uncertainty of small gain ≈ 0.2). For each n it prints the CPU seconds of the LMI route
(:func:`hinfnav.design.synthesize`, unit-free scaling, certificate included), its number of solver calls, the
certified γ, and beside it python-control's Riccati (slycot ``sb02od`` through ``control.dare``) for the
nominal a-priori H∞ filter Riccati equation of the same plant (no uncertainty, no certificate: the cost floor of
a Riccati design). A route whose predicted cost at the next n (from the fitted growth exponent) exceeds
``--budget`` CPU seconds is skipped there ("skip"). The last line fits the growth exponent ``t ∝ n^a``.

Run: ``python benchmarks/bench_design_scale.py [--sizes 6 12 18 24 48] [--budget 300] [--plants chaser random]``
(not a test; minutes).
"""

from __future__ import annotations

import argparse
import time

import control
import numpy as np
import scipy.linalg

from hinfnav.design import SolverOptions, synthesize
from hinfnav.papers.sun2011 import Scenario
from hinfnav.systems.uncertain import UncertainSystem


def stacked_chasers(n: int) -> UncertainSystem:
    """``n / 6`` copies of Sun et al. (2011)'s design model at δ̄ = 0.05, block-diagonal."""
    s = Scenario().design_model(0.05)
    k = n // 6
    bd = lambda M: scipy.linalg.block_diag(*([M] * k))
    return UncertainSystem(bd(s.A), bd(s.B), bd(s.C), bd(s.D), bd(s.L), bd(s.H), bd(s.E), dt=s.dt)


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


def lmi_route(system):
    c0 = time.process_time()
    res = synthesize(system, structure="full", options=SolverOptions(state_scaling="units"))
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
    ap.add_argument("--plants", nargs="+", default=["chaser", "random"], choices=["chaser", "random"])
    args = ap.parse_args()
    synthesize(stacked_chasers(6), structure="full")  # warm-up: imports, cvxpy's first canonicalisation
    for plant in args.plants:
        make = stacked_chasers if plant == "chaser" else dense_random
        print(f"\n== {plant} plant ==")
        print(f"{'n':>4} {'LMI CPU s':>10} {'solves':>7} {'certified γ':>14} {'control.dare CPU s':>19}")
        ns, ts = [], []
        for n in args.sizes:
            system = make(n)
            a = fit_exponent(ns, ts)
            predicted = ts[-1] * (n / ns[-1]) ** (a if np.isfinite(a) else 6.0) if ts else 0.0
            if predicted > args.budget:
                lmi = f"{'skip':>10} {'':>7} {'(predicted ' + format(predicted, '.0f') + ' s)':>14}"
            else:
                try:
                    t, calls, g = lmi_route(system)
                    ns.append(n)
                    ts.append(t)
                    lmi = f"{t:10.2f} {calls:7d} {g:14.8g}"
                except Exception as exc:
                    lmi = f"{'failed':>10} {'':>7} {type(exc).__name__:>14}"
            tr, ok = riccati_floor(system, 10.0)
            print(f"{n:4d} {lmi} {tr:12.4f} ({ok})", flush=True)
        print(f"fitted growth exponent of the LMI route (t ∝ n^a over the sizes run): a = {fit_exponent(ns, ts):.2f}")


if __name__ == "__main__":
    main()
