"""Benchmark of the certified mixed H2/H∞ synthesis (issue 12) on Sun et al. (2011)'s chaser.

Prints

1. the wall time of one certified mixed design at δ̄ = 0.05 (γ = 0.4, about
   1.1 γ*), solve + certification (target: under 2 s), best and median of
   ``--repeat`` runs, for the extended (default) and the common-Lyapunov
   formulation, with their certified ν;
2. the wall time of the 12-point front γ* … 10 γ* plus the unconstrained H2
   design, including Corollary 1 for γ* (target: under 30 s), with every
   point's certified γ, ν, sampled H2 norm and time.

The machine's load matters (CVXOPT does most of the work, single-threaded):
run it on an idle machine. The CPU time of the process is printed beside the
wall time (on a busy machine it is the better estimate of the idle wall time),
with the load average. Not a test: it asserts nothing.

Run: ``python benchmarks/bench_mixed.py [--repeat N] [--delta-bar D] [--points K]``.
"""

import argparse
import os
import statistics
import time

from hinfnav.papers.sun2011 import Scenario, mixed_design_for_scenario, mixed_front_for_scenario


def one_design(scenario, delta_bar, gamma, repeat, lyapunov):
    times, cpu, res = [], [], None
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = mixed_design_for_scenario(scenario, delta_bar, gamma, lyapunov=lyapunov)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    print(f"{lyapunov:>9}: wall best {min(times):5.2f} s, median {statistics.median(times):5.2f} s; CPU best "
          f"{min(cpu):5.2f} s (over {repeat}); certified γ {res.gamma:.8f}, ν {res.h2_bound:.8f} "
          f"(synthesis LMI alone {res.h2_synthesis_bound:.8f}), sampled ‖Ψ‖₂ {res.h2_verified:.8f}")
    return min(times)


def front(scenario, delta_bar, points):
    t0, c0 = time.perf_counter(), time.process_time()
    fr = mixed_front_for_scenario(scenario, delta_bar, points=points)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    env, _ = fr.pareto()
    print(f"\n== front at δ̄ = {delta_bar:g}: {points} points + H2, γ* = {fr.gamma_star:.8f} ==")
    print(f"{'γ bound / γ*':>13} {'certified γ':>12} {'ν certified':>12} {'ν synthesis':>12} {'ν sampled':>12} "
          f"{'front ν':>12} {'time s':>7}")
    for r, e in zip(fr.results, env):
        print(f"{r.gamma_bound / fr.gamma_star:13.5f} {r.gamma:12.8f} {r.h2_bound:12.8f} {r.h2_synthesis_bound:12.8f} "
              f"{r.h2_verified:12.8f} {e:12.8f} {r.total_time_s:7.2f}")
    h2 = fr.h2_result
    print(f"{'H2 (no γ)':>13} {h2.gamma:12.8f} {h2.h2_bound:12.8f} {h2.h2_synthesis_bound:12.8f} "
          f"{h2.h2_verified:12.8f} {'':12} {h2.total_time_s:7.2f}")
    k = fr.knee
    print(f"knee: point {k}, γ = {fr.gamma_bounds[k]:.6g} ({fr.gamma_bounds[k] / fr.gamma_star:.4g} γ*); "
          f"each point monotone: {fr.monotone()}")
    print(f"whole front with γ*: wall {wall:.2f} s, CPU {cpu:.2f} s (target < 30 s); "
          f"load average {os.getloadavg()[0]:.2f}")
    return wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="repetitions of the single design (default 3)")
    parser.add_argument("--delta-bar", type=float, default=0.05, help="uncertainty bound (default 0.05)")
    parser.add_argument("--points", type=int, default=12, help="front points (default 12)")
    args = parser.parse_args()
    sc = Scenario()
    mixed_design_for_scenario(sc, args.delta_bar, 0.4)  # warm-up: imports and first compilations
    print(f"== one certified mixed design at δ̄ = {args.delta_bar:g}, γ = 0.4 (target < 2 s); "
          f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs ==")
    for lyapunov in ("extended", "common"):
        one_design(sc, args.delta_bar, 0.4, args.repeat, lyapunov)
    front(sc, args.delta_bar, args.points)


if __name__ == "__main__":
    main()
