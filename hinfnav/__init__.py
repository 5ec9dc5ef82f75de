"""hinfnav: robust H∞ relative navigation of a chaser satellite.

A research workbook reproducing and extending Sun Zhao-wei, Deng Hong,
Liu Hao, Zhong Wei-chao, "Relative navigation algorithm for chaser
satellite based on robust H∞ filtering", Journal of Astronautics 32(7),
1462–1470, 2011 (DOI 10.3873/j.issn.1000-1328.2011.07.005).
"""

from .ekf import EKF, build_ekf, position_from_range_angles, range_angle_measurements, range_angles
from .estimators import EstimateHistory, Estimator, LTIFilter
from .exceptions import (
    CertificationError,
    HinfnavError,
    InfeasibleLMIError,
    InputError,
    SynthesisError,
    UnstablePlantError,
)
from .filters import FILTER_NAMES, make_estimator
from .kalman import KalmanLimit, kalman_limit, lti_error_covariance, steady_state_kalman
from .metrics import convergence_time, max_error, monte_carlo_summary, rms_error, rms_per_run
from .models import UncertainSystem, discretize, hill_matrices, uncertainty_F, uncertainty_structure
from .noise import NOISE_NAMES, make_noise
from .scenario import Scenario, infer_sampling_time, published_filter
from .simulation import SimulationResult, simulate, simulate_truth
from .synthesis import (
    GammaSweep,
    SynthesisResult,
    compare_with_published,
    design_for_scenario,
    design_report,
    gamma_sweep,
    synthesize,
)

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "Scenario",
    "published_filter",
    "infer_sampling_time",
    "UncertainSystem",
    "hill_matrices",
    "uncertainty_structure",
    "uncertainty_F",
    "discretize",
    "make_noise",
    "NOISE_NAMES",
    "Estimator",
    "EstimateHistory",
    "LTIFilter",
    "make_estimator",
    "EKF",
    "build_ekf",
    "range_angles",
    "range_angle_measurements",
    "position_from_range_angles",
    "kalman_limit",
    "KalmanLimit",
    "steady_state_kalman",
    "lti_error_covariance",
    "FILTER_NAMES",
    "synthesize",
    "SynthesisResult",
    "design_for_scenario",
    "gamma_sweep",
    "GammaSweep",
    "design_report",
    "compare_with_published",
    "simulate",
    "simulate_truth",
    "SimulationResult",
    "rms_error",
    "rms_per_run",
    "max_error",
    "convergence_time",
    "monte_carlo_summary",
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
]
