"""Open-loop truth of a nonlinear system, and Monte Carlo runs of an estimator on it.

The companion of :func:`hinfnav.sim.simulate_truth` for systems that are not
a :class:`~hinfnav.systems.LinearSystem`: the system offers
``step(x, u, w, t) -> x_next`` for a batch (and ``n``, ``n_input``,
``n_noise``, ``dt``, ``state``), the :class:`~hinfnav.sim.TruthModel`'s
controller (optional) is any callable ``u = controller(x)`` on the true state
with ``source == "truth"``::

    x(k+1) = step(x(k), u(k), w(k), t_k),   u(k) = controller(x(k)) (or 0)
    y(k)   = h(x(k)) + D v(k)

Randomness exactly as :func:`~hinfnav.sim.simulate_truth`: run r draws its
noise from the r-th child of ``numpy.random.default_rng(seed).spawn(runs)``,
w first then v, whole histories at once; the same seed gives the same
numbers whatever the batch size. All runs are stepped together.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike
from tqdm import tqdm

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least
from ..estimators.base import Estimator
from .montecarlo import SimulationResult, resolve_estimator
from .truth import (
    Truth,
    TruthModel,
    child_rngs,
    draw_noise,
    noise_models,
    scenario_truth_model,
)

if TYPE_CHECKING:
    from ..design.result import SynthesisResult
    from ..noise import NoiseModel

__all__ = ["run_on_truth", "simulate_nonlinear", "simulate_nonlinear_truth"]


def simulate_nonlinear_truth(model: TruthModel, *, noise: str | NoiseModel = "gaussian", measurement_noise: str | NoiseModel | None = None,
                             runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0, first_run: int = 0) -> Truth:
    """Simulate a nonlinear :class:`TruthModel` (its system has ``step``); returns a :class:`Truth`.

    Parameters
    ----------
    model : TruthModel
    noise, measurement_noise : str or NoiseModel
    runs : int
    seed : int or numpy.random.Generator
    first_run : int
        Index of the first run among the seed's children.
    """
    if not isinstance(model, TruthModel):
        raise InputError(f"model must be a hinfnav TruthModel; got {type(model).__name__}")
    system, meas = model.system, model.measurement
    if not callable(getattr(system, "step", None)):
        raise InputError(f"model.system must offer step(x, u, w, t); got {type(system).__name__}")
    runs = as_int_at_least("runs", runs, 1)
    first_run = as_int_at_least("first_run", first_run, 0)
    ctrl = model.controller
    if ctrl is not None and getattr(ctrl, "source", "truth") != "truth":
        raise InputError("simulate_nonlinear_truth takes feedback on the true state only")
    w_model, v_model = noise_models(noise, measurement_noise)
    n1 = model.n_steps + 1
    rngs = child_rngs(seed, first_run + runs)[first_run:]
    w, v = draw_noise(w_model, v_model, rngs, n1, system.n_noise, meas.n_noise)
    x = np.empty((runs, n1, system.n))
    u = np.zeros((runs, n1, system.n_input))
    x[:, 0] = model.x0
    t = model.time
    for k in range(n1):
        if ctrl is not None:
            u[:, k] = ctrl(x[:, k])
        if k < n1 - 1:
            x[:, k + 1] = system.step(x[:, k], u[:, k], w[:, k], t[k])
    y = meas.measure(x, v)
    settings = dict(model.settings)
    settings.update(noise=w_model.name, measurement_noise=v_model.name, runs=runs,
                    seed=seed if isinstance(seed, (int, np.integer)) else repr(seed))
    return Truth(t=t, x=x, u=u, y=y, settings=settings, state=system.state, measurement=meas)


def run_on_truth(estimator: Estimator, truth: Truth, xhat0: ArrayLike, *, P0: ArrayLike | None = None,
                 keep_covariance: bool | str = False, diagnostics: bool = False) -> SimulationResult:
    """Run an estimator on a simulated truth (all runs at once), keeping only what is asked for.

    As :func:`hinfnav.sim.run_estimator`, but the covariance history is not
    kept unless ``keep_covariance`` says so (True, or ``"diagonal"`` for
    estimators that offer it): over 10⁴ steps and 100 runs a 9 × 9 history
    is 0.75 GB.

    Returns
    -------
    SimulationResult
    """
    if not isinstance(estimator, Estimator):
        raise InputError(f"estimator must be a hinfnav Estimator; got {type(estimator).__name__}")
    hist = estimator.estimate(truth.y, truth.u, xhat0, P0, keep_covariance=keep_covariance, diagnostics=diagnostics)
    if hist.xhat.shape != truth.x.shape:
        raise InputError(f"estimator {estimator.name!r} returned estimates of shape {hist.xhat.shape}; expected {truth.x.shape}")
    settings = dict(truth.settings, filter=estimator.name)
    return SimulationResult(t=truth.t, x=truth.x, xhat=hist.xhat, u=truth.u, y=truth.y, P=hist.P, settings=settings,
                            state=truth.state, diagnostics=hist.diagnostics, xhat0=np.asarray(xhat0, dtype=float))


def simulate_nonlinear(scenario: Any, estimator: str | Estimator | SynthesisResult, *, noise: str | NoiseModel = "gaussian",
                       measurement_noise: str | NoiseModel | None = None, runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0,
                       batch_size: int = 100, progress: bool = False, keep_covariance: bool | str = False,
                       diagnostics: bool = False, **conditions: Any) -> SimulationResult:
    """Monte Carlo runs of an estimator on a scenario with a nonlinear truth (as :func:`hinfnav.sim.simulate`).

    Parameters
    ----------
    scenario : scenario object
        ``truth_model(**conditions)`` (a :class:`TruthModel` whose system has
        ``step``) and ``xhat0``.
    estimator : Estimator or str
    noise, measurement_noise, runs, seed, batch_size, progress
        As in :func:`hinfnav.sim.simulate`; the numbers do not depend on
        ``batch_size``.
    keep_covariance : bool or "diagonal"
        Keep the covariance history (see :func:`run_on_truth`).
    diagnostics : bool or iterable of str
        Keep the estimator's diagnostics histories (all, or those named).
    **conditions
        The scenario's conditions.

    Returns
    -------
    SimulationResult
    """
    model = scenario_truth_model(scenario, conditions)
    estimator = resolve_estimator(estimator, scenario)
    runs = as_int_at_least("runs", runs, 1)
    batch_size = as_int_at_least("batch_size", batch_size, 1)
    if isinstance(seed, np.random.Generator):
        seed = int(seed.integers(2**63))
    parts = []
    with tqdm(total=runs, disable=not progress, desc=f"{estimator.name}", unit="run") as bar:
        for start in range(0, runs, batch_size):
            n = min(batch_size, runs - start)
            truth = simulate_nonlinear_truth(model, noise=noise, measurement_noise=measurement_noise, runs=n,
                                             seed=seed, first_run=start)
            parts.append(run_on_truth(estimator, truth, scenario.xhat0, keep_covariance=keep_covariance,
                                      diagnostics=diagnostics))
            bar.update(n)
    if len(parts) == 1:
        res = parts[0]
        res.settings["runs"] = runs
        return res
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])
    P = None if parts[0].P is None else np.concatenate([np.broadcast_to(p.P, p.x.shape[:2] + p.P.shape[2:]) for p in parts])
    diag = {k: np.concatenate([p.diagnostics[k] for p in parts]) for k in parts[0].diagnostics}
    settings = dict(parts[0].settings, runs=runs)
    return SimulationResult(t=parts[0].t, x=cat("x"), xhat=cat("xhat"), u=cat("u"), y=cat("y"), P=P, settings=settings,
                            state=parts[0].state, diagnostics=diag, xhat0=parts[0].xhat0)
