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
from .lazy import exported_from, lazy_exports
from .validation import as_choice, as_int_at_least, as_matrix, as_nonnegative, as_positive, as_real, as_vector

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .linalg import as_covariance, discretize, spectral_radius, sym
    from .protocols import (  # "X as X": re-exported, their __all__ entries read from this block
        CampaignTruthScenario as CampaignTruthScenario, DesignResultProtocol as DesignResultProtocol,
        DynamicsProtocol as DynamicsProtocol, EstimatorHooks as EstimatorHooks,
        MeasurementProtocol as MeasurementProtocol, OwnTruthScenario as OwnTruthScenario,
        ScenarioProtocol as ScenarioProtocol, TruthModelProtocol as TruthModelProtocol,
    )

__getattr__, __dir__ = lazy_exports(__name__)

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
    *exported_from(__name__, ".protocols"),
]
