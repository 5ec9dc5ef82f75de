"""The H2/H∞ Pareto study on Sun et al. (2011)'s chaser: what robustness costs in accuracy, and where the knee is.

For each δ̄ the certified front of :func:`mixed_front_for_scenario` (12
mixed designs from γ* to 10 γ* and the robust H2 filter) is run on the
paper's scenario beside the references of Table 1:

* **simulated**: per-axis RMS error over the scenario's window (100–1000 s),
  pooled over runs, RMS over the three axes; with the orbit maneuver u = Kx
  each LTI filter runs verbatim as (12) (the closed loop it was designed on),
  without maneuver it is told the applied thrust (as in Table 1);
* **stationary**: the noise-only steady-state error of the filter with
  maneuver (Lyapunov equation, :func:`~hinfnav.papers.sun2011.limits.lti_error_covariance`),
  which separates what the noise costs from what the initial transient and
  the plant-state leak cost;
* **references**: the Kalman limit of the same model (predicted, like (12),
  and filtered), the H∞ optimum of Corollary 1 and the published filter.

The units of ν and γ are those of the error system: e = z − z_f mixes m
(position) and m/s (velocity), τ = [w; v] is unit white noise; ν² is the sum
over the six components of the stationary mean-square error.
"""

from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from ...analysis.error_system import error_system
from ...analysis.norms import h2_norm
from ...analysis.observer import observer_form
from ...core.exceptions import InputError, UnstablePlantError
from ...core.validation import as_int_at_least
from ...metrics.errors import axes_rms, rms_error
from ...sim.montecarlo import run_estimator
from ...sim.truth import simulate_truth
from .constants import published_filter
from .designs import delta_grid
from .filters import lti_from_matrices
from .limits import kalman_limit, lti_error_covariance
from .mixed_designs import certified_knee, mixed_front_for_scenario
from .scenario import Scenario

__all__ = ["ParetoStudy", "pareto_study", "robustness_cost", "format_pareto_table", "plot_front",
           "plot_front_accuracy"]


def worst_h2(scenario, delta_bar, A_F, B_F, C_F, delta_points=21):
    """Largest H2 norm of the error system (13) of a filter over the δ grid of δ̄ (Lyapunov equations)."""
    system = scenario.design_model(delta_bar)
    from_grid = [scenario.design_A(float(d)) for d in delta_grid(delta_bar, delta_points)]
    return max(h2_norm(error_system(A, system.B, system.C, system.D, system.L, A_F, B_F, C_F, True))
               for A in from_grid)


@dataclass(frozen=True, eq=False)
class ParetoStudy:
    """Certified fronts and the accuracy of every filter along them.

    Attributes
    ----------
    fronts : dict
        δ̄ → :class:`~hinfnav.design.mixed.MixedFront`.
    rows : dict
        δ̄ → list of dicts, one per filter, in this order: the front's points,
        the robust H2 filter, the H∞ optimum, the published filter. Keys:
        ``filter`` (label), ``kind`` ("mixed", "h2", "hinf_optimum",
        "published"), ``gamma_bound``, ``gamma`` (certified worst-case H∞;
        for the published filter its worst sampled norm), ``nu`` (certified
        ν; NaN for filters without an H2 certificate), ``h2_sampled``
        (worst H2 norm over the δ grid), ``pos_m``, ``vel_mps`` (simulated
        with maneuver), ``pos_m_free``, ``vel_mps_free`` (without maneuver,
        told the thrust), ``pos_m_stat``, ``vel_mps_stat`` (stationary, with
        maneuver; NaN if the filter is unstable), ``observer_residual``
        (:func:`hinfnav.analysis.observer_form` on the nominal model: 0 for a
        predictor observer, whose error does not see the plant state).
    kalman : dict
        ``maneuver`` / ``no_maneuver`` → ``(pos_m, vel_mps)`` of the predicted
        and ``..._filtered`` of the filtered Kalman limit.
    knees : dict
        δ̄ → index of the knee in ``rows[δ̄]`` (:func:`~hinfnav.papers.sun2011.mixed_designs.certified_knee`:
        chosen on the certified γ and ν of the points and the robust H2 filter).
    settings : dict
    """

    fronts: dict
    rows: dict
    kalman: dict
    knees: dict
    settings: dict = field(default_factory=dict)

    def knee_row(self, delta_bar):
        """The row of the knee's filter at δ̄."""
        return self.rows[delta_bar][self.knees[delta_bar]]

    def row(self, delta_bar, kind):
        """The first row of a kind ("h2", "hinf_optimum", "published") at δ̄."""
        for r in self.rows[delta_bar]:
            if r["kind"] == kind:
                return r
        raise InputError(f"no row of kind {kind!r} at delta_bar = {delta_bar:g}")


def _cell(res, t, window, state):
    rms = rms_error(res.error, t, window)
    return axes_rms(state.select(rms, "position")), axes_rms(state.select(rms, "velocity"))


def _stationary(scenario, A_F, B_F, C_F):
    try:
        std = np.sqrt(np.diag(lti_error_covariance(scenario, A_F, B_F, C_F, maneuver=True)))
    except (InputError, UnstablePlantError):
        return float("nan"), float("nan")
    return axes_rms(std[:3]), axes_rms(std[3:])


def pareto_study(scenario=None, delta_bars=(0.05, 1.0), *, points=12, runs=10, seed=0, delta=0.0, fronts=None,
                 progress=False):
    """Fronts at several δ̄ and the simulated accuracy of each filter on the paper's scenario.

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    delta_bars : sequence of float
        Uncertainty bounds of the fronts (default 0.05, the paper's, and 1, its Fig 7).
    points : int
        Mixed designs per front (γ* … 10 γ*), plus the unconstrained H2 design.
    runs, seed : int
        Monte Carlo runs and seed (the same truth for every filter).
    delta : float
        True orbital-rate error δ of the simulated truth (default 0, the paper's scenario).
    fronts : dict, optional
        δ̄ → MixedFront computed before (skips the synthesis).
    progress : bool

    Returns
    -------
    ParetoStudy
    """
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    runs = as_int_at_least("runs", runs, 1)
    fronts = dict(fronts or {})
    for db in delta_bars:
        if db not in fronts:
            fronts[db] = mixed_front_for_scenario(scenario, db, points=points, progress=progress)
    truths = {m: simulate_truth(scenario.truth_model(maneuver=m, delta=delta), runs=runs, seed=seed)
              for m in (True, False)}
    win = scenario.rms_window_s
    pub = published_filter()
    rows, knees = {}, {}
    nominal = scenario.design_model(0.0)
    total = sum(len(fronts[db].results) + 3 for db in delta_bars)
    with tqdm(total=total, disable=not progress, desc="accuracy along the fronts", unit="filter") as bar:
        for db in delta_bars:
            fr = fronts[db]
            entries = [(f"mixed, γ ≤ {r.gamma_bound:.4g}", "mixed", r) for r in fr.results]
            entries.append(("robust H2 (no γ bound)", "h2", fr.h2_result))
            entries.append(("H∞ optimum (Corollary 1)", "hinf_optimum", fr.hinf_result))
            entries.append(("published (Sun 2011)", "published", pub))
            rows[db] = []
            for label, kind, res in entries:
                if res is None:
                    continue
                A_F, B_F, C_F = res.A_F, res.B_F, res.C_F
                cells = {}
                for maneuver, truth in truths.items():
                    est = lti_from_matrices(scenario, A_F, B_F, C_F, name=kind, uses_input=not maneuver)
                    cells[maneuver] = _cell(run_estimator(est, truth, scenario.xhat0), truth.t, win, truth.state)
                pos_s, vel_s = _stationary(scenario, A_F, B_F, C_F)
                gamma = getattr(res, "gamma", None)
                if kind == "published":
                    gamma = float("nan")
                rows[db].append({
                    "filter": label, "kind": kind, "delta_bar": float(db),
                    "gamma_bound": getattr(res, "gamma_bound", None),
                    "gamma": float(gamma),
                    "nu": float(getattr(res, "h2_bound", float("nan"))),
                    "h2_sampled": worst_h2(scenario, db, A_F, B_F, C_F),
                    "pos_m": cells[True][0], "vel_mps": cells[True][1],
                    "pos_m_free": cells[False][0], "vel_mps_free": cells[False][1],
                    "pos_m_stat": pos_s, "vel_mps_stat": vel_s,
                    "observer_residual": observer_form(A_F, B_F, C_F, nominal.A, nominal.C)["residual"],
                })
                bar.update(1)
            knees[db] = certified_knee(fr)
    kalman = {}
    for case, maneuver in (("maneuver", True), ("no_maneuver", False)):
        kl = kalman_limit(scenario, maneuver=maneuver)
        kalman[case] = (axes_rms(kl.pos_m_predicted), axes_rms(kl.vel_mps_predicted))
        kalman[case + "_filtered"] = (axes_rms(kl.pos_m), axes_rms(kl.vel_mps))
    settings = {"runs": runs, "seed": seed, "delta": float(delta), "points": points, "window_s": list(win),
                "error_measure": "per-axis RMS over window_s pooled over runs; RMS over x, y, z"}
    return ParetoStudy(fronts=fronts, rows=rows, kalman=kalman, knees=knees, settings=settings)


def robustness_cost(study, delta_bar):
    """The numbers that answer "what does robustness cost, and where is the knee" at δ̄.

    Returns
    -------
    dict
        ``gamma_star``; ``gamma_h2`` (certified γ of the robust H2 filter) and
        ``gamma_h2_ratio`` (÷ γ*); ``knee_gamma_ratio`` (certified γ of the knee ÷ γ*);
        ``nu_first``, ``nu_h2``, ``nu_excess`` (certified ν at the first point,
        γ*(1 + 10⁻³), against the H2 end, relative); ``nu_hinf_opt`` (worst
        sampled H2 norm of the H∞ optimum); for the first point, the H∞
        optimum and the published filter, the simulated position and velocity
        error with maneuver relative to the predicted Kalman limit
        (``*_pos_ratio``, ``*_vel_ratio``).
    """
    fr = study.fronts[delta_bar]
    rows = study.rows[delta_bar]
    first, h2 = rows[0], study.row(delta_bar, "h2")
    kp, kv = study.kalman["maneuver"]
    out = {
        "gamma_star": fr.gamma_star,
        "gamma_h2": fr.h2_result.gamma,
        "gamma_h2_ratio": fr.h2_result.gamma / fr.gamma_star,
        "knee_gamma_ratio": float(study.knee_row(delta_bar)["gamma"] / fr.gamma_star),
        "nu_first": first["nu"],
        "nu_h2": h2["nu"],
        "nu_excess": first["nu"] / h2["nu"] - 1.0,
        "nu_hinf_opt": study.row(delta_bar, "hinf_optimum")["h2_sampled"],
        "kalman_pos_m": kp,
        "kalman_vel_mps": kv,
    }
    for key, r in (("first", first), ("h2", h2), ("hinf_opt", study.row(delta_bar, "hinf_optimum")),
                   ("published", study.row(delta_bar, "published"))):
        out[f"{key}_pos_ratio"] = r["pos_m"] / kp
        out[f"{key}_vel_ratio"] = r["vel_mps"] / kv
    return out


def format_pareto_table(study, delta_bar):
    """Text table of one δ̄: γ, ν, sampled H2 and the simulated / stationary errors of every filter."""
    head = (f"{'filter':28} {'γ':>8} {'ν cert.':>9} {'H2 samp.':>9} {'pos m':>8} {'vel m/s':>8} "
            f"{'pos free':>9} {'vel free':>9} {'pos stat':>9} {'vel stat':>9} {'obs. res.':>9}")
    lines = [f"δ̄ = {delta_bar:g}  (simulated: with maneuver verbatim (12); free: no maneuver, told the thrust; "
             "stat: stationary with maneuver)", head]
    knee = study.knees[delta_bar]
    for i, r in enumerate(study.rows[delta_bar]):
        mark = " *knee" if i == knee else ""
        lines.append(
            f"{r['filter'][:28]:28} {r['gamma']:8.4f} {r['nu']:9.5f} {r['h2_sampled']:9.5f} {r['pos_m']:8.4f} "
            f"{r['vel_mps']:8.4f} {r['pos_m_free']:9.4g} {r['vel_mps_free']:9.4g} {r['pos_m_stat']:9.4f} "
            f"{r['vel_mps_stat']:9.4f} {r['observer_residual']:9.2g}{mark}")
    kp, kv = study.kalman["maneuver"]
    fp, fv = study.kalman["no_maneuver"]
    lines.append(f"{'Kalman limit, predicted':28} {'':8} {'':9} {'':9} {kp:8.4f} {kv:8.4f} {fp:9.4g} {fv:9.4g}")
    return "\n".join(lines)


def plot_front(front, *, ax, sampled=True, synthesis=True, color="C0"):
    """ν against γ/γ*: the certified Pareto front, the synthesis bound, the sampled H2 norms, the H2 end, the knee.

    Parameters
    ----------
    front : MixedFront
    ax : matplotlib.axes.Axes
    sampled : bool
        Also draw the worst sampled H2 norm over the δ grid (a lower bound).
    synthesis : bool
        Also draw the ν the synthesis LMI certifies by itself (before the
        analysis of the returned filter).
    color : str

    Returns
    -------
    list of matplotlib artists
    """
    g = front.gamma_bounds / front.gamma_star
    env, _ = front.pareto()
    artists = ax.plot(g, env, "o-", color=color, label="certified ν (Pareto front of certified designs)")
    if synthesis:
        artists += ax.plot(g, front.synthesis_nus, "^:", mfc="none", color="C7",
                           label="ν certified by the mixed LMI alone (shared slack G)")
    if sampled:
        h2s = np.array([r.h2_verified for r in front.results])
        artists += ax.plot(g, h2s, "s--", mfc="none", color=color, alpha=0.6, label="worst sampled ‖Ψ‖₂ over |δ| ≤ δ̄")
    if front.h2_result is not None:
        h2 = front.h2_result
        artists += ax.plot([h2.gamma / front.gamma_star], [h2.h2_bound], "D", color="C2",
                           label=f"robust H2 filter (certified γ = {h2.gamma / front.gamma_star:.3g} γ*)")
    knee = (list(front.results) + [front.h2_result])[certified_knee(front)]
    artists += ax.plot([knee.gamma / front.gamma_star], [knee.h2_bound], "*", ms=14, color="C3",
                       label="knee (Kneedle on the certified rows)")
    ax.set_xscale("log")
    ax.set_xlabel("H∞ bound γ / γ* (–)")
    ax.set_ylabel("ν: H2 norm of Ψ (m or m/s per unit noise)")
    ax.grid(True, which="both", alpha=0.3)
    return artists


def plot_front_accuracy(study, delta_bar, *, axes, free=False, references=True):
    """Simulated RMS position and velocity error along the front, beside the references.

    Parameters
    ----------
    study : ParetoStudy
    delta_bar : float
    axes : sequence of two matplotlib.axes.Axes
        Position and velocity.
    free : bool
        Without maneuver (told the thrust) instead of with it.
    references : bool
        Also draw the H∞ optimum and the published filter (log axes); False
        zooms on the front (linear axes, the robust H2 filter and the Kalman
        limit only).

    Returns
    -------
    list of matplotlib artists
    """
    rows = study.rows[delta_bar]
    gstar = study.fronts[delta_bar].gamma_star
    mixed = [r for r in rows if r["kind"] == "mixed"]
    g = np.array([r["gamma_bound"] for r in mixed]) / gstar
    suffix = "_free" if free else ""
    case = "no_maneuver" if free else "maneuver"
    kinds = (("h2", "C2", ":"), ("hinf_optimum", "C1", "--"), ("published", "C4", "-."))
    if not references:
        kinds = kinds[:1]
    artists = []
    for ax, key, unit, j in ((axes[0], "pos_m", "m", 0), (axes[1], "vel_mps", "m/s", 1)):
        artists += ax.plot(g, [r[key + suffix] for r in mixed], "o-", color="C0", label="mixed H2/H∞ (simulated)")
        if not free:
            artists += ax.plot(g, [r[key + "_stat"] for r in mixed], "s--", mfc="none", color="C0", alpha=0.6,
                               label="mixed, stationary (noise only)")
        for kind, color, ls in kinds:
            r = study.row(delta_bar, kind)
            artists.append(ax.axhline(r[key + suffix], color=color, ls=ls, label=r["filter"]))
        artists.append(ax.axhline(study.kalman[case][j], color="k", ls="-", lw=0.8, label="Kalman limit (predicted)"))
        ax.set_xscale("log")
        if references:
            ax.set_yscale("log")
        ax.set_xlabel("H∞ bound γ / γ* (–)")
        ax.set_ylabel(f"RMS {'position' if j == 0 else 'velocity'} error ({unit})")
        ax.grid(True, which="both", alpha=0.3)
    return artists
