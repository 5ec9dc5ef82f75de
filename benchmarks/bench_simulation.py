"""Benchmark: Monte Carlo simulation speed, vectorized vs run by run.

Run: ``python benchmarks/bench_simulation.py [--runs N]``. Prints times and
ratios; it asserts nothing (speed is not a test).
"""

import argparse
import time

import numpy as np

import hinfnav as hn
from hinfnav.papers import sun2011


def _time(fn, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=100, help="Monte Carlo runs (default 100)")
    args = p.parse_args(argv)
    s = sun2011.Scenario()
    print(f"scenario: {s.n_steps} steps of T = {s.dt} s, {args.runs} runs")
    rows = []
    for name in ("published", "ekf", "ekf_known_input"):
        est = sun2011.make_estimator(s, name)
        vec = _time(lambda: hn.simulate(s, est, runs=args.runs, seed=0, batch_size=args.runs), repeat=2)
        loop = _time(lambda: hn.simulate(s, est, runs=min(args.runs, 10), seed=0, batch_size=1), repeat=1)
        loop *= args.runs / min(args.runs, 10)
        rows.append((name, vec, loop))
    print(f"{'filter':18}{'vectorized (s)':>16}{'run by run (s)':>16}{'ratio':>8}")
    for name, vec, loop in rows:
        print(f"{name:18}{vec:16.2f}{loop:16.2f}{loop / vec:8.1f}")
    model = s.truth_model(maneuver=True)
    truth = _time(lambda: hn.simulate_truth(model, runs=args.runs, seed=0), repeat=2)
    print(f"truth alone: {truth:.2f} s for {args.runs} runs ({1e3 * truth / args.runs:.1f} ms per run)")
    # the step contract: the LTI filter's vectorized estimate against the generic step loop
    tr = hn.simulate_truth(model, runs=args.runs, seed=0)
    est = sun2011.make_estimator(s, "published")
    fast = _time(lambda: est.estimate(tr.y, tr.u, s.xhat0), repeat=2)
    loop = _time(lambda: hn.Estimator.estimate(est, tr.y, tr.u, s.xhat0), repeat=1)
    print(f"LTI filter, {args.runs} runs: vectorized estimate {fast:.2f} s, generic step loop {loop:.2f} s "
          f"(ratio {loop / fast:.1f})")


if __name__ == "__main__":
    main()
