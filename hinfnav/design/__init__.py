"""Design layer: generic, certified robust filter synthesis (no scenario defaults).

Every filter returned is certified with :mod:`hinfnav.analysis`, whatever
the solver reported.
"""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # what static type checkers read; the same names as _EXPORTS (tests/test_import_time.py)
    from ..lmi.solve import SOLVERS, SolverOptions
    from .from_file import design_from_system_file, design_summary
    from .io import check_design_system, load_design, save_design, system_fingerprint
    from .mixed import MixedFront, MixedSynthesisResult, front_gammas, knee_index, mixed_front, synthesize_mixed
    from .compare import compare_uncertainty_models
    from .explain import small_gain_number
    from .polytopic import PolytopicResult, certify_polytopic, synthesize_polytopic
    from .recertify import recertify
    from .result import SynthesisResult
    from .robust_hinf import FORMS, synthesize
    from .samples import SampleSet, check_plant, check_samples, default_uncertainty_samples

#: Public name -> the module it comes from, imported on first use (PEP 562, :mod:`hinfnav.core.lazy`).
_EXPORTS = {
    "SOLVERS": "..lmi.solve",
    "SolverOptions": "..lmi.solve",
    "design_from_system_file": ".from_file",
    "design_summary": ".from_file",
    "check_design_system": ".io",
    "load_design": ".io",
    "save_design": ".io",
    "system_fingerprint": ".io",
    "MixedFront": ".mixed",
    "MixedSynthesisResult": ".mixed",
    "front_gammas": ".mixed",
    "knee_index": ".mixed",
    "mixed_front": ".mixed",
    "synthesize_mixed": ".mixed",
    "compare_uncertainty_models": ".compare",
    "small_gain_number": ".explain",
    "PolytopicResult": ".polytopic",
    "certify_polytopic": ".polytopic",
    "synthesize_polytopic": ".polytopic",
    "recertify": ".recertify",
    "SynthesisResult": ".result",
    "FORMS": ".robust_hinf",
    "synthesize": ".robust_hinf",
    "SampleSet": ".samples",
    "check_plant": ".samples",
    "check_samples": ".samples",
    "default_uncertainty_samples": ".samples",
}

__all__ = [
    "synthesize",
    "synthesize_mixed",
    "mixed_front",
    "MixedSynthesisResult",
    "MixedFront",
    "front_gammas",
    "knee_index",
    "SynthesisResult",
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
    "PolytopicResult",
    "small_gain_number",
    "recertify",
    "design_from_system_file",
    "design_summary",
    "compare_uncertainty_models",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
