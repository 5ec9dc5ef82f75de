"""Analogues of Figs 5-12 of Yang et al. (2020). Plot functions take ``ax=``; ``figN`` builds a whole figure.

The paper's figures are lost (captions only); each analogue shows what its
caption and the text describe, on the x (pitch) axis unless stated:

* Fig 5 — accelerometer reading and the disturbance estimates L1, L2, L3 (drag-free loop open);
* Fig 6 — displacement and velocity errors of Algorithms 1 and 2;
* Fig 7 — disturbance estimates of Algorithms 1 and 2;
* Fig 8 — disturbance estimate of the fusion (Algorithm 3);
* Fig 9 — relative displacement under PID and ADRC with the periodic disturbance;
* Fig 10 — the steady state of φ_sc, r_rel, φ_rel under ADRC;
* Fig 11 — the attitude step and its effect on the relative attitude;
* Fig 12 — residual-acceleration ASD against the 3×10⁻¹⁴ m·s⁻²/√Hz requirement.
"""

import numpy as np
from scipy.stats import norm

from ...analysis.truncated import truncated_normal_moments
from ...plotting.errors import new_figure
from .constants import ACCELEROMETER_RANGE, REQUIREMENT_ASD, REQUIREMENT_BAND_HZ

__all__ = ["plot_series", "plot_asd", "plot_truncated_update", "fig5", "fig6", "fig7", "fig8", "fig9", "fig10", "fig11",
           "fig12"]

_COLORS = {"L1": "C0", "L2": "C2", "L3": "C3", "alg1": "C1", "fused": "C4", "truth": "k"}


def plot_series(t, y, *, ax, label=None, ylabel="", **kw):
    """One time series (t in s) on ``ax``; returns the artists."""
    artists = ax.plot(t, y, label=label, **{"lw": 0.7, **kw})
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    return artists


def plot_asd(f, asd, *, ax, label=None, requirement=True, **kw):
    """An amplitude spectral density (m·s⁻²/√Hz) against frequency (Hz), log-log, with the requirement band."""
    artists = ax.loglog(f[1:], asd[1:], lw=0.8, label=label, **kw)
    if requirement:
        lo, hi = REQUIREMENT_BAND_HZ
        artists += ax.loglog([lo, hi], [REQUIREMENT_ASD, REQUIREMENT_ASD], "k--", lw=1.2, label="3e-14 requirement")
        ax.axvspan(lo, hi, color="0.9", zorder=0, label="1-30 mHz band")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("ASD (m s$^{-2}$/$\\sqrt{\\mathrm{Hz}}$)")
    ax.grid(True, which="both", alpha=0.3)
    return artists


def plot_truncated_update(yhat, S_y, lower, upper, *, ax, reading="lower"):
    """The predicted normal N(ŷ⁻, S_y) of a reading, the range, and the truncated moments of (29)-(30).

    Parameters
    ----------
    yhat, S_y : float
        Predicted reading (m/s²) and its variance (27).
    lower, upper : float
        Sensor range (14).
    reading : {"lower", "upper"}
        Which bound the clipped reading sits at.

    Returns
    -------
    (float, float)
        The truncated mean and variance used by (33)-(34).
    """
    sd = np.sqrt(S_y)
    a, b = (-np.inf, lower) if reading == "lower" else (upper, np.inf)
    m, v = truncated_normal_moments(yhat, S_y, a, b)
    y = np.linspace(min(yhat - 4 * sd, lower - 2 * sd), max(yhat + 4 * sd, upper + 2 * sd), 600)
    pdf = norm.pdf(y, yhat, sd)
    ax.plot(y, pdf, "k", lw=1.0, label="predicted N(ŷ⁻, S$_y$)")
    mask = (y >= a) & (y <= b)
    side = "≤" if reading == "lower" else "≥"
    ax.fill_between(y, 0, pdf, where=mask, color="C0", alpha=0.3, label=f"reading {side} bound")
    for bound in (lower, upper):
        ax.axvline(bound, color="r", ls="--", lw=0.8, label="range ±6e-6 m/s²" if bound == lower else None)
    ax.axvline(yhat, color="k", ls=":", lw=0.8, label="ŷ⁻")
    ax.axvline(m, color="C0", lw=1.5, label=f"E[y | clipped] = {m:.3g}")
    ax.set_xlabel("accelerometer reading y (m/s$^2$)")
    ax.set_ylabel("density (s$^2$/m)")
    ax.legend(fontsize=8)
    return m, v


def _decimate(n, target=6000):
    return slice(None, None, max(1, n // target))


def _span(result, span_s):
    """``k0, k1, s, t``: sample indices of the time span ``span_s`` (s), clipped to the run, the plot's
    decimation ``s`` and the decimated times ``t`` (s) of the span."""
    k0, k1 = (int(v / result.settings["dt"]) for v in span_s)
    k1 = min(k1, result.x.shape[1])
    s = _decimate(k1 - k0)
    return k0, k1, s, result.t[k0:k1][s]


def fig5(result, *, axis=0, run=0):
    """Accelerometer reading (raw, clipped) and the disturbance estimates L1, L2, L3 against the truth."""
    fig, axes = new_figure(2, 1, figsize=(8, 6), sharex=True)
    n = result.passive["L1"].shape[1]
    s = _decimate(n)
    t = result.t[:n][s]
    plot_series(t, result.acc[run, :n, axis][s], ax=axes[0, 0], label="true reading", color="0.6")
    plot_series(t, result.acc_clipped[run, :n, axis][s], ax=axes[0, 0], label="clipped (what the filters get)",
                color="k", ylabel="accelerometer (m/s$^2$)")
    for b in ACCELEROMETER_RANGE:
        axes[0, 0].axhline(b, color="r", ls="--", lw=0.8, label="range" if b == ACCELEROMETER_RANGE[0] else None)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    ax = axes[1, 0]
    plot_series(t, 1e3 * result.f[:n, 3 + axis][s], ax=ax, label="truth", color="k", lw=1.2)
    for name in ("L1", "L2", "L3"):
        plot_series(t, 1e3 * result.passive[name][run, :, 6 + axis][s], ax=ax, label=name, color=_COLORS[name],
                    ylabel="F$_{Dsc,x}$ estimate (mN)")
    ax.legend(loc="upper right", fontsize=8)
    fig.suptitle("Fig 5 analogue, drag-free loop OPEN (F_Csc = 0)\nsaturated accelerometer, Algorithm 2 as "
                 "L1 / L2 (ideal) / L3 (skip)")
    return fig


def fig6(result, *, axis=0, run=0):
    """``|errors|`` of displacement and velocity of Algorithm 1 and Algorithm 2 (L1), standalone."""
    fig, axes = new_figure(2, 1, figsize=(8, 6), sharex=True)
    truth = result.dragfree_truth()[run]
    n = result.passive["alg1"].shape[1]
    s = _decimate(n)
    t = result.t[:n][s]
    for row, (off, unit, what) in enumerate(((0, "m", "displacement"), (3, "m/s", "velocity"))):
        for name, label in (("alg1", "Algorithm 1"), ("L1", "Algorithm 2")):
            e = np.abs(result.passive[name][run, :, off + axis] - truth[:n, off + axis])
            axes[row, 0].semilogy(t, e[s], lw=0.7, color=_COLORS[name], label=label)
        axes[row, 0].set_ylabel(f"|{what} error| ({unit})")
        axes[row, 0].grid(True, which="both", alpha=0.3)
        axes[row, 0].legend(fontsize=8)
    axes[1, 0].set_xlabel("time t (s)")
    fig.suptitle("Fig 6 analogue: Algorithm 1 stays put, Algorithm 2 accumulates")
    return fig


def fig7(result, *, axis=0, run=0, early_s=300.0):
    """Disturbance-estimate errors of Algorithms 1 and 2: the first ``early_s`` seconds and the whole span."""
    fig, axes = new_figure(2, 1, figsize=(8, 6))
    truth = result.dragfree_truth()[run]
    n = result.passive["alg1"].shape[1]
    k_e = min(n, int(early_s / result.settings["dt"]))
    for row, (k1, title) in enumerate(((k_e, f"first {early_s:g} s"), (n, "whole span"))):
        s = _decimate(k1)
        for name, label in (("alg1", "Algorithm 1"), ("L1", "Algorithm 2")):
            e = np.abs(result.passive[name][run, :k1, 6 + axis] - truth[:k1, 6 + axis])
            axes[row, 0].semilogy(result.t[:k1][s], e[s], lw=0.7, color=_COLORS[name], label=label)
        axes[row, 0].set_ylabel("|F$_{Dsc,x}$ error| (N)")
        axes[row, 0].set_title(title, fontsize=9)
        axes[row, 0].grid(True, which="both", alpha=0.3)
        axes[row, 0].legend(fontsize=8)
        axes[row, 0].set_xlabel("time t (s)")
    fig.suptitle("Fig 7 analogue: disturbance estimates of Algorithms 1 and 2")
    return fig


def fig8(result, *, axis=0, run=0):
    """The fused disturbance estimate (Algorithm 3) and its error, with Algorithms 1 and 2 for reference."""
    fig, axes = new_figure(2, 1, figsize=(8, 6), sharex=True)
    truth = result.dragfree_truth()[run]
    n = result.passive["alg1"].shape[1] if result.passive else truth.shape[0]
    s = _decimate(n)
    t = result.t[:n][s]
    plot_series(t, 1e3 * truth[:n, 6 + axis][s], ax=axes[0, 0], label="truth", color="k", lw=1.2)
    plot_series(t, 1e3 * result.xhat[run, :n, 15 + axis][s], ax=axes[0, 0], label="Algorithm 3", color=_COLORS["fused"],
                ylabel="F$_{Dsc,x}$ (mN)")
    axes[0, 0].legend(fontsize=8)
    e3 = np.abs(result.xhat[run, :n, 15 + axis] - truth[:n, 6 + axis])
    axes[1, 0].semilogy(t, e3[s], lw=0.7, color=_COLORS["fused"], label="Algorithm 3")
    for name, label in (("alg1", "Algorithm 1"), ("L1", "Algorithm 2")):
        if name in result.passive:
            e = np.abs(result.passive[name][run, :, 6 + axis] - truth[:n, 6 + axis])
            axes[1, 0].semilogy(t, e[s], lw=0.5, color=_COLORS[name], label=label, alpha=0.7)
    axes[1, 0].set_ylabel("|error| (N)")
    axes[1, 0].set_xlabel("time t (s)")
    axes[1, 0].grid(True, which="both", alpha=0.3)
    axes[1, 0].legend(fontsize=8)
    fig.suptitle("Fig 8 analogue: fused disturbance estimate")
    return fig


def fig9(results, *, axis=0, run=0, span_s=(2000.0, 6000.0)):
    """Relative displacement under the tuned PID and the ADRCs (``results``: label → LoopResult)."""
    fig, axes = new_figure(1, 1, figsize=(8, 4))
    ax = axes[0, 0]
    for i, (label, res) in enumerate(results.items()):
        k0, k1, s, t = _span(res, span_s)
        ax.plot(t, 1e6 * res.x[run, k0:k1, 6 + axis][s], lw=0.8, label=label, color=f"C{i}")
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("r$_{rel,x}$ (µm, symlog)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle("Fig 9 analogue: periodic disturbance, PID against ADRC")
    return fig


def fig10(result, *, run=0, span_s=(2000.0, 9000.0)):
    """Steady state under ADRC: φ_sc, r_rel, φ_rel (three axes each)."""
    fig, axes = new_figure(3, 1, figsize=(8, 7), sharex=True)
    k0, k1, s, t = _span(result, span_s)
    for row, (sl, unit, name) in enumerate(((slice(0, 3), "rad", "φ$_{sc}$"), (slice(6, 9), "m", "r$_{rel}$"),
                                            (slice(12, 15), "rad", "φ$_{rel}$"))):
        for a, lab in enumerate(("x/pitch", "y/yaw", "z/roll")):
            axes[row, 0].plot(t, result.x[run, k0:k1, sl][s, a], lw=0.6, label=lab)
        axes[row, 0].set_ylabel(f"{name} ({unit})")
        axes[row, 0].grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8, ncol=3)
    axes[2, 0].set_xlabel("time t (s)")
    fig.suptitle("Fig 10 analogue: steady state under ADRC")
    return fig


def fig11(result, *, run=0, around_s=(9500.0, 21500.0)):
    """The attitude step of Section 3 (on at 1e4 s, off at 2e4 s) and the relative attitude."""
    fig, axes = new_figure(2, 1, figsize=(8, 6), sharex=True)
    k0, k1, s, t = _span(result, around_s)
    for a, lab in enumerate(("pitch", "yaw", "roll")):
        axes[0, 0].plot(t, result.x[run, k0:k1, a][s], lw=0.8, label=lab, color=f"C{a}")
        axes[0, 0].plot(t, result.reference[k0:k1, a][s], "--", lw=0.6, color=f"C{a}")
        axes[1, 0].plot(t, result.x[run, k0:k1, 12 + a][s], lw=0.7, label=lab, color=f"C{a}")
    axes[0, 0].set_ylabel("φ$_{sc}$ (rad), command dashed")
    axes[1, 0].set_ylabel("φ$_{rel}$ (rad)")
    axes[1, 0].set_xlabel("time t (s)")
    for ax in axes[:, 0]:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, ncol=3)
    fig.suptitle("Fig 11 analogue: attitude step and the relative attitude")
    return fig


def fig12(spectra, *, ax=None):
    """Residual-acceleration ASDs (``spectra``: label → :func:`~.studies.residual_spectrum` output)."""
    fig = None
    if ax is None:
        fig, axes = new_figure(1, 1, figsize=(8, 5))
        ax = axes[0, 0]
    for i, (label, sp) in enumerate(spectra.items()):
        plot_asd(sp["f"], sp["asd"][:, 0], ax=ax, label=f"{label} (x)", requirement=(i == len(spectra) - 1),
                 color=f"C{i}")
    ax.legend(fontsize=8)
    ax.set_xlim(1e-4, 5.0)
    if fig is not None:
        fig.suptitle("Fig 12 analogue: residual acceleration on the test mass")
    return fig if fig is not None else ax.figure
