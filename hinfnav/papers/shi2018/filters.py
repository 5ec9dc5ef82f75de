"""The two filters of Shi & Wang (2018), registered by name: the EKF and the Huber-based filter.

=================  ==========================================================
name               estimator
=================  ==========================================================
``ekf_converted``  the EKF of the comparison: Hill/CW prediction with the
                   measured control acceleration, Kalman update on the
                   indirect position measurement (20)–(22), R_k = J R Jᵀ at
                   each reading (fits this paper's scenario only)
``hbf``            the Huber-based filter: the same filter with the Huber
                   update (:class:`hinfnav.estimators.HuberFilter`). Fits any
                   scenario that has a Kalman filter to robustify (see
                   :func:`build_hbf`), e.g. Sun 2011's chaser
``ukf``            the unscented (sigma-point) Kalman filter that papers 000
                   and 001 name as the usual alternative to the EKF
                   (:class:`hinfnav.estimators.SigmaPointFilter`): here on the
                   direct range/angle readings; on other papers' scenarios the
                   sigma-point version of their Kalman filter (see :func:`build_ukf`)
=================  ==========================================================

Both filters know the true Q and the true sensor errors unless told others
(``sigma_range``, ``sigma_angle``: the sensor errors the filter assumes, for
the mistuning study), so under Gaussian noise the EKF is (to first order in
the conversion) the optimal filter.
"""

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_choice, as_positive
from ...estimators.huber_filter import HuberFilter, HuberStrongTrackingEKF
from ...estimators.kalman import ExtendedKalmanFilter, StrongTrackingEKF
from ...estimators.registry import (Requires, build_estimator, estimator_entry, register_composition, register_estimator,
                                   registered_estimators)
from ...estimators.sigma_point import SigmaPointFilter
from .constants import GAMMA
from .scenario import Scenario

__all__ = ["EKF", "HBF", "build_hbf", "build_ukf", "build_stekf", "build_huber_stekf"]

#: How the filters use the readings: converted to position (the paper's indirect measurement) or directly.
MEASUREMENTS = ("converted", "direct")

#: Kalman filters that ``hbf`` robustifies on other papers' scenarios, tried in this order
#: (Sun 2011: the EKF told the applied thrust, as Shi & Wang's filters know the control acceleration).
HBF_BASES = ("ekf_known_input", "ekf")


def EKF(scenario, *, measurement="converted", sigma_range=None, sigma_angle=None, Q=None, P0=None,
        output="filtered", name=None):
    """The EKF of Shi & Wang (2018) on :class:`~hinfnav.papers.shi2018.Scenario`.

    Parameters
    ----------
    scenario : Scenario
    measurement : {"converted", "direct"}
        ``"converted"`` (the paper's): readings converted to position, a
        linear measurement with R_k = J(y_k) R Jᵀ. ``"direct"``: the
        range/angle readings with their own Jacobian (an extension).
    sigma_range, sigma_angle : float, optional
        Sensor errors (1σ; m, rad) the filter assumes; default the true ones.
    Q : array_like, shape (6, 6), optional
        Process-noise covariance per step; default the true ``Γ Γᵀ σ_a²``.
    P0 : array_like, shape (6, 6), optional
        Initial covariance; default the scenario's.
    output : {"filtered", "predicted"}
    name : str, optional

    Returns
    -------
    hinfnav.estimators.ExtendedKalmanFilter
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Shi 2018 Scenario; got {type(scenario).__name__}")
    measurement = as_choice("measurement", measurement, MEASUREMENTS)
    sr = None if sigma_range is None else as_positive("sigma_range", sigma_range)
    sa = None if sigma_angle is None else as_positive("sigma_angle", sigma_angle)
    model = scenario.filter_measurement(sr, sa) if measurement == "converted" else scenario.sensor(sr, sa)
    if name is None:
        name = "ekf_converted" if measurement == "converted" else "ekf_direct"
    return ExtendedKalmanFilter(scenario.system(), model, P0=scenario.P0 if P0 is None else P0, Q=Q,
                                uses_input=True, output=output, name=name)


def HBF(scenario, *, gamma=GAMMA, tol=1e-10, max_iter=50, name=None, **ekf_options):
    """The Huber-based filter of Shi & Wang (2018): :func:`EKF` with the Huber update.

    Parameters
    ----------
    scenario : Scenario
    gamma : float
        Huber threshold (1.345).
    tol, max_iter
        Of the M-estimation.
    name : str, optional
    **ekf_options
        As for :func:`EKF` (``measurement``, ``sigma_range``, ``sigma_angle``, ``Q``, ``P0``, ``output``).
    """
    if name is None:
        name = "hbf" if ekf_options.get("measurement", "converted") == "converted" else "hbf_direct"
    return HuberFilter.from_ekf(EKF(scenario, **ekf_options), gamma=gamma, tol=tol, max_iter=max_iter, name=name)


def _base_name(scenario):
    """The first of :data:`HBF_BASES` registered and fitting ``scenario`` (None if none)."""
    known = registered_estimators()
    for name in HBF_BASES:
        if name in known and estimator_entry(name).fits(scenario):
            return name
    return None


def _fits_hbf(scenario):
    if isinstance(scenario, Scenario):
        return True
    if _base_name(scenario) is not None:
        return True
    return hasattr(scenario, "truth_model") and hasattr(scenario, "xhat0") and hasattr(scenario, "P0")


def build_hbf(scenario, *, gamma=GAMMA, tol=1e-10, max_iter=50, base=None, **options):
    """The registry's ``hbf`` on any scenario it fits.

    * Shi & Wang (2018)'s scenario: :func:`HBF`.
    * a scenario with a registered Kalman filter (``base``, default the
      first of :data:`HBF_BASES` that fits, e.g. Sun 2011's
      ``ekf_known_input``): that filter with the Huber update — same model,
      Q, R, P₀ and input use; ``options`` go to its builder.
    * otherwise a scenario with ``truth_model()`` (a LinearSystem and a
      measurement), ``xhat0`` and ``P0``: the HBF on the truth's system and
      measurement, Q = B Bᵀ, R = D Dᵀ, told the input.
    """
    if isinstance(scenario, Scenario):
        if base is not None:
            raise InputError("base applies only to scenarios of other papers")
        return HBF(scenario, gamma=gamma, tol=tol, max_iter=max_iter, **options)
    base = _base_name(scenario) if base is None else base
    if base is not None:
        ekf = build_estimator(scenario, base, **options)
        return HuberFilter.from_ekf(ekf, gamma=gamma, tol=tol, max_iter=max_iter, name="hbf")
    if not _fits_hbf(scenario):
        raise InputError(f"hbf needs a scenario with a registered Kalman filter ({', '.join(HBF_BASES)}) or with "
                         f"truth_model(), xhat0 and P0; {type(scenario).__name__} has neither")
    model = scenario.truth_model()
    return HuberFilter(model.system, model.measurement, P0=np.asarray(scenario.P0, dtype=float),
                       gamma=gamma, tol=tol, max_iter=max_iter, uses_input=True, name="hbf", **options)


def _fits_ukf(scenario):
    return isinstance(scenario, Scenario) or _base_name(scenario) is not None


def build_ukf(scenario, *, rule="unscented", alpha=1.0, beta=2.0, kappa=0.0, base=None, **options):
    """The registry's ``ukf``: the sigma-point version of a scenario's Kalman filter.

    * Shi & Wang (2018)'s scenario: :func:`EKF` with ``measurement="direct"``
      by default (the range/angle readings themselves; on the converted,
      linear measurement the unscented transform is exact and the filter
      would be the EKF), its Q, R and P₀.
    * a scenario with a registered Kalman filter (``base``, default the first
      of :data:`HBF_BASES` that fits, e.g. Sun 2011's ``ekf_known_input``):
      that filter's model, Q, R, P₀ and input use. On Sun 2011's chaser
      (linear dynamics, Cartesian position (8)) it equals that Kalman filter
      to rounding: the comparison the paper names, answered.

    ``rule``, ``alpha``, ``beta``, ``kappa``: of
    :class:`~hinfnav.estimators.SigmaPointFilter`; ``options`` go to the
    Kalman filter's builder.
    """
    return SigmaPointFilter.from_ekf(_kalman_base(scenario, base, options, "ukf"), name="ukf", rule=rule, alpha=alpha,
                                     beta=beta, kappa=kappa)


def _kalman_base(scenario, base, options, what):
    """The Kalman filter a variant is built on: Shi 2018's EKF on the range/angle readings themselves (a constant R,
    which strong tracking needs), or the scenario's registered Kalman filter (``base``, default :func:`_base_name`)."""
    if isinstance(scenario, Scenario):
        if base is not None:
            raise InputError("base applies only to scenarios of other papers")
        options.setdefault("measurement", "direct")
        return EKF(scenario, **options)
    base = _base_name(scenario) if base is None else base
    if base is None:
        raise InputError(f"{what} needs a scenario with a registered Kalman filter ({', '.join(HBF_BASES)}); "
                         f"{type(scenario).__name__} has none")
    return build_estimator(scenario, base, **options)


def build_stekf(scenario, *, rho=0.95, beta=1.0, a=None, base=None, **options):
    """The registry's ``stekf``: strong tracking (paper 002, (S1)-(S4)) on a scenario's Kalman filter.

    On Shi & Wang (2018)'s scenario the EKF of the range/angle readings
    (``measurement="direct"``: strong tracking needs a constant R); elsewhere
    the scenario's registered Kalman filter (as for ``ukf``), same model, Q,
    R, P₀ and input use. ``rho``, ``beta``, ``a``: of
    :class:`~hinfnav.estimators.StrongTrackingEKF`; ``options`` go to the Kalman filter's builder.
    """
    ekf = _kalman_base(scenario, base, options, "stekf")
    return StrongTrackingEKF(ekf.system, ekf.measurement, P0=ekf.P0, Q=ekf.Q, R=ekf.R, uses_input=ekf.uses_input,
                             output=ekf.output, name="stekf", rho=rho, beta=beta, a=a)


def build_huber_stekf(scenario, *, gamma=GAMMA, tol=1e-10, max_iter=50, rho=0.95, beta=1.0, a=None, base=None,
                      **options):
    """The registry's ``huber_stekf``: :func:`build_stekf` with Huber's M-estimation as the correction
    (:class:`~hinfnav.estimators.HuberStrongTrackingEKF`; ``gamma``, ``tol``, ``max_iter`` as for ``hbf``)."""
    ekf = _kalman_base(scenario, base, options, "huber_stekf")
    return HuberStrongTrackingEKF(ekf.system, ekf.measurement, P0=ekf.P0, Q=ekf.Q, R=ekf.R,
                                  uses_input=ekf.uses_input, output=ekf.output, name="huber_stekf", rho=rho,
                                  beta=beta, a=a, gamma=gamma, tol=tol, max_iter=max_iter)


def _build_ekf(scenario, **options):
    return EKF(scenario, **options)


register_estimator("hbf", build_hbf, fits=_fits_hbf, requires=Requires(error_form="additive"),
                   description="Huber-based filter (Karlgaard & Schaub 2007; Shi & Wang 2018): the scenario's Kalman "
                               "filter with Huber's M-estimation as its update")
register_estimator("ukf", build_ukf, fits=_fits_ukf, requires=Requires(error_form="additive"),
                   description="unscented (sigma-point) Kalman filter, the alternative to the EKF that Sun 2011 and "
                               "Shi & Wang 2018 name: the scenario's Kalman filter with the unscented transform")
register_estimator("ekf_converted", _build_ekf, fits=lambda scenario: isinstance(scenario, Scenario),
                   requires=Requires(model="shi2018", measurement=("range_angle",), input=True),
                   description="EKF on the converted (indirect) position measurement, R_k = J R J^T "
                               "(Shi & Wang 2018's comparison)")
register_estimator("stekf", build_stekf, fits=_fits_ukf,
                   description="strong-tracking EKF (paper 002's fading factors) on the scenario's Kalman filter "
                               "(Shi 2018: the range/angle EKF; elsewhere its registered Kalman filter)")
register_estimator("huber_stekf", build_huber_stekf, fits=_fits_ukf,
                   description="Huber x strong tracking: the strong-tracking EKF with Huber's M-estimation as its "
                               "correction")
# the sigma-point filter with the core's ideas composed onto it (hinfnav.estimators.strategies): no class of their own
register_composition("huber_ukf", "ukf", correction="huber",
                     description="Huber x sigma-point: the ukf with Huber's M-estimation as its correction, on the "
                                 "statistical linearisation of its moments (gamma = 1.345)")
register_composition("stukf", "ukf", fading="strong_tracking",
                     description="strong tracking x sigma-point: the ukf with paper 002's fading factors on its "
                                 "predicted covariance (rho = 0.95, beta = 1)")
