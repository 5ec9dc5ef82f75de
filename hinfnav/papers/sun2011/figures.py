"""Figs 2–7 of Sun et al. (2011), reproduced: one function per figure, each returning a Figure."""

import textwrap

import numpy as np

from ...core.exceptions import InputError
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



#: Figure sizes (width, height) in inches: a journal column, a full page width, and the screen default.
FIGURE_SIZES = {"single": (3.5, 3.2), "double": (7.0, 4.2), "default": (12.0, 5.5)}
_FONT = {"single": 6.5, "double": 8.0, "default": None}


def _fonts(fig, size):
    """Readable fonts at a journal size (set on the artists: no global matplotlib state)."""
    pt = _FONT[size]
    if pt is None:
        return
    for ax in fig.axes:
        ax.tick_params(labelsize=pt)
        ax.xaxis.label.set_size(pt)
        ax.yaxis.label.set_size(pt)
        ax.title.set_size(pt)
        if ax.get_legend() is not None:
            for t in ax.get_legend().get_texts():
                t.set_size(pt)
    for t in fig.texts:
        t.set_size(pt - 1)
    if fig._suptitle is not None:
        fig._suptitle.set_size(pt + 0.5)
        fig._suptitle.set_text(textwrap.fill(fig._suptitle.get_text(), 48 if size == "single" else 100))
    main = [ax for ax in fig.axes if ax.get_label() != "inset"]
    grid = np.asarray(main).reshape(2, -1) if len(main) % 2 == 0 else None
    if grid is not None:
        for ax in grid[0]:
            ax.set_xlabel("")


def figure_errors(result, title, *, run=0, t_zoom_from=5.0, size="default", inset=True):
    """Per-axis position and velocity errors of one run (the layout of Figs 2–5, 7).

    The y limits leave out the first ``t_zoom_from`` seconds (the 30–40 m
    initial error), as the paper's figures do; a note under the figure says
    what was clipped, and (``inset``, not at the single-column size) an inset
    in the upper part of each panel shows those first seconds (to twice
    ``t_zoom_from``) on their own y scale, where the paper claims the fast
    convergence.

    Parameters
    ----------
    result : SimulationResult
    title : str
    run : int
    t_zoom_from : float
        Seconds left out of the y limits, s.
    size : {"default", "single", "double"}
        12 × 5.5 in (screen), 3.5 in (one journal column) or 7 in (full width).
    inset : bool
        Draw the inset of the first seconds.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if size not in FIGURE_SIZES:
        raise InputError(f"size must be one of {', '.join(FIGURE_SIZES)}; got {size!r}")
    state = result.state
    fig, axes = new_figure(len(state.groups), max(len(i) for i in state.groups.values()), figsize=FIGURE_SIZES[size])
    m = result.t >= t_zoom_from
    err = result.error[run][m]
    lim = lambda a: 1.15 * max(np.max(np.abs(a)), 1e-6)
    inset = bool(inset) and size != "single" and t_zoom_from > result.t[0]
    top = 2.8 if inset else 1.0  # room above the error band for the inset
    ylims = {g: (-lim(state.select(err, g)), top * lim(state.select(err, g))) for g in state.groups}
    plot_errors(result, axes=axes, run=run, ylims=ylims, title=title)
    if inset:
        early = result.t <= 2 * t_zoom_from
        for i, ax in enumerate(fig.axes[:state.n]):
            ins = ax.inset_axes([0.42, 0.6, 0.55, 0.37])
            ins.set_label("inset")
            ins.plot(result.t[early], result.error[run][early, i], lw=0.8)
            ins.axvline(t_zoom_from, color="0.5", ls=":", lw=0.7, label=f"t = {t_zoom_from:g} s (end of the clip)")
            ins.axhline(0.0, color="0.7", lw=0.5, label="zero error")
            ins.tick_params(labelsize=6)
            ins.set_title(f"first {2 * t_zoom_from:g} s", fontsize=6, pad=3)
    if t_zoom_from > result.t[0]:
        early = result.error[run][~m]
        peak = {g: float(np.max(np.abs(state.select(early, g)))) for g in state.groups}
        clipped = ", ".join(f"{g} up to {peak[g]:.3g} {state.group_unit(g)}" for g in state.groups)
        note = (f"y axes clipped: the first {t_zoom_from:g} s (initial error: {clipped}) lie outside"
                + (" (the insets show them)" if inset else ""))
        wrapped = textwrap.fill(note, 70 if size == "single" else 160)
        txt = fig.text(0.01, 0.005, wrapped, fontsize=7, color="0.35", ha="left", va="bottom")
        txt.set_in_layout(False)
        bottom = 0.03 * (1 + wrapped.count("\n")) * (2 if size == "single" else 1)
        fig.get_layout_engine().set(rect=(0, bottom, 1, 1 - bottom))  # (left, bottom, width, height)
    _fonts(fig, size)
    return fig


def paper_runs(scenario=None, *, seed=0):
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
            out[(key, maneuver)] = run_estimator(make_estimator(scenario, name), truth, scenario.xhat0)
    return out


def fig2(runs, size="default"):
    """Fig 2: EKF errors without maneuver."""
    return figure_errors(runs[("ekf", False)], "Fig 2 — EKF, no orbit maneuver: position (m) and velocity (m/s) errors", size=size)


def fig3(runs, size="default"):
    """Fig 3: robust H∞ filter (published matrices) errors without maneuver."""
    return figure_errors(runs[("hinf_published", False)], "Fig 3 — robust H∞ filter (published), no orbit maneuver", size=size)


def fig4(runs, size="default"):
    """Fig 4: EKF errors with maneuver; the paper's variant (control law unknown)
    in colour, the variant that knows the thrust in grey; the dotted line at
    500 s marks where the thrust has died away (Fig 6)."""
    res = runs[("ekf", True)]
    fig = figure_errors(res, "Fig 4 — EKF with orbit maneuver: control law unknown (colour) vs known thrust (grey)",
                        size=size)
    known = runs[("ekf_known_input", True)]
    for i, ax in enumerate(fig.axes[:6]):
        ax.plot(known.t, known.error[0, :, i], color="0.45", lw=0.6, zorder=3)
        ax.axvline(500.0, color="k", ls=":", lw=0.8, label="t = 500 s: thrust ≈ 0")
    ax0 = fig.axes[0]
    ann = ax0.annotate("500 s" if size == "single" else "t = 500 s: thrust ≈ 0", xy=(500.0, 0.97), xycoords=("data", "axes fraction"), xytext=(3, 0),
                       textcoords="offset points", fontsize=6 if size == "single" else 8, va="top", ha="left")
    ann.set_in_layout(False)
    return fig


def fig5(runs, size="default"):
    """Fig 5: robust H∞ filter (published matrices) errors with maneuver."""
    return figure_errors(runs[("hinf_published", True)], "Fig 5 — robust H∞ filter (published), with orbit maneuver", size=size)


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


def fig7(result, size="default"):
    """Fig 7: robust H∞ filter with δ = 1 and non-Gaussian (Gaussian-mixture) noise."""
    d = result.settings["delta"]
    return figure_errors(result, f"Fig 7 — robust H∞ filter (published), δ = {d:g}, {result.settings['noise']} noise, "
                                 "with maneuver", size=size)


