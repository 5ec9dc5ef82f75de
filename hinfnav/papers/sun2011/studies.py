"""Studies on Sun et al. (2011)'s scenario beyond Table 1: robustness to δ and noise, the
published filter against the re-synthesized ones in simulation, and the small computations
the notebooks share (RMS by filter and case, observer residuals and stationary errors,
sweep look-up by δ̄).
"""

import numpy as np
import scipy.linalg
from tqdm import tqdm

from ...analysis.observer import observer_form
from ...core.exceptions import InputError
from ...core.linalg import spectral_radius
from ...core.validation import as_choice
from ...io.progress import bar_disabled
from ...metrics.errors import axes_rms, max_error, rms_error, rms_per_run
from ...sim.montecarlo import run_estimator, simulate
from ...sim.truth import simulate_truth
from .constants import published_filter
from .designs import design_for_scenario
from .filters import lti_from_matrices
from .limits import lti_error_covariance
from .scenario import Scenario

__all__ = [
    "robustness_table",
    "format_robustness_table",
    "simulation_comparison",
    "stationary_std",
    "sweep_result",
    "pos_vel",
    "filter_case_rms",
]


def pos_vel(values, state):
    """Split per-component values into (position, velocity) by the state's groups."""
    return state.select(values, "position"), state.select(values, "velocity")


def filter_case_rms(scenario, filters, *, maneuvers=(False, True), runs=20, seed=0, noise="gaussian"):
    """Per-axis RMS and maximum error of registered filters with and without maneuver.

    Parameters
    ----------
    scenario : Scenario
    filters : sequence of str
        Registered filter names (``"published"``, ``"ekf"`` …).
    maneuvers : sequence of bool
    runs, seed, noise
        As in :func:`hinfnav.simulate`.

    Returns
    -------
    list of dict
        One per (filter, maneuver): ``filter``, ``maneuver``, ``pos_m`` and
        ``vel_mps`` (per-axis RMS over the scenario's window, pooled over runs),
        ``max_pos_m``, ``max_vel_mps``.
    """
    rows = []
    for name in filters:
        for maneuver in maneuvers:
            res = simulate(scenario, name, maneuver=maneuver, runs=runs, seed=seed, noise=noise)
            pos, vel = pos_vel(rms_error(res.error, res.t, scenario.rms_window_s), res.state)
            mpos, mvel = pos_vel(max_error(res.error, res.t, scenario.rms_window_s), res.state)
            rows.append({"filter": name, "maneuver": bool(maneuver), "pos_m": pos, "vel_mps": vel,
                         "max_pos_m": mpos, "max_vel_mps": mvel})
    return rows


def sweep_result(sweep, delta_bar):
    """The design of a :class:`~hinfnav.papers.sun2011.designs.GammaSweep` at ``delta_bar``.

    Raises
    ------
    InputError
        If the sweep has no design at that δ̄ (the message lists those it has).
    """
    matches = np.flatnonzero(np.isclose(sweep.delta_bars, float(delta_bar), rtol=1e-12, atol=0.0))
    if matches.size == 0:
        have = ", ".join(f"{d:g}" for d in sweep.delta_bars)
        raise InputError(f"the sweep has no design at delta_bar = {delta_bar:g}; it has {have}")
    return sweep.results[int(matches[0])]


def stationary_std(scenario, A_F, B_F, C_F, *, maneuver=True, discretization="euler"):
    """Noise-only stationary per-axis standard deviations (position m, velocity m/s) of a filter.

    With maneuver: the filter run verbatim as (12) on the closed loop
    (:func:`~hinfnav.papers.sun2011.limits.lti_error_covariance`). Without
    maneuver: only a filter exactly in observer form told the thrust has one,
    ``e⁺ = (I + T A₁ − G C) e + B w − G D v``; NaN for the others, whose error
    depends on the drifting plant state.
    """
    if maneuver:
        std = np.sqrt(np.diag(lti_error_covariance(scenario, A_F, B_F, C_F, discretization=discretization)))
        return std[:3], std[3:]
    design_A = scenario.design_model(0.0).A
    C = scenario.design_model(0.0).C
    open_loop = design_A - scenario.input_matrix_design() @ scenario.K  # I + T A₁ (Euler, u = 0)
    std = np.full(6, np.nan)
    obs = observer_form(A_F, B_F, C_F, design_A, C)
    if obs["residual"] <= 1e-9 * np.max(np.abs(design_A)):
        G = obs["G"]
        Ae = open_loop - G @ C
        if spectral_radius(Ae) < 1:
            Q = scenario.B @ scenario.B.T + G @ scenario.D @ scenario.D.T @ G.T
            std = np.sqrt(np.diag(scipy.linalg.solve_discrete_lyapunov(Ae, Q)))
    return std[:3], std[3:]


def robustness_table(scenario=None, *, deltas=(0.0, 1.0), noises=("gaussian", "colored", "mixture", "uniform",
                     "laplace", "student_t"), filters=("published", "ekf_known_input"), runs=20, seed=0, maneuver=True,
                     progress=False):
    """Per-axis RMS error (RMS over axes) against the true δ and the noise model.

    Extends Fig 7 (one run, δ = 1, one non-Gaussian noise) to every noise of
    :mod:`hinfnav.noise` and several δ, for the H∞ filter and an EKF.

    Returns
    -------
    list of dict
        One row per (filter, delta, noise): ``pos_m``, ``vel_mps`` (pooled over
        runs), ``runs``.
    """
    scenario = Scenario() if scenario is None else scenario
    rows = []
    combos = [(f, d, n) for f in filters for d in deltas for n in noises]
    for f, d, n in tqdm(combos, disable=bar_disabled(progress), desc="robustness", unit="case"):
        res = simulate(scenario, f, maneuver=maneuver, delta=d, noise=n, runs=runs, seed=seed)
        per = rms_per_run(res.error, res.t, scenario.rms_window_s)
        pos, vel = pos_vel(np.sqrt(np.mean(per**2, axis=0)), res.state)
        rows.append({"filter": f, "delta": float(d), "noise": n, "runs": runs,
                     "pos_m": axes_rms(pos), "vel_mps": axes_rms(vel)})
    return rows


def format_robustness_table(rows):
    """The rows of :func:`robustness_table` as aligned text."""
    lines = [f"{'filter':18}{'delta':>7}  {'noise':11}{'pos (m)':>10}{'vel (m/s)':>11}"]
    for r in rows:
        lines.append(f"{r['filter']:18}{r['delta']:7g}  {r['noise']:11}{r['pos_m']:10.4f}{r['vel_mps']:11.4f}")
    return "\n".join(lines)


def simulation_comparison(scenario=None, design=None, runs=20, seed=0, *, observer=None, starts=("paper", "rest"),
                          delta_bar=None):
    """Monte Carlo RMS errors of the published and the re-synthesized filters.

    The filters run on the same simulated truths (:func:`hinfnav.sim.simulate_truth`),
    with and without maneuver, from the paper's initial state and from rest
    (x₀ = 0, x̂₀ = 0, where only the noise excites the error, the setting of
    the H∞ bound). With maneuver the filters run exactly as (12); without
    maneuver they are told the applied thrust u = 0
    (:func:`~hinfnav.papers.sun2011.filters.lti_from_matrices`), since (12) assumes u = Kx.
    That correction is exact only for a filter in observer form.

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    design : DesignResult, optional
        The general (LMI (20)) design; default :func:`design_for_scenario`
        at ``delta_bar``.
    runs : int, optional
        Monte Carlo runs per case.
    seed : int, optional
    observer : DesignResult or bool, optional
        A third filter, in observer form (:func:`synthesize` with
        ``form="observer"``): a result to reuse, or True to design it at
        the δ̄ of ``design`` (``delta_bar`` if unset). None or False: two filters.
    starts : sequence of {"paper", "rest"}, optional
        Initial conditions to simulate.
    delta_bar : float, optional
        Uncertainty bound δ̄ of (5) of the filters designed here; default
        ``scenario.delta_bar`` (0.05, the published filter's).

    Returns
    -------
    list of dict
        One row per (start, maneuver, filter): ``start``, ``maneuver``,
        ``filter`` (``"published"``, ``"re-synthesized"``, ``"observer form"``),
        ``pos_rms`` (3,) m, ``vel_rms`` (3,) m/s over the scenario's RMS
        window (default 100–1000 s); and the filter's noise-only stationary
        standard deviations ``stationary_pos_std`` (3,) m and
        ``stationary_vel_std`` (3,) m/s (Euler truth, δ = 0, the design
        model), which a filter whose error does not depend on the trajectory
        approaches from any start once its initial error has decayed:

        * with maneuver, (12) run verbatim on the closed loop,
          :func:`~hinfnav.papers.sun2011.limits.lti_error_covariance`;
        * without maneuver, for a filter exactly in observer form
          (:func:`observer_form` residual ≤ 1e-9·max|A|) told the thrust,
          whose error obeys ``e⁺ = (I + T A₁ − G C) e + B w − G D v`` (the
          correction removes the ``−T G₀ K`` of the closed loop, so the error
          decays without the controller's damping); NaN for the other
          filters, whose error depends on the drifting plant state and has no
          stationary covariance.
    """
    scenario = Scenario() if scenario is None else scenario
    delta_bar = scenario.delta_bar if delta_bar is None else delta_bar
    design = design_for_scenario(scenario, delta_bar) if design is None else design
    starts = [as_choice("start", st, ("paper", "rest")) for st in starts]
    pub = published_filter()
    filters = {"published": (pub.A_F, pub.B_F, pub.C_F), "re-synthesized": (design.A_F, design.B_F, design.C_F)}
    if observer is True:
        db = delta_bar if getattr(design, "uncertainty_bound", None) is None else design.uncertainty_bound
        observer = design_for_scenario(scenario, db, form="observer")
    if observer is not None and observer is not False:
        filters["observer form"] = (observer.A_F, observer.B_F, observer.C_F)
    stationary = {}
    for name, (A_F, B_F, C_F) in filters.items():
        for maneuver in (True, False):
            stationary[name, maneuver] = stationary_std(scenario, A_F, B_F, C_F, maneuver=maneuver)
    rows = []
    for start in starts:
        sc = scenario if start == "paper" else scenario.replace(x0=np.zeros(6), xhat0=np.zeros(6))
        for maneuver in (True, False):
            truth = simulate_truth(sc.truth_model(maneuver=maneuver), runs=runs, seed=seed)
            for name, (A_F, B_F, C_F) in filters.items():
                est = lti_from_matrices(sc, A_F, B_F, C_F, name=name, uses_input=not maneuver)
                res = run_estimator(est, truth, sc.xhat0)
                pos, vel = pos_vel(rms_error(res.error, res.t, sc.rms_window_s), res.state)
                rows.append(
                    {
                        "start": start,
                        "maneuver": maneuver,
                        "filter": name,
                        "pos_rms": pos,
                        "vel_rms": vel,
                        "stationary_pos_std": stationary[name, maneuver][0],
                        "stationary_vel_std": stationary[name, maneuver][1],
                    }
                )
    return rows
