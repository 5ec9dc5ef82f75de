"""hinfnav: a research workbook on robust navigation filtering of spacecraft.

It reproduces, explains and extends Sun Zhao-wei, Deng Hong, Liu Hao, Zhong
Wei-chao, "Relative navigation algorithm for chaser satellite based on robust
H∞ filtering", Journal of Astronautics 32(7), 1462–1470, 2011
(DOI 10.3873/j.issn.1000-1328.2011.07.005), and its peer papers.

The package is layered, each layer importing only those before it:
``core`` → ``systems`` → ``noise`` → ``analysis`` → ``lmi`` → ``io`` →
``design`` → ``estimators`` → ``control`` → ``sim`` → ``metrics`` →
``plotting`` → ``campaign`` → ``papers`` → ``cli`` (checked by import-linter,
``pyproject.toml``, and at import time by ``tests/test_import_time.py``).
The names below are the generic public API a user starts from (about 50),
re-exported from those layers; the rest of each layer's API is in its
subpackage (``hinfnav.systems``, ``hinfnav.analysis``, …), and each paper's
names live in its own package, :mod:`hinfnav.papers.sun2011` and
its peers.

Names are loaded lazily (PEP 562, :mod:`hinfnav.core.lazy`): ``import hinfnav``
is cheap, and the heavy layers (cvxpy, python-control, matplotlib) are imported
on first use, so the command line starts fast.

Sun 2011's names (``Scenario``, ``design_for_scenario``, …), re-exported here
up to 0.2, live in :mod:`hinfnav.papers.sun2011` only (removed here in 0.3).
"""

import importlib
from typing import TYPE_CHECKING

from .core.lazy import exported_from, lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .core import (
        CertificationError, HinfnavError, InfeasibleLMIError, InputError, SynthesisError,
        UnstablePlantError,
    )
    from .core.protocols import (  # "X as X": re-exported, their __all__ entries read from this block
        CampaignTruthScenario as CampaignTruthScenario, DesignResultProtocol as DesignResultProtocol,
        DynamicsProtocol as DynamicsProtocol, EstimatorHooks as EstimatorHooks,
        MeasurementProtocol as MeasurementProtocol, OwnTruthScenario as OwnTruthScenario,
        ScenarioProtocol as ScenarioProtocol, TruthModelProtocol as TruthModelProtocol,
    )
    from .systems import (
        LinearMeasurement, LinearSystem, PolytopicSystem, RangeAzimuthElevation, Saturated, StateSpec, UncertainSystem,
    )
    from .noise import make_noise
    from .analysis import h2_norm, hinf_norm
    from .design import (
        DesignResult, recertify, SolverOptions,
        synthesize, synthesize_mixed, synthesize_polytopic,
    )
    from .estimators import (
        build_estimator, Estimator, ExtendedKalmanFilter,
        HuberFilter, LTIFilter, RecursiveHInfinityFilter, register_estimator, registered_estimators,
    )
    from .control import LinearFeedback
    from .sim import simulate, simulate_closed_loop, simulate_truth, SimulationResult, TruthModel
    from .metrics import monte_carlo_statistics, monte_carlo_summary, rms_error
    from .campaign import Campaign, load_campaign, read_campaign, run_campaign

_lazy_getattr, __dir__ = lazy_exports(__name__)


def __getattr__(name: str) -> object:
    if name == "__version__":  # the installed distribution's (see io.provenance.package_version); computed once
        globals()[name] = value = importlib.import_module(".io.provenance", __name__).package_version()
        return value
    return _lazy_getattr(name)

__all__ = [
    "__version__",
    # systems
    "StateSpec",
    "LinearSystem",
    "LinearMeasurement",
    "RangeAzimuthElevation",
    "Saturated",
    "UncertainSystem",
    "PolytopicSystem",
    # noise
    "make_noise",
    # analysis
    "hinf_norm",
    "h2_norm",
    # design
    "synthesize",
    "run_campaign",
    "load_campaign",
    "read_campaign",
    "Campaign",
    "synthesize_mixed",
    "HuberFilter",
    "RecursiveHInfinityFilter",
    "DesignResult",
    "SolverOptions",
    "synthesize_polytopic",
    "recertify",
    # estimators
    "Estimator",
    "LTIFilter",
    "ExtendedKalmanFilter",
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
    "monte_carlo_summary",
    "monte_carlo_statistics",
    # protocols (hinfnav.core.protocols): what your own scenario, system, sensor, filter, design offer
    *exported_from(__name__, ".core.protocols"),
    # errors
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
]
