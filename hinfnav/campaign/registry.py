"""Scenarios by name, for campaigns: each paper registers the factory of its scenario.

A campaign names its scenario (the key of its paper) and the scenario's settings
(``mass``, ``dt``, …); :func:`build_scenario` makes it with
``factory(**settings)``. The factory's keyword parameters are the settings a
campaign grid may vary; the parameters of the scenario's
``truth_model(**conditions)`` are its conditions (``maneuver``, ``delta``, …).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..core.exceptions import InputError
from ..estimators.registry import PROVIDER_GROUP, load_providers, providers

__all__ = ["register_scenario", "registered_scenarios", "scenario_entry", "build_scenario", "scenario_parameters",
           "condition_parameters", "load_providers", "providers", "PROVIDER_GROUP"]


@dataclass(frozen=True)
class _ScenarioEntry:
    name: str
    factory: object
    description: str


_SCENARIOS = {}


def register_scenario(name: str, factory: Callable[..., Any], *, description: str = "") -> None:
    """Register ``factory(**settings) -> scenario`` under ``name``.

    Parameters
    ----------
    name : str
        The name a campaign uses (the paper's key).
    factory : callable
        Returns an object with ``truth_model(**conditions)`` and ``xhat0``
        (:class:`~hinfnav.core.protocols.ScenarioProtocol`); called with no
        argument it gives the paper's scenario. Optional: ``offers`` (an
        :class:`~hinfnav.estimators.registry.Offers`: what its estimators may
        rely on) and ``campaign_truth(conditions, noise, rngs)`` returning a
        :class:`~hinfnav.sim.truth.Truth` (a truth the simulators cannot make
        from ``truth_model`` alone: an impulse, another noise per channel; the
        campaign runner uses it when present, :func:`~hinfnav.campaign.runner.cell_truth`).
    description : str
    """
    if not isinstance(name, str) or not name:
        raise InputError(f"scenario name must be a non-empty string; got {name!r}")
    if not callable(factory):
        raise InputError(f"factory of scenario {name!r} must be callable; got {type(factory).__name__}")
    _SCENARIOS[name] = _ScenarioEntry(name, factory, description)


_LOADED = {"providers": False}


def registered_scenarios() -> tuple[str, ...]:
    """Names of the registered scenarios, in registration order.

    The first call loads the providers (:func:`load_providers`), so the list is complete in a fresh process.
    """
    if not _LOADED["providers"]:
        _LOADED["providers"] = True
        load_providers()
    return tuple(_SCENARIOS)


def scenario_entry(name: str, field: str = "scenario") -> _ScenarioEntry:
    """The registry entry of ``name``; an :class:`InputError` naming ``field`` and the known names otherwise."""
    if name not in _SCENARIOS:
        load_providers()
    if name not in _SCENARIOS:
        known = ", ".join(_SCENARIOS) or ("none (no installed package declares a provider under the entry-point "
                                          f"group {PROVIDER_GROUP!r}; import the module that registers it)")
        raise InputError(f"{field}: unknown scenario {name!r}; registered: {known}")
    return _SCENARIOS[name]


def _keyword_names(func):
    try:
        params = inspect.signature(func).parameters.values()
    except (TypeError, ValueError):  # pragma: no cover - builtins without a signature
        return ()
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return tuple(p.name for p in params if p.kind in kinds and p.name != "self")


def scenario_parameters(name: str) -> tuple[str, ...]:
    """Settings the scenario ``name`` accepts (the keyword parameters of its factory)."""
    return _keyword_names(scenario_entry(name).factory)


def condition_parameters(scenario: Any) -> tuple[str, ...]:
    """Conditions a scenario's ``truth_model`` accepts (``maneuver``, ``delta``, ``discretization`` for Sun 2011)."""
    return _keyword_names(scenario.truth_model)


def build_scenario(name: str, **settings: Any) -> Any:
    """The scenario registered as ``name`` with ``settings`` (validated by the scenario itself)."""
    return scenario_entry(name).factory(**settings)
