"""Monte Carlo runs of an estimator on a scenario's truth, in batches.

A *scenario* here is any object that offers

* ``truth_model(**conditions) -> TruthModel`` (the conditions, such as
  ``maneuver`` or ``delta``, are the scenario's own and it validates them),
* ``xhat0`` — the estimators' initial estimate,

and, to resolve an estimator given by name, whose estimators are registered
in :mod:`hinfnav.estimators.registry`. Nothing here defaults to one paper.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from tqdm import tqdm

from ..core.exceptions import InputError
from ..io.progress import bar_disabled
from ..core.validation import as_int_at_least
from ..estimators.base import EstimateHistory, Estimator
from ..estimators.registry import build_estimator
from .truth import scenario_truth_model, simulate_truth

if TYPE_CHECKING:
    from ..design.result import SynthesisResult
    from ..noise import NoiseModel
    from ..systems.measurements import MeasurementModel
    from .truth import Truth


__all__ = ["SimulationResult", "available_memory_bytes", "history_bytes", "check_history_memory", "check_measurement_match", "run_estimator", "simulate", "simulate_batches", "resolve_estimator"]


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Truth plus one estimator's output.

    Attributes
    ----------
    t : ndarray, shape (n_samples,)
    x, xhat : ndarray, shape (runs, n_samples, n)
    u : ndarray, shape (runs, n_samples, m_u)
    y : ndarray, shape (runs, n_samples, m)
    P : ndarray, shape (runs, n_samples, n, n), or None
    settings : dict
        The truth's settings plus ``filter``.
    state : StateSpec
        Labels, units, groups and error definition of the state.
    diagnostics : dict
        The estimator's diagnostics histories, when asked for.
    xhat0 : ndarray, shape (n,) or None
        The estimator's initial estimate (for the consistency checks,
        :func:`hinfnav.metrics.consistency`).
    """

    t: np.ndarray
    x: np.ndarray
    xhat: np.ndarray
    u: np.ndarray
    y: np.ndarray
    P: np.ndarray = None
    settings: dict = field(default_factory=dict)
    state: object = None
    diagnostics: dict = field(default_factory=dict)
    xhat0: np.ndarray = None

    @property
    def error(self) -> NDArray[np.float64]:
        """Estimation error by the state's definition (``x − x̂`` for an additive state)."""
        if self.state is None:
            return self.x - self.xhat
        return self.state.error(self.x, self.xhat)

    @property
    def runs(self) -> int:
        """Number of Monte Carlo runs."""
        return self.x.shape[0]


def resolve_estimator(estimator: str | Estimator | SynthesisResult, scenario: Any) -> Estimator:
    """An :class:`Estimator`: given, registered under a name for ``scenario``, or built from a design.

    A :class:`~hinfnav.design.SynthesisResult` is turned into an estimator by
    the scenario's ``estimator_from_design`` (which checks that it was
    designed for this scenario's sampling time).
    """
    if isinstance(estimator, str):
        return build_estimator(estimator, scenario)
    if estimator is None:
        raise InputError("estimator must be given (an Estimator or a registered filter name such as 'published')")
    if isinstance(estimator, Estimator):
        return estimator
    # Anything else must be a design the scenario can run; the scenario checks its type (not imported
    # here, so that the simulation layer loads neither the design layer nor python-control).
    if hasattr(scenario, "estimator_from_design"):
        try:
            return scenario.estimator_from_design(estimator)
        except InputError as err:
            raise InputError(f"estimator: {err}") from err
    raise InputError(f"estimator must be a hinfnav Estimator or a filter name (this scenario, {type(scenario).__name__}, "
                     f"cannot run a synthesized design directly); got {type(estimator).__name__}")


def check_measurement_match(estimator: Estimator, measurement: MeasurementModel | None) -> None:
    """Refuse an estimator whose measurement model is not what the simulation produces.

    An estimator built for range, azimuth and elevation must not be fed
    Cartesian positions (nor the reverse): the channels' labels and units must agree.
    """
    if measurement is None:
        return
    mine = estimator.measurement
    if (mine.n_meas, tuple(mine.labels), tuple(mine.units)) != (measurement.n_meas, tuple(measurement.labels),
                                                                tuple(measurement.units)):
        raise InputError(
            f"estimator {estimator.name!r} expects measurements {', '.join(f'{a} ({b})' for a, b in zip(mine.labels, mine.units))} "
            f"but the scenario produces {', '.join(f'{a} ({b})' for a, b in zip(measurement.labels, measurement.units))}: "
            "simulate the measurements the estimator was built for, or build it for the scenario's measurement"
        )


def run_estimator(estimator: Estimator, truth: Truth, xhat0: ArrayLike, *, P0: ArrayLike | None = None,
                  diagnostics: bool = False) -> SimulationResult:
    """Run an estimator on a simulated truth (all runs at once).

    Returns
    -------
    SimulationResult
    """
    if not isinstance(estimator, Estimator):
        raise InputError(f"estimator must be a hinfnav Estimator; got {type(estimator).__name__}")
    check_measurement_match(estimator, truth.measurement)
    hist = estimator.estimate(truth.y, truth.u, xhat0, P0, diagnostics=diagnostics)
    if not isinstance(hist, EstimateHistory) or hist.xhat.shape != truth.x.shape:
        raise InputError(
            f"estimator {estimator.name!r} returned estimates of shape {np.shape(hist.xhat)}; expected {truth.x.shape}"
        )
    settings = dict(truth.settings, filter=estimator.name)
    return SimulationResult(t=truth.t, x=truth.x, xhat=hist.xhat, u=truth.u, y=truth.y, P=hist.P, settings=settings,
                            state=truth.state, diagnostics=hist.diagnostics, xhat0=np.asarray(xhat0, dtype=float))


def _concat_covariances(Ps, runs):
    """Join per-batch covariance histories; keep a shared (data-independent) one as a view.

    Filters whose covariance does not depend on the data (a Kalman filter with a
    linear measurement) return it broadcast over the runs (stride 0); copying
    it per run would cost ~290 MB per 100 runs of 10 001 samples of a 6-state.
    """
    if Ps[0] is None:
        return None
    shared = all(P.strides[0] == 0 for P in Ps) and all(np.array_equal(P[0], Ps[0][0]) for P in Ps[1:])
    if shared:
        return np.broadcast_to(Ps[0][0], (runs,) + Ps[0].shape[1:])
    return np.concatenate(Ps)


def simulate_batches(scenario: Any, estimator: str | Estimator | SynthesisResult, *, noise: str | NoiseModel = "gaussian",
                     measurement_noise: str | NoiseModel | None = None, runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0,
                     batch_size: int = 100, progress: bool = False, diagnostics: bool = False,
                     **conditions: Any) -> Iterator[tuple[int, SimulationResult]]:
    """Yield ``(first_run, SimulationResult)`` batch by batch: histories of ``batch_size`` runs at a time.

    Memory is that of one batch, whatever ``runs``; the numbers of run r do not
    depend on the batch size (run r always draws from the r-th child generator).
    Arguments as in :func:`simulate`; ``diagnostics`` (True, False or names)
    says which of the estimator's diagnostics histories to keep.
    """
    model = scenario_truth_model(scenario, conditions)
    estimator = resolve_estimator(estimator, scenario)
    runs = as_int_at_least("runs", runs, 1)
    batch_size = as_int_at_least("batch_size", batch_size, 1)
    if isinstance(seed, np.random.Generator):
        seed = int(seed.integers(2**63))
    with tqdm(total=runs, disable=bar_disabled(progress), desc=f"{estimator.name}", unit="run") as bar:
        for start in range(0, runs, batch_size):
            n = min(batch_size, runs - start)
            truth = simulate_truth(model, noise=noise, measurement_noise=measurement_noise, runs=n, seed=seed,
                                   first_run=start)
            yield start, run_estimator(estimator, truth, scenario.xhat0, diagnostics=diagnostics)
            bar.update(n)


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
    n, m_u, m = model.system.n, model.system.n_input, model.measurement.n_meas
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


def simulate(scenario: Any, estimator: str | Estimator | SynthesisResult, *, noise: str | NoiseModel = "gaussian",
             measurement_noise: str | NoiseModel | None = None, runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0, batch_size: int = 100,
             progress: bool = False, **conditions: Any) -> SimulationResult:
    """Simulate a scenario's truth and run an estimator on it, over Monte Carlo runs.

    Parameters
    ----------
    scenario : scenario object
        Provides ``truth_model(**conditions)`` and ``xhat0`` (see the module docstring).
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
    check_history_memory(scenario, runs, **conditions)
    keys = ("innovation", "innovation_covariance")  # = hinfnav.metrics.NIS_KEYS (a higher layer)
    parts = [res for _, res in simulate_batches(scenario, estimator, noise=noise, measurement_noise=measurement_noise,
                                                runs=runs, seed=seed, batch_size=batch_size, progress=progress,
                                                diagnostics=keys, **conditions)]
    if len(parts) == 1:
        res = parts[0]
        res.settings["runs"] = runs
        return res
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])
    P = _concat_covariances([p.P for p in parts], runs)
    settings = dict(parts[0].settings, runs=runs)
    diag = {k: np.concatenate([p.diagnostics[k] for p in parts]) for k in parts[0].diagnostics}
    return SimulationResult(t=parts[0].t, x=cat("x"), xhat=cat("xhat"), u=cat("u"), y=cat("y"), P=P, settings=settings,
                            state=parts[0].state, diagnostics=diag, xhat0=parts[0].xhat0)
