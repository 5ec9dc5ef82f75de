"""hinfnav: a research workbook on robust navigation filtering of spacecraft.

It reproduces, explains and extends Sun Zhao-wei, Deng Hong, Liu Hao, Zhong
Wei-chao, "Relative navigation algorithm for chaser satellite based on robust
H∞ filtering", Journal of Astronautics 32(7), 1462–1470, 2011
(DOI 10.3873/j.issn.1000-1328.2011.07.005), and its peer papers.

The package is layered, each layer importing only those before it:
``core`` → ``systems`` → ``noise`` → ``analysis`` → ``lmi`` → ``design`` →
``estimators`` → ``control`` → ``sim`` → ``metrics`` → ``plotting`` →
``papers`` → ``cli`` (checked by import-linter, ``pyproject.toml``).
The names below are the public API, re-exported from those layers.
"""

from .analysis import (
    h2_norm,
    hinf_norm,
    observer_form,
    steady_state_hinf,
    steady_state_kalman,
    truncated_normal_moments,
    worst_case_norm,
)
from .control import LinearFeedback
from .core import (
    CertificationError,
    HinfnavError,
    InfeasibleLMIError,
    InputError,
    SynthesisError,
    UnstablePlantError,
    discretize,
)
from .design import SampleSet, SolverOptions, SynthesisResult, synthesize
from .estimators import (
    EstimateHistory,
    Estimator,
    ExtendedKalmanFilter,
    FilterState,
    LTIFilter,
    StepOutput,
    build_estimator,
    huber_update,
    register_estimator,
    registered_estimators,
)
from .metrics import convergence_time, max_error, monte_carlo_summary, rms_error, rms_per_run
from .noise import NOISE_NAMES, make_noise
from .papers.sun2011 import (
    EKF,
    FILTER_NAMES,
    GammaSweep,
    KalmanLimit,
    Scenario,
    build_ekf,
    compare_with_published,
    design_for_scenario,
    design_report,
    gamma_sweep,
    infer_sampling_time,
    kalman_limit,
    lti_error_covariance,
    make_estimator,
    published_filter,
    range_angle_measurements,
)
from .sim import SimulationResult, TruthModel, simulate, simulate_closed_loop, simulate_truth
from .systems import (
    LinearMeasurement,
    LinearSystem,
    MeasurementModel,
    RangeAzimuthElevation,
    Saturated,
    StateSpec,
    UncertainSystem,
    hill_matrices,
    position_from_range_angles,
    range_angles,
    uncertainty_F,
    uncertainty_structure,
)

__version__ = "0.2.0"

__all__ = [
    "__version__",
    # systems
    "StateSpec",
    "LinearSystem",
    "MeasurementModel",
    "LinearMeasurement",
    "RangeAzimuthElevation",
    "Saturated",
    "UncertainSystem",
    "hill_matrices",
    "uncertainty_structure",
    "uncertainty_F",
    "discretize",
    "range_angles",
    "position_from_range_angles",
    # noise
    "make_noise",
    "NOISE_NAMES",
    # analysis
    "hinf_norm",
    "h2_norm",
    "worst_case_norm",
    "steady_state_kalman",
    "observer_form",
    "steady_state_hinf",
    "truncated_normal_moments",
    # design
    "synthesize",
    "SynthesisResult",
    "SolverOptions",
    "SampleSet",
    # estimators
    "Estimator",
    "EstimateHistory",
    "FilterState",
    "StepOutput",
    "LTIFilter",
    "ExtendedKalmanFilter",
    "huber_update",
    "register_estimator",
    "build_estimator",
    "registered_estimators",
    # control and simulation
    "LinearFeedback",
    "TruthModel",
    "simulate",
    "simulate_truth",
    "simulate_closed_loop",
    "SimulationResult",
    # metrics
    "rms_error",
    "rms_per_run",
    "max_error",
    "convergence_time",
    "monte_carlo_summary",
    # Sun et al. (2011)
    "Scenario",
    "published_filter",
    "infer_sampling_time",
    "make_estimator",
    "FILTER_NAMES",
    "EKF",
    "build_ekf",
    "range_angle_measurements",
    "kalman_limit",
    "KalmanLimit",
    "lti_error_covariance",
    "design_for_scenario",
    "gamma_sweep",
    "GammaSweep",
    "design_report",
    "compare_with_published",
    # errors
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
]
