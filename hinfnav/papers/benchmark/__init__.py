"""The cross-paper benchmark (issue 13): every registered estimator on Sun et al. (2011)'s chaser.

Every estimator that fits the chaser, with and without maneuver, δ ∈ {0, 1, 5}
and four noises (Gaussian, paper 001's mixture, Student-t, coloured), ≥ 200
Monte Carlo runs per cell, run as a campaign on Dask
(:func:`hinfnav.run_campaign`); RMS position and velocity over 0–500 s and
100–1000 s with 95 % intervals, each as a ratio to the cell's Kalman limit.
Its grid (:mod:`.grid`), limits (:mod:`.limits`), table and heat map
(:mod:`.table`) and ``reproduce``. Notebook ``90_cross_paper_benchmark`` reads it.
"""

from .grid import (
    DELTAS,
    NOISES,
    PAPER_MODULES,
    TOL,
    WINDOWS,
    benchmark_campaign,
    fit_matrix,
    load_papers,
)
from . import estimators as _estimators  # noqa: F401  (registers the generic filters)
from .limits import cell_kalman_limit
from .reproduce import reproduce
from .table import QUANTITIES, benchmark_table, best_by_condition, format_markdown, plot_heatmap

__all__ = [
    "DELTAS",
    "NOISES",
    "PAPER_MODULES",
    "TOL",
    "WINDOWS",
    "benchmark_campaign",
    "fit_matrix",
    "load_papers",
    "cell_kalman_limit",
    "reproduce",
    "QUANTITIES",
    "benchmark_table",
    "best_by_condition",
    "format_markdown",
    "plot_heatmap",
]
