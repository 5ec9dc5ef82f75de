"""Filter ideas as strategies composed onto one Kalman core, whatever its moment rule.

A filter of the Kalman core (:class:`~hinfnav.estimators.kalman.KalmanCore`) is built from parts:

* its **moment rule** (:mod:`hinfnav.estimators.moments`): linearised (the EKF, the augmented and attitude
  filters) or sigma-point (:class:`~hinfnav.estimators.sigma_point.SigmaPointFilter`: the unscented or
  cubature transform), which gives the moments of the predicted reading and the prediction;
* a **correction** strategy acting on those moments: the Kalman update (J1)-(J2) unless one is composed,
  ``"huber"`` (:class:`~hinfnav.estimators.huber_filter.HuberStrategy`) or ``"correntropy"``
  (:class:`~hinfnav.estimators.correntropy.CorrentropyStrategy`, Chen et al. 2017);
* a **fading** strategy completing the prior at the next reading: none, or ``"strong_tracking"``
  (:class:`~hinfnav.estimators.adaptive.StrongTrackingStrategy`).

:func:`compose` puts strategies on a built filter (a configured copy; no new class), so any idea combines
with any moment rule: ``compose(ukf, correction="huber")`` is the Huber-based sigma-point filter,
``compose(ukf, fading="strong_tracking")`` the strong-tracking sigma-point filter, and on the EKF the same
calls give exactly the numbers of the named classes :class:`~hinfnav.estimators.HuberFilter` and
:class:`~hinfnav.estimators.StrongTrackingEKF` (which stay as named configurations with a compiled kernel).
The registry composes by name: ``build_estimator(scenario, "ukf", correction="huber")``, and
:func:`~hinfnav.estimators.registry.register_composition` names a combination (``huber_ukf``, ``stukf``).

A strategy is given by its name (its defaults), by the dict ``{"name": ..., **parameters}`` (a campaign
cell's JSON), or as an instance (``HuberStrategy(gamma=2.0)``). A composed filter runs on the NumPy path:
:func:`~hinfnav.estimators.compiled.why_numpy` says so (no kernel knows the combination).

A correction strategy is an object with ``name``, ``bind(estimator)`` (checks) and
``correct_error(estimator, P, H, R, innovation, x) -> (δx, P⁺, diagnostics)``; a fading strategy has ``name``,
``bind``, ``check_runs(runs)``, ``initial_diagnostics(estimator, runs)`` and ``complete_prior(estimator, ΦPΦᵀ,
Q_d, state, innovation, H, mask)`` (the core's hooks, with the filter passed in).

Not (yet) strategies: the Student-t and noise-adaptive variational corrections
(:mod:`hinfnav.estimators.variational`) carry their noise estimates between readings through their own
``correct`` and stay classes on the linearised rule; rate-adapted noise
(:class:`~hinfnav.estimators.adaptive.RateAdaptive`) keeps its mixin.
"""

from __future__ import annotations

import copy
from typing import Any

from ..core.exceptions import InputError
from .adaptive import StrongTrackingStrategy
from .correction import KalmanCorrection
from .correntropy import CorrentropyStrategy
from .huber_filter import HuberStrategy
from .kalman import KalmanCore

__all__ = ["CORRECTIONS", "FADINGS", "as_strategy", "compose"]

#: Correction strategies by name.
CORRECTIONS = {"huber": HuberStrategy, "correntropy": CorrentropyStrategy}
#: Prior-fading strategies by name.
FADINGS = {"strong_tracking": StrongTrackingStrategy}


def as_strategy(kind: str, value: Any) -> Any:
    """The strategy ``value`` of ``kind`` ("correction" or "fading"): a name, a dict ``{"name": …, **params}``
    or an instance; None stays None."""
    table = CORRECTIONS if kind == "correction" else FADINGS
    if value is None or isinstance(value, tuple(table.values())):
        return value
    params = {}
    if isinstance(value, dict):
        params = dict(value)
        value = params.pop("name", None)
    if not isinstance(value, str) or value not in table:
        raise InputError(f"{kind} must be one of {', '.join(map(repr, table))} (a name, a dict with 'name' and its "
                         f"parameters, or a strategy instance); got {value!r}")
    try:
        return table[value](**params)
    except TypeError as exc:
        raise InputError(f"{kind} {value!r}: {exc}") from None


def compose(estimator: KalmanCore, *, correction: Any = None, fading: Any = None, name: str | None = None) -> KalmanCore:
    """A copy of ``estimator`` with the given correction and/or fading strategy (see the module docstring).

    Parameters
    ----------
    estimator : KalmanCore
        A filter of the Kalman core (EKF, sigma-point, augmented …) whose class has the plain Kalman correction
        (for ``correction``) and no fading of its own (for ``fading``).
    correction : str, dict or strategy, optional
        ``"huber"`` (:data:`CORRECTIONS`).
    fading : str, dict or strategy, optional
        ``"strong_tracking"`` (:data:`FADINGS`).
    name : str, optional
        The composed filter's name (default: the strategies' names before the filter's).

    Returns
    -------
    KalmanCore
        Same class, model, P₀, Q, R and options; every run carries its own covariance.
    """
    if not isinstance(estimator, KalmanCore):
        raise InputError(f"strategies compose onto a filter of the Kalman core (ExtendedKalmanFilter, "
                         f"SigmaPointFilter, AugmentedEKF …); got {type(estimator).__name__}")
    correction, fading = as_strategy("correction", correction), as_strategy("fading", fading)
    cls = type(estimator)
    if correction is not None and (estimator.correction_rule is not None or cls.correct is not KalmanCore.correct
                                   or cls.correct_error is not KalmanCorrection.correct_error):
        raise InputError(f"correction: {cls.__name__} {estimator.name!r} already has its own correction; compose "
                         "onto the plain filter (e.g. the EKF or the sigma-point filter)")
    if fading is not None and (estimator.fading_rule is not None or cls.defers_prior):
        raise InputError(f"fading: {cls.__name__} {estimator.name!r} already completes its prior at the reading "
                         "(strong tracking or adapted noise); compose onto the plain filter")
    if getattr(estimator, "form", None) == "sqrt":
        raise InputError(f"strategies compose onto the covariance form; {estimator.name!r} is a square-root filter")
    for rule in (correction, fading):
        if rule is not None:
            rule.bind(estimator)
    new = copy.copy(estimator)
    parts = []
    if correction is not None:
        new.correction_rule = correction
        parts.append(correction.name)
    if fading is not None:
        new.fading_rule = fading
        new.defers_prior = True
        parts.append(fading.name)
    if parts:
        new.data_dependent_covariance = True  # the weights and fading factors depend on the data
        new.name = name if name is not None else "_".join(parts + [estimator.name])
    return new
