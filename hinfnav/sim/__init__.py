"""Simulation layer: open-loop truth, closed loop, Monte Carlo with seeding and batching."""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # what static type checkers read; the same names as _EXPORTS (tests/test_import_time.py)
    from .closed_loop import simulate_closed_loop
    from .montecarlo import SimulationResult, resolve_estimator, run_estimator, simulate, simulate_batches
    from .truth import Truth, TruthModel, child_rngs, draw_noise, noise_models, simulate_truth

#: Public name -> the module it comes from, imported on first use (PEP 562, :mod:`hinfnav.core.lazy`).
_EXPORTS = {
    "simulate_closed_loop": ".closed_loop",
    "SimulationResult": ".montecarlo",
    "resolve_estimator": ".montecarlo",
    "run_estimator": ".montecarlo",
    "simulate": ".montecarlo",
    "simulate_batches": ".montecarlo",
    "Truth": ".truth",
    "TruthModel": ".truth",
    "child_rngs": ".truth",
    "draw_noise": ".truth",
    "noise_models": ".truth",
    "simulate_truth": ".truth",
}

__all__ = [
    "TruthModel",
    "Truth",
    "SimulationResult",
    "simulate_truth",
    "simulate",
    "simulate_batches",
    "run_estimator",
    "resolve_estimator",
    "simulate_closed_loop",
    "child_rngs",
    "noise_models",
    "draw_noise",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
