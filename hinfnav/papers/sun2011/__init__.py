"""Sun et al. (2011), "Relative navigation algorithm for chaser satellite based on robust H∞ filtering".

Journal of Astronautics 32(7):1462–1470, doi:10.3873/j.issn.1000-1328.2011.07.005.
Its constants and published filter (:mod:`.constants`), scenario
(:mod:`.scenario`), EKF baseline (:mod:`.ekf`), registered filters
(:mod:`.filters`), designs (:mod:`.designs`), accuracy limits
(:mod:`.limits`), Table 1 (:mod:`.table1`), figures (:mod:`.figures`),
studies (:mod:`.studies`, :mod:`.closed_loop`) and ``reproduce``.
"""

from ...campaign.registry import register_scenario
from .closed_loop import ClosedLoopStudy, closed_loop_study, plot_closed_loop
from .constants import CITATION, DEFAULT_DELTA_BARS, PAPER_K, PAPER_TABLE1, PublishedFilter, infer_sampling_time, published_filter
from .designs import (
    GammaSweep,
    compare_with_published,
    delta_grid,
    delta_samples,
    design_for_scenario,
    design_report,
    format_design_report,
    gamma_sweep,
    load_design,
    save_design,
)
from .ekf import EKF, build_ekf, range_angle_measurements
from .filters import FILTER_NAMES, lti_from_matrices, make_estimator
from .limits import KalmanLimit, kalman_limit, lti_error_covariance
from .mixed_designs import (
    format_mixed_design_report,
    mixed_design_for_scenario,
    mixed_design_report,
    mixed_front_for_scenario,
)
from .pareto import ParetoStudy, format_pareto_table, pareto_study, plot_front, plot_front_accuracy, robustness_cost
from .recursive_hinf import ThetaStudy, build_recursive_hinf, plot_theta_study, theta_study
from .reproduce import reproduce
from .scenario import Scenario, paper_scenario
from .studies import filter_case_rms, format_robustness_table, pos_vel, robustness_table, simulation_comparison, stationary_std, sweep_result
from .table1 import Table1, format_table1, table1, table1_rows, write_table1

register_scenario("sun2011", Scenario, description="Sun et al. 2011: chaser relative navigation, Section 4")

__all__ = [
    "CITATION",
    "PAPER_K",
    "PAPER_TABLE1",
    "DEFAULT_DELTA_BARS",
    "PublishedFilter",
    "published_filter",
    "infer_sampling_time",
    "Scenario",
    "paper_scenario",
    "EKF",
    "build_ekf",
    "range_angle_measurements",
    "FILTER_NAMES",
    "make_estimator",
    "lti_from_matrices",
    "KalmanLimit",
    "kalman_limit",
    "lti_error_covariance",
    "delta_grid",
    "delta_samples",
    "design_for_scenario",
    "GammaSweep",
    "gamma_sweep",
    "design_report",
    "format_design_report",
    "compare_with_published",
    "save_design",
    "load_design",
    "Table1",
    "table1",
    "table1_rows",
    "format_table1",
    "write_table1",
    "robustness_table",
    "format_robustness_table",
    "simulation_comparison",
    "stationary_std",
    "sweep_result",
    "pos_vel",
    "filter_case_rms",
    "ClosedLoopStudy",
    "closed_loop_study",
    "plot_closed_loop",
    "reproduce",
    "mixed_design_for_scenario",
    "mixed_front_for_scenario",
    "mixed_design_report",
    "format_mixed_design_report",
    "ParetoStudy",
    "pareto_study",
    "format_pareto_table",
    "plot_front",
    "plot_front_accuracy",
    "robustness_cost",
    "build_recursive_hinf",
    "ThetaStudy",
    "theta_study",
    "plot_theta_study",
]
