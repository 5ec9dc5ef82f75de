"""Estimators by name: each paper registers the builders that fit its scenarios.

A builder takes a scenario (and options) and returns an
:class:`~hinfnav.estimators.base.Estimator`. Whether it applies to a scenario
is declared on both sides: the estimator's :class:`Requires` (state error
form, measurement kind, the applied input, linear dynamics, the model it is
built from) against the scenario's :class:`Offers` (its ``offers``
attribute); :func:`fit_reason` says why a pair does not fit. A ``fits(scenario)``
callable is still accepted for scenario objects that declare no offers. The simulation resolves estimator
names through :func:`build_estimator`; the contract test suite runs over
:func:`registered_estimators`.

The modules that register estimators (the papers, which sit above this layer)
are found through the entry-point group :data:`PROVIDER_GROUP`, as a plugin
host finds its plugins: :func:`registered_estimators` loads them on its first
call, and :func:`estimator_entry` on an unknown name, so a fresh Python process
lists and builds every paper's estimators without this layer naming a paper.
"""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata
from typing import TYPE_CHECKING, Any

from ..core.exceptions import InputError
from ..core.validation import as_choice
from .sqrt import FORMS, square_root
from .strategies import as_strategy, compose

if TYPE_CHECKING:
    from .base import Estimator

__all__ = ["register_estimator", "register_composition", "build_estimator", "registered_estimators",
           "estimator_entry", "load_providers", "providers", "PROVIDER_GROUP", "Requires", "Offers", "fit_reason",
           "CORE_OPTIONS"]

#: Options every estimator takes whatever its builder (issue 36): applied by :func:`build_estimator` to the built
#: estimator through the :class:`~hinfnav.estimators.base.Estimator` contract (``missing``, its property).
CORE_OPTIONS = ("missing",)

#: State error forms: additive (x − x̂) or multiplicative quaternion (attitude).
ERROR_FORMS = ("additive", "quaternion")


@dataclass(frozen=True)
class Offers:
    """What a scenario offers its estimators (its ``offers`` attribute).

    Attributes
    ----------
    error_form : {"additive", "quaternion"}
        How its state error is formed.
    measurement : str
        Kind of its readings (``"position"``, ``"range_angle"``, ``"star_vectors"``, ``"saturated_linear"``…).
    input : bool
        The applied input (control) is known to the estimators.
    linear : bool
        Its dynamics are linear (a LinearSystem), as the LMI designs need.
    models : tuple of str
        Models it hands to builders: a paper's key (its own scenario object, by the key its provider registers) and/or
        ``"kalman"`` (a generic ``kalman_model()``: system, measurement, P0, Q, uses_input).
    """

    error_form: str = "additive"
    measurement: str = ""
    input: bool = False
    linear: bool = False
    models: tuple = ()

    def __post_init__(self):
        if self.error_form not in ERROR_FORMS:
            raise InputError(f"error_form must be one of {', '.join(ERROR_FORMS)}; got {self.error_form!r}")
        object.__setattr__(self, "models", tuple(self.models))


@dataclass(frozen=True)
class Requires:
    """What an estimator needs of a scenario (declared at registration; None: anything).

    Attributes
    ----------
    error_form : str or None
    measurement : tuple of str or None
        Measurement kinds it can use.
    input : bool
        Needs the applied input.
    linear : bool
        Needs linear dynamics (the LMI designs, the steady-state filters).
    model : str or None
        The model it is built from (see :attr:`Offers.models`).
    """

    error_form: str | None = "additive"
    measurement: tuple | None = None
    input: bool = False
    linear: bool = False
    model: str | None = None

    def __post_init__(self):
        if self.error_form is not None and self.error_form not in ERROR_FORMS:
            raise InputError(f"error_form must be one of {', '.join(ERROR_FORMS)} or None; got {self.error_form!r}")
        if self.measurement is not None:
            object.__setattr__(self, "measurement", tuple(self.measurement))

    def reason(self, offers: Offers) -> str | None:
        """Why a scenario offering ``offers`` does not fit (None: it fits)."""
        if self.model is not None and self.model not in offers.models:
            return (f"built from the {self.model!r} model; the scenario offers "
                    f"{', '.join(map(repr, offers.models)) or 'none'}")
        if self.error_form is not None and offers.error_form != self.error_form:
            return f"needs an {self.error_form} state error; the scenario's is {offers.error_form}"
        if self.measurement is not None and offers.measurement not in self.measurement:
            return (f"uses {' or '.join(self.measurement)} readings; the scenario has {offers.measurement or 'other'} "
                    "readings")
        if self.input and not offers.input:
            return "needs the applied input; the scenario does not give it"
        if self.linear and not offers.linear:
            return "needs linear dynamics (an LMI design or a Riccati equation); the scenario's are nonlinear"
        return None


@dataclass(frozen=True)
class _Entry:
    name: str
    builder: object
    fits: object
    description: str
    requires: Requires | None = None
    #: A composition's base estimator and its strategies (:func:`register_composition`); None: a builder of its own
    composed: tuple | None = None


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
    """Import the providers (registering their scenarios and estimators); return those that failed, with why.

    A provider module that defines ``register()`` (``hinfnav.papers`` does: its papers load lazily) has it
    called after the import; the others register as they are imported.
    """
    _PROVIDERS["loaded"] = True  # first, so that a provider asking for the registry while it loads does not recurse
    failed = {}
    for ep in metadata.entry_points(group=PROVIDER_GROUP):
        try:
            provider = ep.load()
            if callable(getattr(provider, "register", None)):
                provider.register()
        except ImportError as exc:  # pragma: no cover - a provider under construction
            failed[ep.value] = str(exc)
    return failed


def _ensure_providers():
    if not _PROVIDERS["loaded"]:
        load_providers()


def register_estimator(name: str, builder: Callable[..., Estimator], *, fits: Callable[[Any], bool] | None = None,
                       description: str = "", requires: Requires | None = None) -> None:
    """Register ``builder(scenario, **options) -> Estimator`` under ``name``.

    Parameters
    ----------
    name : str
    builder : callable
    fits : callable, optional
        ``fits(scenario) -> bool``, for scenarios that declare no :class:`Offers`
        (and checked too on those that do); default: fits every scenario. It may
        return a string instead of False: the reason it does not fit (a string is
        truthy: ask :func:`fit_reason`, not ``fits`` itself).
    description : str
    requires : Requires, optional
        What the estimator needs, checked against a scenario's ``offers`` (:func:`fit_reason`).
    """
    if not isinstance(name, str) or not name:
        raise InputError(f"estimator name must be a non-empty string; got {name!r}")
    if not callable(builder):
        raise InputError(f"builder must be callable as builder(scenario, **options); got {type(builder).__name__}")
    if fits is not None and not callable(fits):
        raise InputError(f"fits must be callable as fits(scenario) -> bool; got {type(fits).__name__}")
    if requires is not None and not isinstance(requires, Requires):
        raise InputError(f"requires must be a hinfnav Requires; got {type(requires).__name__}")
    _REGISTRY[name] = _Entry(name, builder, fits or (lambda scenario: True), description, requires)


def register_composition(name: str, base: str, *, correction: Any = None, fading: Any = None,
                         description: str = "") -> None:
    """Register ``name`` as the estimator ``base`` with strategies composed onto it
    (:func:`~hinfnav.estimators.strategies.compose`): e.g. ``register_composition("huber_ukf", "ukf",
    correction="huber")``.

    The composition fits the scenarios ``base`` fits and takes ``base``'s options; ``correction``/``fading``
    given to :func:`build_estimator` replace its defaults (e.g. ``correction={"name": "huber", "gamma": 2.0}``).
    ``base`` must be registered first.
    """
    entry = estimator_entry(base)
    if correction is None and fading is None:
        raise InputError(f"a composition names a correction or a fading strategy; {name!r} has neither")
    parts = [str(part if isinstance(part, str) else getattr(part, "name", part)) for part in (correction, fading)
             if part is not None]
    as_strategy("correction", correction), as_strategy("fading", fading)  # checked now, built at each build
    register_estimator(name, entry.builder, fits=entry.fits, requires=entry.requires,
                       description=description or f"{base} composed with {' and '.join(parts)}")
    _REGISTRY[name] = _Entry(name, entry.builder, entry.fits, _REGISTRY[name].description, entry.requires,
                             composed=(base, correction, fading))


def fit_reason(scenario: Any, name: str) -> str | None:
    """Why the estimator ``name`` does not fit ``scenario`` (None: it fits).

    A scenario with ``offers`` (:class:`Offers`) is checked against the
    estimator's :class:`Requires` first; then the estimator's ``fits`` callable.
    """
    entry = estimator_entry(name)
    offers = getattr(scenario, "offers", None)
    if isinstance(offers, Offers) and entry.requires is not None:
        why = entry.requires.reason(offers)
        if why is not None:
            return why
    fits = entry.fits(scenario)
    if isinstance(fits, str):  # the builder's own reason
        return fits
    if not fits:
        return f"its builder does not take a {type(scenario).__name__} (fits() is False)"
    return None


def registered_estimators(scenario: Any = None) -> tuple[str, ...]:
    """Names of the registered estimators (that fit ``scenario`` when given), in registration order.

    The first call loads the providers (:func:`load_providers`), so the list is complete in a fresh process.
    """
    _ensure_providers()
    return tuple(n for n in tuple(_REGISTRY) if scenario is None or fit_reason(scenario, n) is None)


def estimator_entry(name: str) -> _Entry:
    """The registry entry of ``name`` (builder, fits, description); an unknown name loads the providers first."""
    if isinstance(name, str) and name not in _REGISTRY:
        _ensure_providers()
    if not isinstance(name, str) or name not in _REGISTRY:
        raise InputError(f"unknown filter {name!r}; choose one of: {', '.join(_REGISTRY)}")
    return _REGISTRY[name]


def build_estimator(scenario: Any, name: str, *, covariance_form: str = "joseph", correction: Any = None,
                    fading: Any = None, **options: Any) -> Estimator:
    """Build the estimator registered as ``name`` for ``scenario``.

    ``correction`` (``"huber"``) and ``fading`` (``"strong_tracking"``): strategies composed onto the filter built
    (:func:`~hinfnav.estimators.strategies.compose`; a name, a dict ``{"name": …, **parameters}`` or an instance),
    e.g. ``build_estimator(scenario, "ukf", correction="huber")``; for a registered composition they replace its
    own (:func:`register_composition`).

    ``covariance_form="sqrt"`` gives its square-root (Cholesky-factor) form
    (:func:`~hinfnav.estimators.sqrt.square_root`; an InputError for a filter without one). ``options`` go to
    the builder (e.g. ``form="observer"`` of a designed filter), except ``gate``: a
    :class:`~hinfnav.estimators.gate.ChiSquareGate` or the dict of its parameters (a campaign's cell
    options), set on the filter built (a filter of the Kalman core or the sigma-point filter).
    """
    form = as_choice("covariance_form", covariance_form, FORMS)
    entry = estimator_entry(name)
    why = fit_reason(scenario, name)
    if why is not None:
        fitting = ", ".join(registered_estimators(scenario))
        raise InputError(f"filter {name!r} does not fit this scenario ({type(scenario).__name__}: {why}); "
                         f"these do: {fitting}")
    gate = options.pop("gate", None)
    core = {key: options.pop(key) for key in CORE_OPTIONS if key in options}
    try:
        est = entry.builder(scenario, **options)
    except TypeError as exc:
        bad = re.search(r"unexpected keyword argument '([^']+)'", str(exc))
        if bad is None:
            raise
        raise InputError(f"filter {name!r} has no option {bad.group(1)!r}; its options: "
                         f"{', '.join(_builder_options(entry.builder)) or 'none'} (and {', '.join(CORE_OPTIONS)}, "
                         "which every filter takes)") from None
    if entry.composed is not None:
        base, correction_0, fading_0 = entry.composed
        correction = correction_0 if correction is None else correction
        fading = fading_0 if fading is None else fading
    if correction is not None or fading is not None:
        if form != "joseph":
            raise InputError(f"covariance_form='sqrt': filter {name!r} with composed strategies has no square-root "
                             "form here")
        est = compose(est, correction=correction, fading=fading, name=name if entry.composed is not None else None)
    if "missing" in core:
        est.missing = core["missing"]  # the contract's property checks the value and names it
    if gate is not None:  # a χ² innovation gate (hinfnav.estimators.gate)
        if not hasattr(type(est), "gate"):
            raise InputError(f"gate: filter {name!r} takes no gate (the Kalman core's filters and the sigma-point "
                             "filter do)")
        est.gate = gate  # a dict is the gate's parameters (the filter's setter builds it)
    return est if form == "joseph" else square_root(est)


def _builder_options(builder):
    """The keyword options a builder declares (its ``**options`` pass-through left out)."""
    try:
        params = list(inspect.signature(builder).parameters.values())[1:]
    except (TypeError, ValueError):  # pragma: no cover - a builder without a signature
        return []
    return [p.name for p in params if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD)]
