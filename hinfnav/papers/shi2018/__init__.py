"""Shi & Wang (2018), "Huber-based filtering in relative navigation of non-cooperative spacecraft".

Shi Changyong, Wang Xiang, Aerospace Control (航天控制) 2018 no. 5. The
extraction lost every equation and both tables; what survives and what is
rebuilt (from Karlgaard & Schaub, JGCD 2007) is said in :mod:`.constants`,
:mod:`.scenario` and the notebooks 10–12. Its constants (:mod:`.constants`),
scenario (:mod:`.scenario`), filters registered as ``hbf`` and
``ekf_converted`` (:mod:`.filters`), calibration of the lost sensor errors
and the Kalman limit (:mod:`.calibration`), Huber's M-estimation step by step
(:mod:`.mestimation`), the three cases
(:mod:`.studies`), sweeps (:mod:`.sweeps`), the results table
(:mod:`.table`), figures (:mod:`.figures`) and ``reproduce``.
"""

from .campaign import CampaignScenario
from .calibration import RiccatiAccuracy, calibrate_sensor_errors, riccati_accuracy
from .constants import (
    CALIBRATED_SENSOR_ERRORS,
    CALIBRATION_TARGET,
    CITATION,
    GAMMA,
    PAPER_CLAIMS,
    PAPER_RESULTS,
)
from .figures import fig3, fig4, fig5, fig6, maneuver_figure, mixture_figures, plot_case_errors, sweeps_figure
from .filters import EKF, HBF, build_hbf
from .mestimation import IrlsPath, huber_efficiency, huber_psi, huber_rho, irls_path, whitened_regression
from .reproduce import STATISTIC, reproduce, statistic, study, verdicts
from .scenario import ContaminatedNoise, Scenario, paper_scenario
from .studies import (
    CASES,
    CaseResult,
    FilterStats,
    accuracy,
    case_conditions,
    filter_summary,
    maneuver_reaction,
    paired_gap,
    run_case,
)
from .sweeps import MISTUNING_FACTORS, SENSOR_VARIANTS, mistuning_sweep, sensitivity_sweep
from .table import format_table, table_rows, write_table

__all__ = [
    "CampaignScenario",
    "CITATION",
    "PAPER_RESULTS",
    "PAPER_CLAIMS",
    "GAMMA",
    "CALIBRATION_TARGET",
    "CALIBRATED_SENSOR_ERRORS",
    "STATISTIC",
    "statistic",
    "Scenario",
    "paper_scenario",
    "ContaminatedNoise",
    "EKF",
    "HBF",
    "build_hbf",
    "huber_rho",
    "huber_psi",
    "huber_efficiency",
    "whitened_regression",
    "IrlsPath",
    "irls_path",
    "RiccatiAccuracy",
    "riccati_accuracy",
    "calibrate_sensor_errors",
    "CASES",
    "CaseResult",
    "FilterStats",
    "case_conditions",
    "run_case",
    "accuracy",
    "filter_summary",
    "paired_gap",
    "maneuver_reaction",
    "SENSOR_VARIANTS",
    "MISTUNING_FACTORS",
    "sensitivity_sweep",
    "mistuning_sweep",
    "table_rows",
    "format_table",
    "write_table",
    "plot_case_errors",
    "fig3",
    "fig4",
    "fig5",
    "fig6",
    "mixture_figures",
    "maneuver_figure",
    "sweeps_figure",
    "study",
    "verdicts",
    "reproduce",
]
