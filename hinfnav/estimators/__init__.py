"""Estimators layer: the step contract and the estimators built on it.

Never imports the design or simulation layers: a designed filter comes in as
matrices.
"""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .base import EstimateHistory, Estimator, FilterState, StepOutput, check_estimator_inputs
    from .huber import HuberUpdate, huber_update
    from .adaptive import RateAdaptive, StrongTracking
    from .augmented import AugmentedEKF, AugmentedInputAdaptiveKF, AugmentedInputHuberSTKF, AugmentedInputKF, AugmentedInputSTKF
    from .extended_state import ExtendedStateKalmanFilter
    from .saturated_state import FusedExtendedStateFilter, SaturatedExtendedStateFilter
    from .correction import KalmanCorrection, drop_missing, joseph_covariance, joseph_update, kalman_gain
    from .huber_filter import HuberCorrection, HuberFilter, HuberStrongTrackingEKF
    from .recursive_hinf import ExtendedHInfinityFilter, RecursiveHInfinityFilter
    from .kalman import OUTPUTS, ExtendedKalmanFilter, KalmanCore, RateAdaptiveEKF, StrongTrackingEKF
    from .lti import LTIFilter
    from .variational import NoiseAdaptiveFilter, StudentTFilter
    from .correntropy import CorrentropyFilter
    from .gate import ChiSquareGate, gate_report, gated
    from .sigma_point import SigmaPointFilter
    from .smoothers import SmoothedHistory, filter_smoother_consistency, smooth
    from .sqrt import SquareRootEKF, SquareRootSigmaPointFilter, square_root
    from .timed import estimate_timed, smooth_timed
    from .hinf_smoother import hinf_fixed_lag
    from .registry import build_estimator, estimator_entry, register_estimator, registered_estimators

__all__ = [
    "Estimator",
    "EstimateHistory",
    "FilterState",
    "StepOutput",
    "check_estimator_inputs",
    "LTIFilter",
    "ExtendedKalmanFilter",
    "OUTPUTS",
    "huber_update",
    "HuberUpdate",
    "HuberFilter",
    "KalmanCore",
    "HuberCorrection",
    "KalmanCorrection",
    "joseph_update",
    "joseph_covariance",
    "kalman_gain",
    "drop_missing",
    "AugmentedInputHuberSTKF",
    "ExtendedStateKalmanFilter",
    "SaturatedExtendedStateFilter",
    "FusedExtendedStateFilter",
    "RecursiveHInfinityFilter",
    "ExtendedHInfinityFilter",
    "SigmaPointFilter",
    "StrongTracking",
    "StrongTrackingEKF",
    "HuberStrongTrackingEKF",
    "RateAdaptiveEKF",
    "RateAdaptive",
    "AugmentedEKF",
    "AugmentedInputKF",
    "AugmentedInputSTKF",
    "AugmentedInputAdaptiveKF",
    "StudentTFilter",
    "NoiseAdaptiveFilter",
    "CorrentropyFilter",
    "ChiSquareGate",
    "gate_report",
    "gated",
    "register_estimator",
    "build_estimator",
    "registered_estimators",
    "estimator_entry",
    "smooth",
    "SmoothedHistory",
    "filter_smoother_consistency",
    "SquareRootEKF",
    "SquareRootSigmaPointFilter",
    "square_root",
    "estimate_timed",
    "smooth_timed",
    "hinf_fixed_lag",
]

__getattr__, __dir__ = lazy_exports(__name__)
