"""Filtering and smoothing of time-stamped readings: a step of its own length between every two stamps.

The documented way (see :mod:`hinfnav.systems.timed` for the system and the readings)::

    est = ExtendedKalmanFilter(timed.at(readings.nominal_dt), meas, P0=P0, missing="skip")
    hist = estimate_timed(est, timed, readings, xhat0)    # EstimateHistory at readings.t
    sm = smooth_timed(est, timed, readings, xhat0)        # SmoothedHistory (RTS; lag=L: fixed lag)

The update at t_k is the filter's own (it does not depend on the step); the
prediction from t_k to t_{k+1} is made by the filter rebuilt on
``timed.at(t_{k+1} − t_k)``: its Φ (or dynamics model), Γ and Q (and the
square-root forms' factor of Q) are that step's; every other setting is the
filter's. Q given to the filter's constructor is therefore replaced by each
step's Q. A dynamics model's ``f(x, u, t)`` is called with ``t = k Δt_k``
(time-invariant models, the usual ones, do not read it).

Filters: the Kalman/EKF family, the Huber filter, the sigma-point filter and
their square-root forms (the filters whose prediction reads ``F``/``system``
and ``Q``); others are refused with an :class:`~hinfnav.core.exceptions.InputError`.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from threadpoolctl import threadpool_limits

from ..core.exceptions import InputError
from ..core.linalg import as_covariance
from .base import EstimateHistory, Estimator, check_estimator_inputs, history_keys, store_diagnostics
from .kalman import ExtendedKalmanFilter
from .sigma_point import SigmaPointFilter
from .smoothers import SmoothedHistory, filter_record, rts_smooth
from .sqrt import factor

__all__ = ["estimate_timed", "smooth_timed"]


def step_filter(estimator: Estimator, system: Any) -> Estimator:
    """A copy of ``estimator`` whose prediction is made on ``system`` (one step's): its F, Γ, Q (and factor of Q)."""
    if not isinstance(estimator, (ExtendedKalmanFilter, SigmaPointFilter)):
        raise InputError(f"{type(estimator).__name__} is not a filter this module rebuilds per step "
                         "(ExtendedKalmanFilter and its variants, SigmaPointFilter, their square-root forms)")
    if getattr(estimator, "defers_prior", False):
        raise InputError(f"{type(estimator).__name__} completes its prior at the next reading with a Q of its own "
                         "step: not rebuilt per step here")
    if system.n != estimator.system.n:
        raise InputError(f"the step's system has {system.n} states, the filter's {estimator.system.n}")
    step = copy.copy(estimator)
    step.system = system
    step.Q = as_covariance("Q of the step's system", system.Q, getattr(estimator, "n_cov", system.n), definite=False)
    if isinstance(estimator, ExtendedKalmanFilter):
        if estimator.nonlinear_dynamics == getattr(system, "linear", True):
            raise InputError("the step's system must be linear exactly when the filter's is")
        step.F = getattr(system, "Phi", None)
        step.Gamma = getattr(system, "Gamma", None)
    if hasattr(estimator, "LQ"):
        step.LQ = factor("Q of the step's system", step.Q)
    return step


def _checked(estimator, timed, readings, u):
    if not hasattr(timed, "at") or not hasattr(readings, "t"):
        raise InputError("timed must be a hinfnav TimedSystem and readings TimedReadings (hinfnav.systems.timed)")
    y = readings.y
    if u is None:
        if estimator.uses_input:
            raise InputError(f"filter {estimator.name!r} uses the applied input: u is needed")
        u = np.zeros(y.shape[:2] + (0,))
    steps = [None] * (readings.t.size - 1)
    dts = readings.dt

    def predictor(k):
        if steps[k] is None:
            steps[k] = step_filter(estimator, timed.at(float(dts[k])))
        return steps[k]

    return y, u, predictor


def estimate_timed(estimator: Estimator, timed: Any, readings: Any, xhat0: ArrayLike, P0: ArrayLike | None = None, *,
                   u: ArrayLike | None = None, keep_covariance: bool = True,
                   diagnostics: bool | Any = False) -> EstimateHistory:
    """Filter time-stamped readings: the estimate (and covariance) at every stamp ``readings.t``.

    Parameters
    ----------
    estimator : Estimator
        Built on any step's system (e.g. ``timed.at(readings.nominal_dt)``);
        ``missing="skip"`` when some channels are not read at some stamps.
    timed : TimedSystem
    readings : TimedReadings
    xhat0 : array_like, shape (n,) or (runs, n)
        Prior estimate at ``readings.t[0]``.
    P0 : array_like, optional
    u : array_like, shape (runs, N, n_input), optional
        Input held from each stamp to the next.
    keep_covariance : bool
    diagnostics : bool or iterable of str

    Returns
    -------
    EstimateHistory
    """
    with threadpool_limits(limits=1):  # small matrices, one step's expm each: threads only cost
        return _estimate_timed(estimator, timed, readings, xhat0, P0, u, keep_covariance, diagnostics)


def _estimate_timed(estimator, timed, readings, xhat0, P0, u, keep_covariance, diagnostics):
    keys = history_keys(keep_covariance, diagnostics)
    y, u, predictor = _checked(estimator, timed, readings, u)
    y, u, xhat0 = check_estimator_inputs(y, u, xhat0, estimator.n_state, estimator.measurement.n_meas,
                                         estimator.n_input if estimator.uses_input else None, estimator.missing)
    runs, N, _ = y.shape
    state = estimator.start(xhat0, P0, runs)
    xhat = np.empty((runs, N, estimator.n_state))
    P_hist, diag = None, {}
    for k in range(N):
        state, out = estimator._update(state, y[:, k])
        xhat[:, k] = out.xhat
        if keep_covariance and out.P is not None:
            if P_hist is None:
                P_hist = np.empty((runs, N) + out.P.shape[-2:])
            P_hist[:, k] = out.P
        store_diagnostics(diag, out.diagnostics, keys, k, runs, N)
        if k < N - 1:
            state = predictor(k)._predict(state, u[:, k])
    return EstimateHistory(xhat=xhat, P=P_hist, state=estimator.system.state, diagnostics=diag)


def smooth_timed(estimator: Estimator, timed: Any, readings: Any, xhat0: ArrayLike, P0: ArrayLike | None = None, *,
                 u: ArrayLike | None = None, lag: int | None = None) -> SmoothedHistory:
    """Smooth time-stamped readings (RTS, or fixed-lag with ``lag`` stamps): :func:`~hinfnav.estimators.smoothers.smooth`
    with a step of its own length between every two stamps."""
    y, u, predictor = _checked(estimator, timed, readings, u)
    with threadpool_limits(limits=1):
        return rts_smooth(filter_record(estimator, y, u, xhat0, P0, predictor=predictor), lag=lag)
