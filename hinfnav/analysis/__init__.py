"""Analysis layer: norms, certificates and Riccati limits, computed without an SDP solver.

Nothing here imports cvxpy or trusts a solver's status.
"""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .certificates import LMICertificate, brl_blocks, brl_matrix, certify_negative_definite, schur_gamma
    from .error_system import WorstCase, error_system, error_system_matrices, worst_case_norm
    from .norms import NORM_TOL, channel_norms, frequency_grid, frequency_response_sigma, h2_norm, hinf_norm, hinf_norm_bisection, hinf_norm_grid
    from .hinf_riccati import max_admissible_theta, steady_state_hinf
    from .observer import observer_form
    from .pcrb import measurement_information, noise_fisher_information, posterior_crb, rms_bound
    from .riccati import stationary_lti_error_covariance, steady_state_kalman
    from .truncated import truncated_normal_moments

__all__ = [
    "NORM_TOL",
    "hinf_norm",
    "hinf_norm_bisection",
    "hinf_norm_grid",
    "h2_norm",
    "frequency_grid",
    "frequency_response_sigma",
    "channel_norms",
    "error_system",
    "error_system_matrices",
    "WorstCase",
    "worst_case_norm",
    "schur_gamma",
    "certify_negative_definite",
    "LMICertificate",
    "brl_matrix",
    "brl_blocks",
    "stationary_lti_error_covariance",
    "steady_state_kalman",
    "observer_form",
    "steady_state_hinf",
    "max_admissible_theta",
    "truncated_normal_moments",
    "posterior_crb",
    "rms_bound",
    "noise_fisher_information",
    "measurement_information",
]

__getattr__, __dir__ = lazy_exports(__name__)
