"""Figs 2–7 of Sun et al. (2011), reproduced: one function per figure, each returning a Figure."""

import numpy as np

from ...plotting.errors import new_figure, plot_errors, plot_inputs
from ...sim.montecarlo import run_estimator, simulate
from ...sim.truth import simulate_truth
from .filters import make_estimator
from .scenario import Scenario

__all__ = ["figure_errors", "paper_runs", "fig2", "fig3", "fig4", "fig5", "fig6", "fig7", "fig7_result", "plot_thrust"]


def plot_thrust(result, *, ax, run=0):
    """Thrust components u = K x (N) of one run against time (Fig 6)."""
    artists = plot_inputs(result, ax=ax, run=run, labels=("F_x", "F_y", "F_z"), unit="N")
    ax.set_ylabel("thrust (N)")
    return artists



def figure_errors(result, title, *, run=0, t_zoom_from=5.0):
    """Per-axis position and velocity errors of one run (the layout of Figs 2–5, 7).

    The y limits leave out the first ``t_zoom_from`` seconds (the 30–40 m
    initial error), as the paper's figures do.

    Returns
    -------
    matplotlib.figure.Figure
    """
    state = result.state
    fig, axes = new_figure(len(state.groups), max(len(i) for i in state.groups.values()), figsize=(12, 5.5))
    m = result.t >= t_zoom_from
    err = result.error[run][m]
    lim = lambda a: 1.15 * max(np.max(np.abs(a)), 1e-6)  # noqa: E731
    ylims = {g: (-lim(state.select(err, g)), lim(state.select(err, g))) for g in state.groups}
    plot_errors(result, axes=axes, run=run, ylims=ylims, title=title)
    return fig


def paper_runs(scenario=None, *, seed=0, progress=False):
    """The single runs behind Figs 2–6: each filter with and without maneuver.

    Returns
    -------
    dict
        ``{(filter_key, maneuver): SimulationResult}`` for filter keys
        ``ekf``, ``ekf_known_input``, ``hinf_published``.
    """
    scenario = Scenario() if scenario is None else scenario
    out = {}
    for maneuver in (False, True):
        truth = simulate_truth(scenario.truth_model(maneuver=maneuver), runs=1, seed=seed)
        for key, name in (("ekf", "ekf"), ("ekf_known_input", "ekf_known_input"), ("hinf_published", "published")):
            out[(key, maneuver)] = run_estimator(make_estimator(name, scenario), truth, scenario.xhat0)
    return out


def fig2(runs):
    """Fig 2: EKF errors without maneuver."""
    return figure_errors(runs[("ekf", False)], "Fig 2 — EKF, no orbit maneuver: position (m) and velocity (m/s) errors")


def fig3(runs):
    """Fig 3: robust H∞ filter (published matrices) errors without maneuver."""
    return figure_errors(runs[("hinf_published", False)], "Fig 3 — robust H∞ filter (published), no orbit maneuver")


def fig4(runs):
    """Fig 4: EKF errors with maneuver; the paper's variant (control law unknown)
    in colour, the variant that knows the thrust in grey."""
    res = runs[("ekf", True)]
    fig = figure_errors(res, "Fig 4 — EKF with orbit maneuver: control law unknown (colour) vs known thrust (grey)")
    known = runs[("ekf_known_input", True)]
    for i, ax in enumerate(fig.axes[:6]):
        ax.plot(known.t, known.error[0, :, i], color="0.45", lw=0.6, zorder=3)
        ax.axvline(500.0, color="k", ls=":", lw=0.8)
    return fig


def fig5(runs):
    """Fig 5: robust H∞ filter (published matrices) errors with maneuver."""
    return figure_errors(runs[("hinf_published", True)], "Fig 5 — robust H∞ filter (published), with orbit maneuver")


def fig6(runs):
    """Fig 6: the chaser's thrust u = K x with maneuver."""
    fig, axes = new_figure(1, 1, figsize=(7, 3.6))
    plot_thrust(runs[("hinf_published", True)], ax=axes[0, 0])
    axes[0, 0].set_title("Fig 6 — orbit thrust of the chaser, u = K x")
    return fig


def fig7_result(scenario=None, *, seed=0, delta=1.0, noise="mixture"):
    """The run behind Fig 7: published H∞ filter, δ = 1, non-Gaussian noise, with maneuver."""
    scenario = Scenario() if scenario is None else scenario
    return simulate(scenario, "published", maneuver=True, delta=delta, noise=noise, runs=1, seed=seed)


def fig7(result):
    """Fig 7: robust H∞ filter with δ = 1 and non-Gaussian (Gaussian-mixture) noise."""
    d = result.settings["delta"]
    return figure_errors(result, f"Fig 7 — robust H∞ filter (published), δ = {d:g}, {result.settings['noise']} noise, with maneuver")


