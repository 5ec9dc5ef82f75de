"""Monte Carlo runs of an estimator on a scenario's truth: thin uses of the engine (:mod:`hinfnav.sim.engine`).

A *scenario* here is any object that offers

* ``truth_model(**conditions) -> TruthModel`` (the conditions, such as
  ``maneuver`` or ``delta``, are the scenario's own and it validates them),
  or its own ``simulate_truth`` (see :func:`hinfnav.sim.engine.truth_batch`),
* ``xhat0`` — the estimators' initial estimate,

and, to resolve an estimator given by name, whose estimators are registered
in :mod:`hinfnav.estimators.registry`. Nothing here defaults to one paper.
Linear and nonlinear truths alike (:func:`hinfnav.sim.simulate_truth`).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..core.protocols import OwnTruthScenario
from ..core.validation import as_int_at_least
from ..estimators.base import Estimator
from ..estimators.compiled import use_backend
from .engine import (
    HistorySink,
    check_measurement_match,
    estimate_on_truth,
    resolve_estimator,
    run_monte_carlo,
    truth_batches,
)
from .result import SimulationResult
from .truth import scenario_truth_model

if TYPE_CHECKING:
    from ..design.result import DesignResult
    from ..noise import NoiseModel
    from .truth import Truth


__all__ = ["SimulationResult", "history_bytes", "check_history_memory",
           "check_measurement_match", "run_estimator", "simulate", "simulate_batches", "resolve_estimator", "NIS_KEYS"]

#: The diagnostics :func:`simulate` keeps by default: innovation and its covariance S
#: (the same names as :data:`hinfnav.metrics.NIS_KEYS`, a higher layer).
NIS_KEYS = ("innovation", "innovation_covariance")


def run_estimator(estimator: Estimator, truth: Truth, xhat0: ArrayLike, *, P0: ArrayLike | None = None,
                  keep_covariance: bool | str = True, diagnostics: bool | Sequence[str] = False) -> SimulationResult:
    """Run an estimator on a simulated truth (all runs at once).

    Returns
    -------
    SimulationResult
    """
    sink = HistorySink(xhat0, truth.x.shape[0])
    name = estimator.name if isinstance(estimator, Estimator) else "filter"
    for _, hist in estimate_on_truth(estimator, truth, xhat0, P0=P0, keep_covariance=keep_covariance,
                                     diagnostics=diagnostics):
        sink.add(name, 0, truth, hist)
    return sink.result()[name]


def simulate_batches(scenario: Any, estimator: str | Estimator | DesignResult, *, noise: str | NoiseModel = "gaussian",
                     measurement_noise: str | NoiseModel | None = None, runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0,
                     batch_size: int = 100, diagnostics: bool | Sequence[str] = False,
                     keep_covariance: bool | str = True, **conditions: Any) -> Iterator[tuple[int, SimulationResult]]:
    """Yield ``(first_run, SimulationResult)`` batch by batch: histories of ``batch_size`` runs at a time.

    Memory is that of one batch, whatever ``runs``; the numbers of run r do not
    depend on the batch size (run r always draws from the r-th child generator).
    Arguments as in :func:`simulate` (no ``progress``: nothing here is long enough to show one). (The engine's pull form: :func:`hinfnav.sim.engine.truth_batches`
    and :func:`~hinfnav.sim.engine.estimate_on_truth`.)
    """
    estimator = resolve_estimator(scenario, estimator)
    xhat0 = np.asarray(scenario.xhat0, dtype=float)
    for start, truth in truth_batches(scenario, conditions, runs=runs, batch_size=batch_size, seed=seed, noise=noise,
                                      measurement_noise=measurement_noise):
        sink = HistorySink(xhat0, truth.x.shape[0])
        for off, hist in estimate_on_truth(estimator, truth, xhat0, keep_covariance=keep_covariance,
                                           diagnostics=diagnostics):
            sink.add(estimator.name, off, truth, hist)
        yield start, sink.result()[estimator.name]


def available_memory_bytes() -> int | None:
    """Memory available to this process now (``MemAvailable`` of /proc/meminfo), or None where unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def history_bytes(scenario: Any, runs: int, **conditions: Any) -> int:
    """Bytes the histories of ``runs`` runs take (x, x̂, u, y, a data-dependent covariance, the innovation and S)."""
    model = scenario_truth_model(scenario, conditions)
    n, m_u, m = model.system.n, getattr(model.system, "n_input", 0), model.measurement.n_meas
    per_sample = 8 * (2 * n + m_u + 2 * m + n * n + m * m)
    return int(runs) * (model.n_steps + 1) * per_sample


def check_history_memory(scenario: Any, runs: int, *, fraction: float = 0.8, **conditions: Any) -> int:
    """Refuse early when the histories of ``runs`` runs would not fit in memory, saying how much they need."""
    runs = as_int_at_least("runs", runs, 1)
    need = history_bytes(scenario, runs, **conditions)
    avail = available_memory_bytes()
    if avail is not None and need > fraction * avail:
        raise InputError(
            f"runs = {runs}: keeping every history needs about {need / 2**30:.1f} GiB but {avail / 2**30:.1f} GiB "
            "are available. Use hinfnav.metrics.monte_carlo_statistics (or `simulate --json`), which keeps running "
            "statistics only and needs the memory of one batch, or fewer runs"
        )
    return need


def simulate(scenario: Any, estimator: str | Estimator | DesignResult, *, noise: str | NoiseModel = "gaussian",
             measurement_noise: str | NoiseModel | None = None, runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0, batch_size: int = 100,
             progress: bool = False, keep_covariance: bool | str = True, diagnostics: bool | Sequence[str] = NIS_KEYS,
             backend: str | None = None, **conditions: Any) -> SimulationResult:
    """Simulate a scenario's truth (linear or nonlinear) and run an estimator on it, over Monte Carlo runs.

    Parameters
    ----------
    scenario : scenario object
        Provides ``truth_model(**conditions)`` (or its own ``simulate_truth``) and ``xhat0`` (see the module docstring).
    estimator : Estimator or str
        An estimator, or a registered name (``"published"``, ``"ekf"``, ...).
    noise, measurement_noise : str or NoiseModel
        Noise of w and v (see :func:`hinfnav.sim.simulate_truth`).
    runs : int
    seed : int or numpy.random.Generator
        A Generator is drawn from once, so every batch agrees.
    batch_size : int
        Runs simulated together; the numbers do not depend on it.
    progress : bool
        Show a tqdm progress bar over the runs.
    keep_covariance : bool or "diagonal"
        Keep the covariance history (True), its diagonal, or none.
    diagnostics : bool or iterable of str
        The estimator's diagnostics histories to keep (default: the innovation and its covariance S).
    backend : {"auto", "numpy", "numba"}, optional
        How the estimator runs (:meth:`~hinfnav.estimators.base.Estimator.estimate`; default
        :func:`~hinfnav.estimators.compiled.default_backend`, "auto").
    **conditions
        The scenario's conditions (``maneuver``, ``delta``, ``discretization``
        for Sun et al. 2011).

    Returns
    -------
    SimulationResult
        Histories of all runs (memory grows with ``runs``: about 3 MB a
        run on Sun 2011's scenario; refused early when they would not fit. For
        statistics only, :func:`hinfnav.metrics.monte_carlo_statistics` streams).
        The diagnostics hold the innovation and its covariance S
        (``innovation_covariance``) of the filters that report them, and
        ``xhat0`` the initial estimate, so that
        :func:`hinfnav.metrics.consistency` gives the NEES, the NIS and the
        divergence flag of the result.
    """
    if not isinstance(scenario, OwnTruthScenario):
        check_history_memory(scenario, runs, **conditions)
    estimator = resolve_estimator(scenario, estimator)
    with use_backend(backend):
        out = run_monte_carlo(scenario, {estimator.name: estimator}, sink=HistorySink(scenario.xhat0, runs), runs=runs,
                              seed=seed, batch_size=batch_size, noise=noise, measurement_noise=measurement_noise,
                              keep_covariance=keep_covariance, diagnostics=diagnostics, progress=progress, **conditions)
    return out[estimator.name]
