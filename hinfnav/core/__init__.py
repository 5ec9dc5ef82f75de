"""Core layer: exceptions, input validation and small linear-algebra helpers.

Imports nothing from the rest of the package.
"""

from .exceptions import (
    CertificationError,
    HinfnavError,
    InfeasibleLMIError,
    InputError,
    SynthesisError,
    UnstablePlantError,
)
from .linalg import as_covariance, discretize, spectral_radius, sym
from .validation import as_choice, as_int_at_least, as_matrix, as_nonnegative, as_positive, as_real, as_vector

__all__ = [
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
    "as_matrix",
    "as_vector",
    "as_real",
    "as_positive",
    "as_nonnegative",
    "as_int_at_least",
    "as_choice",
    "as_covariance",
    "spectral_radius",
    "sym",
    "discretize",
]
