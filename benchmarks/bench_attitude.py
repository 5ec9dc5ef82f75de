"""Time of paper 002's three filters (AEKF, ASTEKF, AAEKF): 1000 steps × 100 runs, batched over runs.

Prints wall-clock and CPU seconds per 1000 steps × 100 runs, and the same
for 10 runs (the per-step overhead of Python). Asserts nothing.

    python benchmarks/bench_attitude.py [--runs 100] [--steps 1000] [--repeat 3]
"""

import argparse
import time

from hinfnav.papers.attitude2018 import Scenario, build_aaekf, build_aekf, build_astekf
from hinfnav.sim import simulate_truth


def bench(runs, steps, repeat):
    sc = Scenario()
    sc = sc.replace(orbits=steps * sc.dt / sc.orbital_period)
    truth = simulate_truth(sc.truth_model(), runs=runs, seed=0)
    n = truth.x.shape[1]
    rows = []
    for build in (build_aekf, build_astekf, build_aaekf):
        est = build(sc)
        best_wall = best_cpu = float("inf")
        for _ in range(repeat):
            w0, c0 = time.perf_counter(), time.process_time()
            est.estimate(truth.y, truth.u, sc.xhat0, keep_covariance=False)
            best_wall = min(best_wall, time.perf_counter() - w0)
            best_cpu = min(best_cpu, time.process_time() - c0)
        scale = 1000.0 / n
        rows.append((est.name, best_wall * scale, best_cpu * scale))
    return n, rows


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=100)
    p.add_argument("--steps", type=int, default=1000)
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    for runs in (args.runs, 10):
        n, rows = bench(runs, args.steps, args.repeat)
        print(f"{runs} runs, {n} steps (best of {args.repeat}); seconds per 1000 steps x {runs} runs:")
        print(f"  {'filter':8}{'wall (s)':>10}{'cpu (s)':>10}{'us/step/run':>13}")
        for name, wall, cpu in rows:
            print(f"  {name:8}{wall:10.3f}{cpu:10.3f}{1e3 * wall / runs:13.1f}")


if __name__ == "__main__":
    main()
