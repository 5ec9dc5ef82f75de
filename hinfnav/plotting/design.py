"""Plots of robust H∞ filter designs (Theorem 1 / Corollary 1).

Every function takes ``ax=`` (or ``axes=``) and returns the artists it drew;
none touches global matplotlib state (make figures with
:func:`hinfnav.plotting.new_figure`).

Units: the error system (13)–(15) maps unit-intensity noise τ = [w; v]
(dimensionless) to the estimation error e = z − z_f (m for the position
components, m/s for the velocity components), so its gains and γ are in
"m or m/s per unit noise". Frequencies are in rad/s (sampling time T = 0.1 s
in the paper's scenario: Nyquist frequency π/T ≈ 31.4 rad/s).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.colors import SymLogNorm
from numpy.typing import ArrayLike

from ..analysis.norms import frequency_grid, frequency_response_sigma
from ..core.exceptions import InputError

if TYPE_CHECKING:
    import control
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes

    from ..design.result import DesignResult

__all__ = [
    "plot_gamma_curve",
    "plot_sigma",
    "plot_worst_case_over_delta",
    "plot_filter_matrices",
]


def plot_gamma_curve(sweep: Any, *, ax: Axes, sampled: bool = True, linthresh: float = 0.01) -> list[Artist]:
    """γ*(δ̄): certified level against the uncertainty bound.

    Parameters
    ----------
    sweep : hinfnav.synthesis.GammaSweep
    ax : matplotlib.axes.Axes
    sampled : bool, optional
        Also draw the worst sampled H∞ norm over the δ grid (a lower bound
        of the true worst case).
    linthresh : float, optional
        Linear range of the symmetric-log δ̄ axis (δ̄ = 0 is on the axis).

    Returns
    -------
    list of matplotlib artists
    """
    db = np.asarray(sweep.delta_bars, dtype=float)
    order = np.argsort(db)
    db = db[order]
    artists = ax.plot(db, sweep.gammas[order], "o-", color="C0", label="certified γ* (LMI (20), Corollary 1)")
    if sampled:
        artists += ax.plot(
            db, sweep.verified_norms[order], "s--", mfc="none", color="C1", label="worst sampled ‖Ψ‖∞ over |δ| ≤ δ̄"
        )
    ax.set_xscale("symlog", linthresh=linthresh)
    ax.set_xlabel("uncertainty bound δ̄ (–)")
    ax.set_ylabel("γ (m or m/s per unit noise)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best")
    return artists


def plot_sigma(sys: control.StateSpace, *, ax: Axes, label: str | None = None, omega: ArrayLike | None = None,
               all_values: bool = False, gamma: float | None = None, nyquist: bool = True, **line_kw: Any) -> list[Artist]:
    """Singular values of an error system Ψ(e^{jωT}) against frequency.

    Parameters
    ----------
    sys : control.StateSpace
        Discrete error system (e.g. :meth:`DesignResult.error_system`).
    ax : matplotlib.axes.Axes
    label : str, optional
    omega : array_like, optional
        Frequencies, rad/s; default :func:`hinfnav.hinfnorm.frequency_grid`.
    all_values : bool, optional
        Draw every singular value (thin lines) instead of the largest.
    gamma : float, optional
        Draw this level as a dashed horizontal line.
    nyquist : bool, optional
        Mark the Nyquist frequency π/T.
    **line_kw
        Passed to ``ax.loglog``.

    Returns
    -------
    list of matplotlib artists
    """
    omega = frequency_grid(sys, 1500) if omega is None else np.asarray(omega, dtype=float)
    omega = omega[omega > 0]
    sig = frequency_response_sigma(sys, omega, all_values=all_values)
    if all_values:
        artists = ax.loglog(omega, sig[:, 0], label=label, **line_kw)
        color = artists[0].get_color()
        artists += ax.loglog(omega, sig[:, 1:], lw=0.6, alpha=0.5, color=color)
    else:
        artists = ax.loglog(omega, sig, label=label, **line_kw)
    if gamma is not None:
        artists.append(ax.axhline(gamma, ls="--", lw=0.8, color=artists[0].get_color(), label=f"γ = {gamma:.4g}"))
    if nyquist and sys.dt not in (True, None):
        artists.append(ax.axvline(np.pi / sys.dt, color="0.5", lw=0.8, ls=":", label="Nyquist π/T"))
    ax.set_xlabel("frequency ω (rad/s)")
    ax.set_ylabel(r"$\sigma(\Psi(e^{j\omega T}))$ (m or m/s per unit noise)")
    ax.grid(True, which="both", alpha=0.3)
    if label is not None:
        ax.legend(loc="best")
    return artists


def plot_worst_case_over_delta(result: DesignResult, *, ax: Axes, label: str | None = None,
                               **line_kw: Any) -> list[Artist]:
    """H∞ norm of the error system at each δ of the certification grid.

    Parameters
    ----------
    result : hinfnav.design.DesignResult
        From :func:`hinfnav.synthesis.design_for_scenario` (``deltas`` set).
    ax : matplotlib.axes.Axes
    label : str, optional

    Returns
    -------
    list of matplotlib artists
    """
    if result.sample_values is None:
        raise InputError("result must come from design_for_scenario (it has no δ grid)")
    artists = ax.plot(result.sample_values, result.sample_norms, "o-", ms=3, label=label or "‖Ψ‖∞ at δ", **line_kw)
    color = artists[0].get_color()
    artists.append(ax.axhline(result.gamma, ls="--", color=color, lw=0.8, label=f"certified γ = {result.gamma:.6g}"))
    k = result.worst_sample
    artists += ax.plot([result.sample_values[k]], [result.sample_norms[k]], "k*", ms=9,
                       label=f"worst δ = {result.sample_values[k]:.3g}")
    ax.set_xlabel("orbital-rate error δ (–)")
    ax.set_ylabel("‖Ψ‖∞ (m or m/s per unit noise)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    return artists


def plot_filter_matrices(A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike, *, axes: Sequence[Axes],
                         linthresh: float = 1e-4, colorbar: bool = True) -> list[Artist]:
    """Heat maps of the filter matrices (12) on a symmetric-log colour scale.

    Parameters
    ----------
    A_F, B_F, C_F : array_like
    axes : sequence of 3 matplotlib.axes.Axes
    linthresh : float, optional
        Entries below this magnitude are on the linear part of the scale.
    colorbar : bool, optional
        Add a colour bar to each panel (through ``ax.figure``).

    Returns
    -------
    list of matplotlib artists
        The three images (and colour bars).
    """
    mats = {"A_F": np.asarray(A_F, float), "B_F": np.asarray(B_F, float), "C_F": np.asarray(C_F, float)}
    axes = list(np.ravel(axes))
    if len(axes) != 3:
        raise InputError(f"axes must hold 3 axes (A_F, B_F, C_F); got {len(axes)}")
    vmax = max(np.max(np.abs(M)) for M in mats.values())
    norm = SymLogNorm(linthresh=linthresh, vmin=-vmax, vmax=vmax)
    artists = []
    for ax, (name, M) in zip(axes, mats.items()):
        im = ax.imshow(M, cmap="RdBu_r", norm=norm)
        artists.append(im)
        ax.set_title(name)
        ax.set_xlabel("column")
        ax.set_ylabel("row")
        ax.set_xticks(range(M.shape[1]))
        ax.set_yticks(range(M.shape[0]))
        if colorbar:
            artists.append(ax.figure.colorbar(im, ax=ax, shrink=0.8))
    return artists
