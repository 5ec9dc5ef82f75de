"""Huang et al. (2017)'s benchmark: the package's robust filters on a target with heavy-tailed noise.

Huang, Zhang, Li, Wu & Chambers, "A novel robust Student's t-based Kalman filter",
IEEE TAES 53(3), 2017, §V (target tracking). The set-up as the paper states it (the
authors' MATLAB code is published on ResearchGate only, which this project cannot
reach; nothing here is taken from it):

* 2-D constant velocity, state ``[x, y, ẋ, ẏ]`` (m, m/s), sampling T = 1 s:
  ``F = [I₂ T I₂; 0 I₂]``, ``H = [I₂ 0]``;
* ``Q = q [T³/3 I₂  T²/2 I₂; T²/2 I₂  T I₂]``, q = 1 m²/s³; ``R = r I₂``, r = 100 m²;
* outlier-contaminated noises (the paper's eqs. for w_k and v_k):
  ``w_k ~ N(0, Q)`` with probability 0.95 and ``N(0, 100 Q)`` with 0.05;
  ``v_k ~ N(0, R)`` with probability 0.9 and ``N(0, 100 R)`` with 0.1;
* x₀ = [0, 0, 10, 10]ᵀ, P₀ = 100 I₄; the filters start at x̂₀ drawn from N(x₀, P₀).
  Here, equivalently, the filters start at x₀ and each run's true x₀ is drawn from
  N(x₀, P₀) (the estimation error has the same law; the step contract has one x̂₀
  for every run);
* the filters are told the nominal Q and R, except the "KF with true covariances"
  (KFTCM), told ``Q_true = (0.95 + 0.05·100) Q`` and ``R_true = (0.9 + 0.1·100) R``;
  the Student-t filter ω = ν = 5, N = 10 (the paper's choices; τ = 1e-8 here);
  Huber γ = 1.345.

The readings are y₁ … y_K (x₀ is not read): every filter starts from the prior
``x̂(1|0) = F x₀``, ``P(1|0) = F P₀ Fᵀ + Q`` (its own Q). The position ARMSE is the
RMS of the position error ‖p_k − p̂_k‖ pooled over runs and steps, with the 95 %
interval of :func:`hinfnav.metrics.accumulator.rms_interval`; two filters are compared
run by run (common random numbers): the mean of the per-run differences of RMS and its
95 % Student-t interval.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_seed
from ...estimators.correntropy import CorrentropyFilter
from ...estimators.gate import ChiSquareGate
from ...estimators.huber_filter import HuberFilter, HuberStrongTrackingEKF
from ...estimators.kalman import ExtendedKalmanFilter, StrongTrackingEKF
from ...estimators.variational import NoiseAdaptiveFilter, StudentTFilter
from ...metrics.accumulator import rms_interval
from ...metrics.intervals import t_half_width
from ...plotting.errors import new_figure
from ...systems.linear import LinearSystem
from ...systems.measurements import LinearMeasurement
from ...systems.state import StateSpec

__all__ = ["SETUP", "huang_system", "huang_truth", "huang_comparison",
           "plot_huang_comparison"]

#: The paper's set-up (see the module docstring).
SETUP = {"T": 1.0, "q": 1.0, "r": 100.0, "p_process": 0.95, "scale_process": 100.0, "p_measurement": 0.9,
         "scale_measurement": 100.0, "x0": (0.0, 0.0, 10.0, 10.0), "P0": 100.0, "dof": 5.0, "iterations": 10}

#: Filters of the comparison, in the table's order (name → description).
FILTERS = {
    "kf": "Kalman filter told the nominal Q, R",
    "kf_true_cov": "Kalman filter told the mixtures' true covariances (Huang's KFTCM)",
    "kf_gated": "Kalman filter (nominal) with a chi-square gate (0.999, per reading, inflate recovery)",
    "hbf": "Huber-based filter, gamma = 1.345",
    "stekf": "strong-tracking EKF (rho = 0.95, beta = 1)",
    "huber_stekf": "Huber x strong tracking",
    "stkf": "Student-t variational filter (Huang 2017), omega = nu = 5, N = 10",
    "vbakf": "VB noise-adaptive filter (Sarkka & Nummenmaa 2009), rho = 1, N = 5",
    "mckf": "maximum-correntropy KF (Chen 2017), sigma = 2",
}


def _matrices(T, q, r):
    F = np.block([[np.eye(2), T * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
    Q = q * np.block([[T**3 / 3 * np.eye(2), T**2 / 2 * np.eye(2)], [T**2 / 2 * np.eye(2), T * np.eye(2)]])
    return F, Q, r * np.eye(2)


def huang_system(setup: Mapping[str, Any] = SETUP) -> tuple[LinearSystem, LinearMeasurement]:
    """The constant-velocity system (nominal Q = B Bᵀ) and the position measurement (nominal R = D Dᵀ)."""
    F, Q, R = _matrices(setup["T"], setup["q"], setup["r"])
    state = StateSpec(labels=("x", "y", "vx", "vy"), units=("m", "m", "m/s", "m/s"),
                      groups={"position": (0, 1), "velocity": (2, 3)})
    system = LinearSystem(Phi=F, Gamma=np.zeros((4, 1)), B=np.linalg.cholesky(Q), dt=setup["T"], state=state,
                          name="2-D constant velocity (Huang 2017)")
    return system, LinearMeasurement(np.hstack([np.eye(2), np.zeros((2, 2))]), np.sqrt(setup["r"]) * np.eye(2),
                                     labels=("x", "y"), units=("m", "m"))


def huang_truth(runs: int, steps: int = 100, seed: int = 0,
                setup: Mapping[str, Any] = SETUP) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)``: true states (runs, steps, 4) at t = 1 … steps s and readings (runs, steps, 2).

    Each run draws from its own child of ``SeedSequence(seed)``, so a run's numbers do not
    depend on how many runs are drawn.
    """
    runs = as_int_at_least("runs", runs, 1)
    steps = as_int_at_least("steps", steps, 1)
    F, Q, R = _matrices(setup["T"], setup["q"], setup["r"])
    LQ, LR = np.linalg.cholesky(Q), np.linalg.cholesky(R)
    x0 = np.asarray(setup["x0"], dtype=float)
    x = np.empty((runs, steps, 4))
    y = np.empty((runs, steps, 2))
    for i, child in enumerate(np.random.SeedSequence(as_seed("seed", seed)).spawn(runs)):
        rng = np.random.default_rng(child)
        xk = x0 + np.sqrt(setup["P0"]) * rng.standard_normal(4)
        sw = np.where(rng.random(steps) >= setup["p_process"], np.sqrt(setup["scale_process"]), 1.0)
        sv = np.where(rng.random(steps) >= setup["p_measurement"], np.sqrt(setup["scale_measurement"]), 1.0)
        w = rng.standard_normal((steps, 4)) @ LQ.T * sw[:, None]
        v = rng.standard_normal((steps, 2)) @ LR.T * sv[:, None]
        for k in range(steps):
            xk = F @ xk + w[k]
            x[i, k] = xk
        y[i] = x[i, :, :2] + v
    return x, y


def huang_filters(names: Sequence[str] | None = None, setup: Mapping[str, Any] = SETUP) -> dict[str, Any]:
    """The filters of :data:`FILTERS` (or those named) on :func:`huang_system`, each with P₀ = F P₀ Fᵀ + Q (its Q)."""
    names = list(FILTERS) if names is None else list(names)
    unknown = [n for n in names if n not in FILTERS]
    if unknown:
        raise InputError(f"names: unknown filter(s) {unknown}; choose from {', '.join(FILTERS)}")
    system, meas = huang_system(setup)
    F, Q, R = system.Phi, system.Q, meas.R
    pq, pr = setup["p_process"], setup["p_measurement"]
    Q_true = (pq + (1 - pq) * setup["scale_process"]) * Q
    R_true = (pr + (1 - pr) * setup["scale_measurement"]) * R
    P0 = setup["P0"] * np.eye(4)

    def prior(Qf):
        return F @ P0 @ F.T + Qf

    nominal = dict(P0=prior(Q), Q=Q, R=R)
    dof, N = setup["dof"], setup["iterations"]
    build = {
        "kf": lambda: ExtendedKalmanFilter(system, meas, name="kf", **nominal),
        "kf_true_cov": lambda: ExtendedKalmanFilter(system, meas, P0=prior(Q_true), Q=Q_true, R=R_true,
                                                    name="kf_true_cov"),
        "kf_gated": lambda: _gated(ExtendedKalmanFilter(system, meas, name="kf_gated", **nominal)),
        "hbf": lambda: HuberFilter(system, meas, gamma=1.345, name="hbf", **nominal),
        "stekf": lambda: StrongTrackingEKF(system, meas, rho=0.95, beta=1.0, name="stekf", **nominal),
        "huber_stekf": lambda: HuberStrongTrackingEKF(system, meas, rho=0.95, beta=1.0, gamma=1.345,
                                                      name="huber_stekf", **nominal),
        "stkf": lambda: StudentTFilter(system, meas, dof_process=dof, dof_measurement=dof, iterations=N, tol=1e-8,
                                       name="stkf", **nominal),
        "vbakf": lambda: NoiseAdaptiveFilter(system, meas, rho=1.0, iterations=5, name="vbakf", **nominal),
        "mckf": lambda: CorrentropyFilter(system, meas, sigma=2.0, name="mckf", **nominal),
    }
    return {n: build[n]() for n in names}


def _gated(est):
    est.gate = ChiSquareGate(probability=0.999)
    return est


def paired_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """Mean of ``a − b`` over runs and its 95 % Student-t interval: ``(mean, low, high)``."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    half = float(t_half_width(d, axis=0))
    return float(d.mean()), float(d.mean() - half), float(d.mean() + half)


def huang_comparison(runs: int = 100, steps: int = 100, seed: int = 0, names: Sequence[str] | None = None,
                     reference: str = "hbf", setup: Mapping[str, Any] = SETUP) -> pd.DataFrame:
    """Every filter on one record of :func:`huang_truth`: position ARMSE with its interval, time per step.

    Returns
    -------
    pandas.DataFrame
        One row per filter: ``armse_m`` (pooled position RMS), ``armse_low``/``armse_high`` (95 %),
        ``vs_<reference>_m`` (mean over runs of the per-run position RMS minus the reference's) with its
        95 % interval ``…_low``/``…_high``, ``us_per_step`` (wall time of ``estimate`` per run and step, µs)
        and ``description``. ``attrs["per_run"]``: name → per-run position RMS (runs,).
    """
    x, y = huang_truth(runs, steps, seed, setup)
    u = np.zeros(y.shape[:2] + (1,))
    filters = huang_filters(names, setup)
    if reference not in filters:
        raise InputError(f"reference must be one of the filters compared; got {reference!r}")
    x0 = np.asarray(setup["x0"], dtype=float)
    F = huang_system(setup)[0].Phi
    per_run, rows = {}, []
    for name, est in filters.items():
        t0 = time.perf_counter()
        hist = est.estimate(y, u, F @ x0, keep_covariance=False)
        elapsed = time.perf_counter() - t0
        sq = np.sum((hist.xhat[..., :2] - x[..., :2]) ** 2, axis=-1)  # (runs, steps)
        ms = sq.mean(axis=1)
        low, high = rms_interval(ms)
        per_run[name] = np.sqrt(ms)
        rows.append({"filter": name, "armse_m": float(np.sqrt(ms.mean())), "armse_low": float(low),
                     "armse_high": float(high), "us_per_step": 1e6 * elapsed / (runs * steps),
                     "description": FILTERS[name]})
    table = pd.DataFrame(rows)
    diffs = [paired_difference(per_run[n], per_run[reference]) for n in table["filter"]]
    key = f"vs_{reference}_m"
    table[key] = [d[0] for d in diffs]
    table[f"{key}_low"] = [d[1] for d in diffs]
    table[f"{key}_high"] = [d[2] for d in diffs]
    table.attrs["per_run"] = per_run
    table.attrs["runs"], table.attrs["steps"], table.attrs["seed"] = runs, steps, seed
    return table


def plot_huang_comparison(table: pd.DataFrame, reference: str = "hbf"):
    """Two panels: each filter's position ARMSE with its 95 % interval, and its time per step (µs, log scale)."""
    fig, axes = new_figure(1, 2, figsize=(11, 3.8))
    ax1, ax2 = axes[0]
    pos = np.arange(len(table))
    arm = table["armse_m"].to_numpy()
    err = np.vstack([arm - table["armse_low"].to_numpy(), table["armse_high"].to_numpy() - arm])
    ax1.barh(pos, arm, xerr=err, color=["C3" if f == reference else "C0" for f in table["filter"]], capsize=3)
    ax1.set_yticks(pos, table["filter"])
    ax1.set_xscale("log")
    lo, hi = float(table["armse_low"].min()), float(table["armse_high"].max())
    ticks = [v * 10.0**e for e in range(-1, 6) for v in (1, 2, 5) if lo / 1.5 <= v * 10.0**e <= hi * 1.5]
    ax1.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax1.tick_params(axis="x", which="minor", labelbottom=False)  # the minor labels of a log axis overlap
    ax1.set_xlabel("position ARMSE, m (95 % interval)")
    ax1.invert_yaxis()
    ax2.barh(pos, table["us_per_step"], color="C2")
    ax2.set_yticks(pos, table["filter"])
    ax2.set_xscale("log")
    ax2.set_xlabel("wall time per run and step, µs")
    ax2.invert_yaxis()
    fig.suptitle(f"Huang 2017 set-up: {table.attrs.get('runs')} runs x {table.attrs.get('steps')} steps")
    return fig
