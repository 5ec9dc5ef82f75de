"""Benchmark: the Huber-based filter over many runs, batched across runs vs run by run.

Run: ``python benchmarks/bench_huber.py [--runs 1000] [--loop-runs 5]``. On Shi &
Wang (2018)'s scenario (2500 steps of T = 0.4 s) it times the HBF (and the EKF
it robustifies) on ``--runs`` runs in one batch, then ``--loop-runs`` runs one
at a time, extrapolated to ``--runs`` (a full run-by-run loop over 1000 runs
would take minutes). Wall time and process CPU time are both printed: on a
shared machine the CPU time is the steadier number. Target (issue 9): the
batched HBF over 1000 runs × 2500 steps under 15 s on 2 cores. Asserts nothing.
"""

import argparse
import time

import numpy as np

from hinfnav.papers.shi2018 import EKF, HBF, ContaminatedNoise, Scenario


def _time(fn):
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - w0, time.process_time() - c0, out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=1000, help="runs of the batched estimate (default 1000)")
    p.add_argument("--loop-runs", type=int, default=5, help="runs timed one at a time, extrapolated (default 5)")
    p.add_argument("--case", default="gaussian", choices=("gaussian", "mixture"), help="sensor noise (default gaussian)")
    args = p.parse_args(argv)
    sc = Scenario()
    noise = {"measurement_noise": ContaminatedNoise() if args.case == "mixture" else "gaussian"}
    wall, cpu, truth = _time(lambda: sc.simulate_truth(runs=args.runs, seed=0, **noise))
    print(f"scenario: {sc.n_steps} steps of T = {sc.dt} s, {args.runs} runs, {args.case} sensor noise")
    print(f"truth: {wall:.2f} s wall, {cpu:.2f} s CPU")
    print(f"{'filter':8}{'batched wall (s)':>18}{'batched CPU (s)':>17}{'run by run (s, extrap.)':>25}{'ratio':>8}"
          f"{'pos RMS (m)':>13}")
    for est in (HBF(sc), EKF(sc)):
        wall, cpu, hist = _time(lambda: est.estimate(truth.y, truth.u, sc.xhat0, keep_covariance=False))
        n = min(args.loop_runs, args.runs)
        lw, _, _ = _time(lambda: [est.estimate(truth.y[r:r + 1], truth.u[r:r + 1], sc.xhat0, keep_covariance=False)
                                  for r in range(n)])
        loop = lw * args.runs / n
        m = sc.time >= sc.rms_window_s[0]
        pos = float(np.sqrt(np.mean((truth.x - hist.xhat)[:, m, :3] ** 2)))
        print(f"{est.name:8}{wall:18.2f}{cpu:17.2f}{loop:25.1f}{loop / wall:8.1f}{pos:13.3f}")
    print("target: HBF batched over 1000 runs x 2500 steps under 15 s on 2 cores")


if __name__ == "__main__":
    main()
