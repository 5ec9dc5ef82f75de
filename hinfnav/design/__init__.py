"""Design layer: generic, certified robust filter synthesis (no scenario defaults).

Every filter returned is certified with :mod:`hinfnav.analysis`, whatever
the solver reported.
"""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from ..lmi.solve import SOLVERS, SolverOptions
    from .from_file import design_from_system_file, design_summary
    from .io import check_design_system, load_design, save_design, system_fingerprint
    from .mixed import MixedFront, front_gammas, mixed_row, knee_index, mixed_front, synthesize_mixed
    from .compare import compare_uncertainty_models
    from .continuous import design_continuous_system, synthesize_continuous_observer
    from .discretised import DiscreteAtRate, design_discrete_at_rate
    from .explain import small_gain_number
    from .polytopic import certify_polytopic, synthesize_polytopic
    from .recertify import recertify
    from .result import DesignResult
    from .robust_hinf import FORMS, synthesize
    from .samples import SampleSet, check_plant, check_samples, default_uncertainty_samples

__all__ = [
    "synthesize",
    "synthesize_mixed",
    "mixed_front",
    "mixed_row",
    "MixedFront",
    "front_gammas",
    "knee_index",
    "DesignResult",
    "SolverOptions",
    "SOLVERS",
    "FORMS",
    "SampleSet",
    "default_uncertainty_samples",
    "check_samples",
    "check_plant",
    "save_design",
    "load_design",
    "check_design_system",
    "system_fingerprint",
    "synthesize_polytopic",
    "certify_polytopic",
    "small_gain_number",
    "recertify",
    "design_from_system_file",
    "design_summary",
    "compare_uncertainty_models",
    "design_continuous_system",
    "synthesize_continuous_observer",
    "DiscreteAtRate",
    "design_discrete_at_rate",
]

__getattr__, __dir__ = lazy_exports(__name__)
