"""The cross-paper benchmark (issues 13, 18): every fitting estimator on every registered scenario.

One Dask campaign per scenario (Sun 2011's chaser, Shi & Wang 2018's target with its maneuver and mixture,
paper 002's gyroless attitude, Yang 2020's saturated drag-free axes; :data:`.grid.SCENARIOS`), each cell's
RMS as a ratio to its bound (:func:`.limits.cell_bound`: Riccati limit or posterior CRB), the pairs that do
not fit listed with the reason; :mod:`.cross` makes the table. The issue-13 grid on the chaser alone:

Every estimator that fits the chaser, with and without maneuver, δ ∈ {0, 1, 5}
and four noises (Gaussian, paper 001's mixture, Student-t, coloured), ≥ 200
Monte Carlo runs per cell, run as a campaign on Dask
(:func:`hinfnav.run_campaign`); RMS position and velocity over 0–500 s and
100–1000 s with 95 % intervals, each as a ratio to the cell's Kalman limit.
Its grid (:mod:`.grid`), limits (:mod:`.limits`), table and heat map
(:mod:`.table`) and ``reproduce``. Notebook ``90_cross_paper_benchmark`` reads it.
"""

from .cross import WINDOW, condition_label, cross_table, plot_scenario_heatmap, winners
from .grid import (
    DELTAS,
    SCENARIOS,
    NOISES,
    PAPER_MODULES,
    TOL,
    WINDOWS,
    benchmark_campaign,
    fit_matrix,
    load_papers,
    non_fitting,
    scenario_campaign,
)
from . import estimators as _estimators  # noqa: F401  (registers the generic filters)
from . import linear_designs as _linear_designs  # noqa: F401  (registers model_hinf, model_lmi)
from .limits import cell_bound, cell_kalman_limit
from .reproduce import reproduce
from .table import QUANTITIES, benchmark_table, best_by_condition, format_markdown, plot_heatmap

__all__ = [
    "SCENARIOS",
    "WINDOW",
    "scenario_campaign",
    "non_fitting",
    "cell_bound",
    "cross_table",
    "winners",
    "plot_scenario_heatmap",
    "condition_label",
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
