"""Sensitivity of the HBF–EKF comparison to the lost sensor errors, and to a filter told the wrong ones.

* :func:`sensitivity_sweep` — the Gaussian case (§3.1) with other true sensor
  errors (both filters told the truth): if the paper's statistic were a 3σ
  bound the errors would be 3× smaller, if the sensor were range- or
  angle-dominated the converted noise would be anisotropic, a quieter
  accelerometer changes the dynamics' weight. Each variant gives both
  filters' accuracy and the Kalman (Riccati) limit.
* :func:`mistuning_sweep` — the true sensor errors unchanged, both filters
  told errors ``c`` times the true ones (``c < 1``: they trust the
  measurements too much, as a filter does that takes a 3σ table value for
  1σ in the truth and for 3σ in the filter, ``c = 1/3``). This is where a
  Huber update can beat the Kalman update under Gaussian noise: its weights
  undo part of the mistuning.
"""

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_positive
from .calibration import riccati_accuracy
from .filters import EKF, HBF
from .scenario import Scenario
from .studies import filter_summary, paired_gap, run_case

__all__ = ["SENSOR_VARIANTS", "MISTUNING_FACTORS", "sensitivity_point", "mistuning_point", "sensitivity_sweep",
           "mistuning_sweep"]

#: Variants of the true sensor errors: label → multipliers of (σ_ρ, σ_α, σ_a).
SENSOR_VARIANTS = {
    "calibrated": (1.0, 1.0, 1.0),
    "all x1/3 (accuracy read as 3 sigma)": (1 / 3, 1 / 3, 1 / 3),
    "all x3": (3.0, 3.0, 3.0),
    "range x1/4 (angle-dominated)": (0.25, 1.0, 1.0),
    "angles x1/4 (range-dominated)": (1.0, 0.25, 1.0),
    "accelerometer x1/4": (1.0, 1.0, 0.25),
}

#: Factors c of the sensor errors the filters are told (c = 1: the truth).
MISTUNING_FACTORS = (1.0, 1 / 3, 1 / 10, 1 / 20)


def _row(res):
    hbf, ekf = res.filters["hbf"], res.filters["ekf"]
    return {"hbf": filter_summary(hbf), "ekf": filter_summary(ekf), "hbf_minus_ekf": paired_gap(hbf, ekf)}


def _check(scenario, runs):
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Shi 2018 Scenario; got {type(scenario).__name__}")
    return as_int_at_least("runs", runs, 2)


def sensitivity_sweep(scenario=None, variants=None, *, runs=40, seed=0, progress=False):
    """The Gaussian case with other true sensor errors, both filters told them.

    Parameters
    ----------
    scenario : Scenario, optional
        The reference (default the rebuilt one, calibrated errors).
    variants : dict, optional
        Label → (factor on σ_ρ, on σ_α, on σ_a); default :data:`SENSOR_VARIANTS`.
    runs : int
        Monte Carlo runs per variant (≥ 2).
    seed : int
    progress : bool

    Returns
    -------
    list of dict
        One per variant: ``variant``, the three σ (1σ), ``hbf`` and ``ekf``
        (:func:`~hinfnav.papers.shi2018.studies.filter_summary`),
        ``hbf_minus_ekf`` (paired gap and ratios), ``kalman_limit``.
    """
    scenario = Scenario() if scenario is None else scenario
    variants = SENSOR_VARIANTS if variants is None else dict(variants)
    return [sensitivity_point(scenario, label, factors, runs=runs, seed=seed, progress=progress)
            for label, factors in variants.items()]


def sensitivity_point(scenario, label, factors, *, runs=40, seed=0, progress=False):
    """One row of :func:`sensitivity_sweep`: the true σ_ρ, σ_α, σ_a multiplied by ``factors``."""
    runs = _check(scenario, runs)
    try:
        fr, fa, fq = (as_positive("sensor factor", f) for f in factors)
    except (TypeError, ValueError):
        raise InputError(f"variant {label!r} must be three positive factors (range, angle, accel); got {factors!r}") from None
    sc = scenario.replace(sigma_range=fr * scenario.sigma_range, sigma_angle=fa * scenario.sigma_angle,
                          sigma_accel=fq * scenario.sigma_accel)
    res = run_case(sc, "gaussian", runs=runs, seed=seed, progress=progress)
    lim = riccati_accuracy(sc)
    return {"variant": label, "factors": [fr, fa, fq], "sigma_range_m": sc.sigma_range,
            "sigma_angle_rad": sc.sigma_angle, "sigma_accel_mps2": sc.sigma_accel, **_row(res),
            "kalman_limit": {"pos_m": lim.pos_m, "vel_mps": lim.vel_mps}}


def mistuning_sweep(scenario=None, factors=MISTUNING_FACTORS, *, runs=40, seed=0, progress=False):
    """Both filters told sensor errors ``c`` times the true ones, Gaussian truth.

    Parameters
    ----------
    scenario : Scenario, optional
    factors : sequence of float
        The factors c (> 0).
    runs, seed, progress
        As in :func:`sensitivity_sweep`.

    Returns
    -------
    list of dict
        One per c: ``c``, ``hbf``, ``ekf``, ``hbf_minus_ekf`` (with
        ``pos_ratio``, ``vel_ratio`` = HBF/EKF Monte Carlo means).
    """
    scenario = Scenario() if scenario is None else scenario
    return [mistuning_point(scenario, c, runs=runs, seed=seed, progress=progress) for c in factors]


def mistuning_point(scenario, c, *, runs=40, seed=0, progress=False):
    """One row of :func:`mistuning_sweep`: both filters told ``c`` times the true sensor errors."""
    runs = _check(scenario, runs)
    c = as_positive("mistuning factor c", c)
    told = {"sigma_range": c * scenario.sigma_range, "sigma_angle": c * scenario.sigma_angle}
    res = run_case(scenario, "gaussian", {"hbf": HBF(scenario, **told), "ekf": EKF(scenario, **told)}, runs=runs,
                   seed=seed, progress=progress)
    return {"c": c, **_row(res)}
