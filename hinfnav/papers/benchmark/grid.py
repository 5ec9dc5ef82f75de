"""The cross-paper benchmark's grid: which estimators, which cells, and which estimator/scenario pairs do not fit.

The table is filled on Sun et al. (2011)'s chaser: every registered estimator
that fits it (:func:`hinfnav.estimators.registered_estimators`), with and
without maneuver, δ ∈ {0, 1, 5}, noise ∈ {gaussian, mixture (paper 001's,
ε = 0.6, σ₂ = 2σ₁), student_t, colored}, ``runs`` ≥ 200 per cell, RMS over
0–500 s (``early``: the initial transient and the thrust phase) and
100–1000 s (``steady``: Table 1's window).

Every paper registers its estimators when imported; :func:`load_papers`
imports every paper that exists (a paper under construction that does not
import yet is reported, not fatal), so estimators that land later join the
benchmark without a change here.
"""

import importlib

from ...campaign.spec import Campaign
from ...estimators.registry import estimator_entry, registered_estimators
from ..sun2011.scenario import Scenario

__all__ = ["PAPER_MODULES", "load_papers", "benchmark_campaign", "fit_matrix", "WINDOWS", "NOISES", "DELTAS",
           "TOL"]

#: Every paper package, in the order of their decades.
PAPER_MODULES = ("sun2011", "shi2018", "attitude2018", "yang2020")
#: RMS windows, s.
WINDOWS = {"early": (0.0, 500.0), "steady": (100.0, 1000.0)}
#: Noises of w and v (all of unit variance).
NOISES = ("gaussian", "mixture", "student_t", "colored")
#: True orbital-rate errors δ of (4).
DELTAS = (0.0, 1.0, 5.0)
#: Convergence tolerance per component: 1 m in position (16 times the Kalman limit), 0.2 m/s in velocity (9 times).
TOL = (1.0, 1.0, 1.0, 0.2, 0.2, 0.2)

def load_papers():
    """Import every paper of :data:`PAPER_MODULES` (registering their scenarios and estimators).

    Returns
    -------
    dict
        Paper key → None when imported, or the error message when it could not be.
    """
    out = {}
    for key in PAPER_MODULES:
        try:
            importlib.import_module(f"{__package__.rsplit('.', 1)[0]}.{key}")
            out[key] = None
        except Exception as exc:
            out[key] = f"{type(exc).__name__}: {exc}"
    return out


def benchmark_campaign(*, runs=200, seed=0, estimators=None, batch_size=200, maneuvers=(True, False),
                       deltas=DELTAS, noises=NOISES):
    """The benchmark's campaign: every fitting estimator on every cell of the grid.

    Parameters
    ----------
    runs : int
        Runs per cell (≥ 200 for the benchmark; fewer for a quick look).
    seed : int
    estimators : sequence of str, optional
        Default: every registered estimator that fits Sun 2011's chaser.
    batch_size : int
        Runs simulated and filtered at once (200: the benchmark's cells are one batch each). Part
        of a filter step's cost is fixed overhead, so one batch of 200 runs takes 85 % of the CPU
        time of two of 100 (37.0 against 43.7 CPU-s for the 13 estimators of a grid point; the
        Huber filter 11.0 against 14.8 s); a worker then holds about 0.5 GB.
    maneuvers, deltas, noises : sequence
        The grid (defaults: the benchmark's).

    Returns
    -------
    Campaign
        Its cells' seeds depend on the truth parameters only, so the
        estimators of a grid point share their truths (common random numbers).
    """
    names = registered_estimators(Scenario()) if estimators is None else tuple(estimators)
    return Campaign(name="benchmark", runs=runs, seed=seed, batch_size=batch_size, windows=WINDOWS, tol=TOL,
                    grid={"scenario": "sun2011", "estimator": list(names), "maneuver": list(maneuvers),
                          "delta": list(deltas), "noise": list(noises)})


#: Why an estimator does not fit another paper's scenario, by the estimator's family (name prefix or name).
_WHY_NOT = {
    "sun2011": "built from Sun 2011's chaser: its 6-state Hill model with the feedback gain K at T = 0.1 s and the "
               "Cartesian position measurement (8); the other scenarios have another state (attitude, drag-free "
               "axes), another T (Shi 2018: 0.4 s) or range/angle readings, and no law u = K x",
    "ekf_converted": "Shi 2018's EKF on the position converted from range, azimuth and elevation (R_k = J R Jᵀ); "
                     "the chaser of Sun 2011 measures Cartesian position directly, where it would be ekf_known_input",
    "attitude": "paper 002's gyroless attitude filters: quaternion, rate and torque states with star-sensor "
                "readings; no translational scenario has them (their idea on the chaser is the "
                "ekf_augmented_thrust family)",
    "augmented_thrust": "paper 002's idea moved to Sun 2011's chaser (the unknown thrust as random-walk state); "
                        "registered for that chaser only",
    "yang2020": "Yang 2020's extended-state filters of a drag-free satellite (accelerometer with saturation, "
                "lumped disturbance states, ADRC loop); no other scenario has those states or readings",
    "hbf": "the Huber update needs a registered Kalman filter of the scenario to robustify (or a scenario with "
           "truth_model, xhat0 and P0); this scenario offers neither",
    "ukf": "the sigma-point filter is built as the unscented version of a registered Kalman filter of the scenario "
           "(Sun 2011's ekf_known_input, Shi 2018's EKF); this scenario has none registered",
    "kalman_variant": "strong tracking (and Huber x strong tracking) is built on a registered Kalman filter of the "
                      "scenario (Sun 2011's ekf_known_input, Shi 2018's EKF); this scenario has none registered",
}


def _family(name):
    if name in ("aekf", "astekf", "aaekf"):
        return "attitude"
    if name.startswith("ekf_augmented_thrust"):
        return "augmented_thrust"
    if name.startswith("yang2020"):
        return "yang2020"
    if name in ("hbf", "ekf_converted", "ukf"):
        return name
    if name in ("stekf", "huber_stekf"):
        return "kalman_variant"
    return "sun2011"


def _scenarios(papers):
    out = {}
    for key in PAPER_MODULES:
        if papers.get(key) is not None:
            continue
        try:
            module = importlib.import_module(f"{__package__.rsplit('.', 1)[0]}.{key}")
            out[key] = module.Scenario()
        except Exception:
            continue
    return out


def fit_matrix(papers=None):
    """Which registered estimator fits which paper's scenario, and why not where it does not.

    Parameters
    ----------
    papers : dict, optional
        The result of :func:`load_papers` (called when not given).

    Returns
    -------
    dict
        ``{"scenarios": [...], "estimators": {name: {"description", "fits": {scenario: bool},
        "why_not": {scenario: reason}}}}``.
    """
    papers = load_papers() if papers is None else papers
    scenarios = _scenarios(papers)
    out = {}
    for name in registered_estimators():
        entry = estimator_entry(name)
        fits = {}
        for key, sc in scenarios.items():
            try:
                fits[key] = bool(entry.fits(sc))
            except Exception:
                fits[key] = False
        why = {key: _WHY_NOT[_family(name)] for key, ok in fits.items() if not ok}
        out[name] = {"description": entry.description, "fits": fits, "why_not": why}
    return {"scenarios": list(scenarios), "estimators": out}
