"""The EKF baseline of Sun et al. (2011) (Table 1, Figs 2 and 4), on the generic filter.

The paper compares its robust H∞ filter with an EKF but prints nothing about
that EKF: not its measurement model, its Q, R, P₀, nor whether it knows the
chaser's control law. This module makes every one of those choices explicit
and selectable; :func:`build_ekf` gives the two variants of the filter
registry (:mod:`hinfnav.papers.sun2011.filters`):

``ekf`` (``known_input=False``)
    propagates the *unforced* Hill model. It does not know the thrust, so
    with the orbit maneuver u = Kx of (3) its model misses accelerations of
    up to ~3 m/s² (|u| ≈ 3000 N on 1000 kg at t = 0) while Q only allows
    0.001 m/s of velocity noise per step: it lags the maneuver until the
    thrust has died away (~500 s), which is the failure the paper describes
    for Fig 4 (measured, 100 runs: per-axis RMS over 100–500 s of
    0.43–0.67 m and 2.7–4.3 m/s; over 500–1000 s 0.064 m and 0.07–0.08 m/s).
    Nothing is tuned to make it fail: Q and R are the true noise levels.
``ekf_known_input`` (``known_input=True``)
    propagates the Hill model driven by the applied thrust u(k) (the ``u``
    argument of :meth:`EKF.estimate`). Its error obeys the unforced model
    whatever u is, so with or without maneuver it sits at the open-loop
    Riccati limit (0.0626 m, 0.0224 m/s per axis).

A third dynamics model, ``dynamics="control_law"``, assumes the law
u = K x̂ (the model the H∞ filter is designed on) without being told u.

Measurement models
------------------
``"position"`` (default)
    the indirect position measurement (8), y = C x + D v with C = [I 0]: the
    same as the H∞ filter's and what :func:`hinfnav.simulate_truth`
    produces. It is linear, so this "EKF" is the Kalman filter and its gain
    sequence does not depend on the data (see *Speed* below).
``"range_angles"``
    the direct measurement of range ρ, azimuth α and elevation β behind (7),
    nonlinear (C_bl = I unless given). Produce such measurements with
    :func:`range_angle_measurements`.

Speed
-----
The filter is :class:`hinfnav.estimators.ExtendedKalmanFilter`, batched over
runs. With the position measurement the covariance and gain sequence is the
same for every run and is computed once per step for all of them; with the
range/angle model each run carries its own covariance.
``tests/test_sun2011_ekf.py`` checks both against filterpy's
``ExtendedKalmanFilter`` run by run.
"""

from __future__ import annotations

import inspect
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...core.exceptions import InputError
from ...core.validation import as_choice, as_nonnegative, as_positive, check_keywords
from ...estimators.kalman import ExtendedKalmanFilter
from ...systems.measurements import RangeAzimuthElevation, wrap_angle
from .constants import DEFAULT_P0_STD, DEFAULT_SIGMA_ANGLE, DEFAULT_SIGMA_RANGE
from .scenario import Scenario

__all__ = [
    "EKF",
    "build_ekf",
    "range_angle_measurements",
]

#: Measurement models of :func:`EKF`.
MEASUREMENT_MODELS = ("position", "range_angles")
#: Dynamics models of :func:`EKF`: what the filter assumes about the thrust.
DYNAMICS_MODELS = ("unforced", "applied_thrust", "control_law")


def EKF(
    scenario: Scenario,
    *,
    measurement: str = "position",
    dynamics: str = "unforced",
    discretization: str = "exact",
    Q: ArrayLike | None = None,
    R: ArrayLike | None = None,
    P0: ArrayLike | None = None,
    sigma_range: float | None = None,
    sigma_angle: float | None = None,
    C_bl: ArrayLike | None = None,
    output: str = "filtered",
    name: str | None = None,
) -> ExtendedKalmanFilter:
    """Extended Kalman filter of the chaser's relative state (filterpy).

    Parameters
    ----------
    scenario : Scenario
        Gives T, ω₀, mass, K, B and D.
    measurement : {"position", "range_angles"}
        ``"position"``: y = C x + D v of (8), R = D Dᵀ by default.
        ``"range_angles"``: y = (ρ, α, β) of (7) plus white noise,
        R = diag(σ_ρ², σ_α², σ_α²) by default.
    dynamics : {"unforced", "applied_thrust", "control_law"}
        ``"unforced"``: x̂(k+1|k) = Φ x̂(k|k), the thrust unknown (the
        paper's EKF). ``"applied_thrust"``: Φ x̂(k|k) + Γ u(k) with the
        applied u. ``"control_law"``: (Φ + Γ K) x̂(k|k), the law u = Kx
        assumed (right with the maneuver: 0.0625 m, 0.0138 m/s; wrong
        without it: 7–12 m, 40–80 m/s over 100–1000 s).
    discretization : {"exact", "euler"}
        (Φ, Γ) from ``scenario.truth_matrices(0.0, discretization)``.
        ``"exact"`` (zero-order hold, default) is the truth simulation's
        default model, so the filter's model is the truth's at δ = 0 and its
        covariance is the true error covariance. ``"euler"`` is the paper's
        (6); the two differ by T²A₀²/2, which is tiny for A₁ but, for the
        thrust, leaves out the T²/2m position term of Γ (5 mm per step at
        1000 N).
    Q : array_like, shape (6, 6), optional
        Process-noise covariance per step; default B Bᵀ (positive
        semidefinite).
    R : array_like, shape (3, 3), optional
        Measurement-noise covariance (positive definite); default D Dᵀ or
        diag(σ_ρ², σ_α², σ_α²).
    P0 : array_like, shape (6, 6), optional
        Initial covariance (positive definite); default
        diag(:data:`DEFAULT_P0_STD`)².
    sigma_range, sigma_angle : float, optional
        Noise of the range/angle model (m, rad) for its default R; only
        with ``measurement="range_angles"``.
    C_bl : array_like, shape (3, 3), optional
        Relative-to-body rotation of the range/angle model (identity).
    output : {"filtered", "predicted"}
        What ``xhat[:, k]`` is: ``"filtered"`` (default) x̂(k|k), which uses
        y(0) … y(k); ``"predicted"`` x̂(k|k−1), which uses y(0) … y(k−1) like
        the fixed LTI filter (12) (and ``xhat[:, 0] = xhat0``).
    name : str, optional

    Notes
    -----
    *Model.* The Hill dynamics (1)–(2) are linear, so the dynamics Jacobian
    is Φ (or Φ + ΓK) itself and the only nonlinearity is the range/angle
    measurement; with the indirect measurement (8) the EKF is exactly the
    Kalman filter. The filter uses the nominal rate ω₀ (δ = 0).

    *Noise.* The simulation drives the truth with unit-variance white w, v
    scaled by B and D ((6), (8)), so Q = B Bᵀ and R = D Dᵀ are the true
    covariances: no tuning. The unforced EKF's failure with maneuver follows
    from Q being far too small for the unmodelled thrust, which is exactly
    what an EKF built on the stated noise model and without the control law
    has to do.

    *Timing.* ``xhat[:, k]`` is by default the filtered estimate x̂(k|k): it
    has used y(k), as a textbook EKF does. The fixed LTI filter (12) is a
    predictor (y up to k−1); its limit is the predicted one (0.0802 m instead
    of 0.0626 m per axis, velocity nearly the same). ``output="predicted"``
    gives the EKF on the same footing.

    *Discretization.* Exact (zero-order hold) by default because the truth
    simulation uses it: the filter's model then is the truth's at δ = 0, so
    its covariance is the true error covariance and it reaches the Riccati
    limit. Euler ((6) of the paper) is available for comparison.

    *Initial covariance.* P₀ = diag(50², 50², 50², 0.1², 0.1², 0.1²) covers
    the initial estimate's errors (30, 30, 40) m, (0.02, 0.08, 0.03) m/s
    within one σ. The position part is irrelevant after the first update
    (R = 0.01 m²); the velocity part sets how fast the velocity converges.

    *Accuracy limit.* Its steady-state covariance is the discrete Riccati
    solution of :func:`hinfnav.papers.sun2011.kalman_limit` for the open-loop
    model: 0.0626 m and 0.0224 m/s per axis, filtered. Table 1's EKF
    numbers (0.04 m, 0.001 m/s) are below that limit.

    Returns
    -------
    hinfnav.estimators.ExtendedKalmanFilter
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    measurement = as_choice("measurement model", measurement, MEASUREMENT_MODELS)
    dynamics = as_choice("dynamics model", dynamics, DYNAMICS_MODELS)
    discretization = as_choice("discretization", discretization, ("exact", "euler"))
    system = scenario.system(0.0, discretization, closed_loop=(dynamics == "control_law"))
    if measurement == "position":
        for key, val in (("sigma_range", sigma_range), ("sigma_angle", sigma_angle), ("C_bl", C_bl)):
            if val is not None:
                raise InputError(f"{key} applies only to measurement='range_angles'")
        model = scenario.measurement
    else:
        sr = DEFAULT_SIGMA_RANGE if sigma_range is None else as_positive("sigma_range", sigma_range)
        sa = DEFAULT_SIGMA_ANGLE if sigma_angle is None else as_positive("sigma_angle", sigma_angle)
        model = RangeAzimuthElevation(6, sr, sa, C_bl)
    if name is None:
        name = {"unforced": "ekf", "applied_thrust": "ekf_known_input", "control_law": "ekf_control_law"}[dynamics]
        if measurement == "range_angles":
            name += "_range_angles"
    P0 = np.diag(DEFAULT_P0_STD**2) if P0 is None else P0
    return ExtendedKalmanFilter(system, model, P0=P0, Q=Q, R=R, uses_input=(dynamics == "applied_thrust"),
                                output=output, name=name)


def build_ekf(scenario: Scenario, known_input: bool = False, **options: Any) -> ExtendedKalmanFilter:
    """Build the EKF of the filter registry (names ``ekf``, ``ekf_known_input``).

    Parameters
    ----------
    scenario : Scenario
    known_input : bool
        False: the paper's EKF, which does not know the thrust
        (``dynamics="unforced"``). True: told the applied thrust
        (``dynamics="applied_thrust"``).
    **options
        Passed to :func:`EKF` (``measurement``, ``discretization``, ``Q``,
        ``R``, ``P0``, ``output``, ...). ``dynamics="control_law"`` is
        accepted with ``known_input=False`` (it does not use u).

    Returns
    -------
    hinfnav.estimators.ExtendedKalmanFilter
    """
    if not isinstance(known_input, (bool, np.bool_)):
        raise InputError(f"known_input must be True or False; got {known_input!r}")
    check_keywords("EKF option", options, _EKF_OPTIONS)
    dynamics = options.pop("dynamics", None)
    if dynamics is None:
        dynamics = "applied_thrust" if known_input else "unforced"
    else:
        as_choice("dynamics model", dynamics, DYNAMICS_MODELS)
        if (dynamics == "applied_thrust") != bool(known_input):
            raise InputError(
                f"dynamics={dynamics!r} contradicts known_input={bool(known_input)}: "
                "only dynamics='applied_thrust' uses the applied thrust"
            )
    return EKF(scenario, dynamics=dynamics, **options)


#: Keyword options of :func:`EKF` (what :func:`build_ekf` and ``make_estimator("ekf", ...)`` pass on).
_EKF_OPTIONS = tuple(p for p in inspect.signature(EKF).parameters if p != "scenario")


def range_angle_measurements(x: ArrayLike, rng: np.random.Generator, sigma_range: float = DEFAULT_SIGMA_RANGE,
                             sigma_angle: float = DEFAULT_SIGMA_ANGLE, C_bl: ArrayLike | None = None) -> NDArray[np.float64]:
    """Noisy range/azimuth/elevation measurements of the states ``x``, eq. (7).

    Parameters
    ----------
    x : array_like, shape (..., 6)
        True states (e.g. ``Truth.x``), m, m/s.
    rng : numpy.random.Generator
        Source of the noise; one ``standard_normal(x.shape[:-1] + (3,))`` draw.
    sigma_range : float
        Standard deviation of the range noise, m (≥ 0).
    sigma_angle : float
        Standard deviation of the azimuth and elevation noise, rad (≥ 0).
    C_bl : array_like, shape (3, 3), optional

    Returns
    -------
    ndarray, shape (..., 3)
        ρ + σ_ρ n₁ (m), α + σ_α n₂ and β + σ_α n₃ (rad), azimuth wrapped to (−π, π].
    """
    if not isinstance(rng, np.random.Generator):
        raise InputError(f"rng must be a numpy.random.Generator (e.g. numpy.random.default_rng(seed)); got {type(rng).__name__}")
    sr = as_nonnegative("sigma_range", sigma_range)
    sa = as_nonnegative("sigma_angle", sigma_angle)
    model = RangeAzimuthElevation(np.shape(x)[-1], max(sr, 1e-300), max(sa, 1e-300), C_bl)
    clean = model.function(x)
    noisy = clean + rng.standard_normal(clean.shape) * np.array([sr, sa, sa])
    noisy[..., 1] = wrap_angle(noisy[..., 1])
    return noisy
