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

Names are loaded lazily (PEP 562): ``import hinfnav`` is cheap, and the heavy
layers (cvxpy, python-control, matplotlib) are imported on first use, so the
command line starts fast.
"""

import importlib

from .io.provenance import package_version

#: Public name -> the module (relative to this package) it comes from.
_EXPORTS = {
    "h2_norm": "analysis",
    "hinf_norm": "analysis",
    "observer_form": "analysis",
    "steady_state_hinf": "analysis",
    "steady_state_kalman": "analysis",
    "truncated_normal_moments": "analysis",
    "worst_case_norm": "analysis",
    "LinearFeedback": "control",
    "CertificationError": "core",
    "HinfnavError": "core",
    "InfeasibleLMIError": "core",
    "InputError": "core",
    "SynthesisError": "core",
    "UnstablePlantError": "core",
    "discretize": "core",
    "SampleSet": "design",
    "SolverOptions": "design",
    "SynthesisResult": "design",
    "PolytopicResult": "design",
    "synthesize_polytopic": "design",
    "recertify": "design",
    "PolytopicSystem": "systems",
    "two_mass_spring": "systems",
    "synthesize": "design",
    "run_campaign": "campaign",
    "load_campaign": "campaign",
    "read_campaign": "campaign",
    "Campaign": "campaign",
    "synthesize_mixed": "design",
    "MixedSynthesisResult": "design",
    "HuberFilter": "estimators",
    "RecursiveHInfinityFilter": "estimators",
    "mixed_design_for_scenario": "papers.sun2011",
    "EstimateHistory": "estimators",
    "Estimator": "estimators",
    "ExtendedKalmanFilter": "estimators",
    "FilterState": "estimators",
    "LTIFilter": "estimators",
    "StepOutput": "estimators",
    "build_estimator": "estimators",
    "huber_update": "estimators",
    "register_estimator": "estimators",
    "registered_estimators": "estimators",
    "convergence_time": "metrics",
    "max_error": "metrics",
    "monte_carlo_summary": "metrics",
    "monte_carlo_statistics": "metrics",
    "rms_error": "metrics",
    "rms_per_run": "metrics",
    "NOISE_NAMES": "noise",
    "make_noise": "noise",
    "EKF": "papers.sun2011",
    "FILTER_NAMES": "papers.sun2011",
    "GammaSweep": "papers.sun2011",
    "KalmanLimit": "papers.sun2011",
    "Scenario": "papers.sun2011",
    "build_ekf": "papers.sun2011",
    "compare_with_published": "papers.sun2011",
    "design_for_scenario": "papers.sun2011",
    "design_report": "papers.sun2011",
    "gamma_sweep": "papers.sun2011",
    "infer_sampling_time": "papers.sun2011",
    "kalman_limit": "papers.sun2011",
    "load_design": "papers.sun2011",
    "lti_error_covariance": "papers.sun2011",
    "make_estimator": "papers.sun2011",
    "published_filter": "papers.sun2011",
    "range_angle_measurements": "papers.sun2011",
    "save_design": "papers.sun2011",
    "SimulationResult": "sim",
    "TruthModel": "sim",
    "simulate": "sim",
    "simulate_closed_loop": "sim",
    "simulate_truth": "sim",
    "LinearMeasurement": "systems",
    "LinearSystem": "systems",
    "MeasurementModel": "systems",
    "RangeAzimuthElevation": "systems",
    "Saturated": "systems",
    "StateSpec": "systems",
    "UncertainSystem": "systems",
    "hill_matrices": "systems",
    "position_from_range_angles": "systems",
    "range_angles": "systems",
    "uncertainty_F": "systems",
    "uncertainty_structure": "systems",
}


def __getattr__(name):
    if name == "__version__":  # from git in a checkout (see core.provenance.package_version); computed once
        globals()[name] = value = package_version()
        return value
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'hinfnav' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


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
    "PolytopicSystem",
    "two_mass_spring",
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
    "run_campaign",
    "load_campaign",
    "read_campaign",
    "Campaign",
    "synthesize_mixed",
    "MixedSynthesisResult",
    "mixed_design_for_scenario",
    "HuberFilter",
    "RecursiveHInfinityFilter",
    "SynthesisResult",
    "SolverOptions",
    "SampleSet",
    "synthesize_polytopic",
    "PolytopicResult",
    "recertify",
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
    "monte_carlo_statistics",
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
    "save_design",
    "load_design",
    # errors
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
]
