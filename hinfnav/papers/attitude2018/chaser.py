"""Paper 002's two ideas on Sun 2011's chaser: estimate the unknown thrust, let the filter fade its memory.

Sun 2011's EKF does not know the orbit-control law u = K x (3), so during the
maneuver (thrust up to ~2.8 kN on 1000 kg, decaying over ~500 s) it fails:
1.0 m and 6.5 m/s RMS over 0–500 s (Fig 4; :mod:`hinfnav.papers.sun2011.ekf`).
Here the thrust is estimated instead (:class:`~hinfnav.estimators.augmented.AugmentedInputKF`),
as paper 002 estimates its disturbance torque:

``plain``     the thrust F (N) as a random walk with density Q_F (AEKF);
``st``        the same with strong tracking (ASTEKF), with a 100× smaller Q_F;
``adaptive``  the same with Q_F(t_k) = Q_F(t₀) max(1, (ε κ)²) (AAEKF).

Documented choices (nothing tuned on the truth):

* Q_F by the rule of Yang et al. 2020 (paper 004, Algorithm 1): per-step
  variance (ḟ_max T)², i.e. density ḟ_max² T, with ḟ_max = 100 N/s a bound on
  the thrust's rate (the truth's largest is 93 N/s) → Q_F = 1000 N²/s.
* The ASTEKF's and the AAEKF's base Q_F = Q_F/100 = 10 N²/s (paper 002's
  ratio between its ASTEKF and best-AEKF Q); ε such that Q_F(t₀)(ε ḟ_max)² =
  Q_F: ε = 0.1 s/N (the rule used for the attitude AAEKF); memory m = 50 steps
  steps (5 s); ρ = 0.95, β = 1 (as for the attitude ASTEKF).
* Initial thrust estimate 0 with σ = 3000 N (the order of Fig 6's largest
  thrust); the chaser state's P₀ and Q = BBᵀ, R = DDᵀ are Sun 2011's EKF's.
"""

import functools
from dataclasses import dataclass

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_choice, as_int_at_least
from ...estimators.augmented import (
    AugmentedInputAdaptiveKF,
    AugmentedInputKF,
    AugmentedInputSTKF,
)
from ...metrics.errors import rms_per_run
from ...metrics.intervals import format_interval, mean_interval
from ...plotting.errors import new_figure
from ...sim.montecarlo import SimulationResult, run_estimator
from ...sim.truth import simulate_truth
from ..sun2011.constants import DEFAULT_P0_STD
from ..sun2011.filters import make_estimator
from ..sun2011.scenario import Scenario as ChaserScenario

__all__ = [
    "P0_THRUST_STD",
    "Q_THRUST_BASE",
    "WINDOWS",
    "ChaserStudy",
    "build_augmented_thrust",
    "chaser_study",
    "format_chaser_table",
    "format_sweeps",
    "plot_chaser",
    "plot_thrust_estimates",
    "run_passes",
]

#: Bound on the thrust's rate of change, N/s (documented prior; the truth's largest is 93 N/s).
THRUST_RATE_MAX = 100.0
#: Thrust random-walk density of the augmented EKF, ḟ_max² T with T = 0.1 s, N²/s.
Q_THRUST = THRUST_RATE_MAX**2 * 0.1
#: Base density of the strong-tracking and adaptive variants, Q_THRUST/100, N²/s.
Q_THRUST_BASE = Q_THRUST / 100.0
#: Compression factor ε of the adaptive variant, s/N: Q_BASE (ε ḟ_max)² = Q_THRUST.
THRUST_EPSILON = float(np.sqrt(Q_THRUST / Q_THRUST_BASE) / THRUST_RATE_MAX)
#: Memory m of the adaptive variant's rate estimate, steps (5 s at T = 0.1 s).
THRUST_MEMORY_STEPS = 50
#: Initial standard deviation of the thrust estimate, N.
P0_THRUST_STD = 3000.0
#: The two windows of the comparison, s: during the maneuver, after it.
WINDOWS = ((0.0, 500.0), (500.0, 1000.0))

VARIANTS = ("plain", "st", "adaptive")


def build_augmented_thrust(scenario, variant="plain", *, Q_input=None, P0_input_std=P0_THRUST_STD, name=None, **options):
    """The thrust-augmented EKF of Sun 2011's chaser (see the module docstring).

    Parameters
    ----------
    scenario : hinfnav.papers.sun2011.Scenario
    variant : {"plain", "st", "adaptive"}
    Q_input : float or array_like, optional
        Thrust density, N²/s (a number means that times I₃, a 1-D array one
        per run); defaults :data:`Q_THRUST` (plain) or :data:`Q_THRUST_BASE`.
    P0_input_std : float
        Initial σ of the thrust estimate, N.
    **options
        ``rho``, ``beta``, ``a`` (st); ``epsilon``, ``memory_steps``, ``floor`` (adaptive).

    Returns
    -------
    AugmentedInputKF (or its strong-tracking / adaptive subclass)
    """
    if not isinstance(scenario, ChaserScenario):
        raise InputError(f"scenario must be a Sun 2011 Scenario; got {type(scenario).__name__}")
    variant = as_choice("variant", variant, VARIANTS)
    q = (Q_THRUST if variant == "plain" else Q_THRUST_BASE) if Q_input is None else Q_input
    q = np.asarray(q, dtype=float)
    Q = q * np.eye(3) if q.ndim == 0 else (q[:, None, None] * np.eye(3) if q.ndim == 1 else q)
    kw = dict(Q_input=Q, P0=np.diag(DEFAULT_P0_STD**2), P0_input=np.eye(3) * float(P0_input_std) ** 2)
    suffix = {"plain": "", "st": "_st", "adaptive": "_adaptive"}[variant]
    name = name or f"ekf_augmented_thrust{suffix}"
    system, meas = scenario.system(), scenario.measurement
    if variant == "plain":
        return AugmentedInputKF(system, meas, name=name, **kw, **options)
    if variant == "st":
        options.setdefault("rho", 0.95)
        options.setdefault("beta", 1.0)
        return AugmentedInputSTKF(system, meas, name=name, **kw, **options)
    options.setdefault("epsilon", THRUST_EPSILON)
    options.setdefault("memory_steps", THRUST_MEMORY_STEPS)
    return AugmentedInputAdaptiveKF(system, meas, name=name, **kw, **options)


def window_stats(error, t, state, window):
    """Position and velocity RMS over a window with 95 % intervals over runs.

    Returns
    -------
    dict
        ``pos_m``/``vel_mps``: RMS over axes, runs and window (pooled);
        ``*_mean`` the mean over runs of the per-run RMS and ``*_ci95`` its
        95 % interval (Student t, mean ± t s/√runs); ``*_axes`` per axis (pooled).
    """
    per = rms_per_run(error, t, window) ** 2
    out = {"window_s": list(window)}
    for key, grp in (("pos_m", "position"), ("vel_mps", "velocity")):
        ms = state.select(per, grp)
        run = np.sqrt(ms.mean(axis=1))
        _, low, high = mean_interval(run)  # Student t; NaN bounds with one run
        out[key] = float(np.sqrt(ms.mean()))
        out[key + "_axes"] = [float(v) for v in np.sqrt(ms.mean(axis=0))]
        out[key + "_mean"] = float(run.mean())
        out[key + "_ci95"] = [low, high]
    return out


@dataclass(frozen=True, eq=False)
class ChaserStudy:
    """The comparison of item 5.

    Attributes
    ----------
    rows : dict
        Filter name → {"0-500": window stats, "500-1000": window stats}.
    sweeps : dict
        ``q_plain`` (the augmented EKF over Q_F), ``beta_st`` (strong tracking
        over β), ``epsilon_adaptive`` (adaptive over ε): lists of
        ``{"value", "0-500", "500-1000"}``.
    runs0 : dict
        Filter name → SimulationResult of run 0 (for the figure), with the
        thrust estimate in ``diagnostics["input_estimate"]``.
    settings : dict
    """

    rows: dict
    sweeps: dict
    runs0: dict
    settings: dict


def _stats(res):
    return {f"{int(w[0])}-{int(w[1])}": window_stats(res.error, res.t, res.state, w) for w in WINDOWS}


def run_passes(scenario, builder, passes, *, diagnostics=()):
    """Several passes of one filter, each ``(truth, params)``, as one batch over all their runs.

    A pass costs mostly its per-step Python overhead, nearly the same for 4 runs as for 56 (measured,
    issue 21: ASTEKF 2.5 s CPU for 4 runs, 5.6 s for 56), so the main runs and a sweep of the same filter
    go through one pass. Every pass gives the same parameter names (scalars); the builder gets one value
    per run. Runs are independent in the batched filters, so each pass's numbers are those of its own pass.

    Returns
    -------
    errors : list of ndarray
        Per pass, the error history (runs, n_samples, 9) of its truth.
    hist : EstimateHistory
        The whole batch (runs in the order of the passes; run 0 is the first pass's run 0).
    """
    sizes = [truth.x.shape[0] for truth, _ in passes]
    keys = tuple(passes[0][1])
    per_run = {k: np.concatenate([np.full(n, params[k], dtype=float) for (_, params), n in zip(passes, sizes)])
               for k in keys}
    est = builder(scenario, **per_run)
    y = np.concatenate([truth.y for truth, _ in passes])
    u = np.concatenate([truth.u for truth, _ in passes])
    hist = est.estimate(y, u, scenario.xhat0, keep_covariance=False,
                        diagnostics=diagnostics if isinstance(diagnostics, bool) else tuple(diagnostics))
    errors, start = [], 0
    for (truth, _), n in zip(passes, sizes):
        errors.append(truth.state.error(truth.x, hist.xhat[start:start + n]))
        start += n
    return errors, hist


#: The sweeps of the thrust-augmented variants: (variant, key in ChaserStudy.sweeps, parameter, its default, values).
SWEEPS = (("plain", "q_plain", "Q_input", Q_THRUST, (1.0, 10.0, 100.0, 1e3, 1e4, 1e5)),
          ("st", "beta_st", "beta", 1.0, (1.0, 1.5, 2.0, 3.0)),
          ("adaptive", "epsilon_adaptive", "epsilon", THRUST_EPSILON, (0.03, 0.1, 0.3, 1.0, 3.0)))


def chaser_study(scenario=None, *, runs=20, seed=0, sweep_runs=None):
    """Item 5: the paper's unaware EKF, the EKF told the thrust and the three thrust-augmented filters.

    Parameters
    ----------
    scenario : hinfnav.papers.sun2011.Scenario, optional
        Sun 2011's scenario (with maneuver); default the paper's.
    runs : int
        Monte Carlo runs of the comparison.
    seed : int
    sweep_runs : int, optional
        Runs of the parameter sweeps (default min(runs, 5)).

    Returns
    -------
    ChaserStudy
    """
    scenario = ChaserScenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    sweep_runs = min(runs, 5) if sweep_runs is None else as_int_at_least("sweep_runs", sweep_runs, 1)
    if scenario.duration_s < WINDOWS[-1][1]:
        raise InputError(f"the chaser study needs duration_s >= {WINDOWS[-1][1]} s; got {scenario.duration_s}")
    truth = simulate_truth(scenario.truth_model(maneuver=True), runs=runs, seed=seed)
    rows, runs0 = {}, {}
    for name in ("ekf", "ekf_known_input"):
        res = run_estimator(make_estimator(scenario, name), truth, scenario.xhat0)
        rows[name] = _stats(res)
        runs0[name] = _first_run(res)
    small = simulate_truth(scenario.truth_model(maneuver=True), runs=sweep_runs, seed=seed)
    # each thrust-augmented variant: its main runs (default parameter) and its sweep in one pass (run_passes)
    sweeps = {}
    for variant, sweep_key, key, default, values in SWEEPS:
        name = build_augmented_thrust(scenario, variant).name
        builder = functools.partial(build_augmented_thrust, variant=variant)
        passes = [(truth, {key: default})] + [(small, {key: v}) for v in values]
        errors, hist = run_passes(scenario, builder, passes, diagnostics=True)
        rows[name] = {f"{int(w[0])}-{int(w[1])}": window_stats(errors[0], truth.t, truth.state, w) for w in WINDOWS}
        runs0[name] = SimulationResult(t=truth.t, x=truth.x[:1], xhat=hist.xhat[:1], u=truth.u[:1], y=truth.y[:1], P=None,
                                       settings=dict(truth.settings, filter=name), state=truth.state,
                                       diagnostics={k: v[:1] for k, v in hist.diagnostics.items() if k == "input_estimate"})
        sweeps[sweep_key] = [{"value": float(v), **{f"{int(w[0])}-{int(w[1])}": window_stats(err, small.t, small.state, w)
                                                    for w in WINDOWS}} for v, err in zip(values, errors[1:])]
    settings = {"runs": runs, "sweep_runs": sweep_runs, "seed": seed, "Q_thrust_N2_per_s": Q_THRUST,
                "Q_thrust_base_N2_per_s": Q_THRUST_BASE, "epsilon_s_per_N": THRUST_EPSILON, "window_steps": THRUST_MEMORY_STEPS,
                "P0_thrust_std_N": P0_THRUST_STD, "windows_s": [list(w) for w in WINDOWS]}
    return ChaserStudy(rows=rows, sweeps=sweeps, runs0=runs0, settings=settings)


def _first_run(res):
    keep = {k: v[:1] for k, v in res.diagnostics.items() if k == "input_estimate"}
    return type(res)(t=res.t, x=res.x[:1], xhat=res.xhat[:1], u=res.u[:1], y=res.y[:1], P=None,
                     settings=res.settings, state=res.state, diagnostics=keep)


def format_chaser_table(study):
    """A text table: position and velocity RMS (mean over runs, 95 % interval) in both windows."""
    lines = [f"{'filter':31}{'0-500 s pos (m)':>27}{'vel (m/s)':>27}{'500-1000 s pos (m)':>27}{'vel (m/s)':>27}"]
    for name, row in study.rows.items():
        cells = []
        for w in ("0-500", "500-1000"):
            for key in ("pos_m", "vel_mps"):
                lo, hi = row[w][key + "_ci95"]
                cells.append(f"{row[w][key + '_mean']:.4g} [{format_interval(lo, hi, sep=', ')}]")
        lines.append(f"{name:31}" + "".join(f"{c:>27}" for c in cells))
    return "\n".join(lines)


_STYLE = {
    "ekf": dict(color="0.6", lw=0.8, label="EKF, thrust unknown (Sun 2011)"),
    "ekf_known_input": dict(color="k", lw=0.6, label="EKF told the thrust"),
    "ekf_augmented_thrust": dict(color="C0", lw=0.7, label="thrust augmented (AEKF)"),
    "ekf_augmented_thrust_st": dict(color="C3", lw=0.7, label="… strong tracking (ASTEKF)"),
    "ekf_augmented_thrust_adaptive": dict(color="C2", lw=0.7, label="… adaptive noise (AAEKF)"),
}


def plot_chaser(study, *, axes=None, moving_rms_s=10.0):
    """Fig 4 with the ideas added: per-axis position and velocity errors of run 0, every filter.

    Each curve is the moving RMS of the error over the last ``moving_rms_s`` seconds (log scale),
    so that the unaware EKF's metres and the others' centimetres show
    together and the noisy curves do not hide each other.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if axes is None:
        fig, axes = new_figure(2, 3, figsize=(13, 6.2), sharex=True)
    else:
        fig = axes[0, 0].figure
    any_res = next(iter(study.runs0.values()))
    state = any_res.state
    dt = float(any_res.t[1] - any_res.t[0])
    w = max(1, int(round(moving_rms_s / dt)))
    kernel = np.ones(w) / w
    for name, res in study.runs0.items():
        err = res.error[0]
        for row, grp in enumerate(("position", "velocity")):
            for col, i in enumerate(state.indices(grp)):
                mrms = np.sqrt(np.convolve(err[:, i] ** 2, kernel, mode="same"))
                style = {k: v for k, v in _STYLE[name].items() if not (row or col) or k != "label"}
                axes[row, col].semilogy(res.t[::5], mrms[::5], **dict(style, lw=1.0))
    for row, grp in enumerate(("position", "velocity")):
        for col, i in enumerate(state.indices(grp)):
            ax = axes[row, col]
            ax.axvline(500.0, color="k", ls=":", lw=0.8, label="t = 500 s" if row == col == 0 else None)
            ax.set_xlabel("time t (s)")
            ax.set_ylabel(f"{moving_rms_s:g}-s RMS of Δ{state.labels[i]} ({state.units[i]})")
            ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=7)
    fig.suptitle("Sun 2011's maneuver, control law unknown: paper 002's ideas on the chaser (run 0)")
    return fig


def plot_thrust_estimates(study, *, axes=None, t_max=600.0):
    """The thrust estimate of each augmented filter against the true thrust u = K x (run 0), N."""
    if axes is None:
        fig, axes = new_figure(3, 1, figsize=(10, 7.5), sharex=True)
    else:
        fig = axes[0, 0].figure
    res = study.runs0["ekf"]
    m = res.t <= t_max
    for k, ax in enumerate(axes[:, 0]):
        ax.plot(res.t[m], res.u[0, m, k], color="k", lw=1.2, label="true thrust u = K x")
        for name, r in study.runs0.items():
            if "input_estimate" in r.diagnostics:
                ax.plot(r.t[m], r.diagnostics["input_estimate"][0, m, k], lw=0.6, color=_STYLE[name]["color"],
                        label=_STYLE[name]["label"])
        ax.set_ylabel(f"F_{'xyz'[k]} (N)")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time t (s)")
    axes[0, 0].legend(loc="upper right", fontsize=7)
    fig.suptitle("Thrust estimated as a random-walk state (run 0)")
    return fig


def format_sweeps(study):
    """The three parameter sweeps as text: position and velocity RMS (pooled) in both windows."""
    names = {"q_plain": "augmented EKF over Q_F (N^2/s)", "beta_st": "strong tracking over beta (Q_F = 10)",
             "epsilon_adaptive": "adaptive over epsilon (s/N)"}
    lines = []
    for key, rows in study.sweeps.items():
        lines.append(f"{names[key]}:  {'value':>8}  0-500 s pos (m), vel (m/s)   500-1000 s pos (m), vel (m/s)")
        for r in rows:
            a, b = r["0-500"], r["500-1000"]
            lines.append(f"{'':{len(names[key]) + 3}}{r['value']:8.3g}  {a['pos_m']:14.4f}{a['vel_mps']:12.4f}"
                         f"{b['pos_m']:20.4f}{b['vel_mps']:12.4f}")
    return "\n".join(lines)
