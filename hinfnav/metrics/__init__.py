"""Metrics layer: error statistics of simulated runs, for any state."""

from .errors import (
    MonteCarloSummary,
    axes_rms,
    by_group,
    convergence_time,
    group_rms,
    max_error,
    monte_carlo_summary,
    rms_error,
    rms_per_run,
    window_mask,
)
from .intervals import format_interval, mean_interval, t_half_width
from .streaming import MonteCarloStatistics, WindowStatistics, monte_carlo_statistics

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
    "t_half_width",
    "mean_interval",
    "format_interval",
]
