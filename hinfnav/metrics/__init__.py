"""Metrics layer: error statistics of simulated runs, for any state."""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # what static type checkers read; the same names as _EXPORTS (tests/test_import_time.py)
    from .consistency import DIVERGENCE_FACTOR, NEES_FACTOR, NIS_KEYS, ConsistencyAccumulator, ConsistencyStatistics, chi2_bounds, consistency, initial_scale, normalized_squared, warn_if_diverged
    from .errors import MonteCarloSummary, axes_rms, by_group, convergence_time, group_rms, max_error, monte_carlo_summary, rms_error, rms_per_run, window_mask
    from .intervals import format_interval, mean_interval, t_half_width
    from .streaming import MonteCarloStatistics, WindowStatistics, monte_carlo_statistics

#: Public name -> the module it comes from, imported on first use (PEP 562, :mod:`hinfnav.core.lazy`).
_EXPORTS = {
    "DIVERGENCE_FACTOR": ".consistency",
    "NEES_FACTOR": ".consistency",
    "NIS_KEYS": ".consistency",
    "ConsistencyAccumulator": ".consistency",
    "ConsistencyStatistics": ".consistency",
    "chi2_bounds": ".consistency",
    "consistency": ".consistency",
    "initial_scale": ".consistency",
    "normalized_squared": ".consistency",
    "warn_if_diverged": ".consistency",
    "MonteCarloSummary": ".errors",
    "axes_rms": ".errors",
    "by_group": ".errors",
    "convergence_time": ".errors",
    "group_rms": ".errors",
    "max_error": ".errors",
    "monte_carlo_summary": ".errors",
    "rms_error": ".errors",
    "rms_per_run": ".errors",
    "window_mask": ".errors",
    "format_interval": ".intervals",
    "mean_interval": ".intervals",
    "t_half_width": ".intervals",
    "MonteCarloStatistics": ".streaming",
    "WindowStatistics": ".streaming",
    "monte_carlo_statistics": ".streaming",
}

__all__ = [
    "window_mask",
    "rms_error",
    "rms_per_run",
    "max_error",
    "convergence_time",
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

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
