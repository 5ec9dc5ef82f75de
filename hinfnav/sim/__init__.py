"""Simulation layer: truths (linear and nonlinear), the one Monte Carlo engine, the one stepped closed loop and their uses."""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .closed_loop import simulate_closed_loop
    from .engine import HistorySink, Sink, run_monte_carlo
    from .montecarlo import resolve_estimator, run_estimator, simulate, simulate_batches
    from .result import SimulationResult
    from .stepped import run_stepped
    from .truth import Truth, TruthModel, child_rngs, draw_noise, noise_models, simulate_truth

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
    "run_monte_carlo",
    "HistorySink",
    "Sink",
    "run_stepped",
    "child_rngs",
    "noise_models",
    "draw_noise",
]

__getattr__, __dir__ = lazy_exports(__name__)
