"""The cross-paper benchmark's grid: which estimators, which cells, and which estimator/scenario pairs do not fit.

The benchmark runs one campaign per registered scenario (:data:`SCENARIOS`,
:func:`scenario_campaign`): every registered estimator that fits it (by the
declared requirements, :func:`hinfnav.estimators.registry.fit_reason`), the
others listed with their reason (:func:`non_fitting`, :func:`fit_matrix`).

:func:`benchmark_campaign` is the larger grid of issue 13 on Sun et al. (2011)'s chaser: every registered estimator
that fits it (:func:`hinfnav.estimators.registered_estimators`), with and
without maneuver, δ ∈ {0, 1, 5}, noise ∈ {gaussian, mixture (paper 001's,
ε = 0.6, σ₂ = 2σ₁), student_t, colored}, ``runs`` ≥ 200 per cell, RMS over
0–500 s (``early``: the initial transient and the thrust phase) and
100–1000 s (``steady``: Table 1's window).

Every paper registers its estimators when imported; :func:`load_papers`
imports every paper that exists (a paper under construction that does not
import yet is reported, not fatal), so estimators that land later join the
benchmark without a change here.
"""

import importlib

from ...campaign.registry import build_scenario, registered_scenarios, scenario_parameters
from ...campaign.spec import Campaign
from ...core.exceptions import InputError
from ...estimators.registry import estimator_entry, fit_reason, registered_estimators
from ..sun2011.scenario import Scenario

__all__ = ["PAPER_MODULES", "load_papers", "benchmark_campaign", "fit_matrix", "WINDOWS", "NOISES", "DELTAS",
           "TOL", "SCENARIOS", "scenario_campaign", "non_fitting"]

#: Every paper package, in the order of their decades.
PAPER_MODULES = ("sun2011", "shi2018", "attitude2018", "yang2020")
#: RMS windows, s.
WINDOWS = {"early": (0.0, 500.0), "steady": (100.0, 1000.0)}
#: Noises of w and v (all of unit variance).
NOISES = ("gaussian", "mixture", "student_t", "colored")
#: True orbital-rate errors δ of (4).
DELTAS = (0.0, 1.0, 5.0)
#: Convergence tolerance per component: 1 m in position (16 times the Kalman limit), 0.2 m/s in velocity (9 times).
TOL = (1.0, 1.0, 1.0, 0.2, 0.2, 0.2)

def load_papers():
    """Import every paper of :data:`PAPER_MODULES` (registering their scenarios and estimators).

    Returns
    -------
    dict
        Paper key → None when imported, or the error message when it could not be.
    """
    out = {}
    for key in PAPER_MODULES:
        try:
            importlib.import_module(f"{__package__.rsplit('.', 1)[0]}.{key}")
            out[key] = None
        except Exception as exc:
            out[key] = f"{type(exc).__name__}: {exc}"
    return out


def _as_written(scenario=None):
    """The registered estimators (fitting ``scenario``) as written: their compositions with strategies
    (:func:`~hinfnav.estimators.registry.register_composition`) are run when asked for by name."""
    return tuple(n for n in registered_estimators(scenario) if estimator_entry(n).composed is None)


def benchmark_campaign(*, runs=200, seed=0, estimators=None, batch_size=200, maneuvers=(True, False),
                       deltas=DELTAS, noises=NOISES):
    """The benchmark's campaign: every fitting estimator on every cell of the grid.

    Parameters
    ----------
    runs : int
        Runs per cell (≥ 200 for the benchmark; fewer for a quick look).
    seed : int
    estimators : sequence of str, optional
        Default: every registered estimator that fits Sun 2011's chaser.
    batch_size : int
        Runs simulated and filtered at once (200: the benchmark's cells are one batch each). Part
        of a filter step's cost is fixed overhead, so one batch of 200 runs takes 85 % of the CPU
        time of two of 100 (37.0 against 43.7 CPU-s for the 13 estimators of a grid point; the
        Huber filter 11.0 against 14.8 s); a worker then holds about 0.5 GB.
    maneuvers, deltas, noises : sequence
        The grid (defaults: the benchmark's).

    Returns
    -------
    Campaign
        Its cells' seeds depend on the truth parameters only, so the
        estimators of a grid point share their truths (common random numbers).
    """
    names = _as_written(Scenario()) if estimators is None else tuple(estimators)
    return Campaign(name="benchmark", runs=runs, seed=seed, batch_size=batch_size, windows=WINDOWS, tol=TOL,
                    grid={"scenario": "sun2011", "estimator": list(names), "maneuver": list(maneuvers),
                          "delta": list(deltas), "noise": list(noises)})


#: The benchmark's grid per scenario: ``grid`` (conditions, settings and noises), ``windows`` (name → (start, end),
#: s; ``steady`` is the table's), ``quantities`` (the two state groups of the table), ``tol`` (convergence
#: tolerance per component, or None), optionally ``same_as`` (estimator → the estimator whose estimates it repeats
#: bit for bit on that scenario: not run, listed with :func:`non_fitting`'s reasons; the generic filters of Sun's
#: declared Kalman model are Sun's own Kalman-type and thrust-adaptive filters, checked in ``tests/test_benchmark_linear_designs.py``).
#: Sized so that the whole benchmark takes at most 5 minutes on 2 cores (measured in the README); the scenarios'
#: own defaults are the papers' (longer runs).
SCENARIOS = {
    "sun2011": {"grid": {"maneuver": [True, False], "delta": [0.0, 5.0], "noise": ["gaussian", "mixture"]},
                "windows": {"early": (0.0, 500.0), "steady": (100.0, 1000.0)}, "quantities": ("position", "velocity"),
                "tol": TOL,
                "same_as": {"model_ekf": "ekf_known_input", "model_ukf": "ukf", "model_hbf": "hbf",
                            "model_stekf": "stekf", "model_adaptive": "ekf_augmented_thrust_adaptive"}},
    "shi2018": {"grid": {"maneuver": [True, False], "noise": ["gaussian", "mixture"]},
                "windows": {"steady": (100.0, 1000.0)}, "quantities": ("position", "velocity"), "tol": None},
    "attitude2018": {"grid": {"orbits": [0.5], "T0": [1e-5, 1e-4], "noise": ["gaussian"]},
                     "windows": {"steady": (1450.0, 2900.0)}, "quantities": ("attitude", "rate"), "tol": None},
    "yang2020": {"grid": {"n_steps": [10_000], "disturbance": [-3e-3, -12.8e-3], "noise": ["gaussian"]},
                 "windows": {"steady": (500.0, 1000.0)}, "quantities": ("displacement", "velocity"), "tol": None},
}


def scenario_campaign(key, *, runs=50, seed=0, estimators=None, batch_size=50, grid=None):
    """The benchmark's campaign on one scenario: every fitting estimator on the scenario's grid (:data:`SCENARIOS`).

    Parameters
    ----------
    key : str
        A key of :data:`SCENARIOS` (a registered scenario).
    runs, seed, batch_size : int
    estimators : sequence of str, optional
        Default: every registered estimator that fits the scenario (its first settings).
    grid : dict, optional
        Replaces entries of the scenario's grid (a smaller one for a quick look).

    Returns
    -------
    Campaign
    """
    if key not in SCENARIOS:
        raise InputError(f"scenario: the benchmark has no scenario {key!r}; choose from {', '.join(SCENARIOS)}")
    spec = SCENARIOS[key]
    g = {**spec["grid"], **(grid or {})}
    if estimators is None:
        settings = {k: v[0] for k, v in g.items() if k in scenario_parameters(key)}
        same = spec.get("same_as", {})
        estimators = [n for n in _as_written(build_scenario(key, **settings)) if n not in same]
    return Campaign(name=f"benchmark_{key}", runs=runs, seed=seed, batch_size=batch_size, windows=spec["windows"],
                    tol=spec["tol"], grid={"scenario": key, "estimator": list(estimators), **g})


def non_fitting(key, settings=None):
    """Every registered estimator that does not fit scenario ``key`` (with ``settings``), with the reason; and those
    of the scenario's ``same_as`` (:data:`SCENARIOS`), not run since they repeat another's estimates."""
    sc = build_scenario(key, **(settings or {}))
    same = SCENARIOS.get(key, {}).get("same_as", {})
    out = {}
    for name in _as_written():
        why = fit_reason(sc, name)
        if why is None and name in same:
            why = f"not run: on this scenario it is the same filter as {same[name]!r} (identical estimates)"
        if why is not None:
            out[name] = why
    return out


def fit_matrix(papers=None):
    """Which registered estimator fits which registered scenario, and why not where it does not.

    Parameters
    ----------
    papers : dict, optional
        The result of :func:`load_papers` (called when not given).

    Returns
    -------
    dict
        ``{"scenarios": [...], "estimators": {name: {"description", "fits": {scenario: bool},
        "why_not": {scenario: reason}}}}`` (reasons from :func:`hinfnav.estimators.registry.fit_reason`).
    """
    papers = load_papers() if papers is None else papers
    scenarios = {key: build_scenario(key) for key in registered_scenarios()}
    out = {}
    for name in _as_written():
        why = {key: fit_reason(sc, name) for key, sc in scenarios.items()}
        out[name] = {"description": estimator_entry(name).description, "fits": {k: w is None for k, w in why.items()},
                     "why_not": {k: w for k, w in why.items() if w is not None}}
    return {"scenarios": list(scenarios), "estimators": out}
