"""Yang et al. (2020), extended-state filtering with saturated observations and ADRC of a drag-free satellite.

Acta Automatica Sinica 46(11):2337–2349, doi:10.16383/j.aas.c190515. Its Table 2
and simulation constants (:mod:`.constants`), the 18-state model and its
27-state extended form (:mod:`.model`), the scenario with every ambiguity a
named reading (:mod:`.scenario`), the registered estimators (:mod:`.filters`:
Algorithms 1-3 of :mod:`hinfnav.estimators.extended_state`), the closed loop
(:mod:`.loop`), studies and spectra (:mod:`.studies`), the claims
(:mod:`.claims`), Figs 5-12 (:mod:`.figures`) and ``reproduce``.
"""

from typing import TYPE_CHECKING

from ...core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports (each module loads on first use: importing the paper loads no figure or solver)
    from .campaign import CampaignScenario
    from .claims import evaluate_claims, format_claims
    from .constants import CITATION, READING_REASONS, READINGS, REQUIREMENT_ASD, TABLE2
    from .figures import fig5, fig6, fig7, fig8, fig9, fig10, fig11, fig12, plot_asd, plot_series, plot_truncated_update
    from .filters import ESTIMATOR_NAMES, L_MODES, SUBSYSTEM_OF, build_alg1, build_alg2, build_fused
    from .loop import PASSIVE, LoopResult, residual_acceleration, run_closed_loop, run_closed_loops
    from .model import (
        DRAGFREE_INDICES,
        DragFreeModel,
        disturbance,
        drag_free_model,
        dragfree_state_spec,
        extended_state_spec,
        increment_bounds,
        noise_std,
        omega_d,
        plant_state_spec,
    )
    from .reproduce import READING_RUNS, algorithm_windows, integral_study, reading_study, reproduce
    from .scenario import CONTROLLERS, SUBSYSTEMS, Scenario
    from .studies import (
        NPERSEG,
        amplitude_spectral_density,
        band_statistics,
        disturbance_errors,
        estimation_errors,
        linear_loop_radius,
        periodic_amplitude,
        residual_spectrum,
        saturation_summary,
        step_response,
    )

__all__ = [
    "CampaignScenario",
    "CITATION",
    "TABLE2",
    "READINGS",
    "READING_REASONS",
    "REQUIREMENT_ASD",
    "DragFreeModel",
    "drag_free_model",
    "disturbance",
    "increment_bounds",
    "noise_std",
    "omega_d",
    "plant_state_spec",
    "extended_state_spec",
    "dragfree_state_spec",
    "DRAGFREE_INDICES",
    "Scenario",
    "CONTROLLERS",
    "SUBSYSTEMS",
    "build_alg1",
    "build_alg2",
    "build_fused",
    "ESTIMATOR_NAMES",
    "SUBSYSTEM_OF",
    "L_MODES",
    "LoopResult",
    "run_closed_loop",
    "run_closed_loops",
    "residual_acceleration",
    "PASSIVE",
    "NPERSEG",
    "amplitude_spectral_density",
    "band_statistics",
    "residual_spectrum",
    "disturbance_errors",
    "estimation_errors",
    "periodic_amplitude",
    "step_response",
    "saturation_summary",
    "evaluate_claims",
    "format_claims",
    "linear_loop_radius",
    "plot_truncated_update",
    "fig5",
    "fig6",
    "fig7",
    "fig8",
    "fig9",
    "fig10",
    "fig11",
    "fig12",
    "plot_series",
    "plot_asd",
    "reproduce",
    "READING_RUNS",
    "reading_study",
    "integral_study",
    "algorithm_windows",
]

__getattr__, __dir__ = lazy_exports(__name__)
