"""Plots of simulation results. Each function takes ``ax=`` (or ``axes=``)
and returns the artists it drew; none touches global matplotlib state.

The paper's figures show the position error (m) and the velocity error (m/s)
per axis against time (s), and the thrust components (N).
"""

import numpy as np

from .exceptions import InputError

__all__ = ["new_figure", "plot_errors", "plot_error_axis", "plot_thrust", "plot_uncertainty_check"]

_AXES = ("x", "y", "z")


def new_figure(nrows=1, ncols=1, *, figsize=None, **kwargs):
    """A figure and axes, from :class:`matplotlib.figure.Figure` (no pyplot state)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize or (4.0 * ncols + 1, 2.6 * nrows + 0.6), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes


def _run(result, run):
    if not 0 <= run < result.x.shape[0]:
        raise InputError(f"run must be in 0 .. {result.x.shape[0] - 1}; got {run}")
    return result.error[run]


def plot_error_axis(t, err, *, ax, quantity="position", axis_name="x", band=None, **line_kw):
    """One error component against time.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    err : ndarray, shape (n,)
        Error, m or m/s.
    ax : matplotlib.axes.Axes
    quantity : {"position", "velocity"}
    axis_name : str
    band : float, optional
        Draw ±band as dashed lines (e.g. a steady-state standard deviation).

    Returns
    -------
    list of matplotlib artists
    """
    unit = "m" if quantity == "position" else "m/s"
    symbol = "Δ" + axis_name if quantity == "position" else "Δv" + axis_name
    artists = ax.plot(t, err, lw=0.6, **line_kw)
    if band is not None:
        artists += ax.plot([t[0], t[-1]], [band, band], "k--", lw=0.8)
        artists += ax.plot([t[0], t[-1]], [-band, -band], "k--", lw=0.8)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(f"{symbol} ({unit})")
    ax.grid(True, alpha=0.3)
    return artists


def plot_errors(result, *, axes, run=0, ylim_pos=None, ylim_vel=None, title=None, bands=None):
    """Per-axis position and velocity errors of one run, the paper's layout.

    Parameters
    ----------
    result : SimulationResult
    axes : array of Axes, shape (2, 3) or (6,)
        Row 0 position x, y, z; row 1 velocity x, y, z.
    run : int
        Which Monte Carlo run to show.
    ylim_pos, ylim_vel : (float, float), optional
        y limits (the paper zooms in on the steady state).
    title : str, optional
        Put on the figure holding the axes.
    bands : ndarray, shape (6,), optional
        ±band lines per component (e.g. steady-state standard deviations).

    Returns
    -------
    list of matplotlib artists
    """
    axes = np.asarray(axes).reshape(-1)
    if axes.size != 6:
        raise InputError(f"axes must hold 6 Axes (2 rows x 3 columns); got {axes.size}")
    err = _run(result, run)
    artists = []
    for i in range(6):
        quantity = "position" if i < 3 else "velocity"
        band = None if bands is None else float(bands[i])
        artists += plot_error_axis(result.t, err[:, i], ax=axes[i], quantity=quantity, axis_name=_AXES[i % 3], band=band)
        lim = ylim_pos if i < 3 else ylim_vel
        if lim is not None:
            axes[i].set_ylim(*lim)
    if title:
        artists.append(axes[0].figure.suptitle(title))
    return artists


def plot_thrust(result, *, ax, run=0):
    """Thrust components u = K x of one run against time (the paper's Fig 6).

    Returns
    -------
    list of matplotlib artists
    """
    if not 0 <= run < result.u.shape[0]:
        raise InputError(f"run must be in 0 .. {result.u.shape[0] - 1}; got {run}")
    artists = []
    for i, name in enumerate(("F_x", "F_y", "F_z")):
        artists += ax.plot(result.t, result.u[run, :, i], lw=1.0, label=f"${name}$")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("thrust (N)")
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    return artists


def plot_uncertainty_check(deltas, gaps, norms, *, ax):
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
