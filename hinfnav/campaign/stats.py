"""Streaming statistics of one campaign cell: fed batch by batch, memory independent of the runs.

The same quantities as :func:`hinfnav.metrics.monte_carlo_statistics`
(tested equal: the per-run RMS and the maxima bitwise, the pooled RMS to the
last bits, as the windows are summed as views here, about three times faster
than the copies there): per
window the pooled RMS and the largest absolute error per component, and per
run its RMS per component (``runs × n`` numbers), from which the 95 %
interval of the pooled RMS (:func:`rms_interval`), the Monte Carlo mean of
the per-run RMS, its 95 % interval (mean ± t s/√runs, Student t) and the 2.5–97.5 % spread of
one run follow; per run the convergence time when tolerances are given. On
top of that, per state group (position, velocity): the RMS over the group's
components (the root mean square of the per-axis RMS, as Table 1 of Sun 2011
reports a single number), pooled and per run. And the consistency of the
cell (:class:`hinfnav.metrics.ConsistencyAccumulator`): the run-averaged NEES
and NIS per step with their 95 % χ² bounds, per window their mean and the
fraction of steps inside, and the ``diverged`` flag with its reasons.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..metrics.consistency import ConsistencyAccumulator
from ..metrics.errors import window_mask
from ..metrics.intervals import t_half_width
from ..metrics.streaming import WindowStatistics

if TYPE_CHECKING:
    from ..systems.state import StateSpec

__all__ = ["CellAccumulator", "group_summary", "rms_interval"]


def _convergence(err, t, tol):
    outside = np.any(np.abs(err) > tol, axis=2)
    last = np.where(outside.any(axis=1), outside.shape[1] - 1 - np.argmax(outside[:, ::-1], axis=1), -1)
    out = np.full(err.shape[0], np.nan)
    ok = last < t.size - 1
    out[ok] = t[last[ok] + 1]
    return out


class CellAccumulator:
    """Accumulate one cell's statistics over batches of runs (see the module docstring).

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
                self._masks[name] = slice(int(idx[0]), int(idx[-1]) + 1)
            n = err.shape[2]
            self.state = state
            self._sums = {name: np.zeros(n) for name in self.windows}
            self._counts = dict.fromkeys(self.windows, 0)
            self._max = {name: np.zeros(n) for name in self.windows}
            self._per_run = {name: np.empty((self.runs, n)) for name in self.windows}
            if self.tol is not None:
                self._tol = np.broadcast_to(np.asarray(self.tol, dtype=float), (n,))
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
            self._conv.append(_convergence(err, t, self._tol))
        self.consistency.add(t, err, P, innovation, S, scale0)

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
            c = np.concatenate(self._conv)
            done = np.isfinite(c)
            conv = {"tol": list(self._tol), "fraction": float(done.mean()),
                    "median_s": float(np.median(c[done])) if done.any() else None}
        return {"labels": labels, "units": units,
                "groups": {g: {"indices": list(idx), "unit": units[idx[0]]} for g, idx in groups.items()},
                "windows": windows, "convergence": conv, "nonfinite_runs": self.nonfinite,
                "consistency": self.consistency.result(filter_name).summary(self.windows)}


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
