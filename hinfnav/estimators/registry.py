"""Estimators by name: each paper registers the builders that fit its scenarios.

A builder takes a scenario (and options) and returns an
:class:`~hinfnav.estimators.base.Estimator`; ``fits(scenario)`` says whether
the estimator applies to that scenario. The simulation resolves estimator
names through :func:`build_estimator`; the contract test suite runs over
:func:`registered_estimators`.
"""

from dataclasses import dataclass

from ..core.exceptions import InputError

__all__ = ["register_estimator", "build_estimator", "registered_estimators", "estimator_entry"]


@dataclass(frozen=True)
class _Entry:
    name: str
    builder: object
    fits: object
    description: str


_REGISTRY = {}


def register_estimator(name, builder, *, fits=None, description=""):
    """Register ``builder(scenario, **options) -> Estimator`` under ``name``.

    Parameters
    ----------
    name : str
    builder : callable
    fits : callable, optional
        ``fits(scenario) -> bool``; default: fits every scenario.
    description : str
    """
    if not isinstance(name, str) or not name:
        raise InputError(f"estimator name must be a non-empty string; got {name!r}")
    if not callable(builder):
        raise InputError(f"builder must be callable as builder(scenario, **options); got {type(builder).__name__}")
    if fits is not None and not callable(fits):
        raise InputError(f"fits must be callable as fits(scenario) -> bool; got {type(fits).__name__}")
    _REGISTRY[name] = _Entry(name, builder, fits or (lambda scenario: True), description)


def registered_estimators(scenario=None):
    """Names of the registered estimators (that fit ``scenario`` when given), in registration order."""
    return tuple(n for n, e in _REGISTRY.items() if scenario is None or e.fits(scenario))


def estimator_entry(name):
    """The registry entry of ``name`` (builder, fits, description)."""
    if not isinstance(name, str) or name not in _REGISTRY:
        raise InputError(f"unknown filter {name!r}; choose one of: {', '.join(_REGISTRY)}")
    return _REGISTRY[name]


def build_estimator(name, scenario, **options):
    """Build the estimator registered as ``name`` for ``scenario``."""
    entry = estimator_entry(name)
    if not entry.fits(scenario):
        fitting = ", ".join(registered_estimators(scenario))
        raise InputError(f"filter {name!r} does not fit this scenario ({type(scenario).__name__}); these do: {fitting}")
    return entry.builder(scenario, **options)
