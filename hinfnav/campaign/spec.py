"""A campaign: a grid of (scenario, estimator, noise, conditions, scenario settings) × Monte Carlo runs.

Written in Python (:class:`Campaign`) or in a small TOML file
(:func:`load_campaign`)::

    name = "demo"
    runs = 200
    seed = 0

    [grid]
    scenario = "<key>"                                     # a registered scenario: registered_scenarios()
    estimator = ["published", "ekf", "ekf_known_input"]   # or "all": every registered estimator that fits
    maneuver = [true, false]                               # a condition of the scenario's truth_model
    delta = [0, 1, 5]
    noise = ["gaussian", "mixture"]
    # mass = [500, 1000]                                   # a setting of the scenario's factory

    [windows]                                              # name = [start, end], s
    early = [0, 500]
    steady = [100, 1000]

Every grid key other than ``scenario``, ``estimator`` and ``noise`` is a
parameter of the scenario's factory (a *setting*: ``Scenario(mass=…)``) or
of its ``truth_model`` (a *condition*: ``maneuver``, ``delta``); anything
else is refused, naming the field.

Seeds. A cell's seed is a hash (SHA-256) of the campaign seed and of the
parameters that define its truth — scenario, settings, conditions, noise —
never of the worker, the order of completion or the estimator. Every
estimator of a grid point therefore sees the same noise draws (common random
numbers: comparisons between estimators are paired, and their differences
have less Monte Carlo noise), and a cell's numbers do not depend on which
other cells the grid holds. A cell's identity (the name of its result file)
hashes everything that determines its numbers: those parameters, the
estimator and its options, runs, batch size, windows and tolerances.

Limits and validation, before any work. :meth:`Campaign.cells` first checks
the counts against :data:`LIMITS` (runs per cell, cells), from the grid's
lengths alone, then validates the grid without building every grid point:
each scenario setting value is tried once (and each condition value once, on
the first settings), with the other keys at their first value; a group of keys
with at most :data:`FULL_CHECK` combinations is tried in full. Then the
estimated work and memory (:meth:`Campaign.estimate`) are checked against
:data:`LIMITS`. A combination of two non-first values that only fails together
is not seen before work (its cell is reported with ``status="error"``). The
runner also builds each estimator once per tried settings
(:func:`hinfnav.campaign.runner.run_campaign`), so bad estimator options or a
filter made for another sampling time are refused before any cell runs.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import numbers
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..core.tomlfile import read_toml
from ..core.exceptions import InputError
from ..estimators.registry import estimator_entry, fit_reason, registered_estimators
from ..noise import NOISE_NAMES
from .registry import build_scenario, condition_parameters, scenario_entry, scenario_parameters

__all__ = ["Campaign", "Cell", "load_campaign", "canonical", "digest", "LIMITS"]

#: Top-level fields of a campaign (TOML or dict).
FIELDS = ("name", "runs", "seed", "batch_size", "grid", "windows", "tol", "estimator_options", "share_truth")
#: Grid keys with a meaning of their own (all others are scenario settings or conditions).
RESERVED = ("scenario", "estimator", "noise")

#: Stated maxima, checked before any work (override one with ``run_campaign(..., limits={"runs": 10**7})`` or
#: ``python -m hinfnav campaign ... --limit runs=10000000``):
#:
#: * ``runs``: Monte Carlo runs per cell (as ``simulate --runs``);
#: * ``cells``: cells of the grid (grid points × estimators);
#: * ``steps``: estimator steps of the whole campaign, cells × runs × time steps: the time estimate, at about
#:   :data:`STEPS_PER_SECOND` per core (1e11 ≈ a day on two cores);
#: * ``batch_bytes``: estimated memory of one batch of runs in a worker (truth, measurements, estimates, errors).
LIMITS = {"runs": 1_000_000, "cells": 20_000, "steps": 1e11, "batch_bytes": 2 * 2**30}
#: Estimator steps per second and core, measured on the cross-paper benchmark (312 cells × 200 runs × 10⁴ steps,
#: ~9 min on 2 cores: ``python -m hinfnav reproduce --paper benchmark``); for the time estimate only.
STEPS_PER_SECOND = 6e5
#: A group of grid keys (settings, or conditions) with at most this many combinations is validated in full;
#: a larger one value by value.
FULL_CHECK = 32


def canonical(value: Any) -> Any:
    """A JSON-ready canonical form for hashing: numbers as floats (so 1 and 1.0 are one value), lists for tuples."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, dict):
        return {str(k): canonical(v) for k, v in sorted(value.items())}
    if isinstance(value, (list, tuple)):
        return [canonical(v) for v in value]
    if hasattr(value, "tolist"):
        return canonical(value.tolist())
    raise InputError(f"campaign values must be numbers, booleans, strings or lists of them; got {type(value).__name__}")


def digest(obj: Any) -> str:
    """SHA-256 hex digest of the canonical JSON of ``obj``."""
    text = json.dumps(canonical(obj), sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True, eq=False)
class Cell:
    """One cell of a campaign: one estimator on one truth, over ``runs`` runs.

    Attributes
    ----------
    scenario : str
    settings : dict
        Scenario factory parameters.
    conditions : dict
        ``truth_model`` parameters.
    noise : str
    estimator : str
    options : dict
        Options of the estimator's builder.
    seed : int
        From the campaign seed and the truth's parameters (see the module docstring).
    truth_key : str
        Digest of the truth's parameters and seed: cells with equal keys share their truth draws.
    cell_id : str
        Digest of everything that determines the cell's numbers (its result file is ``cells/<cell_id>.json``).
    """

    scenario: str
    settings: dict
    conditions: dict
    noise: str
    estimator: str
    options: dict
    seed: int
    truth_key: str
    cell_id: str

    @property
    def params(self) -> dict[str, Any]:
        """The cell's parameters as one flat dict (scenario, estimator, noise, settings, conditions)."""
        return {"scenario": self.scenario, "estimator": self.estimator, "noise": self.noise, **self.settings,
                **self.conditions}


def _as_list(field_name, value):
    if isinstance(value, (list, tuple)):
        values = list(value)
    else:
        values = [value]
    if not values:
        raise InputError(f"{field_name}: empty list; the grid would have no cell")
    return values


def _window(name, value):
    try:
        start, end = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(f"windows.{name} must be a pair [start, end] in seconds; got {value!r}") from None
    if not (math.isfinite(start) and math.isfinite(end) and 0 <= start < end):
        raise InputError(f"windows.{name} must satisfy 0 <= start < end (finite, s); got [{start}, {end}]")
    return (start, end)


@dataclass(frozen=True, eq=False)
class Campaign:
    """A campaign spec (see the module docstring); validated when made.

    Parameters
    ----------
    grid : dict
        Grid key → list of values (a single value is a list of one). Needs
        ``scenario`` and ``estimator`` (``"all"``: every registered estimator
        that fits); ``noise`` defaults to ``["gaussian"]``.
    runs : int
        Monte Carlo runs per cell, ≥ 1.
    windows : dict
        Name → (start, end) of an RMS window, s.
    seed : int
        Campaign seed, ≥ 0.
    batch_size : int
        Runs simulated together (memory is that of one batch, whatever ``runs``).
    tol : sequence of float, optional
        Per-component tolerance of the convergence time (a run has converged
        from the first sample after which every component stays within it).
    estimator_options : dict
        Estimator name → options of its builder.
    share_truth : bool
        Run every estimator of a grid point on one simulated truth (one task
        per grid point). False: one task per cell. The numbers are the same
        either way (the seed does not involve the estimator).
    name : str
    """

    grid: dict
    runs: int
    windows: dict
    seed: int = 0
    batch_size: int = 100
    tol: tuple = None
    estimator_options: dict = field(default_factory=dict)
    share_truth: bool = True
    name: str = "campaign"

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)
        for key, minimum in (("runs", 1), ("seed", 0), ("batch_size", 1)):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                raise InputError(f"{key} must be an integer >= {minimum}; got {value!r}")
            if value < minimum:
                raise InputError(f"{key} must be an integer >= {minimum}; got {value}")
            set_(key, int(value))
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"name must be a non-empty string; got {self.name!r}")
        if not isinstance(self.share_truth, bool):
            raise InputError(f"share_truth must be true or false; got {self.share_truth!r}")
        if not isinstance(self.grid, dict) or not self.grid:
            raise InputError("grid must be a non-empty table of key = [values] (with scenario and estimator)")
        grid = {str(k): tuple(_as_list(f"grid.{k}", v)) for k, v in self.grid.items()}
        for key in ("scenario", "estimator"):
            if key not in grid:
                raise InputError(f"grid.{key} is missing; a campaign needs at least one {key}")
        grid.setdefault("noise", ("gaussian",))
        for value in grid["noise"]:
            if value not in NOISE_NAMES:
                raise InputError(f"grid.noise: unknown noise {value!r}; choose from {', '.join(NOISE_NAMES)}")
        for key, values in grid.items():
            canonical(list(values))  # refuses values that cannot be written down (objects, arrays of objects)
            if len({json.dumps(canonical(v), sort_keys=True) for v in values}) != len(values):
                raise InputError(f"grid.{key}: repeated values {list(values)!r}")
        set_("grid", grid)
        if not isinstance(self.windows, dict) or not self.windows:
            raise InputError("windows must be a non-empty table of name = [start, end] in seconds")
        set_("windows", {str(k): _window(k, v) for k, v in self.windows.items()})
        if self.tol is not None:
            try:
                tol = tuple(float(v) for v in _as_list("tol", self.tol))
            except (TypeError, ValueError):
                raise InputError(f"tol must be a list of positive numbers; got {self.tol!r}") from None
            if not all(math.isfinite(v) and v > 0 for v in tol):
                raise InputError(f"tol must be finite and > 0 for every component; got {list(tol)}")
            set_("tol", tol)
        if not isinstance(self.estimator_options, dict):
            raise InputError(f"estimator_options must be a table name -> options; got {self.estimator_options!r}")
        for key, opts in self.estimator_options.items():
            if not isinstance(opts, dict):
                raise InputError(f"estimator_options.{key} must be a table of options; got {opts!r}")
            canonical(opts)
        set_("estimator_options", {str(k): dict(v) for k, v in self.estimator_options.items()})
        in_grid = self.grid["estimator"]
        stray = sorted(set(self.estimator_options) - set(registered_estimators() if "all" in in_grid else in_grid))
        if stray:  # options for an estimator the grid does not run: a misspelt name, never silently ignored
            raise InputError(f"estimator_options.{stray[0]}: {stray[0]!r} is not an estimator of the grid "
                             f"({', '.join(map(str, in_grid))}); options apply only to estimators the grid runs")
        object.__setattr__(self, "_cells", None)
        object.__setattr__(self, "_sizes", ())
        object.__setattr__(self, "_tried", ())

    # -- construction --------------------------------------------------------

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, source: str = "campaign") -> Campaign:
        """A campaign from a dict with the fields of :data:`FIELDS` (a TOML file's content)."""
        if not isinstance(data, dict):
            raise InputError(f"{source} must be a table of fields; got {type(data).__name__}")
        unknown = sorted(set(data) - set(FIELDS))
        if unknown:
            raise InputError(f"{source}: unknown field {', '.join(map(repr, unknown))}; known: {', '.join(FIELDS)}")
        for key in ("grid", "runs", "windows"):
            if key not in data:
                raise InputError(f"{source}: field {key!r} is missing")
        return cls(**data)

    def as_dict(self) -> dict[str, Any]:
        """The spec as a JSON-ready dict (what :meth:`from_dict` reads)."""
        return {"name": self.name, "runs": self.runs, "seed": self.seed, "batch_size": self.batch_size,
                "grid": {k: list(v) for k, v in self.grid.items()},
                "windows": {k: list(v) for k, v in self.windows.items()},
                "tol": None if self.tol is None else list(self.tol),
                "estimator_options": self.estimator_options, "share_truth": self.share_truth}

    # -- the cells -----------------------------------------------------------

    def _split(self, scenario_name):
        """Grid keys of one scenario: (settings keys, condition keys); unknown keys → InputError naming them."""
        settings_ok = scenario_parameters(scenario_name)
        probe = build_scenario(scenario_name)
        conditions_ok = condition_parameters(probe)
        settings, conditions = [], []
        for key in self.grid:
            if key in RESERVED:
                continue
            if key in conditions_ok:
                conditions.append(key)
            elif key in settings_ok:
                settings.append(key)
            else:
                raise InputError(
                    f"grid.{key}: unknown parameter for scenario {scenario_name!r}; its conditions are "
                    f"{', '.join(conditions_ok) or 'none'} and its settings {', '.join(settings_ok) or 'none'}"
                )
        return settings, conditions

    def _estimators(self, scenario, scenario_name):
        names = self.grid["estimator"]
        if "all" in names:
            if len(names) > 1:
                raise InputError(f"grid.estimator: 'all' stands alone; got {list(names)!r}")
            fitting = registered_estimators(scenario)
            if not fitting:
                raise InputError(f"grid.estimator: no registered estimator fits scenario {scenario_name!r}")
            return fitting
        for name in names:
            if not isinstance(name, str):
                raise InputError(f"grid.estimator: estimator names are strings; got {name!r}")
            try:
                entry = estimator_entry(name)
            except InputError:
                raise InputError(f"grid.estimator: unknown estimator {name!r}; registered: "
                                 f"{', '.join(registered_estimators())}") from None
            why = fit_reason(scenario, entry.name)
            if why is not None:
                raise InputError(f"grid.estimator: {name!r} does not fit scenario {scenario_name!r} ({why}); these do: "
                                 f"{', '.join(registered_estimators(scenario))}")
        return names

    def _check_windows(self, model, scenario_name):
        duration = model.n_steps * model.system.dt
        for name, (start, end) in self.windows.items():
            if end > duration + 1e-9:
                raise InputError(f"windows.{name}: [{start:g}, {end:g}] s ends after the {duration:g} s that "
                                 f"scenario {scenario_name!r} simulates")
        if self.tol is not None and len(self.tol) not in (1, model.system.n):
            raise InputError(f"tol must have 1 or {model.system.n} entries (one per state component); got "
                             f"{len(self.tol)}")

    def _limits(self, limits):
        merged = dict(LIMITS)
        for key, value in (limits or {}).items():
            if key not in LIMITS:
                raise InputError(f"limits: unknown limit {key!r}; known: {', '.join(LIMITS)}")
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not value > 0:
                raise InputError(f"limits.{key} must be a number > 0; got {value!r}")
            merged[key] = value
        return merged

    def _check_counts(self, limits):
        """Runs and cells against ``limits``, from the grid's lengths alone (nothing is built)."""
        if self.runs > limits["runs"]:
            raise InputError(f"runs = {self.runs} exceeds the limit of {limits['runs']:g} runs per cell "
                             "(raise it with limits={'runs': N} or --limit runs=N if you mean it)")
        names = self.grid["estimator"]
        n_est = len(registered_estimators()) if "all" in names else len(names)
        n_cells = math.prod(len(v) for k, v in self.grid.items() if k != "estimator") * max(n_est, 1)
        if n_cells > limits["cells"]:
            sizes = " × ".join(f"{k} {len(v)}" for k, v in self.grid.items() if len(v) > 1 and k != "estimator")
            raise InputError(f"grid: {n_cells} cells ({sizes or '1 point'} × {n_est} estimators) exceed the limit "
                             f"of {limits['cells']:g} cells (raise it with limits={{'cells': N}} or --limit cells=N)")

    def estimate(self) -> dict[str, float]:
        """Estimated work and memory of the campaign (after validation): a dict.

        ``steps``: estimator steps, cells × runs × the longest validated scenario's time steps; ``seconds``:
        steps / :data:`STEPS_PER_SECOND` (one core); ``batch_bytes``: one batch of ``min(batch_size, runs)``
        runs of the longest scenario, 8 bytes per number, for the true state, the estimate and the error
        (n each), the measurements (p) and the input (m) at every step.
        """
        cells = self.cells()
        steps, per_step = max(s[0] for s in self._sizes), max(s[1] for s in self._sizes)
        total = float(len(cells)) * self.runs * steps
        return {"steps": total, "seconds": total / STEPS_PER_SECOND,
                "batch_bytes": float(min(self.batch_size, self.runs)) * (steps + 1) * per_step * 8}

    def cells(self, limits: Mapping[str, float] | None = None) -> list[Cell]:
        """Every cell of the grid, in grid order, after the checks of the module docstring (limits, names, values).

        Parameters
        ----------
        limits : dict, optional
            Overrides of :data:`LIMITS` (name → maximum).
        """
        if self._cells is not None:
            return self._cells
        limits = self._limits(limits)
        self._check_counts(limits)
        sizes, tried, out = [], [], []
        for scenario_name in self.grid["scenario"]:
            scenario_entry(scenario_name, field="grid.scenario")
            skeys, ckeys = self._split(scenario_name)
            estimators = None
            for settings in _variants(self.grid, skeys):
                scenario = self._build(scenario_name, settings)
                names = self._estimators(scenario, scenario_name)
                estimators = names if estimators is None else estimators
                tried.append((scenario_name, settings, scenario, tuple(names)))
                first = len(tried) == 1 or tried[-2][0] != scenario_name
                for conditions in _variants(self.grid, ckeys) if first else [{k: self.grid[k][0] for k in ckeys}]:
                    try:
                        model = scenario.truth_model(**conditions)
                    except (InputError, TypeError, ValueError) as exc:
                        where = ", ".join(f"{k} = {v!r}" for k, v in {**settings, **conditions}.items())
                        raise InputError(f"grid ({where}): {exc}") from None
                    self._check_windows(model, scenario_name)
                    n, p = model.system.n, model.measurement.n_meas
                    m = getattr(model.system, "n_input", n)
                    sizes.append((int(model.n_steps), 3 * n + p + m))  # x, x̂, error, y, u per step and run
            for svals in itertools.product(*(self.grid[k] for k in skeys)):
                settings = dict(zip(skeys, svals))
                for cvals in itertools.product(*(self.grid[k] for k in ckeys)):
                    conditions = dict(zip(ckeys, cvals))
                    for noise in self.grid["noise"]:
                        out.extend(self._make_cells(scenario_name, settings, conditions, noise, estimators))
        if not out:
            raise InputError("grid: the grid has no cell")
        object.__setattr__(self, "_sizes", tuple(sizes))
        object.__setattr__(self, "_tried", tuple(tried))
        object.__setattr__(self, "_cells", tuple(out))
        estimate = self.estimate()
        for key, what in (("steps", "estimator steps"), ("batch_bytes", "bytes per batch")):
            if estimate[key] > limits[key]:
                object.__setattr__(self, "_cells", None)
                hint = (f", about {estimate['seconds'] / 3600:.3g} core-hours" if key == "steps"
                        else "; lower batch_size")
                raise InputError(f"{'runs' if key == 'steps' else 'batch_size'}: the campaign's estimated "
                                 f"{estimate[key]:.3g} {what}{hint} exceed the limit {key} = {limits[key]:.3g} "
                                 f"(raise it with limits={{'{key}': N}} or --limit {key}=N if you mean it)")
        return self._cells

    def tried(self) -> tuple[tuple[Any, ...], ...]:
        """``(scenario name, settings, scenario, estimator names)`` of each settings combination validated."""
        self.cells()
        return self._tried

    def _build(self, scenario_name, settings):
        try:
            return build_scenario(scenario_name, **settings)
        except (InputError, TypeError, ValueError) as exc:
            raise InputError(f"grid ({', '.join(f'{k} = {v!r}' for k, v in settings.items())}): {exc}") from None

    def _make_cells(self, scenario_name, settings, conditions, noise, estimators):
        truth = {"campaign_seed": self.seed, "scenario": scenario_name, "settings": settings,
                 "conditions": conditions, "noise": noise}
        truth_key = digest(truth)
        seed = int(truth_key[:16], 16) >> 1  # 63 bits
        common = {"truth": truth, "runs": self.runs, "batch_size": self.batch_size, "windows": self.windows,
                  "tol": self.tol}
        cells = []
        for est in estimators:
            options = self.estimator_options.get(est, {})
            cell_id = digest({**common, "estimator": est, "options": options})[:20]
            cells.append(Cell(scenario_name, dict(settings), dict(conditions), noise, est, dict(options), seed,
                              truth_key[:20], cell_id))
        return cells


def _variants(grid, keys):
    """Combinations of ``keys`` to validate: all of them up to :data:`FULL_CHECK`, else each value once."""
    if math.prod(len(grid[k]) for k in keys) <= FULL_CHECK:
        return [dict(zip(keys, vals)) for vals in itertools.product(*(grid[k] for k in keys))]
    base = {k: grid[k][0] for k in keys}
    return [base] + [{**base, k: v} for k in keys for v in grid[k][1:]]


def load_campaign(spec: Campaign | Mapping[str, Any] | str | os.PathLike[str]) -> Campaign:
    """A :class:`Campaign` from a Campaign, a dict, or the path of a TOML file."""
    if isinstance(spec, Campaign):
        return spec
    if isinstance(spec, dict):
        return Campaign.from_dict(spec)
    if isinstance(spec, (str, Path)):
        path = Path(spec).expanduser()
        if not path.is_file():
            raise InputError(f"spec: no campaign file at {path}")
        data = read_toml(path, "spec: campaign file")  # names a BOM, an encoding, invalid TOML, a key given twice
        return Campaign.from_dict(data, source=f"spec {path.name}")
    raise InputError(f"spec must be a Campaign, a dict or the path of a TOML file; got {type(spec).__name__}")
