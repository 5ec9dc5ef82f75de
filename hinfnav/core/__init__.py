"""Core layer: exceptions, input validation and small linear-algebra helpers.

Imports nothing from the rest of the package. The linear-algebra helpers
(which load scipy) are loaded on first use, so that the command line, which
needs only the exceptions, starts fast.
"""

import importlib

from .exceptions import (
    CertificationError,
    HinfnavError,
    InfeasibleLMIError,
    InputError,
    LooseBoundWarning,
    SolverAccuracyWarning,
    SynthesisError,
    UnstablePlantError,
)
from .validation import as_choice, as_int_at_least, as_matrix, as_nonnegative, as_positive, as_real, as_vector

_LAZY = {"as_covariance": "linalg", "discretize": "linalg", "spectral_radius": "linalg", "sym": "linalg"}


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'hinfnav.core' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value


__all__ = [
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
    "LooseBoundWarning",
    "SolverAccuracyWarning",
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
