"""Streaming statistics of an estimator's errors: fed batch by batch, memory independent of the runs.

:class:`StatisticsAccumulator` keeps, per window, the pooled RMS and the
largest absolute error per component (the windows summed as views: about
three times faster than copies), and per run its RMS per component
(``runs × n`` numbers), from which the 95 % interval of the pooled RMS
(:func:`rms_interval`), the Monte Carlo mean of the per-run RMS, its 95 %
interval (mean ± t s/√runs, Student t) and the 2.5–97.5 % spread of one run
follow; per run the convergence time when tolerances are given
(:func:`hinfnav.metrics.convergence_time`). On top of that, per state group
(position, velocity): the RMS over the group's components (the root mean
square of the per-axis RMS, as Table 1 of Sun 2011 reports a single number),
pooled and per run. And the consistency
(:class:`hinfnav.metrics.ConsistencyAccumulator`): the run-averaged NEES and
NIS per step with their 95 % χ² bounds, per window their mean and the
fraction of steps inside, and the ``diverged`` flag with its reasons.

:class:`StatisticsSink` is the sink of the Monte Carlo engine
(:func:`hinfnav.sim.run_monte_carlo`) that keeps these statistics only: one
accumulator per estimator, memory of one batch whatever the runs. It serves
:func:`hinfnav.metrics.monte_carlo_statistics` and the campaign's cells.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..sim.engine import Sink
from .consistency import NIS_KEYS, ConsistencyAccumulator, initial_scale
from .errors import check_tolerance, convergence_time, window_mask
from .intervals import t_half_width

if TYPE_CHECKING:
    from ..estimators.base import EstimateHistory
    from ..sim.truth import Truth
    from ..systems.state import StateSpec

__all__ = ["WindowStatistics", "StatisticsAccumulator", "StatisticsSink", "group_summary", "rms_interval",
           "GATE_KEY"]

#: The diagnostic of a gated filter (:mod:`hinfnav.estimators.gate`) whose rejections a cell counts.
GATE_KEY = "gate_rejected"


@dataclass(frozen=True, eq=False)
class WindowStatistics:
    """Statistics of the estimation error over one time window.

    Attributes
    ----------
    window : (float, float)
        Start and end, s.
    pooled : ndarray, shape (n,)
        RMS pooled over all runs and samples of the window.
    per_run : ndarray, shape (runs, n)
        RMS of each run over the window.
    max_abs : ndarray, shape (n,)
        Largest absolute error over runs and window.
    """

    window: tuple
    pooled: np.ndarray
    per_run: np.ndarray
    max_abs: np.ndarray

    @property
    def runs(self) -> int:
        return self.per_run.shape[0]

    @property
    def mean(self) -> NDArray[np.float64]:
        """Mean over runs of the per-run RMS, shape (n,)."""
        return self.per_run.mean(axis=0)

    @property
    def ci95(self) -> NDArray[np.float64]:
        """95 % confidence interval of :attr:`mean` (Student t, :func:`~hinfnav.metrics.intervals.t_half_width`;
        NaN with one run), shape (2, n)."""
        half = t_half_width(self.per_run, axis=0)
        return np.vstack([self.mean - half, self.mean + half])

    @property
    def spread95(self) -> NDArray[np.float64]:
        """2.5 and 97.5 percentiles of the per-run RMS (what one run may give), shape (2, n)."""
        return np.percentile(self.per_run, [2.5, 97.5], axis=0)


def add_batch(acc: StatisticsAccumulator, start: int, truth: Truth, history: EstimateHistory,
              xhat0: ArrayLike) -> None:
    """Add the runs ``start …`` of an estimator's ``history`` on ``truth`` to ``acc``: the errors by the state's
    definition, the covariance, innovation and S histories and the initial error scales (non-finite values kept)."""
    x = truth.x
    error = (lambda a, b: a - b) if truth.state is None else truth.state.error
    with np.errstate(all="ignore"):
        err = error(x, history.xhat)
        P = history.P if history.P is not None and history.P.ndim == 4 else None
        scale0 = initial_scale(error(x[:, 0], np.broadcast_to(np.asarray(xhat0, dtype=float), x[:, 0].shape)),
                               None if P is None else P[:, 0], err[:, 0])
        acc.add(start, truth.t, err, truth.state, P, history.diagnostics.get(NIS_KEYS[0]),
                history.diagnostics.get(NIS_KEYS[1]), scale0)
    if GATE_KEY in history.diagnostics:
        acc.add_rejections(history.diagnostics[GATE_KEY])


class StatisticsSink(Sink):
    """The engine's sink of streaming statistics: ``result()`` is name → :class:`StatisticsAccumulator`.

    Parameters
    ----------
    windows : dict
        Name → (start, end), s.
    runs : int
    xhat0 : array_like
        The estimators' initial estimate (for the initial error scale of the consistency checks).
    tol : array_like, optional
        Per-component tolerance of the convergence time.
    """

    def __init__(self, windows: Mapping[str, Sequence[float]], runs: int, xhat0: ArrayLike,
                 tol: ArrayLike | None = None) -> None:
        if not isinstance(windows, dict) or not windows:
            raise InputError(f"windows must be a non-empty dict name -> (start, end) in seconds; got {windows!r}")
        self.windows, self.runs, self.tol = windows, int(runs), tol
        self.xhat0 = np.asarray(xhat0, dtype=float)
        self.accumulators: dict[str, StatisticsAccumulator] = {}
        self.settings: dict[str, dict] = {}

    def add(self, name: str, start: int, truth: Truth, history: EstimateHistory) -> None:
        if name not in self.accumulators:
            self.accumulators[name] = StatisticsAccumulator(self.windows, self.runs, self.tol)
            self.settings[name] = dict(truth.settings, filter=name, runs=self.runs)
        add_batch(self.accumulators[name], start, truth, history, self.xhat0)

    def result(self) -> dict[str, StatisticsAccumulator]:
        return dict(self.accumulators)


class StatisticsAccumulator:
    """Accumulate one estimator's error statistics over batches of runs (see the module docstring).

    Parameters
    ----------
    windows : dict
        Name → (start, end), s.
    runs : int
        Total number of runs of the cell.
    tol : sequence of float, optional
        Per-component tolerance of the convergence time.
    """

    def __init__(self, windows: Mapping[str, Sequence[float]], runs: int, tol: Sequence[float] | None = None) -> None:
        self.windows = dict(windows)
        self.runs = int(runs)
        self.tol = tol
        self.state = None
        self._masks = None
        self._conv = []
        self.consistency = ConsistencyAccumulator(self.runs)
        self._gate = None

    def add_rejections(self, rejected: ArrayLike) -> None:
        """Count a gated filter's rejections: ``rejected`` (batch, samples, m) bool, the ``gate_rejected`` history."""
        rejected = np.asarray(rejected, dtype=bool)
        if self._gate is None:
            self._gate = {"readings": 0, "rejected_readings": 0, "per_channel": np.zeros(rejected.shape[2], dtype=int)}
        self._gate["readings"] += rejected.shape[0] * rejected.shape[1]
        self._gate["rejected_readings"] += int(rejected.any(axis=2).sum())
        self._gate["per_channel"] += rejected.sum(axis=(0, 1))

    @property
    def gate(self) -> dict[str, Any] | None:
        """A gated filter's rejections (None for a filter without a gate): ``readings`` seen, ``rejected_readings``
        (with at least one channel rejected), ``rejected_channels`` and ``per_channel``, ``rejected_fraction``."""
        if self._gate is None:
            return None
        g = self._gate
        return {"readings": g["readings"], "rejected_readings": g["rejected_readings"],
                "rejected_channels": int(g["per_channel"].sum()), "per_channel": [int(v) for v in g["per_channel"]],
                "rejected_fraction": g["rejected_readings"] / max(g["readings"], 1)}

    def add(self, start: int, t: NDArray[np.float64], err: NDArray[np.float64], state: StateSpec | None, P: NDArray[np.float64] | None = None,
            innovation: NDArray[np.float64] | None = None, S: NDArray[np.float64] | None = None, scale0: NDArray[np.float64] | None = None) -> None:
        """Add the errors ``err`` (shape (batch, samples, n)) of runs ``start … start + batch − 1``.

        ``P``, ``innovation``, ``S`` and ``scale0``: the covariance history,
        innovation and innovation covariance histories and initial error
        scales of those runs, for the consistency statistics (see
        :meth:`hinfnav.metrics.ConsistencyAccumulator.add`).
        """
        if self._masks is None:
            # t is increasing, so each window is one contiguous range of samples: slices (views), not copies
            self._masks = {}
            for name, w in self.windows.items():
                idx = np.flatnonzero(window_mask(t, w))
                if idx.size == 0:
                    raise InputError(f"window {name!r} = {tuple(w)} s holds no sample of t = {t[0]:g} … {t[-1]:g} s")
                self._masks[name] = slice(int(idx[0]), int(idx[-1]) + 1)
            n = err.shape[2]
            self.state = state
            self._sums = {name: np.zeros(n) for name in self.windows}
            self._counts = dict.fromkeys(self.windows, 0)
            self._max = {name: np.zeros(n) for name in self.windows}
            self._per_run = {name: np.empty((self.runs, n)) for name in self.windows}
            if self.tol is not None:
                self._tol = check_tolerance(self.tol, n)
        b = err.shape[0]
        sq_all = err * err
        for name, m in self._masks.items():
            sq = sq_all[:, m]
            self._sums[name] += sq.sum(axis=(0, 1))
            self._counts[name] += sq.shape[0] * sq.shape[1]
            # sqrt(fl(e*e)) == |e| in IEEE arithmetic (barring underflow), so this is the largest |e|
            self._max[name] = np.maximum(self._max[name], np.sqrt(sq.max(axis=(0, 1))))
            self._per_run[name][start:start + b] = np.sqrt(sq.mean(axis=1))
        del sq_all
        if self.tol is not None:
            self._conv.append(convergence_time(err, t, self._tol, nonfinite="outside"))
        self.consistency.add(t, err, P, innovation, S, scale0)

    @property
    def convergence_s(self) -> NDArray[np.float64] | None:
        """Per-run convergence time, s (NaN: never settles), in the order of the runs added; None without ``tol``."""
        return np.concatenate(self._conv) if self.tol is not None and self._conv else None

    @property
    def nonfinite(self) -> int:
        """Number of runs added whose errors are not all finite."""
        return self.consistency.nonfinite_runs

    def window_statistics(self) -> dict[str, WindowStatistics]:
        """Name → :class:`~hinfnav.metrics.WindowStatistics` (the same object the streaming Monte Carlo returns)."""
        return {name: WindowStatistics(tuple(self.windows[name]), np.sqrt(self._sums[name] / self._counts[name]),
                                       self._per_run[name], self._max[name])
                for name in self.windows}

    def result(self, filter_name: str = "filter") -> dict[str, Any]:
        """JSON-ready statistics: per window and component, per window and state group, convergence, consistency."""
        st = self.state
        labels = list(st.labels) if st is not None else [f"x{i}" for i in range(self._sums[next(iter(self.windows))].size)]
        units = list(st.units) if st is not None else [""] * len(labels)
        groups = dict(getattr(st, "groups", {}) or {})
        windows = {}
        for name, ws in self.window_statistics().items():
            ci, spread = ws.ci95, ws.spread95
            lo, hi = rms_interval(ws.per_run ** 2)
            windows[name] = {
                "window": list(ws.window),
                "pooled": ws.pooled, "rms_ci95_low": lo, "rms_ci95_high": hi,
                "mean": ws.mean, "ci95_low": ci[0], "ci95_high": ci[1],
                "spread95_low": spread[0], "spread95_high": spread[1], "max_abs": ws.max_abs,
                "groups": {g: group_summary(ws, idx) for g, idx in groups.items()},
            }
        conv = None
        if self.tol is not None:
            c = self.convergence_s
            done = np.isfinite(c)
            conv = {"tol": list(self._tol), "fraction": float(done.mean()),
                    "median_s": float(np.median(c[done])) if done.any() else None}
        out = {"labels": labels, "units": units,
               "groups": {g: {"indices": list(idx), "unit": units[idx[0]]} for g, idx in groups.items()},
               "windows": windows, "convergence": conv, "nonfinite_runs": self.nonfinite,
               "consistency": self.consistency.result(filter_name).summary(self.windows)}
        if self._gate is not None:  # a gated filter: its rejections (the key is absent otherwise)
            out["gate"] = self.gate
        return out


def rms_interval(ms: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """95 % interval of the pooled RMS from the per-run mean squares ``ms`` (shape (runs,) or (runs, n)).

    Every run has the same number of samples in a window, so the pooled mean
    square is the mean of the runs' mean squares m̄; its 95 % interval
    m̄ ± t s/√runs (Student t, s their standard deviation over runs) gives
    ``sqrt(max(0, m̄ − h)), sqrt(m̄ + h)``. This is the interval to set beside a
    standard deviation such as the Kalman limit: the mean of the per-run RMS
    is smaller than the pooled RMS (Jensen's inequality), by several per cent
    when the error is correlated over the window (few independent samples per run).
    """
    ms = np.asarray(ms, dtype=float)
    m = ms.mean(axis=0)
    half = t_half_width(ms, axis=0)  # Student t; NaN with one run
    return np.sqrt(np.maximum(m - half, 0.0)), np.sqrt(m + half)


def group_summary(ws: WindowStatistics, idx: Iterable[int]) -> dict[str, float]:
    """RMS over the components ``idx`` of a :class:`WindowStatistics`: pooled with its interval, per-run mean,
    95 % CI, spread, max."""
    idx = list(idx)
    ms = np.mean(ws.per_run[:, idx] ** 2, axis=1)
    rlo, rhi = rms_interval(ms)
    per = np.sqrt(ms)
    mean = per.mean()
    half = t_half_width(per)  # Student t; NaN with one run
    lo, hi = np.percentile(per, [2.5, 97.5])
    return {"pooled": float(np.sqrt(np.mean(ws.pooled[idx] ** 2))), "rms_ci95_low": float(rlo),
            "rms_ci95_high": float(rhi), "mean": float(mean),
            "ci95_low": float(mean - half), "ci95_high": float(mean + half),
            "spread95_low": float(lo), "spread95_high": float(hi), "max_abs": float(ws.max_abs[idx].max())}
