"""GRACE on an irregular log: thinned real epochs, the per-step Hill model, filter and RTS smoother (issue 34).

The study of notebook 41, in the package so that the notebook only calls and prints:

1. :func:`irregular_log` keeps a random share of the day's real 10 s epochs and cuts gaps into them, then reads
   relative GNSS positions at the kept epochs (truth + white noise of σ = ``sigma_m`` per axis, the study's
   ``gnss`` variant): the time stamps and the motion are real, the GNSS noise is simulated. The estimates are
   kept on a grid with prediction-only stamps every :data:`~.constants.DT_S` in the gaps
   (:meth:`~hinfnav.systems.TimedReadings.with_max_step`).
2. :func:`hill_timed_model` is the continuous Hill/CW model (paper 000 = Sun et al. 2011, eq. (2)) with a white
   acceleration noise of density

   .. math:: q = \\operatorname{tr}\\big(Q_{\\text{mismatch}}^{vv}\\big) / (3\\,\\Delta t)   \\qquad (\\text{m}^2/\\text{s}^3)

   per axis, from the measured one-step velocity mismatch :func:`~.mismatch.one_step_mismatch` over one step
   Δt = 10 s; it is discretised per step by Van Loan's exponential (:mod:`hinfnav.systems.timed`, eq. (T1)).
3. :func:`filter_and_smooth` runs the Kalman filter and the RTS smoother on the grid
   (:func:`~hinfnav.estimators.estimate_timed`, :func:`~hinfnav.estimators.smooth_timed`) from x̂₀ ~ N(x₀, P₀).
4. :func:`smoother_figure` draws the along-track error of both with their ±2σ bands, and the step lengths.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.validation import as_nonnegative, as_positive, as_vector
from ...estimators import ExtendedKalmanFilter, estimate_timed, smooth_timed
from ...plotting.errors import new_figure
from ...systems import TimedReadings, TimedSystem
from ...systems.hill import hill_matrices, position_measurement
from ...systems.state import chaser_state_spec
from .constants import DT_S, GNSS_SIGMA_M
from .mismatch import one_step_mismatch

__all__ = ["IrregularLog", "irregular_log", "hill_timed_model", "filter_and_smooth", "smoother_figure",
           "DEFAULT_P0"]

#: Prior covariance of the study: 10 m per position axis, 0.1 m/s per velocity axis (1σ).
DEFAULT_P0 = np.diag([10.0, 10.0, 10.0, 0.1, 0.1, 0.1]) ** 2


@dataclass(frozen=True)
class IrregularLog:
    """An irregularly thinned log of the real day.

    Attributes
    ----------
    t : ndarray, shape (k,)
        Kept epochs, s since 2010-07-27 00:00.
    truth : ndarray, shape (k, 6)
        POD truth of GRACE-A in GRACE-B's Hill frame at them (m, m/s).
    readings : TimedReadings
        Relative GNSS positions at the kept epochs (m).
    grid : TimedReadings
        ``readings`` with prediction-only stamps every ``DT_S`` in the gaps.
    truth_grid : ndarray, shape (g, 6)
        The truth on ``grid``.
    """

    t: np.ndarray
    truth: np.ndarray
    readings: TimedReadings
    grid: TimedReadings
    truth_grid: np.ndarray


def irregular_log(data, rng: np.random.Generator, hours: float = 2.0, keep_fraction: float = 0.6,
                  gap_starts_min=(20.0, 65.0), gap_s: float = 150.0, sigma_m: float = GNSS_SIGMA_M) -> IrregularLog:
    """Keep a random share of the first ``hours`` of 10 s epochs, cut gaps, read GNSS positions at the rest.

    Parameters
    ----------
    data : GraceData
        The day (:func:`~.dataset.load`).
    rng : numpy.random.Generator
        Draws which epochs are kept, then the readings' noise (in that order).
    hours : float
        Length of the log, h (at most the day's length).
    keep_fraction : float
        Share of the epochs kept, in (0, 1]. The first epoch is always kept.
    gap_starts_min : sequence of float
        Start of each gap, min since the start of the log.
    gap_s : float
        Length of each gap, s.
    sigma_m : float
        1σ of the readings per axis, m.
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    hours = as_positive("hours", hours)
    keep_fraction = as_positive("keep_fraction", keep_fraction)
    if keep_fraction > 1.0:
        raise ValueError(f"keep_fraction must be in (0, 1], got {keep_fraction!r}")
    gap_starts = as_vector("gap_starts_min", np.atleast_1d(np.asarray(gap_starts_min, dtype=float)))
    gap_s = as_nonnegative("gap_s", gap_s)
    sigma_m = as_positive("sigma_m", sigma_m)
    n = int(hours * 3600.0 / DT_S)
    if n < 2 or n > data.t.size:
        raise ValueError(f"hours = {hours:g} gives {n} epochs; the day has {data.t.size} "
                         f"({data.t.size * DT_S / 3600:.1f} h) and the log needs at least 2")
    keep = rng.random(n) < keep_fraction
    t_all = data.t[:n]
    for start in gap_starts:
        keep[(t_all >= 60.0 * start) & (t_all < 60.0 * start + gap_s)] = False
    keep[0] = True
    t, truth = t_all[keep], data.truth[:n][keep]
    readings = TimedReadings(t, truth[:, :3] + sigma_m * rng.standard_normal((t.size, 3)), ("x", "y", "z"))
    grid = readings.with_max_step(DT_S)
    truth_grid = data.truth[np.rint(grid.t / DT_S).astype(int)]
    return IrregularLog(t, truth, readings, grid, truth_grid)


def hill_timed_model(data, q: float | None = None) -> tuple[TimedSystem, float]:
    """The Hill/CW model with an acceleration-noise density ``q`` (m²/s³ per axis), for any step.

    ``q = None`` measures it from the day's one-step mismatch (the formula in the module docstring; a few
    seconds); a number is used as given.
    """
    if q is None:
        q = float(np.trace(one_step_mismatch(data)["Q_mismatch"][3:, 3:]) / 3.0 / DT_S)
    else:
        q = as_positive("q", q)
    A0, _ = hill_matrices(data.orbital_rate, 1.0)
    return TimedSystem.from_continuous(A0, np.diag([0.0, 0.0, 0.0, q, q, q]), chaser_state_spec()), q


def filter_and_smooth(log: IrregularLog, timed: TimedSystem, rng: np.random.Generator, P0=DEFAULT_P0,
                      sigma_m: float = GNSS_SIGMA_M):
    """Kalman filter and RTS smoother of ``log`` from x̂₀ = x₀ + N(0, P₀) (drawn with ``rng``).

    Returns ``(filtered, smoothed, xhat0)``: the two histories on ``log.grid`` and the initial estimate.
    """
    P0 = np.asarray(P0, dtype=float)
    xhat0 = log.truth[0] + np.sqrt(np.diag(P0)) * rng.standard_normal(P0.shape[0])
    kf = ExtendedKalmanFilter(timed.at(DT_S), position_measurement(sigma_m * np.eye(3)), P0=P0, missing="skip")
    return estimate_timed(kf, timed, log.grid, xhat0), smooth_timed(kf, timed, log.grid, xhat0), xhat0


def smoother_figure(log: IrregularLog, filtered, smoothed, axis: int = 1):
    """Error of the filter and the smoother on one Hill axis with their ±2σ bands, and the step lengths."""
    label = chaser_state_spec().labels[axis]
    fig, ax = new_figure(2, 1, figsize=(9, 5), sharex=True)
    minutes = log.grid.t / 60.0
    for h, name in ((filtered, "filter"), (smoothed, "RTS smoother")):
        sd = 2.0 * np.sqrt(h.P[0, :, axis, axis])
        ax[0, 0].plot(minutes, log.truth_grid[:, axis] - h.xhat[0, :, axis], lw=0.8, label=f"{name} error")
        ax[0, 0].fill_between(minutes, -sd, sd, alpha=0.2, label=f"{name} ±2σ")
    unit = "m" if axis < 3 else "m/s"
    ax[0, 0].set_ylabel(f"{label} error ({unit})")
    ax[0, 0].legend(ncol=4, fontsize=8)
    ax[1, 0].plot(log.t[1:] / 60.0, log.readings.dt, ".", ms=3, label="time between readings")
    ax[1, 0].set_ylabel("step (s)")
    ax[1, 0].set_xlabel("time since 2010-07-27 00:00 (min)")
    ax[1, 0].legend(fontsize=8)
    fig.suptitle("GRACE-A/B on an irregular log: filter and smoother errors")
    return fig
