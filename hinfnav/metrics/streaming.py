"""Monte Carlo statistics kept while the runs stream past: memory does not grow with runs.

:func:`monte_carlo_statistics` runs the Monte Carlo engine
(:func:`hinfnav.sim.run_monte_carlo`) into a
:class:`~hinfnav.metrics.StatisticsSink`, which keeps, per time window, only

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
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..estimators.compiled import use_backend
from ..sim.engine import resolve_estimator, run_monte_carlo
from .accumulator import StatisticsSink, WindowStatistics
from .consistency import NIS_KEYS, warn_if_diverged

if TYPE_CHECKING:
    from ..design.result import DesignResult
    from ..estimators.base import Estimator
    from ..noise import NoiseModel

__all__ = ["WindowStatistics", "MonteCarloStatistics", "monte_carlo_statistics"]


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


def monte_carlo_statistics(scenario: Any, estimator: str | Estimator | DesignResult, *, windows: Mapping[str, Sequence[float]],
                           runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0, noise: str | NoiseModel = "gaussian",
                           measurement_noise: str | NoiseModel | None = None, batch_size: int = 100, progress: bool = False,
                           tol: ArrayLike | None = None, backend: str | None = None,
                           **conditions: Any) -> MonteCarloStatistics:
    """Run Monte Carlo batches and keep running statistics only.

    Parameters
    ----------
    scenario, estimator, runs, seed, noise, measurement_noise, batch_size, progress, backend, **conditions
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
    sink = StatisticsSink(windows, runs, scenario.xhat0, tol)
    est = resolve_estimator(scenario, estimator)
    with use_backend(backend):
        acc = run_monte_carlo(scenario, {est.name: est}, sink=sink, runs=runs, seed=seed, batch_size=batch_size,
                              noise=noise, measurement_noise=measurement_noise, keep_covariance=True,
                              diagnostics=NIS_KEYS, progress=progress, **conditions)[est.name]
    if acc.nonfinite:
        raise InputError(f"the estimator {est.name!r} produced non-finite estimates in {acc.nonfinite} of {runs} runs "
                         "(it diverged); no statistics can be formed")
    ws = acc.window_statistics()
    stats = {name: WindowStatistics(tuple(float(v) for v in windows[name]), w.pooled, w.per_run, w.max_abs)
             for name, w in ws.items()}
    consistency = acc.consistency.result(est.name)
    summary = consistency.summary(windows)
    warn_if_diverged(summary, consistency.name)
    return MonteCarloStatistics(stats, acc.convergence_s, acc.state, sink.settings[est.name], consistency, summary)
