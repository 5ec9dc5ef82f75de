"""Benchmark: the closed loop of Yang et al. (2020) — plant, Algorithm 1, Algorithm 2 per axis, fusion, ADRC.

Run: ``python benchmarks/bench_dragfree.py [--steps N] [--runs R] [--passive] [--exact-steps M]``.
Prints the time and steps per second of the full loop (target: 3×10⁵ steps in
under 60 s on 2 cores), the step from which the gains are frozen, and, over
``--exact-steps``, the cost of the full covariance recursion at every step and
how far the frozen-gain loop moves from it. It asserts nothing (speed is not a test).

The gains of Algorithms 1-3 are frozen once their covariance recursions have
converged (``Scenario.steady_tol`` = 1e-6: largest change of P⁻ per step,
each entry relative to √(P_ii P_jj)); a clipped accelerometer reading
unfreezes them. Before that every step runs the full recursions (27×27 and
3×(3×3)); after it a step is a handful of small matrix-vector products.
"""

import argparse
import time
from dataclasses import replace

import numpy as np

from hinfnav.papers.yang2020 import Scenario, run_closed_loop


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=300_000, help="closed-loop steps (default 3e5)")
    p.add_argument("--runs", type=int, default=1, help="runs in the batch (default 1)")
    p.add_argument("--passive", action="store_true", help="also run the standalone filters of Figs 5-7 (1e5 steps)")
    p.add_argument("--exact-steps", type=int, default=0,
                   help="also time this many steps with the full covariance recursion at every step (no freezing)")
    args = p.parse_args(argv)
    sc = Scenario(n_steps=args.steps)
    t0, c0 = time.perf_counter(), time.process_time()
    res = run_closed_loop(sc, controller="adrc", runs=args.runs, passive=args.passive)
    dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    n = args.steps + 1
    print(f"closed loop (ADRC, Algorithm 3 = Algorithms 1 + 2 fused), {n} steps x {args.runs} run(s)"
          f"{' + standalone filters' if args.passive else ''}")
    print(f"  time {dt:.1f} s wall, {cpu:.1f} s CPU   {n * args.runs / dt:,.0f} steps/s (wall), "
          f"{n * args.runs / cpu:,.0f} (CPU)   (target: 3e5 steps < 60 s)")
    print("  (on a busy machine the wall time overstates the cost: the loop is single-threaded)")
    print(f"  gains frozen from step {res.settings['fused_steady_from_step']} (steady_tol {sc.steady_tol:g})")
    if args.exact_steps:
        m = args.exact_steps
        t0 = time.perf_counter()
        exact = run_closed_loop(replace(sc, n_steps=m, steady_tol=None), runs=args.runs, passive=False)
        te = time.perf_counter() - t0
        print(f"full recursion every step: {m + 1} steps in {te:.1f} s ({(m + 1) * args.runs / te:,.0f} steps/s)")
        frozen = run_closed_loop(replace(sc, n_steps=m), runs=args.runs, passive=False)
        err = np.sqrt(np.mean((exact.xhat - exact.true_extended()) ** 2, axis=(0, 1)))
        diff = np.abs(frozen.xhat - exact.xhat).max(axis=(0, 1))
        print(f"  frozen vs exact: largest |difference| / RMS error over the 27 states = {np.max(diff / err):.2e}"
              f" (gains frozen from step {frozen.settings['fused_steady_from_step']})")


if __name__ == "__main__":
    main()
