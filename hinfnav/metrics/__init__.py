"""Metrics layer: error statistics of simulated runs, for any state."""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .consistency import DIVERGENCE_FACTOR, NEES_FACTOR, NIS_KEYS, ConsistencyAccumulator, ConsistencyStatistics, chi2_bounds, consistency, initial_scale, normalized_squared, warn_if_diverged
    from .errors import MonteCarloSummary, axes_rms, by_group, convergence_time, group_rms, check_tolerance, max_error, monte_carlo_summary, rms_error, rms_per_run, window_mask
    from .intervals import format_interval, mean_interval, t_half_width
    from .accumulator import StatisticsAccumulator, StatisticsSink, WindowStatistics, group_summary, rms_interval
    from .streaming import MonteCarloStatistics, monte_carlo_statistics

__all__ = [
    "window_mask",
    "rms_error",
    "rms_per_run",
    "max_error",
    "convergence_time",
    "check_tolerance",
    "StatisticsAccumulator",
    "StatisticsSink",
    "group_summary",
    "rms_interval",
    "MonteCarloSummary",
    "monte_carlo_summary",
    "by_group",
    "group_rms",
    "axes_rms",
    "monte_carlo_statistics",
    "MonteCarloStatistics",
    "WindowStatistics",
    "chi2_bounds",
    "normalized_squared",
    "initial_scale",
    "consistency",
    "warn_if_diverged",
    "ConsistencyAccumulator",
    "ConsistencyStatistics",
    "DIVERGENCE_FACTOR",
    "NEES_FACTOR",
    "NIS_KEYS",
    "t_half_width",
    "mean_interval",
    "format_interval",
]

__getattr__, __dir__ = lazy_exports(__name__)
