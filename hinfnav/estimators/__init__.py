"""Estimators layer: the step contract and the estimators built on it.

Never imports the design or simulation layers: a designed filter comes in as
matrices.
"""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # what static type checkers read; the same names as _EXPORTS (tests/test_import_time.py)
    from .base import EstimateHistory, Estimator, FilterState, StepOutput, check_estimator_inputs
    from .huber import HuberUpdate, huber_update
    from .adaptive import RateAdaptive, StrongTracking
    from .augmented import AugmentedEKF, AugmentedInputAdaptiveKF, AugmentedInputHuberSTKF, AugmentedInputKF, AugmentedInputSTKF
    from .extended_state import ExtendedStateKalmanFilter
    from .saturated_state import FusedExtendedStateFilter, SaturatedExtendedStateFilter
    from .correction import KalmanCorrection, drop_missing, joseph_update, kalman_gain
    from .huber_filter import HuberCorrection, HuberFilter
    from .recursive_hinf import RecursiveHInfinityFilter
    from .kalman import OUTPUTS, ExtendedKalmanFilter, KalmanCore, StrongTrackingEKF
    from .lti import LTIFilter
    from .sigma_point import SigmaPointFilter
    from .registry import build_estimator, estimator_entry, register_estimator, registered_estimators

#: Public name -> the module it comes from, imported on first use (PEP 562, :mod:`hinfnav.core.lazy`).
_EXPORTS = {
    "EstimateHistory": ".base",
    "Estimator": ".base",
    "FilterState": ".base",
    "StepOutput": ".base",
    "check_estimator_inputs": ".base",
    "HuberUpdate": ".huber",
    "huber_update": ".huber",
    "RateAdaptive": ".adaptive",
    "StrongTracking": ".adaptive",
    "AugmentedEKF": ".augmented",
    "AugmentedInputAdaptiveKF": ".augmented",
    "AugmentedInputHuberSTKF": ".augmented",
    "AugmentedInputKF": ".augmented",
    "AugmentedInputSTKF": ".augmented",
    "ExtendedStateKalmanFilter": ".extended_state",
    "FusedExtendedStateFilter": ".saturated_state",
    "SaturatedExtendedStateFilter": ".saturated_state",
    "KalmanCorrection": ".correction",
    "drop_missing": ".correction",
    "joseph_update": ".correction",
    "kalman_gain": ".correction",
    "HuberCorrection": ".huber_filter",
    "HuberFilter": ".huber_filter",
    "RecursiveHInfinityFilter": ".recursive_hinf",
    "OUTPUTS": ".kalman",
    "ExtendedKalmanFilter": ".kalman",
    "KalmanCore": ".kalman",
    "StrongTrackingEKF": ".kalman",
    "LTIFilter": ".lti",
    "SigmaPointFilter": ".sigma_point",
    "build_estimator": ".registry",
    "estimator_entry": ".registry",
    "register_estimator": ".registry",
    "registered_estimators": ".registry",
}

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
    "kalman_gain",
    "drop_missing",
    "AugmentedInputHuberSTKF",
    "ExtendedStateKalmanFilter",
    "SaturatedExtendedStateFilter",
    "FusedExtendedStateFilter",
    "RecursiveHInfinityFilter",
    "SigmaPointFilter",
    "StrongTracking",
    "StrongTrackingEKF",
    "RateAdaptive",
    "AugmentedEKF",
    "AugmentedInputKF",
    "AugmentedInputSTKF",
    "AugmentedInputAdaptiveKF",
    "register_estimator",
    "build_estimator",
    "registered_estimators",
    "estimator_entry",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
