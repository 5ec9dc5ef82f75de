"""Tuning a filter against its consistency: scalar scales of Q and R (or θ) that put NEES and NIS in their bands.

A filter told the wrong noise is inconsistent: its average NEES (C1, the error
normalised by the covariance it reports) and NIS (C2, the innovation normalised
by its S) leave their χ² bands (:func:`~hinfnav.metrics.consistency.chi2_bounds`).
:func:`tune_consistency` acts on it: on one Monte Carlo record (the truth
``x`` and the readings ``y`` of N runs, common to every trial, so the cost is a
deterministic function of the scales) it searches positive scalars ``s`` — the
factors of Q and R, or an H∞ filter's θ, whatever the caller's ``build(**s)``
multiplies — minimising

.. math::

    J(s) = \\ln^2\\!\\big(\\overline{\\mathrm{NEES}}(s)/n\\big)
         + \\ln^2\\!\\big(\\overline{\\mathrm{NIS}}(s)/m\\big)
         + \\sum_i \\ln^2\\!\\big(\\overline{e_i^2/P_{ii}}(s)\\big),

the averages taken over runs and the steps after ``skip`` (the start's
transient), by Nelder–Mead on ``ln s`` (scipy). J = 0 where the averages equal
their expectations under a consistent filter (n, m and 1 per component; the
component terms single out Q and R, which the two averages alone do not). The result says whether
they sit inside the 95 % bands of an average over N runs at one step
(``chi2_bounds(n, N)``: the usual per-step band, wider than one for the time
average, so "inside" is the necessary condition) and reports the RMS error the
tuning costs or gains (before and after).

For a linear-Gaussian model told Q₀ = a Q and R₀ = b R, the scales
``(1/a, 1/b)`` make J's expectation 0; with enough runs and steps the minimiser
is close to them (a test recovers Q and R within 10 %).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least
from .consistency import NIS_KEYS, chi2_bounds, normalized_squared

__all__ = ["TuningResult", "tune_consistency", "consistency_averages"]


@dataclass(frozen=True)
class TuningResult:
    """What :func:`tune_consistency` found.

    Attributes
    ----------
    scales : dict
        Name → the tuned positive scalar.
    nees, nis : float
        Average NEES and NIS at the tuned scales.
    nees_band, nis_band : (float, float)
        Their 95 % bands (an average over the runs at one step).
    inside : bool
        Both averages inside their bands.
    rms, rms_initial : ndarray, shape (n,)
        RMS error per state component at the tuned and at the initial scales (after ``skip``).
    cost, cost_initial : float
        J at the tuned and at the initial scales.
    evaluations : int
        Filter runs the search took.
    history : list of (dict, float, float)
        Every trial: scales, NEES, NIS.
    """

    scales: dict
    nees: float
    nis: float
    nees_band: tuple
    nis_band: tuple
    inside: bool
    rms: np.ndarray
    rms_initial: np.ndarray
    cost: float
    cost_initial: float
    evaluations: int
    history: list = field(default_factory=list, repr=False)


def consistency_averages(est: Any, x: ArrayLike, y: ArrayLike, u: ArrayLike, xhat0: ArrayLike,
                         P0: ArrayLike | None = None, skip: int = 0) -> tuple[float, float, np.ndarray, np.ndarray]:
    """``(NEES, NIS, RMS per component, e_i²/P_ii per component)`` of ``est`` on the record, averaged over runs and
    the steps from ``skip``.

    The error is ``x − x̂`` (additive states); the NIS uses the filter's ``innovation`` and
    ``innovation_covariance`` diagnostics (NaN when it reports none).
    """
    x = np.asarray(x, dtype=float)
    hist = est.estimate(y, u, xhat0, P0, keep_covariance=True, diagnostics=NIS_KEYS)
    if hist.P is None:
        raise InputError(f"filter {est.name!r} reports no covariance: it has no NEES to tune")
    err = (x - hist.xhat)[:, skip:]
    nees = float(np.nanmean(normalized_squared(err, hist.P[:, skip:])))
    if all(k in hist.diagnostics for k in NIS_KEYS):
        nu = hist.diagnostics[NIS_KEYS[0]][:, skip:]
        nis = float(np.nanmean(normalized_squared(nu, hist.diagnostics[NIS_KEYS[1]][:, skip:])))
    else:
        nis = float("nan")
    with np.errstate(all="ignore"):
        per = np.nanmean(err**2 / np.diagonal(hist.P[:, skip:], axis1=-2, axis2=-1), axis=(0, 1))
    return nees, nis, np.sqrt(np.mean(err**2, axis=(0, 1))), per


def tune_consistency(build: Callable[..., Any], initial: Mapping[str, float], x: ArrayLike, y: ArrayLike,
                     u: ArrayLike, xhat0: ArrayLike, *, P0: ArrayLike | None = None, skip: int | None = None,
                     use_nis: bool = True, components: bool = True, xatol: float = 1e-3, max_evaluations: int = 400) -> TuningResult:
    """Tune positive scalars so that the filter's average NEES and NIS sit at their expectations (see the module
    docstring).

    Parameters
    ----------
    build : callable
        ``build(**scales) -> Estimator`` (a filter of the step contract with a covariance), e.g.
        ``lambda Q, R: ExtendedKalmanFilter(system, meas, P0=P0, Q=Q * Q0, R=R * R0)``.
    initial : dict
        Name → initial positive value of each scalar tuned.
    x : array_like, shape (runs, n_samples, n)
        The true states of the record.
    y, u : array_like
        Its readings (runs, n_samples, m) and inputs (runs, n_samples, n_input).
    xhat0 : array_like, shape (n,)
    P0 : array_like, optional
    skip : int, optional
        Steps left out of the averages (default a tenth of the record).
    use_nis : bool
        Include the NIS term (False: the NEES alone, for one scalar).
    components : bool
        Include the normalised error of each component, ``Σ_i ln²(mean(e_i²/P_ii))`` (True): the NEES and
        NIS averages alone do not single out Q and R (measured: a filter told 10 Q matches both with R
        adjusted), each component's does.
    xatol : float
        Nelder–Mead's tolerance on ln s.
    max_evaluations : int

    Returns
    -------
    TuningResult
    """
    if not isinstance(initial, Mapping) or not initial:
        raise InputError(f"initial must be a dict name -> positive value; got {initial!r}")
    names = list(initial)
    s0 = np.array([float(initial[k]) for k in names])
    if not np.all(np.isfinite(s0)) or np.any(s0 <= 0):
        raise InputError(f"initial: every scale must be a positive number; got {dict(initial)!r}")
    y = np.asarray(y, dtype=float)
    runs, n1 = y.shape[:2]
    skip = n1 // 10 if skip is None else as_int_at_least("skip", skip, 0)
    if skip >= n1:
        raise InputError(f"skip must be below the record's {n1} steps; got {skip}")
    max_evaluations = as_int_at_least("max_evaluations", max_evaluations, 1)
    history = []

    def evaluate(log_s):
        scales = dict(zip(names, np.exp(log_s)))
        nees, nis, rms, per = consistency_averages(build(**scales), x, y, u, xhat0, P0, skip)
        history.append((scales, nees, nis))
        return nees, nis, rms, per

    n, m = np.shape(x)[-1], y.shape[-1]

    def cost(log_s):
        nees, nis, _, per = evaluate(log_s)
        if not (np.isfinite(nees) and nees > 0 and np.all(np.isfinite(per)) and np.all(per > 0)):
            return 1e6
        J = np.log(nees / n) ** 2 + (np.sum(np.log(per) ** 2) if components else 0.0)
        if use_nis:
            J += np.log(nis / m) ** 2 if np.isfinite(nis) and nis > 0 else 1e6
        return J

    cost_initial = cost(np.log(s0))
    rms0 = evaluate(np.log(s0))[2]
    found = scipy.optimize.minimize(cost, np.log(s0), method="Nelder-Mead",
                                    options={"xatol": xatol, "fatol": 1e-6, "maxfev": max_evaluations})
    nees, nis, rms, _ = evaluate(found.x)
    nees_band, nis_band = chi2_bounds(n, runs), chi2_bounds(m, runs)
    inside = bool(nees_band[0] <= nees <= nees_band[1] and (not use_nis or nis_band[0] <= nis <= nis_band[1]))
    return TuningResult(scales=dict(zip(names, map(float, np.exp(found.x)))), nees=nees, nis=nis,
                        nees_band=nees_band, nis_band=nis_band, inside=inside, rms=rms, rms_initial=rms0,
                        cost=float(found.fun), cost_initial=float(cost_initial), evaluations=len(history),
                        history=history)
