"""Sun et al. (2011)'s computation claim, timed: the LTI robust filter (12) against the EKF, per step.

§1 of the paper: "most papers use the recursive form of the H∞ filter, which computes many coefficient matrices
at every step; the filter designed here by LMI needs no recursive coefficient matrices, which greatly reduces
the computation" (大多数论文均采用递推形式的 H∞ 滤波算法, 每递推一步均需计算大量系数矩阵。本文采用 LMI …
设计的滤波器, 无需递推系数阵, 从而大大减少了计算量). The recursive H∞ filter
(:mod:`.recursive_hinf`) and the EKF both propagate a covariance and compute a gain every step. :func:`step_times` times one filter step
(``update`` then ``predict``, the public step interface a navigation computer would call once per sample)
of the published filter, the recursive H∞ filter and the EKF on the same simulated readings, one run, best of ``repeats``
passes of ``steps`` steps (wall-clock, :func:`time.perf_counter`; the numbers depend on the machine, the
ratio much less). The batch ``estimate`` of both is timed too (all steps in one call).
"""

import time

import numpy as np

from ...core.validation import as_int_at_least
from ...sim.truth import simulate_truth
from .filters import make_estimator
from .recursive_hinf import build_recursive_hinf
from .scenario import Scenario

__all__ = ["step_times"]


def _step_pass(est, y, u, xhat0):
    state = est.start(xhat0, runs=1)
    t0 = time.perf_counter()
    for k in range(y.shape[1]):
        state, _ = est.update(state, y[:, k])
        state = est.predict(state, u[:, k] if est.uses_input else None)
    return time.perf_counter() - t0


def _builders(sc):
    return {"published": lambda: make_estimator(sc, "published"), "ekf": lambda: make_estimator(sc, "ekf"),
            "recursive_hinf": lambda: build_recursive_hinf(sc)}


def step_times(scenario=None, *, steps=1000, repeats=3, seed=0, filters=("published", "recursive_hinf", "ekf")):
    """Wall-clock time per step of each filter (see the module docstring).

    Returns
    -------
    dict
        Per filter ``step_time_s`` (update + predict, s per step) and ``batch_step_time_s``; ``ratio_ekf_over_lti``
        (EKF time over the published filter's, step interface and batch), ``ratio_recursive_hinf_over_lti``;
        ``steps``, ``repeats``, ``note``.
    """
    sc = Scenario() if scenario is None else scenario
    steps = min(as_int_at_least("steps", steps, 10), sc.n_steps)
    repeats = as_int_at_least("repeats", repeats, 1)
    truth = simulate_truth(sc.truth_model(maneuver=False), runs=1, seed=seed)
    y, u = truth.y[:, :steps], truth.u[:, :steps]
    out = {}
    for name in filters:
        est = _builders(sc)[name]()
        step = min(_step_pass(est, y, u, sc.xhat0) for _ in range(repeats))
        batch = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            est.estimate(y, u, sc.xhat0, keep_covariance=False)
            batch.append(time.perf_counter() - t0)
        out[name] = {"step_time_s": step / steps, "batch_step_time_s": min(batch) / steps}
    res = {"filters": out, "steps": steps, "repeats": repeats,
           "note": "one run, best of the repeats; update + predict through the public step interface, and the "
                   "batch estimate; wall-clock on this machine (the ratio is what carries over)"}
    for other in ("ekf", "recursive_hinf"):
        if "published" in out and other in out:
            res[f"ratio_{other}_over_lti"] = {
                "step": float(np.divide(out[other]["step_time_s"], out["published"]["step_time_s"])),
                "batch": float(np.divide(out[other]["batch_step_time_s"], out["published"]["batch_step_time_s"]))}
    return res
