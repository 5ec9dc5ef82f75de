"""Benchmark: the per-step cost of the checked step interface (issue 17, item 4).

Run: ``python benchmarks/bench_step.py [--steps 2000] [--repeat 3]``. On the
Sun (2011) chaser (1 run, 0.1 s steps, range/angle measurement) it times
``update`` + ``predict`` per step, in µs, for the EKF told the thrust, the
Huber-based filter built from it, the thrust-augmented strong-tracking EKF
and the recursive H∞ filter, two ways:

* *hooks*: ``_update``/``_predict`` called directly (no checks: the cost
  before issue 17, and the path the batch ``estimate`` takes);
* *public*: ``update``/``predict``, which check the call order, the shapes
  and the finiteness of y and u at every step.

filterpy's ``ExtendedKalmanFilter`` (``predict`` + ``update``) on the same
data is printed beside them. The best of ``--repeat`` timings is kept (a
shared machine). Asserts nothing.
"""

import argparse
import time

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEKF

import hinfnav.papers  # noqa: F401 - registers the papers' estimators
from hinfnav.estimators import HuberFilter, build_estimator
from hinfnav.papers.sun2011 import Scenario
from hinfnav.sim import simulate_truth


def _loop(est, y, u, x0, checked):
    upd, pre = (est.update, est.predict) if checked else (est._update, est._predict)
    state = est.start(x0, None, 1)
    t0 = time.perf_counter()
    for k in range(y.shape[1]):
        state, _ = upd(state, y[:, k])
        state = pre(state, u[:, k])
    return (time.perf_counter() - t0) / y.shape[1] * 1e6


def _filterpy(ekf, y, u, x0):
    f = FilterpyEKF(dim_x=6, dim_z=3, dim_u=3)
    f.x, f.P = np.array(x0, dtype=float), ekf.P0.copy()
    f.F, f.Q, f.R, f.B = ekf.F, ekf.Q, ekf.R, ekf.Gamma
    meas = ekf.measurement
    t0 = time.perf_counter()
    for k in range(y.shape[1]):
        f.update(y[0, k], meas.jacobian, meas.function, residual=meas.residual)
        f.predict(u=u[0, k])
    return (time.perf_counter() - t0) / y.shape[1] * 1e6


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=2000, help="steps timed (default 2000)")
    p.add_argument("--repeat", type=int, default=3, help="timings per filter, the best kept (default 3)")
    args = p.parse_args(argv)
    sc = Scenario(duration_s=args.steps * 0.1, rms_window_s=(0.0, args.steps * 0.1))
    truth = simulate_truth(sc.truth_model(maneuver=True), runs=1, seed=0)
    y, u, x0 = truth.y, truth.u, sc.xhat0
    ekf = build_estimator(sc, "ekf_known_input")
    filters = {
        "ekf": ekf,
        "huber": HuberFilter.from_ekf(ekf),
        "strong tracking": build_estimator(sc, "ekf_augmented_thrust_st"),
        "recursive hinf": build_estimator(sc, "recursive_hinf"),
    }
    print(f"Sun 2011 chaser, 1 run, {y.shape[1]} steps: µs per step of update + predict (best of {args.repeat})")
    print(f"{'filter':18}{'hooks (before)':>16}{'public (after)':>16}{'checks':>10}")
    for name, est in filters.items():
        before = min(_loop(est, y, u, x0, False) for _ in range(args.repeat))
        after = min(_loop(est, y, u, x0, True) for _ in range(args.repeat))
        print(f"{name:18}{before:16.1f}{after:16.1f}{after - before:10.1f}")
    fp = min(_filterpy(ekf, y, u, x0) for _ in range(args.repeat))
    print(f"{'filterpy ekf':18}{fp:16.1f}")


if __name__ == "__main__":
    main()
