"""The recursive H∞ filter (Simon 2006, ch. 11) on Sun et al. (2011)'s scenario, registered as ``recursive_hinf``.

The filter of :class:`hinfnav.estimators.recursive_hinf.RecursiveHInfinityFilter`
is built on the truth's model at δ = 0 (exact zero-order hold, T = 0.1 s),
Q = B Bᵀ, R = D Dᵀ, the position measurement (8), z = x (L = I, S = I) and
P₀ = diag(50², 50², 50², 0.1², 0.1², 0.1²) (the EKF's). Documented choices:

* ``known_input=True`` (the registered filter): it propagates
  ``Φ x̂ + Γ u`` with the applied thrust, so it works with and without
  maneuver and its error does not depend on u;
* ``known_input=False``: it assumes the control law, ``(Φ + Γ K) x̂`` (the
  model the LTI filters (12) are designed on); right only with maneuver;
* θ: by default half the largest θ for which the steady state exists
  (:func:`hinfnav.analysis.max_admissible_theta` of the filter's model), a
  point in the middle of the admissible interval [0, θ_max). θ = 0 is the
  Kalman predictor.

:func:`theta_study` gives the error against θ up to θ_max (notebook 08).
"""

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ...analysis.hinf_riccati import max_admissible_theta, steady_state_hinf
from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_nonnegative, as_positive
from ...estimators.recursive_hinf import RecursiveHInfinityFilter
from ...estimators.registry import Requires, register_estimator
from ...metrics.errors import axes_rms, rms_error
from ...sim.montecarlo import run_estimator
from ...sim.truth import simulate_truth
from .constants import DEFAULT_P0_STD
from .scenario import Scenario

__all__ = ["build_recursive_hinf", "recursive_model", "ThetaStudy", "theta_study", "plot_theta_study"]


def recursive_model(scenario, known_input=True):
    """``(system, F, H, Q, R)`` of the recursive filter on ``scenario`` (see the module notes)."""
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    system = scenario.system(closed_loop=not known_input)
    meas = scenario.measurement
    return system, system.Phi, meas.H, system.Q, meas.R


def build_recursive_hinf(scenario, *, theta=None, theta_fraction=0.5, P0=None, known_input=True,
                         on_violation="raise", name="recursive_hinf"):
    """Simon's a-priori recursive H∞ filter for the scenario.

    Parameters
    ----------
    scenario : Scenario
    theta : float, optional
        Performance bound θ ≥ 0, 1/(m² or (m/s)²) (the error of z = x is
        weighted by S = I). Default ``theta_fraction · θ_max``.
    theta_fraction : float, optional
        Used when ``theta`` is None; in [0, 1).
    P0 : array_like, shape (6, 6), optional
        Initial P (default diag(DEFAULT_P0_STD)²).
    known_input : bool, optional
        Told the applied thrust (True) or assuming u = K x (False).
    on_violation : {"raise", "flag"}
    name : str

    Returns
    -------
    RecursiveHInfinityFilter
    """
    system, F, H, Q, R = recursive_model(scenario, known_input)
    if theta is None:
        frac = as_nonnegative("theta_fraction", theta_fraction)
        if not frac < 1:
            raise InputError(f"theta_fraction must be in [0, 1); got {frac}")
        theta = frac * max_admissible_theta(F, H, Q, R)
    P0 = np.diag(DEFAULT_P0_STD**2) if P0 is None else P0
    return RecursiveHInfinityFilter(system, scenario.measurement, theta=theta, P0=P0, uses_input=bool(known_input),
                                    on_violation=on_violation, name=name)


@dataclass(frozen=True, eq=False)
class ThetaStudy:
    """Error of the recursive H∞ filter against θ.

    Attributes
    ----------
    theta_max : float
        Largest admissible θ of the steady state.
    thetas : ndarray, shape (k,)
    pos_m, vel_mps : ndarray, shape (k,)
        Simulated RMS error (per-axis RMS over the window, pooled over runs,
        RMS over axes), m and m/s.
    pos_m_stat, vel_mps_stat : ndarray, shape (k,)
        Stationary RMS error of the steady-state filter under the true noise
        (Lyapunov equation), m and m/s.
    trace_P : ndarray, shape (k,)
        trace of the steady-state P (at θ = 0 the predictor covariance).
    transient_ok : ndarray of bool, shape (k,)
        Whether the existence condition held at every step from P₀ (where it
        did not, the filter stops with an error and the simulated errors are
        NaN: the steady state exists for every θ < θ_max, the transient from
        a large P₀ may not).
    settings : dict
    """

    theta_max: float
    thetas: np.ndarray
    pos_m: np.ndarray
    vel_mps: np.ndarray
    pos_m_stat: np.ndarray
    vel_mps_stat: np.ndarray
    trace_P: np.ndarray
    transient_ok: np.ndarray
    settings: dict


def theta_study(scenario=None, fractions=(0.0, 0.25, 0.5, 0.75, 0.9, 0.97, 0.99), *, known_input=True, maneuver=True,
                runs=10, seed=0):
    """Simulated and stationary error of the recursive H∞ filter for θ = fraction · θ_max.

    Parameters
    ----------
    scenario : Scenario, optional
    fractions : sequence of float
        Fractions of θ_max, each in [0, 1).
    known_input : bool
        Told the thrust (True) or assuming u = K x (False, needs ``maneuver``).
    maneuver : bool
    runs, seed : int

    Returns
    -------
    ThetaStudy
    """
    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    system, F, H, Q, R = recursive_model(scenario, known_input)
    theta_max = max_admissible_theta(F, H, Q, R)
    fr = np.array([as_nonnegative("fractions entry", f) for f in fractions])
    if np.any(fr >= 1):
        raise InputError("fractions must be below 1 (θ_max itself has no steady state)")
    truth = simulate_truth(scenario.truth_model(maneuver=maneuver), runs=runs, seed=seed)
    out = {k: [] for k in ("pos", "vel", "pos_s", "vel_s", "tr", "ok")}
    B, D = scenario.B, scenario.D
    for theta in fr * theta_max:
        est = build_recursive_hinf(scenario, theta=theta, known_input=known_input)
        try:
            res = run_estimator(est, truth, scenario.xhat0)
        except InputError:  # the existence condition failed in the transient from P₀
            out["ok"].append(False)
            out["pos"].append(float("nan"))
            out["vel"].append(float("nan"))
        else:
            rms = rms_error(res.error, truth.t, scenario.rms_window_s)
            out["ok"].append(True)
            out["pos"].append(axes_rms(rms[:3]))
            out["vel"].append(axes_rms(rms[3:]))
        P, K = steady_state_hinf(F, H, Q, R, theta)
        FK = F @ K
        Ae = F - FK @ H  # e⁺ = (F − F K H) e + B w − F K D v
        cov = scipy.linalg.solve_discrete_lyapunov(Ae, B @ B.T + FK @ D @ D.T @ FK.T)
        std = np.sqrt(np.diag(cov))
        out["pos_s"].append(axes_rms(std[:3]))
        out["vel_s"].append(axes_rms(std[3:]))
        out["tr"].append(float(np.trace(P)))
    return ThetaStudy(theta_max=float(theta_max), thetas=fr * theta_max, pos_m=np.array(out["pos"]),
                      vel_mps=np.array(out["vel"]), pos_m_stat=np.array(out["pos_s"]),
                      vel_mps_stat=np.array(out["vel_s"]), trace_P=np.array(out["tr"]),
                      transient_ok=np.array(out["ok"], dtype=bool),
                      settings={"known_input": bool(known_input), "maneuver": bool(maneuver), "runs": runs,
                                "seed": seed, "window_s": list(scenario.rms_window_s)})


def plot_theta_study(study, *, axes, label=None, color="C0"):
    """Simulated (markers) and stationary (lines) RMS position and velocity error against θ/θ_max.

    Parameters
    ----------
    study : ThetaStudy
    axes : sequence of two matplotlib.axes.Axes
    label : str, optional
    color : str

    Returns
    -------
    list of matplotlib artists
    """
    x = study.thetas / as_positive("theta_max", study.theta_max)
    label = label or "recursive H∞"
    artists = []
    for ax, sim, stat, what, unit in ((axes[0], study.pos_m, study.pos_m_stat, "position", "m"),
                                      (axes[1], study.vel_mps, study.vel_mps_stat, "velocity", "m/s")):
        artists += ax.plot(x, sim, "o", color=color, label=f"{label}, simulated")
        artists += ax.plot(x, stat, "-", color=color, label=f"{label}, stationary")
        ax.set_xlabel("θ / θ_max (–)")
        ax.set_ylabel(f"RMS {what} error ({unit})")
        ax.grid(True, alpha=0.3)
    return artists


def _fits(scenario):
    return isinstance(scenario, Scenario)


def _build(scenario, **options):
    return build_recursive_hinf(scenario, **options)


register_estimator("recursive_hinf", _build, fits=_fits, requires=Requires(model="sun2011", linear=True, input=True),
                   description="Simon's recursive (game-theoretic) H-inf filter, a-priori form, told the thrust "
                               "(theta = theta_max/2 by default)")
