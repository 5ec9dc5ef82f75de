"""Plots of simulation results. Each function takes ``ax=`` (or ``axes=``)
and returns the artists it drew; none touches global matplotlib state.

Error plots read the state's labels, units and groups from the result
(:class:`~hinfnav.systems.StateSpec`): one row per group (position,
velocity, …), one column per component.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..sim.montecarlo import SimulationResult

__all__ = ["new_figure", "plot_errors", "plot_error_axis", "plot_inputs", "plot_uncertainty_check"]


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize: tuple[float, float] | None = None,
               **kwargs: Any) -> tuple[Figure, Any]:
    """A figure and axes, from :class:`matplotlib.figure.Figure` (no pyplot state)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize or (4.0 * ncols + 1, 2.6 * nrows + 0.6), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes


def _run(result, run):
    if not 0 <= run < result.x.shape[0]:
        raise InputError(f"run must be in 0 .. {result.x.shape[0] - 1}; got {run}")
    return result.error[run]


def plot_error_axis(t: ArrayLike, err: ArrayLike, *, ax: Axes, label: str = "x", unit: str = "m",
                    band: float | None = None, **line_kw: Any) -> list[Artist]:
    """One error component against time.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    err : ndarray, shape (n,)
        Error, in ``unit``.
    ax : matplotlib.axes.Axes
    label : str
        Component name; the axis reads ``Δ<label> (<unit>)``.
    unit : str
    band : float, optional
        Draw ±band as dashed lines (e.g. a steady-state standard deviation).

    Returns
    -------
    list of matplotlib artists
    """
    artists = ax.plot(t, err, lw=0.6, **line_kw)
    if band is not None:
        artists += ax.plot([t[0], t[-1]], [band, band], "k--", lw=0.8)
        artists += ax.plot([t[0], t[-1]], [-band, -band], "k--", lw=0.8)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(f"Δ{label} ({unit})")
    ax.grid(True, alpha=0.3)
    return artists


def plot_errors(result: SimulationResult, *, axes: Any, run: int = 0, ylims: Mapping[str, Any] | None = None,
                title: str | None = None, bands: ArrayLike | None = None) -> list[Artist]:
    """Errors of one run, one row per state group and one column per component.

    Parameters
    ----------
    result : SimulationResult
        Carries ``state`` (labels, units, groups).
    axes : array of Axes, shape (groups, components per group)
        For the chaser: row 0 position x, y, z; row 1 velocity x, y, z.
    run : int
        Which Monte Carlo run to show.
    ylims : dict, optional
        Group name → (low, high) y limits.
    title : str, optional
        Put on the figure holding the axes.
    bands : ndarray, shape (n,), optional
        ±band lines per component (e.g. steady-state standard deviations).

    Returns
    -------
    list of matplotlib artists
    """
    state = result.state
    groups = list(state.groups.items())
    axes = np.asarray(axes)
    if axes.ndim != 2 or axes.shape[0] != len(groups) or any(len(idx) > axes.shape[1] for _, idx in groups):
        raise InputError(
            f"axes must be a grid with one row per state group ({len(groups)}: {', '.join(g for g, _ in groups)}) "
            f"and a column per component; got shape {axes.shape}"
        )
    err = _run(result, run)
    artists = []
    for row, (group, idx) in enumerate(groups):
        for col, i in enumerate(idx):
            band = None if bands is None else float(bands[i])
            ax = axes[row, col]
            artists += plot_error_axis(result.t, err[:, i], ax=ax, label=state.labels[i], unit=state.units[i], band=band)
            if ylims and group in ylims:
                ax.set_ylim(*ylims[group])
    if title:
        artists.append(axes[0, 0].figure.suptitle(title))
    return artists


def plot_inputs(result: SimulationResult, *, ax: Axes, run: int = 0, labels: Sequence[str] | None = None,
                unit: str = "") -> list[Artist]:
    """Input components of one run against time.

    Parameters
    ----------
    result : SimulationResult
    ax : matplotlib.axes.Axes
    run : int
    labels : sequence of str, optional
        One per input channel (default ``u_0``, ``u_1`` …).
    unit : str

    Returns
    -------
    list of matplotlib artists
    """
    if not 0 <= run < result.u.shape[0]:
        raise InputError(f"run must be in 0 .. {result.u.shape[0] - 1}; got {run}")
    m = result.u.shape[2]
    labels = labels or [f"u_{i}" for i in range(m)]
    artists = []
    for i, name in enumerate(labels):
        artists += ax.plot(result.t, result.u[run, :, i], lw=1.0, label=f"${name}$")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(f"input ({unit})" if unit else "input")
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    return artists


def plot_uncertainty_check(deltas: ArrayLike, gaps: ArrayLike, norms: ArrayLike, *, ax: Axes) -> list[Artist]:
    """Check of the norm-bounded structure (10)–(11) over δ.

    Parameters
    ----------
    deltas : ndarray
    gaps : ndarray
        ``max |ΔA₁(δ) − H_a F(δ) E_a|`` per δ (should be at round-off).
    norms : ndarray
        ``‖F(δ)‖₂`` per δ (should be ≤ 1).

    Returns
    -------
    list of matplotlib artists
    """
    artists = ax.plot(deltas, norms, label="‖F(δ)‖₂")
    artists += ax.plot(deltas, np.ones_like(deltas), "k--", lw=0.8, label="bound 1")
    ax.set_xlabel("δ (–)")
    ax.set_ylabel("‖F(δ)‖₂ (–)")
    twin = ax.twinx()
    artists += twin.semilogy(deltas, np.maximum(gaps, 1e-300), "C3:", label="|ΔA₁ − H F E|max")
    twin.set_ylabel("identity gap (1/s, 1/s²)")
    ax.legend(loc="lower center")
    ax.grid(True, alpha=0.3)
    return artists
