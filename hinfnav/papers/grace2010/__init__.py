"""Real formation flying: every filter on GRACE-A/B, 27 July 2010, against centimetre truth (issue 20).

Not a paper: a real-data study. The vendored data and their loader, the inertial and Hill-frame truth
(:mod:`.dataset`), continuous orbital dynamics with RK4 (:mod:`.dynamics`), the measured model mismatch
(:mod:`.mismatch`), the measurement variants (:mod:`.measurements`), the estimators (:mod:`.filters`),
the runs and metrics (:mod:`.studies`), the figures (:mod:`.figures`) and ``reproduce``.
"""

from .constants import CITATION, DT_S, TRUTH_SIGMA_M
from .dataset import (
    GraceData,
    ecef_to_inertial,
    hill_to_inertial,
    inertial_to_ecef,
    inertial_to_hill,
    load,
)
from .dynamics import MODELS, hill_linear, pair, rk4, two_body, two_body_j2
from .figures import errors_figure, mismatch_figure, truth_figure
from .filters import (
    FILTER_NAMES,
    NonlinearPredictionEKF,
    build_filters,
    lmi_designs,
    model_mismatch_moment,
)
from .measurements import (
    VARIANTS,
    MeasurementSet,
    kband_noise,
    linear_form,
    make_measurements,
)
from .mismatch import (
    chief_rate_range,
    hill_transition,
    one_step_mismatch,
    propagation_errors,
)
from .reproduce import DESIGN_DELTA_BAR, kband_check, reproduce, run_study, table_rows
from .studies import error_metrics, nees, run_filter

__all__ = [
    "CITATION", "DT_S", "TRUTH_SIGMA_M", "GraceData", "load", "ecef_to_inertial", "inertial_to_ecef",
    "inertial_to_hill", "hill_to_inertial", "MODELS", "two_body", "two_body_j2", "hill_linear", "pair", "rk4",
    "truth_figure", "mismatch_figure", "errors_figure", "FILTER_NAMES", "NonlinearPredictionEKF", "build_filters",
    "lmi_designs", "model_mismatch_moment", "VARIANTS", "MeasurementSet", "kband_noise", "linear_form",
    "make_measurements", "hill_transition", "one_step_mismatch", "propagation_errors", "chief_rate_range",
    "DESIGN_DELTA_BAR", "kband_check", "reproduce", "run_study", "table_rows", "error_metrics", "nees", "run_filter",
]
