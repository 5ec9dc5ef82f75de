"""Estimators by name: each paper registers the builders that fit its scenarios.

A builder takes a scenario (and options) and returns an
:class:`~hinfnav.estimators.base.Estimator`; ``fits(scenario)`` says whether
the estimator applies to that scenario. The simulation resolves estimator
names through :func:`build_estimator`; the contract test suite runs over
:func:`registered_estimators`.

The modules that register estimators (the papers, which sit above this layer)
are found through the entry-point group :data:`PROVIDER_GROUP`, as a plugin
host finds its plugins: :func:`registered_estimators` loads them on its first
call, and :func:`estimator_entry` on an unknown name, so a fresh Python process
lists and builds every paper's estimators without this layer naming a paper.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata
from typing import TYPE_CHECKING, Any

from ..core.exceptions import InputError

if TYPE_CHECKING:
    from .base import Estimator

__all__ = ["register_estimator", "build_estimator", "registered_estimators", "estimator_entry", "load_providers",
           "providers", "PROVIDER_GROUP"]


@dataclass(frozen=True)
class _Entry:
    name: str
    builder: object
    fits: object
    description: str


_REGISTRY = {}

#: Entry-point group of the modules that register scenarios and estimators when imported. This
#: package declares its papers (``hinfnav.papers``) in ``pyproject.toml``; another installed package
#: may declare its own.
PROVIDER_GROUP = "hinfnav.providers"

_PROVIDERS = {"loaded": False}


def providers() -> tuple[str, ...]:
    """The provider modules declared under :data:`PROVIDER_GROUP` by the installed packages."""
    return tuple(ep.value for ep in metadata.entry_points(group=PROVIDER_GROUP))


def load_providers() -> dict[str, str]:
    """Import the providers (registering their scenarios and estimators); return those that failed, with why."""
    _PROVIDERS["loaded"] = True  # first, so that a provider asking for the registry while it loads does not recurse
    failed = {}
    for ep in metadata.entry_points(group=PROVIDER_GROUP):
        try:
            ep.load()
        except ImportError as exc:  # pragma: no cover - a provider under construction
            failed[ep.value] = str(exc)
    return failed


def _ensure_providers():
    if not _PROVIDERS["loaded"]:
        load_providers()


def register_estimator(name: str, builder: Callable[..., Estimator], *, fits: Callable[[Any], bool] | None = None,
                       description: str = "") -> None:
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


def registered_estimators(scenario: Any = None) -> tuple[str, ...]:
    """Names of the registered estimators (that fit ``scenario`` when given), in registration order.

    The first call loads the providers (:func:`load_providers`), so the list is complete in a fresh process.
    """
    _ensure_providers()
    return tuple(n for n, e in _REGISTRY.items() if scenario is None or e.fits(scenario))


def estimator_entry(name: str) -> _Entry:
    """The registry entry of ``name`` (builder, fits, description); an unknown name loads the providers first."""
    if isinstance(name, str) and name not in _REGISTRY:
        _ensure_providers()
    if not isinstance(name, str) or name not in _REGISTRY:
        raise InputError(f"unknown filter {name!r}; choose one of: {', '.join(_REGISTRY)}")
    return _REGISTRY[name]


def build_estimator(name: str, scenario: Any, **options: Any) -> Estimator:
    """Build the estimator registered as ``name`` for ``scenario``."""
    entry = estimator_entry(name)
    if not entry.fits(scenario):
        fitting = ", ".join(registered_estimators(scenario))
        raise InputError(f"filter {name!r} does not fit this scenario ({type(scenario).__name__}); these do: {fitting}")
    return entry.builder(scenario, **options)
