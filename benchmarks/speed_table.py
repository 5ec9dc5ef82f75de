"""Speed table (issue 21): µs per step of five filters on Sun (2011)'s chaser, NumPy, numba and filterpy.

Run: ``python benchmarks/speed_table.py`` (``--quick`` for a short check,
``--big-runs N`` to replace the 10⁴-run batch by N runs, ``--repeat N``
timings per cell, the minimum kept; ``--compile-cost`` also times the first
call in a new process from an empty numba cache and from the filled one).

On the chaser (6 states, 3 position readings, 0.1 s steps, thrust told to
the filters that use it; the strong-tracking filter is the registered
``ekf_augmented_thrust_st``, 9 error coordinates) it prints, for 1, 100, 200
and 10⁴ runs (the larger batches on fewer steps), the CPU time per step of
the whole batch:

* **NumPy**: ``est.estimate(..., backend="numpy")``, the reference path;
* **numba**: ``est.estimate(..., backend="numba")``, what the default ``"auto"`` runs (kernels already compiled
  and cached: the first call's cost is printed separately, with
  ``--compile-cost`` from a cold and from a warm cache);
* **filterpy**: filterpy 2.0's loop (``predict``/``update`` per run and
  step) on the same data where filterpy has the filter (EKF, UKF; it has no
  Huber or strong-tracking filter, and its ``HInfinityFilter`` is another
  filter, see :mod:`hinfnav.estimators.recursive_hinf`), timed on at most 20
  runs and scaled linearly (its loop is per run);
* the **estimate difference** of numba and filterpy to the NumPy reference:
  the largest ``|Δx̂|`` over runs and steps, each state channel divided by its
  largest ``|x̂|``;
* the **arithmetic limit**: the floating-point operations per run and step,
  counted from the kernels' equations (:func:`flops`), times the runs, over
  this machine's single-core GEMM rate (OpenBLAS, one thread, 512 × 512,
  measured in a subprocess).

A second table times your own nonlinear model, one run: the README's
constant-turn target with a range/bearing sensor (the package's models, their
compiled functions declared by the models) and a pendulum written here with
``numba.njit`` functions as a user would (:mod:`hinfnav.systems.compiled`):
the EKF and the sigma-point filter by default (``backend="auto"``: the
kernels of :mod:`hinfnav.estimators.compiled_models`) and on the NumPy path,
each the median and the least of ``--repeat`` CPU timings, and the largest
relative difference of the default's estimates to the NumPy path's.

The machine may be shared: every cell is the minimum of ``--repeat`` timings
of the process's CPU time (the least disturbed one; the wall clock would count
the waits of a batch for a shared CPU); the load average at the start and the
end is printed.
Asserts nothing.
"""

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEKF
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

import hinfnav.papers  # noqa: F401 - registers the papers' estimators
from hinfnav.estimators import HuberFilter, build_estimator
from hinfnav.papers.sun2011 import Scenario
from hinfnav.sim import simulate_truth

#: (runs, steps) of the table (10⁴ runs on fewer steps).
SIZES = ((1, 2000), (100, 300), (200, 300), (10_000, 30))
QUICK = ((1, 200), (200, 50), (10_000, 5))


def machine():
    """``(CPU model, physical cores, logical CPUs)`` from /proc/cpuinfo (else the platform module)."""
    model, cores = platform.processor() or platform.machine(), set()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            phys = None
            for line in f:
                key, _, value = line.partition(":")
                key, value = key.strip(), value.strip()
                if key == "model name":
                    model = value
                elif key == "physical id":
                    phys = value
                elif key == "core id":
                    cores.add((phys, value))
    except OSError:
        pass
    return model, len(cores) or None, os.cpu_count()


def gemm_rate():
    """Single-core double-precision GEMM rate, flop/s (512 × 512, best CPU time of 20, one BLAS thread)."""
    code = ("import time, numpy as np\n"
            "a = np.random.default_rng(0).standard_normal((512, 512)); b = a.copy(); best = 1e9\n"
            "for _ in range(20):\n"
            "    t = time.process_time(); a @ b; best = min(best, time.process_time() - t)\n"
            "print(2 * 512 ** 3 / best)")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    return float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                                check=True, timeout=120).stdout)


def flops(kind, n=6, m=3, nu=3, n_aug=3):
    """Floating-point operations per run and step counted from the kernels' equations (multiply-add = 2).

    ``shared``: the mean recursion of a filter whose gain does not depend on the data (the covariance
    recursion is shared by all runs, counted once per step and divided among them elsewhere): ``ν = y − H x``,
    ``x + K ν``, ``F x + G u``. ``joseph``: one covariance recursion (``F P Fᵀ + Q``, (J1)-(J2)).
    """
    if kind == "shared":
        return 2 * n * m + m + 2 * n * m + n + 2 * n * n + 2 * n * nu + n
    if kind == "joseph":
        return (4 * n**3 + n * n) + (2 * n * n * m + 2 * n * m * m + m**3 + 2 * n * m * m + 2 * n * n * m + 4 * n**3
                                     + 4 * n * m * m + n * n) + flops("shared", n, m, nu)
    if kind == "huber":  # the Kalman form of the M-estimation (its common case) and L_P⁻¹ δx
        return flops("joseph", n, m, nu) + n**3 / 3 + n**3 / 3 + n * n + 2 * m * m
    if kind == "strong":  # augmented by n_aug input states (no G u), plus (S1)-(S4)
        na = n + n_aug
        return flops("joseph", na, m, 0) + 2 * m * m + 2 * m * na * na + 2 * m * m * na + 2 * na * m + 3 * na * na
    if kind == "lti":  # x̂ = C_F x_f, x_f⁺ = A x_f + B_F y + M u
        return 2 * n * n + 2 * n * n + 2 * n * m + 2 * n * nu + n
    if kind == "ukf":
        N = 2 * n + 1
        return 2 * (n**3 / 3) + 2 * N * n * m + 4 * N * m * m + 2 * N * n * m + m**3 + 2 * n * m * m + 2 * n * m \
            + 2 * n * m * m + 2 * n * n * m + 2 * N * n * n + 2 * N * n * n + 2 * n * n + 2 * n * nu
    raise ValueError(kind)


def _min_time(fn, repeat):
    """The least of ``repeat`` CPU-time timings of ``fn()`` (this process, all threads) and its last result.

    CPU time, not wall clock: on a shared machine a batch longer than a scheduler slice waits for the CPU,
    which the wall clock would count and this does not.
    """
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return float(best), out


def _ratio(r):
    return f"{r:.1f}×" if r < 10 else f"{r:.0f}×"


def _rel(ref, got):
    return float(np.max(np.abs(got - ref) / np.abs(ref).max(axis=(0, 1))))


def _filterpy_ekf(ekf, y, u, x0):
    meas = ekf.measurement
    xs = np.empty(y.shape[:2] + (ekf.n_state,))
    for r in range(y.shape[0]):
        f = FilterpyEKF(dim_x=ekf.n_state, dim_z=meas.n_meas, dim_u=u.shape[2])
        f.x, f.P = np.array(x0, dtype=float), ekf.P0.copy()
        f.F, f.Q, f.R, f.B = ekf.F, ekf.Q, ekf.R, ekf.Gamma
        for k in range(y.shape[1]):
            f.update(y[r, k], meas.jacobian, meas.function, residual=meas.residual)
            xs[r, k] = f.x
            f.predict(u=u[r, k])
    return xs


def _filterpy_ukf(ukf, y, u, x0):
    sysm = ukf.system
    xs = np.empty(y.shape[:2] + (ukf.n_state,))
    for r in range(y.shape[0]):
        points = MerweScaledSigmaPoints(ukf.n_state, alpha=ukf.alpha, beta=ukf.beta, kappa=ukf.kappa)
        f = UnscentedKalmanFilter(dim_x=ukf.n_state, dim_z=ukf.measurement.n_meas, dt=ukf.dt,
                                  hx=lambda x: ukf.measurement.H @ x,
                                  fx=lambda x, dt, u: sysm.Phi @ x + sysm.Gamma @ u, points=points)
        f.x, f.P, f.Q, f.R = np.array(x0, dtype=float), ukf.P0.copy(), ukf.Q, ukf.R
        f.sigmas_f = points.sigma_points(f.x, f.P)  # the first update draws its points from the prior
        for k in range(y.shape[1]):
            f.update(y[r, k])
            xs[r, k] = f.x
            f.predict(u=u[r, k])
    return xs


def filters(sc):
    """The table's filters: name → (estimator, filterpy loop or None, flop kind per run, flop kind of the covariance
    recursion shared by all runs or None).

    On the chaser's linear model the gains of the EKF, the sigma-point filter (its sigma points' deviations do
    not depend on the state) and the recursive H∞ filter do not depend on the data: the kernels compute their
    covariance recursion once per batch (counted once) and every run's mean recursion.
    """
    ekf = build_estimator(sc, "ekf_known_input")
    return {
        "EKF": (ekf, _filterpy_ekf, "shared", "joseph"),
        "sigma-point (UKF)": (build_estimator(sc, "ukf"), _filterpy_ukf, "shared", "ukf"),
        "Huber": (HuberFilter.from_ekf(ekf), None, "huber", None),
        "strong tracking": (build_estimator(sc, "ekf_augmented_thrust_st"), None, "strong", None),
        "recursive H∞": (build_estimator(sc, "recursive_hinf"), None, "shared", "joseph"),
        "LTI filter (12)": (build_estimator(sc, "published_closed_loop"), None, "lti", None),
    }


def constant_turn_data(steps, runs=1):
    """The README's own-model example: constant turn (5 states), range/bearing sensor; ``(model, sensor, x0, P0, y,
    u)`` of ``runs`` runs × ``steps`` steps (a noise-free truth, noisy readings; seed 0)."""
    from hinfnav.systems import ConstantTurn, RangeBearing

    model = ConstantTurn(dt=1.0, sigma_accel=0.05, sigma_turn_rate=1e-3)
    sensor = RangeBearing(model.n, sigma_range=5.0, sigma_bearing=0.01)
    x0, P0 = np.array([-1500.0, 400.0, 0.0, -15.0, 0.03]), np.diag([50, 50, 5, 5, 0.02]) ** 2.0
    x = [np.broadcast_to(x0, (runs, 5))]
    for _ in range(steps - 1):
        x.append(model.f(x[-1]))
    y = sensor.measure(np.stack(x, 1), np.random.default_rng(0).standard_normal((runs, steps, 2)))
    return model, sensor, x0, P0, y, np.zeros((runs, steps, 0))


# -- a model of one's own, written with numba (hinfnav.systems.compiled): a pendulum, its bob's position measured --

@numba.njit(cache=True)
def _pendulum_f(x, u, t, p):  # one explicit Euler step of θ̈ = −(g/ℓ) sin θ; p = (Δt, g/ℓ)
    out = np.empty(2)
    out[0] = x[0] + p[0] * x[1]
    out[1] = x[1] - p[0] * p[1] * np.sin(x[0])
    return out


@numba.njit(cache=True)
def _pendulum_jacobian(x, u, t, p):
    J = np.empty((2, 2))
    J[0, 0], J[0, 1], J[1, 0], J[1, 1] = 1.0, p[0], -p[0] * p[1] * np.cos(x[0]), 1.0
    return J


@numba.njit(cache=True)
def _bob_h(x, p):  # (ℓ sin θ, −ℓ cos θ); p = (ℓ,)
    out = np.empty(2)
    out[0], out[1] = p[0] * np.sin(x[0]), -p[0] * np.cos(x[0])
    return out


@numba.njit(cache=True)
def _bob_jacobian(x, p):
    H = np.zeros((2, 2))
    H[0, 0], H[1, 0] = p[0] * np.cos(x[0]), p[0] * np.sin(x[0])
    return H


def pendulum_data(steps):
    """A user's pendulum (DynamicsModel and MeasurementModel subclasses declaring numba functions) and one run."""
    from hinfnav.systems import DynamicsModel, MeasurementModel, StateSpec
    from hinfnav.systems.compiled import CompiledDynamics, CompiledMeasurement

    class Pendulum(DynamicsModel):
        def f(self, x, u=None, t=0.0):
            return np.stack([x[:, 0] + self.dt * x[:, 1], x[:, 1] - self.dt * 4.905 * np.sin(x[:, 0])], axis=-1)

        def jacobian(self, x, u=None, t=0.0):
            J = np.zeros((x.shape[0], 2, 2))
            J[:, 0, 0], J[:, 0, 1], J[:, 1, 1] = 1.0, self.dt, 1.0
            J[:, 1, 0] = -self.dt * 4.905 * np.cos(x[:, 0])
            return J

        def compiled_functions(self):
            return CompiledDynamics(_pendulum_f, _pendulum_jacobian, [self.dt, 4.905])

    class Bob(MeasurementModel):
        def function(self, x):
            return np.stack([2.0 * np.sin(x[..., 0]), -2.0 * np.cos(x[..., 0])], axis=-1)

        def jacobian(self, x):
            H = np.zeros(np.shape(x)[:-1] + (2, 2))
            H[..., 0, 0], H[..., 1, 0] = 2.0 * np.cos(x[..., 0]), 2.0 * np.sin(x[..., 0])
            return H

        def compiled_functions(self):
            return CompiledMeasurement(_bob_h, _bob_jacobian, None, [2.0])

    model = Pendulum(StateSpec(("theta", "omega"), ("rad", "rad/s")), 0.01, np.diag([0.0, 1e-6]))
    sensor = Bob(2, 0.02 * np.eye(2), ("x", "z"), ("m", "m"))
    x0 = np.array([1.0, 0.0])
    x = [x0[None]]
    for _ in range(steps - 1):
        x.append(model.f(x[-1]))
    y = sensor.measure(np.stack(x, 1), np.random.default_rng(0).standard_normal((1, steps, 2)))
    return model, sensor, x0, np.diag([0.1, 0.1]), y, np.zeros((1, steps, 0))


def _med_time(fn, repeat):
    """Median and least of ``repeat`` CPU-time timings of ``fn()``, and its last result."""
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return float(np.median(times)), float(min(times)), out


def own_model_rows(repeat, steps=2000):
    """µs per step (median and least of ``repeat`` CPU timings) of the EKF and the sigma-point filter on the README's
    own-model example (constant turn, range/bearing) and on a user's numba pendulum, one run: the default backend,
    the NumPy path, the largest relative difference of the estimates, and the backend the default ran."""
    from hinfnav.estimators import ExtendedKalmanFilter, SigmaPointFilter
    from hinfnav.estimators.compiled import why_numpy

    rows = []
    for label, data in (("constant turn + range/bearing", constant_turn_data(steps)),
                        ("user's numba pendulum", pendulum_data(steps))):
        model, sensor, x0, P0, y, u = data
        for est in (ExtendedKalmanFilter(model, sensor, P0=P0), SigmaPointFilter(model, sensor, P0=P0)):
            est.estimate(y[:, :2], u[:, :2], x0)  # the first call: the model's functions compiled or loaded
            med_d, min_d, got = _med_time(lambda est=est: est.estimate(y, u, x0, keep_covariance=False).xhat, repeat)
            med_n, _, ref = _med_time(lambda est=est: est.estimate(y, u, x0, keep_covariance=False,
                                                                    backend="numpy").xhat, max(1, repeat // 2))
            rows.append((label, type(est).__name__, med_d * 1e6 / steps, min_d * 1e6 / steps, med_n * 1e6 / steps,
                         _rel(ref, got), "numba" if why_numpy(est) is None else f"NumPy: {why_numpy(est)}"))
    return rows


_FIRST_CALL = """import os, sys, time
c0, w0 = time.process_time(), time.perf_counter()
import hinfnav.papers
from hinfnav.estimators import HuberFilter, build_estimator
from hinfnav.papers.sun2011 import Scenario
from hinfnav.sim import simulate_truth
sc = Scenario(duration_s=2.0, rms_window_s=(0.0, 2.0))
t = simulate_truth(sc.truth_model(maneuver=True), runs=1, seed=0)
ests = [build_estimator(sc, n) for n in ('ekf_known_input', 'ukf', 'recursive_hinf', 'ekf_augmented_thrust_st')]
ests.append(HuberFilter.from_ekf(ests[0]))
c1, w1 = time.process_time(), time.perf_counter()
for est in ests:
    est.estimate(t.y, t.u, sc.xhat0, backend='numba')
print(time.process_time() - c1, time.perf_counter() - w1)
"""


def first_call_cost():
    """CPU and wall seconds of the first numba call of the five filters in a new process (numba imported,
    every kernel compiled or loaded): ``((cpu, wall) from an empty cache, (cpu, wall) from the filled one)``."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = []
        for _ in range(2):  # cold, then warm
            res = subprocess.run([sys.executable, "-c", _FIRST_CALL], capture_output=True, text=True, check=True,
                                 timeout=1800, env=env)
            out.append(tuple(float(v) for v in res.stdout.split()[-2:]))
    return out[0], out[1]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=5, help="timings per cell, the minimum kept (default 5)")
    p.add_argument("--quick", action="store_true", help="short sizes (a check that the script runs)")
    p.add_argument("--big-runs", type=int, default=10_000, help="runs of the largest batch (default 10⁴)")
    p.add_argument("--compile-cost", action="store_true",
                   help="also time the first call in a new process from an empty and from a filled numba cache")
    args = p.parse_args(argv)
    if args.repeat < 1 or args.big_runs < 1:
        p.error("--repeat and --big-runs must be at least 1")
    model, cores, cpus = machine()
    rate = gemm_rate()
    load0 = os.getloadavg()
    print(f"Machine: {model}, {cores or '?'} physical cores, {cpus} logical CPUs; Python {platform.python_version()}, "
          f"NumPy {np.__version__}; single-core GEMM {rate / 1e9:.1f} GFLOP/s; load average {load0[0]:.1f} at the start")
    sizes = [(args.big_runs if runs == 10_000 else runs, steps) for runs, steps in (QUICK if args.quick else SIZES)]
    longest = max(s for _, s in sizes)
    sc = Scenario(duration_s=longest * 0.1, rms_window_s=(0.0, longest * 0.1))
    truths = {}  # one truth per (runs, steps), simulated for its steps only (memory: that of the largest batch)
    for runs, steps in sizes:
        sc_k = Scenario(duration_s=steps * 0.1, rms_window_s=(0.0, steps * 0.1))
        truths[runs, steps] = simulate_truth(sc_k.truth_model(maneuver=True), runs=runs, seed=0)
    truth = truths[sizes[0]]
    table = filters(sc)
    t0 = time.perf_counter()
    for est, *_ in table.values():  # first call: numba imported, kernels loaded from the cache (or compiled)
        est.estimate(truth.y[:1, :2], truth.u[:1, :2], sc.xhat0, backend="numba")
    print(f"First numba call of the five filters in this process (import, cache load or compilation): "
          f"{time.perf_counter() - t0:.2f} s wall")
    if args.compile_cost:
        (c_cpu, c_wall), (w_cpu, w_wall) = first_call_cost()
        print(f"First call of the five filters in a new process: empty cache (compilation) {c_cpu:.1f} s CPU "
              f"({c_wall:.1f} s wall); filled cache {w_cpu:.2f} s CPU ({w_wall:.2f} s wall)")
    print()
    print("| filter | runs × steps | NumPy µs/step | numba µs/step | NumPy ÷ numba | filterpy µs/step | "
          "filterpy ÷ numba | limit µs/step | numba Δ | filterpy Δ |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, (est, fp, kind, shared) in table.items():
        for runs, steps in sizes:
            y, u = truths[runs, steps].y[:, :steps], truths[runs, steps].u[:, :steps]

            def run(backend, est=est, y=y, u=u):
                return est.estimate(y, u, sc.xhat0, keep_covariance=False, backend=backend).xhat

            t_np, ref = _min_time(lambda: run("numpy"), args.repeat)
            t_nb, got = _min_time(lambda: run("numba"), args.repeat)
            per = 1e6 / steps
            cells = [f"{t_np * per:.1f}", f"{t_nb * per:.2f}", _ratio(t_np / t_nb)]
            if fp is not None:
                few = min(runs, 20)
                t_fp, xs = _min_time(lambda fp=fp, few=few, y=y, u=u: fp(est, y[:few], u[:few], sc.xhat0),
                                        max(1, args.repeat // 2) if few > 1 else args.repeat)
                t_fp *= runs / few
                cells += [f"{t_fp * per:.0f}", _ratio(t_fp / t_nb)]
                d_fp = f"{_rel(ref[:few], xs):.0e}"
            else:
                cells += ["—", "—"]
                d_fp = "—"
            work = flops(kind) * runs + (flops(shared) if shared else 0)
            cells += [f"{work / rate * 1e6:.3f}", f"{_rel(ref, got):.0e}", d_fp]
            print(f"| {name} | {runs} × {steps} | " + " | ".join(cells) + " |", flush=True)
    own_steps = 200 if args.quick else 2000
    print(f"\nYour own nonlinear model (1 run × {own_steps} steps; the median and the least of {args.repeat} CPU "
          "timings):")
    print("| model | filter | default µs/step (median) | default µs/step (least) | NumPy µs/step (median) | "
          "default Δ | default backend |")
    print("|---|---|---:|---:|---:|---:|---|")
    for label, name, med_d, min_d, med_n, diff, how in own_model_rows(args.repeat, own_steps):
        print(f"| {label} | {name} | {med_d:.2f} | {min_d:.2f} | {med_n:.1f} | {diff:.0e} | {how} |", flush=True)
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end; each cell the least of {args.repeat} CPU-time "
          "timings of the whole batch divided by its steps (filterpy: of fewer, on at most 20 runs, scaled to the "
          "runs); Δ: largest |x̂ − x̂_NumPy| over runs and steps, each state channel over its largest |x̂_NumPy|")


if __name__ == "__main__":
    main()
