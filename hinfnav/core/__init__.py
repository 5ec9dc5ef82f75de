"""Core layer: exceptions, input validation and small linear-algebra helpers.

Imports nothing from the rest of the package, and writes no file (file I/O is
the :mod:`hinfnav.io` layer). The linear-algebra helpers (which load scipy) are
loaded on first use (PEP 562, :mod:`hinfnav.core.lazy`), so that the command
line, which needs only the exceptions, starts fast.
"""

from typing import TYPE_CHECKING

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
from .lazy import lazy_exports
from .validation import as_choice, as_int_at_least, as_matrix, as_nonnegative, as_positive, as_real, as_vector

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .linalg import as_covariance, discretize, spectral_radius, sym
    from .protocols import (
        CampaignTruthScenario, DesignResultProtocol, DynamicsProtocol, EstimatorHooks, MeasurementProtocol,
        OwnTruthScenario, ScenarioProtocol, TruthModelProtocol,
    )

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
    "ScenarioProtocol",
    "OwnTruthScenario",
    "CampaignTruthScenario",
    "TruthModelProtocol",
    "DynamicsProtocol",
    "MeasurementProtocol",
    "EstimatorHooks",
    "DesignResultProtocol",
]

__getattr__, __dir__ = lazy_exports(__name__)
