"""Closed loop: plant, estimator and controller stepped together, vectorized over runs.

At each t_k the plant is measured, the estimator updates with y_k and
reports x̂_k, the controller computes u_k (from x̂_k, or from the true x_k
for the idealized loop), the plant moves to x_{k+1} = Φ x_k + Γ u_k + B w_k
and the estimator predicts with u_k. The noise of run r comes from the r-th
child generator of the seed, drawn exactly as :func:`hinfnav.sim.simulate_truth`
draws it, so with a controller on the true state both give the same truth.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike
from tqdm import tqdm

from ..control.feedback import LinearFeedback
from ..core.exceptions import InputError
from ..io.progress import bar_disabled
from ..core.validation import as_int_at_least
from .montecarlo import SimulationResult, resolve_estimator
from .truth import child_rngs, draw_noise, noise_models, scenario_truth_model

if TYPE_CHECKING:
    from ..design.result import SynthesisResult
    from ..estimators.base import Estimator
    from ..noise import NoiseModel


__all__ = ["simulate_closed_loop"]


def simulate_closed_loop(scenario: Any, estimator: str | Estimator | SynthesisResult, controller: LinearFeedback | None = None, *,
                         noise: str | NoiseModel = "gaussian", measurement_noise: str | NoiseModel | None = None, runs: int = 1,
                         seed: int | np.random.SeedSequence | np.random.Generator = 0, P0: ArrayLike | None = None, progress: bool = False,
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
    noise, measurement_noise, runs, seed
        As in :func:`hinfnav.sim.simulate`.
    P0 : array_like, optional
        Initial covariance of the estimator.
    progress : bool
    **conditions
        The scenario's conditions.

    Returns
    -------
    SimulationResult
        ``u`` is the input actually applied.
    """
    model = scenario_truth_model(scenario, conditions)
    estimator = resolve_estimator(estimator, scenario)
    if controller is None:
        if model.controller is None:
            raise InputError("controller must be given: this truth model has no feedback law")
        controller = model.controller.acting_on("estimate")
    if not isinstance(controller, LinearFeedback):
        raise InputError(f"controller must be a hinfnav LinearFeedback; got {type(controller).__name__}")
    runs = as_int_at_least("runs", runs, 1)
    if isinstance(seed, np.random.Generator):
        seed = int(seed.integers(2**63))
    system, meas = model.system, model.measurement
    if controller.n_input != system.n_input or controller.n_state != system.n:
        raise InputError(f"controller gain must be {system.n_input}x{system.n}; got {controller.K.shape}")
    w_model, v_model = noise_models(noise, measurement_noise, system.dt)
    n1 = model.n_steps + 1
    w, v = draw_noise(w_model, v_model, child_rngs(seed, runs), n1, system.n_noise, meas.n_noise)
    x = np.empty((runs, n1, system.n))
    xhat = np.empty_like(x)
    u = np.empty((runs, n1, system.n_input))
    y = np.empty((runs, n1, meas.n_meas))
    x[:, 0] = model.x0
    state = estimator.start(np.asarray(scenario.xhat0, dtype=float), P0, runs)
    for k in tqdm(range(n1), disable=bar_disabled(progress), desc=f"closed loop ({estimator.name})", unit="step", leave=False):
        y[:, k] = meas.measure(x[:, k], v[:, k])
        state, out = estimator.update(state, y[:, k])
        xhat[:, k] = out.xhat
        u[:, k] = controller(xhat[:, k] if controller.source == "estimate" else x[:, k])
        if k < n1 - 1:
            x[:, k + 1] = system.propagate(x[:, k], u[:, k], w[:, k])
            state = estimator.predict(state, u[:, k])
    settings = dict(model.settings)
    settings.update(noise=w_model.name, measurement_noise=v_model.name, runs=runs,
                    seed=seed if isinstance(seed, (int, np.integer)) else repr(seed),
                    filter=estimator.name, feedback=controller.source)
    return SimulationResult(t=model.time, x=x, xhat=xhat, u=u, y=y, settings=settings, state=system.state)
