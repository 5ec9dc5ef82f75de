"""Monte Carlo statistics kept while the runs stream past: memory does not grow with runs.

:func:`monte_carlo_statistics` simulates batch by batch
(:func:`hinfnav.sim.simulate_batches`) and keeps, per time window, only

* the pooled sum of squares and the sample count per component (pooled RMS),
* the largest absolute error per component,
* per run, its RMS per component (``runs × n`` numbers — 48 bytes a run for a
  6-state, against ~2.8 MB a run for the histories of the paper's scenario),
  from which the Monte Carlo mean, its 95 % interval and the spread follow;
* per run, the convergence time when tolerances are given;
* per step, the NEES and NIS summed over runs, and the divergence checks
  (:class:`~hinfnav.metrics.consistency.ConsistencyAccumulator`); a filter
  flagged ``diverged`` raises a :class:`~hinfnav.core.exceptions.FilterDivergenceWarning`.

The numbers equal those computed from full histories up to the order of
floating-point summation (tested).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..sim.montecarlo import simulate_batches
from .consistency import NIS_KEYS, ConsistencyAccumulator, initial_scale, warn_if_diverged
from .errors import window_mask
from .intervals import t_half_width

if TYPE_CHECKING:
    from ..design.result import SynthesisResult
    from ..estimators.base import Estimator
    from ..noise import NoiseModel

__all__ = ["WindowStatistics", "MonteCarloStatistics", "monte_carlo_statistics"]


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


@dataclass(frozen=True, eq=False)
class MonteCarloStatistics:
    """Streaming Monte Carlo statistics of one estimator on one scenario condition.

    Attributes
    ----------
    windows : dict
        Name → :class:`WindowStatistics`.
    convergence_s : ndarray, shape (runs,) or None
        Per-run convergence time (NaN when a run never settles), when tolerances were given.
    state : StateSpec
    settings : dict
    consistency : ConsistencyStatistics or None
        Run-averaged NEES and NIS per step and the divergence counts.
    consistency_summary : dict
        :meth:`~hinfnav.metrics.ConsistencyStatistics.summary` over the windows
        (``diverged``, bounds, per-window NEES/NIS and the fraction of steps inside).
    """

    windows: dict
    convergence_s: np.ndarray = None
    state: object = None
    settings: dict = field(default_factory=dict)
    consistency: object = None
    consistency_summary: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.windows[name]


def _convergence(err, t, tol):
    outside = np.any(np.abs(err) > tol, axis=2)
    out = np.full(err.shape[0], np.nan)
    for r in range(err.shape[0]):
        idx = np.flatnonzero(outside[r])
        if idx.size == 0:
            out[r] = t[0]
        elif idx[-1] < t.size - 1:
            out[r] = t[idx[-1] + 1]
    return out


def monte_carlo_statistics(scenario: Any, estimator: str | Estimator | SynthesisResult, *, windows: Mapping[str, Sequence[float]],
                           runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0, noise: str | NoiseModel = "gaussian",
                           measurement_noise: str | NoiseModel | None = None, batch_size: int = 100, progress: bool = False,
                           tol: ArrayLike | None = None, **conditions: Any) -> MonteCarloStatistics:
    """Run Monte Carlo batches and keep running statistics only.

    Parameters
    ----------
    scenario, estimator, runs, seed, noise, measurement_noise, batch_size, progress, **conditions
        As in :func:`hinfnav.simulate`.
    windows : dict
        Name → (start, end) in s.
    tol : array_like, shape (n,), optional
        Per-component tolerance for the convergence time.

    Returns
    -------
    MonteCarloStatistics
        With the consistency statistics; warns (:class:`~hinfnav.core.exceptions.FilterDivergenceWarning`)
        when the filter is flagged ``diverged``.
    """
    if not isinstance(windows, dict) or not windows:
        raise InputError(f"windows must be a non-empty dict name -> (start, end) in seconds; got {windows!r}")
    sums, counts, maxima, per_run, conv = {}, {}, {}, {}, []
    masks, state, settings = None, None, {}
    cons = ConsistencyAccumulator(runs)
    for start, res in simulate_batches(scenario, estimator, runs=runs, seed=seed, noise=noise,
                                       measurement_noise=measurement_noise, batch_size=batch_size, progress=progress,
                                       diagnostics=NIS_KEYS, **conditions):
        err = res.error
        if masks is None:
            masks = {name: window_mask(res.t, w) for name, w in windows.items()}
            n = err.shape[2]
            for name in windows:
                sums[name], counts[name], maxima[name] = np.zeros(n), 0, np.zeros(n)
                per_run[name] = np.empty((runs, n))
            state, settings = res.state, dict(res.settings)
            if tol is not None:
                tol = np.broadcast_to(np.asarray(tol, dtype=float), (n,))
                if not np.all(np.isfinite(tol)) or np.any(tol <= 0):
                    raise InputError(f"tol must be finite and > 0 for every component; got {tol}")
        if not np.all(np.isfinite(err)):
            raise InputError(
                f"the estimator {res.settings.get('filter')!r} produced non-finite estimates (it diverged); "
                "no statistics can be formed"
            )
        b = err.shape[0]
        for name, m in masks.items():
            sq = err[:, m] ** 2
            sums[name] += sq.sum(axis=(0, 1))
            counts[name] += sq.shape[0] * sq.shape[1]
            maxima[name] = np.maximum(maxima[name], np.abs(err[:, m]).max(axis=(0, 1)))
            per_run[name][start:start + b] = np.sqrt(sq.mean(axis=1))
        if tol is not None:
            conv.append(_convergence(err, res.t, tol))
        P = res.P if res.P is not None and res.P.ndim == 4 else None
        x0 = res.x[:, 0]
        e_prior = res.state.error(x0, np.broadcast_to(np.asarray(scenario.xhat0, dtype=float), x0.shape))
        cons.add(res.t, err, P, res.diagnostics.get(NIS_KEYS[0]), res.diagnostics.get(NIS_KEYS[1]),
                 initial_scale(e_prior, None if P is None else P[:, 0], err[:, 0]))
        del res, err, P
    settings["runs"] = runs
    stats = {
        name: WindowStatistics(tuple(float(v) for v in windows[name]), np.sqrt(sums[name] / counts[name]),
                               per_run[name], maxima[name])
        for name in windows
    }
    consistency = cons.result(settings.get("filter", "filter"))
    summary = consistency.summary(windows)
    warn_if_diverged(summary, consistency.name)
    return MonteCarloStatistics(stats, np.concatenate(conv) if conv else None, state, settings, consistency, summary)
