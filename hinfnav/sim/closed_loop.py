"""Closed loop: plant, estimator and controller stepped together, vectorized over runs (the engine's closed loop).

At each t_k the plant is measured, the estimator updates with y_k and
reports x̂_k, the controller computes u_k (from x̂_k, or from the true x_k
for the idealized loop), the plant moves to x_{k+1} = Φ x_k + Γ u_k + B w_k
(or by its ``step``) and the estimator predicts with u_k
(:func:`hinfnav.sim.engine.closed_loop_batch`). The noise of run r comes from
the r-th child generator of the seed, drawn exactly as
:func:`hinfnav.sim.simulate_truth` draws it, so with a controller on the true
state both give the same truth.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..control.feedback import LinearFeedback
from ..core.exceptions import InputError
from .engine import HistorySink, resolve_estimator, run_monte_carlo

if TYPE_CHECKING:
    from ..design.result import DesignResult
    from ..estimators.base import Estimator
    from ..noise import NoiseModel
    from .result import SimulationResult


__all__ = ["simulate_closed_loop"]


def simulate_closed_loop(scenario: Any, estimator: str | Estimator | DesignResult, controller: LinearFeedback | None = None, *,
                         noise: str | NoiseModel = "gaussian", measurement_noise: str | NoiseModel | None = None, runs: int = 1,
                         seed: int | np.random.SeedSequence | np.random.Generator = 0, P0: ArrayLike | None = None, progress: bool = False,
                         batch_size: int = 100, keep_covariance: bool | str = False, diagnostics: bool = False,
                         **conditions: Any) -> SimulationResult:
    """Simulate the loop plant → measurement → estimator → controller → plant.

    Parameters
    ----------
    scenario : scenario object
        Provides ``truth_model(**conditions)`` and ``xhat0``.
    estimator : Estimator or str
    controller : LinearFeedback, optional
        The law; ``source="estimate"`` closes the loop through the estimator,
        ``"truth"`` is the idealized loop. Default: the truth model's own
        controller acting on the estimate.
    noise, measurement_noise, runs, seed, batch_size
        As in :func:`hinfnav.sim.simulate` (the numbers do not depend on ``batch_size``).
    P0 : array_like, optional
        Initial covariance of the estimator.
    progress : bool
    keep_covariance, diagnostics
        What the histories keep (off by default).
    **conditions
        The scenario's conditions.

    Returns
    -------
    SimulationResult
        ``u`` is the input actually applied.
    """
    if controller is not None and not isinstance(controller, LinearFeedback):
        raise InputError(f"controller must be a hinfnav LinearFeedback; got {type(controller).__name__}")
    estimator = resolve_estimator(scenario, estimator)
    out = run_monte_carlo(scenario, {estimator.name: estimator}, sink=HistorySink(scenario.xhat0, runs), runs=runs,
                          seed=seed, batch_size=batch_size, noise=noise, measurement_noise=measurement_noise,
                          controller=controller, closed_loop=True, P0=P0, keep_covariance=keep_covariance,
                          diagnostics=diagnostics, progress=progress, **conditions)
    return out[estimator.name]
