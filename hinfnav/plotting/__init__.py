"""Plotting layer: functions that take ``ax=`` and never touch global matplotlib state."""

from .design import plot_filter_matrices, plot_gamma_curve, plot_sigma, plot_worst_case_over_delta
from .save import save_figure
from .errors import new_figure, plot_error_axis, plot_errors, plot_inputs, plot_uncertainty_check

__all__ = [
    "new_figure",
    "plot_errors",
    "plot_error_axis",
    "plot_inputs",
    "plot_uncertainty_check",
    "plot_gamma_curve",
    "plot_sigma",
    "plot_worst_case_over_delta",
    "plot_filter_matrices",
    "save_figure",
]
