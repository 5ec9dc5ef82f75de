"""Analogues of Shi & Wang (2018)'s Figs 3–6, the mixture case, the maneuver reaction and the sweeps.

Figs 3–4: three-axis position and velocity errors under Gaussian sensor
errors (§3.1); Figs 5–6: the same with the target's maneuver (§3.3). The
paper's figures are lost (captions only); each analogue shows one run (run 0
of the Monte Carlo set) of the EKF and the HBF on the same truth. Every
function takes ``ax=``/``axes=`` or returns a figure from
:func:`hinfnav.plotting.new_figure` (no global matplotlib state).
"""

import numpy as np

from ...core.exceptions import InputError
from ...plotting.errors import new_figure, plot_error_axis
from .constants import MANEUVER_TIME_S, PAPER_RESULTS

__all__ = [
    "plot_case_errors",
    "errors_figure",
    "fig3",
    "fig4",
    "fig5",
    "fig6",
    "mixture_figures",
    "plot_maneuver_bias",
    "maneuver_figure",
    "sweeps_figure",
]

#: Line style per filter label.
FILTER_STYLE = {"ekf": {"color": "C0", "label": "EKF"}, "hbf": {"color": "C3", "label": "HBF"},
                "ekf_tuned": {"color": "C2", "label": "EKF told the mixture's variance"}}

_GROUPS = {"position": ((0, 1, 2), "m"), "velocity": ((3, 4, 5), "m/s")}
_AXES = ("x", "y", "z")


def plot_case_errors(result, group, *, axes, filters=("ekf", "hbf"), run_label=True):
    """One run's errors of each filter, one axis per component of ``group``.

    Parameters
    ----------
    result : CaseResult
    group : {"position", "velocity"}
    axes : sequence of 3 Axes
    filters : sequence of str
        Filter labels of ``result`` to draw (EKF first, so the HBF is on top).
    run_label : bool
        Put a legend on the first axis.

    Returns
    -------
    list of matplotlib artists
    """
    if group not in _GROUPS:
        raise InputError(f"group must be 'position' or 'velocity'; got {group!r}")
    axes = list(np.ravel(axes))
    if len(axes) != 3:
        raise InputError(f"axes must hold 3 axes (x, y, z); got {len(axes)}")
    idx, unit = _GROUPS[group]
    artists = []
    for name in filters:
        if name not in result.filters:
            raise InputError(f"filter {name!r} is not in this result; it has {', '.join(result.filters)}")
        style = FILTER_STYLE.get(name, {"label": name})
        for ax, i, axis in zip(axes, idx, _AXES):
            label = axis if group == "position" else f"v{axis}"  # plot_error_axis writes Δ<label>
            drawn = plot_error_axis(result.t, result.filters[name].single[:, i], ax=ax, label=label, unit=unit,
                                    color=style.get("color"))
            drawn[0].set_label(style["label"])
            artists += drawn
    if run_label:
        axes[0].legend(loc="upper right", fontsize="small")
    return artists


def errors_figure(result, group, title):
    """A 1 × 3 figure of :func:`plot_case_errors`."""
    fig, axes = new_figure(1, 3, figsize=(12, 3.4))
    plot_case_errors(result, group, axes=axes[0])
    fig.suptitle(title)
    return fig


def _numbers(summary, case, group):
    if summary is None:
        return ""
    key = "mc_mean_pos_m" if group == "position" else "mc_mean_vel_mps"
    unit = "m" if group == "position" else "m/s"
    s = summary[case]
    return f" — MC mean: EKF {s['ekf'][key]:.3g} {unit}, HBF {s['hbf'][key]:.3g} {unit}"


def fig3(gaussian, summary=None):
    """Fig 3 analogue: three-axis relative position errors, Gaussian sensor errors."""
    p = PAPER_RESULTS["gaussian"]
    return errors_figure(gaussian, "position", "Fig 3 analogue: position errors, Gaussian (run 0)"
                         f"{_numbers(summary, 'gaussian', 'position')}; paper EKF {p['ekf']['pos_m']} m, "
                         f"HBF {p['hbf']['pos_m']} m")


def fig4(gaussian, summary=None):
    """Fig 4 analogue: three-axis relative velocity errors, Gaussian sensor errors."""
    p = PAPER_RESULTS["gaussian"]
    return errors_figure(gaussian, "velocity", "Fig 4 analogue: velocity errors, Gaussian (run 0)"
                         f"{_numbers(summary, 'gaussian', 'velocity')}; paper EKF {p['ekf']['vel_mps']} m/s, "
                         f"HBF {p['hbf']['vel_mps']} m/s")


def _mark(fig, t):
    for ax in fig.axes:
        ax.axvline(t, color="k", lw=0.8, ls=":", label=f"t = {t:g} s")
    return fig


def _maneuver_figure(result, group, title, t_m, span=(-50.0, 250.0)):
    """Run 0 over the whole run (top) and, zoomed on the maneuver, the mean error over the runs (bottom):
    in one run the 0.1 m/s jump is buried in the noise, in the mean it shows."""
    fig, axes = new_figure(2, 3, figsize=(12, 6.2))
    plot_case_errors(result, group, axes=axes[0])
    idx, unit = _GROUPS[group]
    zoom = (result.t >= t_m + span[0]) & (result.t <= t_m + span[1])
    for name in ("ekf", "hbf"):
        style = FILTER_STYLE[name]
        for ax, i, axis in zip(axes[1], idx, _AXES):
            ax.plot(result.t[zoom], result.filters[name].mean_error[zoom, i], color=style["color"], lw=1.2,
                    label=f"{style['label']}, mean of {result.runs} runs")
            ax.set_xlabel("time t (s)")
            ax.set_ylabel(f"mean Δ{axis if group == 'position' else 'v' + axis} ({unit})")
    axes[1][0].legend(loc="upper right", fontsize="small")
    axes[1][1].set_title(f"zoom on the maneuver: mean error over the runs, {t_m + span[0]:g}-{t_m + span[1]:g} s",
                         fontsize="medium")
    fig.suptitle(title)
    return _mark(fig, t_m)


def fig5(maneuver, summary=None, maneuver_time_s=MANEUVER_TIME_S):
    """Fig 5 analogue: position errors with the target's maneuver (dotted line); below, a zoom on it (mean error)."""
    return _maneuver_figure(maneuver, "position", f"Fig 5 analogue: position errors, target maneuver at "
                            f"{maneuver_time_s:g} s (run 0){_numbers(summary, 'maneuver', 'position')}", maneuver_time_s)


def fig6(maneuver, summary=None, maneuver_time_s=MANEUVER_TIME_S):
    """Fig 6 analogue: velocity errors with the target's maneuver (dotted line); below, a zoom on it (mean error)."""
    return _maneuver_figure(maneuver, "velocity", f"Fig 6 analogue: velocity errors, target maneuver at "
                            f"{maneuver_time_s:g} s (run 0){_numbers(summary, 'maneuver', 'velocity')}", maneuver_time_s)


def mixture_figures(mixture, summary=None):
    """Position and velocity errors under the mixture (23) (§3.2 has no figure: Table 2 is lost)."""
    return (errors_figure(mixture, "position", "Mixture ε = 0.6, σ₂ = 2σ₁: position errors (run 0)"
                          f"{_numbers(summary, 'mixture', 'position')}"),
            errors_figure(mixture, "velocity", "Mixture ε = 0.6, σ₂ = 2σ₁: velocity errors (run 0)"
                          f"{_numbers(summary, 'mixture', 'velocity')}"))


def plot_maneuver_bias(scenario, result, *, axes, filters=("ekf", "hbf"), span_s=300.0):
    """Mean error over the runs (the bias) of x and vx around the maneuver: how fast each filter follows it.

    Parameters
    ----------
    result : CaseResult
        Of the ``maneuver`` case.
    scenario : Scenario
    axes : sequence of 2 Axes
    filters : sequence of str
    span_s : float
        Time shown after the maneuver, s.
    """
    axes = list(np.ravel(axes))
    if len(axes) != 2:
        raise InputError(f"axes must hold 2 axes (x and vx); got {len(axes)}")
    t = result.t
    m = (t >= scenario.maneuver_time_s - 50.0) & (t <= scenario.maneuver_time_s + span_s)
    artists = []
    for name in filters:
        style = FILTER_STYLE.get(name, {"label": name})
        for ax, i, label, unit in ((axes[0], 0, "mean Δx", "m"), (axes[1], 3, "mean Δvx", "m/s")):
            artists += ax.plot(t[m], result.filters[name].mean_error[m, i], color=style.get("color"), lw=1.0,
                               label=style["label"])
            ax.set_xlabel("time t (s)")
            ax.set_ylabel(f"{label} ({unit})")
            ax.grid(True, alpha=0.3)
    for ax in axes:
        artists.append(ax.axvline(scenario.maneuver_time_s, color="k", lw=0.8, ls=":", label="maneuver"))
    axes[1].axhline(float(scenario.maneuver_dv()[3]) / 2, color="k", lw=0.6, ls="--", label="half the maneuver Δv")
    axes[0].legend(loc="upper right", fontsize="small")
    return artists


def maneuver_figure(scenario, result):
    """The reaction to the maneuver, mean over the Monte Carlo runs."""
    fig, axes = new_figure(1, 2, figsize=(10, 3.4))
    plot_maneuver_bias(scenario, result, axes=axes[0])
    fig.suptitle(f"Target maneuver at {scenario.maneuver_time_s:g} s: bias over {result.runs} runs "
                 "(dashed: half the velocity change)")
    return fig


def plot_ratio_sweep(rows, key, *, ax, title=None, paper=True):
    """HBF/EKF ratios (Monte Carlo means) of a sweep, position and velocity, with the paper's ratios.

    Parameters
    ----------
    rows : list of dict
        From :func:`~hinfnav.papers.shi2018.sensitivity_sweep` or
        :func:`~hinfnav.papers.shi2018.mistuning_sweep`.
    key : {"variant", "c"}
    ax : Axes
    """
    labels = [str(r[key]) if key == "variant" else f"c = {r[key]:.3g}" for r in rows]
    pos = [r["hbf_minus_ekf"]["pos_ratio"] for r in rows]
    vel = [r["hbf_minus_ekf"]["vel_ratio"] for r in rows]
    x = np.arange(len(rows))
    artists = list(ax.bar(x - 0.2, pos, 0.4, label="position", color="C0"))
    artists += list(ax.bar(x + 0.2, vel, 0.4, label="velocity", color="C1"))
    artists.append(ax.axhline(1.0, color="k", lw=0.8, label="HBF = EKF"))
    if paper:
        p = PAPER_RESULTS["gaussian"]
        artists.append(ax.axhline(p["hbf"]["pos_m"] / p["ekf"]["pos_m"], color="C0", ls="--", lw=0.8,
                                  label="paper, position"))
        artists.append(ax.axhline(p["hbf"]["vel_mps"] / p["ekf"]["vel_mps"], color="C1", ls="--", lw=0.8,
                                  label="paper, velocity"))
    ax.set_xticks(x, labels, rotation=20, ha="right", fontsize="small")
    ax.set_ylabel("HBF / EKF error (–)")
    ax.grid(True, axis="y", alpha=0.3)
    # the legend in a band above the tallest bar, so that it covers none
    ax.set_ylim(0.0, 1.45 * max(1.0, max(pos + vel)))
    ax.legend(fontsize="small", loc="upper center", ncol=3)
    if title:
        ax.set_title(title, fontsize="medium")
    return artists


def sweeps_figure(sensitivity, mistuning):
    """Both sweeps side by side."""
    fig, axes = new_figure(1, 2, figsize=(12, 4.2))
    plot_ratio_sweep(sensitivity, "variant", ax=axes[0, 0], title="true sensor errors varied (filters told them)")
    plot_ratio_sweep(mistuning, "c", ax=axes[0, 1], title="filters told c × the true sensor errors")
    return fig
