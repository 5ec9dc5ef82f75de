"""Monte Carlo runs on a nonlinear truth: the names kept for the engine's uses (:mod:`hinfnav.sim.engine`).

:func:`hinfnav.sim.simulate_truth` simulates linear and nonlinear truth
models alike (a nonlinear system offers ``step(x, u, w, t)``) and
:func:`hinfnav.sim.simulate` runs any estimator on either; the functions here
are those with the covariance history off by default (over 10⁴ steps and 100
runs a 9 × 9 history is 0.75 GB).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .montecarlo import run_estimator, simulate
from .truth import simulate_truth

if TYPE_CHECKING:
    from ..design.result import DesignResult
    from ..estimators.base import Estimator
    from ..noise import NoiseModel
    from .result import SimulationResult
    from .truth import Truth, TruthModel

__all__ = ["run_on_truth", "simulate_nonlinear", "simulate_nonlinear_truth"]


def simulate_nonlinear_truth(model: TruthModel, *, noise: str | NoiseModel = "gaussian",
                             measurement_noise: str | NoiseModel | None = None, runs: int = 1,
                             seed: int | np.random.SeedSequence | np.random.Generator = 0, first_run: int = 0) -> Truth:
    """:func:`hinfnav.sim.simulate_truth` (which takes nonlinear truth models too), under its former name."""
    return simulate_truth(model, noise=noise, measurement_noise=measurement_noise, runs=runs, seed=seed,
                          first_run=first_run)


def run_on_truth(estimator: Estimator, truth: Truth, xhat0: ArrayLike, *, P0: ArrayLike | None = None,
                 keep_covariance: bool | str = False, diagnostics: bool | Sequence[str] = False) -> SimulationResult:
    """:func:`hinfnav.sim.run_estimator` with the covariance history off unless ``keep_covariance`` says so
    (True, or ``"diagonal"`` for estimators that offer it)."""
    return run_estimator(estimator, truth, xhat0, P0=P0, keep_covariance=keep_covariance, diagnostics=diagnostics)


def simulate_nonlinear(scenario: Any, estimator: str | Estimator | DesignResult, *, noise: str | NoiseModel = "gaussian",
                       measurement_noise: str | NoiseModel | None = None, runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0,
                       batch_size: int = 100, progress: bool = False, keep_covariance: bool | str = False,
                       diagnostics: bool | Sequence[str] = False, **conditions: Any) -> SimulationResult:
    """:func:`hinfnav.sim.simulate` with the covariance history and the diagnostics off by default.

    Parameters
    ----------
    scenario, estimator, noise, measurement_noise, runs, seed, batch_size, progress, **conditions
        As in :func:`hinfnav.sim.simulate`; the numbers do not depend on ``batch_size``.
    keep_covariance : bool or "diagonal"
    diagnostics : bool or iterable of str
        Keep the estimator's diagnostics histories (all, or those named).

    Returns
    -------
    SimulationResult
    """
    return simulate(scenario, estimator, noise=noise, measurement_noise=measurement_noise, runs=runs, seed=seed,
                    batch_size=batch_size, progress=progress, keep_covariance=keep_covariance,
                    diagnostics=diagnostics, **conditions)
