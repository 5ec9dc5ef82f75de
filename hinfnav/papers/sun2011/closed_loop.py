"""The question Sun et al. (2011) leave open: does the orbit maneuver still work when the
feedback law acts on the *estimate*, u = K x̂, instead of the true state?

The paper's chaser applies u = K x with the true relative state (3); a real
chaser only has its navigation filter's estimate. :func:`closed_loop_study`
closes the loop through three filters — the published H∞ filter, the robust
filter designed here in observer form, and the EKF that knows the applied
thrust — beside the idealized u = K x, on the same noise (same seed, same
child generators), and reports for each:

* whether the maneuver converges: the final distance to the target
  ``|r(t_end)|`` and the time after which ``|r|`` stays below ``arrive_m``;
* the thrust: peak ``|F|`` (N), the velocity change ``∫|F|/m dt`` (m/s) and the
  RMS thrust once the maneuver is over (the last 40 % of the run, N), which
  is where navigation noise fed through K shows;
* the navigation error: per-axis RMS of x − x̂ over the scenario's window.
"""

from dataclasses import dataclass, field

import numpy as np

from ...metrics.errors import convergence_time, rms_error
from ...plotting.errors import new_figure
from ...sim.closed_loop import simulate_closed_loop
from .designs import design_for_scenario
from .filters import lti_from_matrices, make_estimator
from .scenario import Scenario

__all__ = ["ClosedLoopStudy", "closed_loop_study", "format_closed_loop", "plot_closed_loop"]

#: Filters closing the loop: key -> label.
CLOSED_LOOP_FILTERS = {
    "truth": "u = K x (the paper's idealized loop; navigation by the published filter)",
    "published": "u = K x̂, published H∞ filter",
    "designed_observer": "u = K x̂, robust H∞ filter in observer form (designed here)",
    "ekf_known_input": "u = K x̂, EKF told the applied thrust",
}


@dataclass(frozen=True, eq=False)
class ClosedLoopStudy:
    """Closed-loop results per filter.

    Attributes
    ----------
    rows : list of dict
        One per key of :data:`CLOSED_LOOP_FILTERS`: ``key``, ``label``,
        ``final_range_m`` (mean over runs), ``arrival_s`` (mean time after
        which ``|r| < arrive_m``, NaN if a run never arrives), ``arrived``
        (fraction of runs), ``peak_thrust_N``, ``delta_v_mps``,
        ``pos_rms_m`` (3,), ``vel_rms_mps`` (3,).
    results : dict
        key -> SimulationResult.
    settings : dict
    """

    rows: list
    results: dict
    settings: dict = field(default_factory=dict)


def closed_loop_study(scenario=None, *, runs=20, seed=0, noise="gaussian", designed=None, arrive_m=5.0, progress=False):
    """Run the maneuver with u = K x̂ through each filter, beside u = K x.

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    runs : int
    seed : int
    noise : str
    designed : DesignResult, optional
        The observer-form design at the scenario's δ̄ (designed here when None).
    arrive_m : float
        Range below which the chaser counts as arrived, m (default 5 m: the
        process noise alone keeps the ideal loop at about 1.5 m RMS).
    progress : bool

    Returns
    -------
    ClosedLoopStudy
    """
    scenario = Scenario() if scenario is None else scenario
    if designed is None:
        designed = design_for_scenario(scenario, form="observer")
    estimators = {
        "truth": make_estimator(scenario, "published"),
        "published": make_estimator(scenario, "published"),
        "designed_observer": lti_from_matrices(scenario, designed.A_F, designed.B_F, designed.C_F,
                                               name="designed_observer"),
        "ekf_known_input": make_estimator(scenario, "ekf_known_input"),
    }
    rows, results = [], {}
    for key, est in estimators.items():
        controller = scenario.controller(True, source="truth" if key == "truth" else "estimate")
        res = simulate_closed_loop(scenario, est, controller, runs=runs, seed=seed, noise=noise, progress=progress)
        results[key] = res
        r = np.linalg.norm(res.state.select(res.x, "position"), axis=-1)
        thrust = np.linalg.norm(res.u, axis=-1)
        arrival = convergence_time(r[..., None], res.t, arrive_m, nonfinite="outside")  # first t after which |r| <= arrive_m
        comp = rms_error(res.error, res.t, scenario.rms_window_s)
        rows.append({
            "key": key,
            "label": CLOSED_LOOP_FILTERS[key],
            "final_range_m": float(np.mean(r[:, -1])),
            "arrival_s": float(np.mean(arrival)) if np.all(np.isfinite(arrival)) else float("nan"),
            "arrived": float(np.mean(np.isfinite(arrival))),
            "peak_thrust_N": float(np.max(thrust)),
            "delta_v_mps": float(np.mean(np.sum(thrust[:, :-1], axis=1) * scenario.dt / scenario.mass)),
            "late_thrust_rms_N": float(np.sqrt(np.mean(thrust[:, res.t >= 0.6 * res.t[-1]] ** 2))),
            "pos_rms_m": res.state.select(comp, "position"),
            "vel_rms_mps": res.state.select(comp, "velocity"),
        })
    settings = {"runs": runs, "seed": seed, "noise": noise, "arrive_m": arrive_m, "window_s": list(scenario.rms_window_s),
                "designed_gamma": float(designed.gamma)}
    return ClosedLoopStudy(rows=rows, results=results, settings=settings)


def format_closed_loop(study):
    """The study's rows as a table of at most 100 columns."""
    head = (f"{'loop':24}{'final |r| m':>12}{'arrive s':>10}{'peak F N':>10}{'dv m/s':>8}{'late F N':>10}"
            f"{'pos m':>8}{'vel m/s':>9}")
    lines = [head, "-" * len(head)]
    names = {"truth": "u = K x (true state)", "published": "K x̂, published H∞",
             "designed_observer": "K x̂, observer-form H∞", "ekf_known_input": "K x̂, EKF (knows u)"}
    for r in study.rows:
        pos = float(np.sqrt(np.mean(np.square(r["pos_rms_m"]))))
        vel = float(np.sqrt(np.mean(np.square(r["vel_rms_mps"]))))
        lines.append(f"{names[r['key']]:24}{r['final_range_m']:12.3g}{r['arrival_s']:10.1f}{r['peak_thrust_N']:10.0f}"
                     f"{r['delta_v_mps']:8.1f}{r['late_thrust_rms_N']:10.2f}{pos:8.3f}{vel:9.3f}")
    return "\n".join(lines)


def plot_closed_loop(study, *, axes=None, run=0):
    """Range to the target, thrust and position-error norm against time, one line per loop.

    Parameters
    ----------
    study : ClosedLoopStudy
    axes : sequence of 3 Axes, optional
        New figure when None.
    run : int

    Returns
    -------
    matplotlib.figure.Figure
    """
    if axes is None:
        fig, grid = new_figure(1, 3, figsize=(12, 3.6))
        axes = grid[0]
    fig = axes[0].figure
    for i, res in enumerate(study.results.values()):
        label = study.rows[i]["label"].split(", ", 1)[-1]  # drop "u = K x̂, " (x̂ is two code points)
        r = np.linalg.norm(res.state.select(res.x[run], "position"), axis=-1)
        axes[0].semilogy(res.t, np.maximum(r, 1e-3), lw=1, label=label)
        axes[1].plot(res.t, np.linalg.norm(res.u[run], axis=-1), lw=1, label=label)
        e = np.linalg.norm(res.state.select(res.error[run], "position"), axis=-1)
        axes[2].semilogy(res.t, np.maximum(e, 1e-4), lw=0.6, label=label)
    axes[0].set_ylabel("range to target |r| (m)")
    axes[1].set_ylabel("thrust |F| (N)")
    axes[2].set_ylabel("position error |x − x̂| (m)")
    for ax in axes:
        ax.set_xlabel("time t (s)")
        ax.grid(True, alpha=0.3)
    axes[1].set_xlim(0, 200)
    axes[0].legend(loc="upper right", fontsize=7)
    return fig
