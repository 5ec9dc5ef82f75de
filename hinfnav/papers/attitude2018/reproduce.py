"""``python -m hinfnav reproduce --paper attitude2018``: paper 002's Figs 1–9, its claims measured, the chaser study."""

import numpy as np

from ...io.outputs import to_json
from ...core.validation import as_int_at_least
from ..claims_table import write_claims_table
from ..verdicts import format_status, paper_status
from ..skeleton import Reproduction
from .chaser import chaser_study, format_chaser_table, plot_chaser
from .claims import format_claims, measure_claims
from .constants import CITATION, PAPER_OMEGA_E_DEG_S, orbit_rate
from .figures import (
    fig1,
    fig2,
    fig3,
    fig4,
    fig5,
    fig6,
    fig7,
    fig8,
    fig9,
    fig_q_sweep,
    fig_tuning,
)
from .scenario import Scenario
from .studies import attitude_study

__all__ = ["NOTEBOOKS", "reproduce", "summarize"]

#: This paper's chapter of the workbook (``reproduce(notebooks=True)``).
NOTEBOOKS = (
    "20_attitude_model.ipynb",
    "21_aekf_q_tradeoff.ipynb",
    "22_astekf_aaekf_claims.ipynb",
    "23_chaser_ideas.ipynb",
)


def stats_entry(s):
    """The JSON record of one :class:`~.studies.FilterStats`."""
    return {
        "euler_rms_deg": [float(v) for v in s.euler_rms_deg],
        "torque_rms_Nm": [float(v) for v in s.torque_rms_Nm],
        "rate_rms_rad_s": [float(v) for v in s.rate_rms],
        "euler_oscillating_deg": [float(v) for v in s.euler_bias_deg],
        "euler_random_deg": [float(v) for v in s.euler_random_deg],
        "torque_oscillating_Nm": [float(v) for v in s.torque_bias_Nm],
        "torque_random_Nm": [float(v) for v in s.torque_random_Nm],
        "euler_ci95_deg": list(s.ci95("euler")),
        "torque_ci95_Nm": list(s.ci95("torque")),
        "params": s.params,
    }


def summarize(study, claims, chaser=None):
    """The summary dict written to ``summary.json``."""
    sc = study.scenario
    omega = np.degrees(orbit_rate(sc.altitude_m))
    smallest = study.q_sweep["aekf"][0]
    out = {
        "paper": CITATION,
        "settings": dict(study.settings, J_kg_m2=sc.J, references=sc.references, R=sc.R, T0_Nm=sc.T0,
                         euler0_deg=sc.euler0_deg, P0_std=sc.P0_std, orbits=sc.orbits,
                         error_measure="per-axis RMS over rms_window_s (the last orbit), pooled over runs; Euler "
                                       "angles (3-2-1) of dq = q x qhat^-1 in deg"),
        "orbit_rate_deg_s": float(omega),
        "orbit_rate_check": {"paper_deg_s": PAPER_OMEGA_E_DEG_S, "relative_difference": float(omega / PAPER_OMEGA_E_DEG_S - 1),
                             "note": "sqrt(mu/(R_E + 650 km)^3) with R_E = 6371 km, mu = 3.986006e14 m^3/s^2"},
        "orbital_period_s": float(sc.orbital_period),
        "torque_periods_s": [float(p) for p in sc.orbital_period / np.array([6.0, 4.0, 8.0])],
        "q_sweep": [{"Q": q, "aekf": stats_entry(a), "astekf": stats_entry(s)}
                    for q, a, s in zip(study.q_sweep["Q"], study.q_sweep["aekf"], study.q_sweep["astekf"])],
        "aekf": stats_entry(study.main["aekf"]),
        "astekf": stats_entry(study.main["astekf"]),
        "aaekf": stats_entry(study.main["aaekf"]),
        "torque_error_rate_correlation": float(np.mean(smallest.corr_rate)),
        "torque_error_rate_correlation_axes": [float(v) for v in smallest.corr_rate],
        "torque_error_rate_correlation_Q": float(study.q_sweep["Q"][0]),
        "st_grid": [{"rho": s.params["rho"], "beta": s.params["beta"], **stats_entry(s)} for s in study.st_grid],
        "epsilon_sweep": [{"epsilon": s.params["epsilon"], **stats_entry(s)} for s in study.epsilon_sweep],
        "window_sweep": [{"window": s.params["window"], **stats_entry(s)} for s in study.window_sweep],
        "claims": claims,
    }
    if chaser is not None:
        out["chaser"] = {"rows": chaser.rows, "sweeps": chaser.sweeps, "settings": chaser.settings}
    return to_json(out)


def reproduce(out_dir="results/attitude2018", *, seed=0, runs=20, notebooks=False, progress=True, scenario=None,
              chaser=True):
    """Regenerate paper 002's Figs 1–9, the sweeps, the claims and the chaser study into ``out_dir``.

    Writes ``fig1`` … ``fig9``, ``fig10_q_sweep``, ``fig11_tuning`` and (with
    ``chaser``) ``fig12_chaser`` as PNG and PDF, ``summary.json`` and the claims
    table ``claims.csv`` / ``claims.md`` (:func:`hinfnav.papers.claims_table.write_claims_table`).

    Parameters
    ----------
    out_dir : str or Path
    seed : int
    runs : int
        Monte Carlo runs of the three filters at the paper's settings and of
        the chaser comparison; the sweeps use the first min(runs, 4) (attitude)
        and min(runs, 5) (chaser) runs of the same truths.
    notebooks : bool
        Also execute :data:`NOTEBOOKS` into ``out_dir``.
    progress : bool
    scenario : Scenario, optional
    chaser : bool
        Run item 5 (Sun 2011's chaser) too.

    Returns
    -------
    dict
        The summary written to ``summary.json``.
    """
    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    rep = Reproduction(out_dir, "attitude2018", notebooks=NOTEBOOKS if notebooks else (),
                       progress=progress, dpi=110, seed=seed, runs=runs)
    study = attitude_study(scenario, runs=runs, seed=seed, progress=progress)
    claims = measure_claims(study)
    ch = chaser_study(runs=runs, seed=seed) if chaser else None
    figs = {"fig1": lambda: fig1(scenario), "fig2": lambda: fig2(study), "fig3": lambda: fig3(study),
            "fig4": lambda: fig4(study), "fig5": lambda: fig5(study), "fig6": lambda: fig6(study),
            "fig7": lambda: fig7(study), "fig8": lambda: fig8(study), "fig9": lambda: fig9(study),
            "fig10_q_sweep": lambda: fig_q_sweep(study), "fig11_tuning": lambda: fig_tuning(study)}
    if ch is not None:
        figs["fig12_chaser"] = lambda: plot_chaser(ch)
    rep.save_figures(figs)
    summary = summarize(study, claims, ch)
    summary["status"] = paper_status("attitude2018", summary)
    summary = rep.write_summary(summary)
    write_claims_table(claims, rep.out, "Paper 002 (gyroless attitude, 2018): the claims, their statistics and verdicts")
    if notebooks:
        rep.run_notebooks()
    if progress:
        print(f"\norbit rate {summary['orbit_rate_deg_s']:.14f} deg/s (paper {PAPER_OMEGA_E_DEG_S}), "
              f"relative difference {summary['orbit_rate_check']['relative_difference']:.1e}")
        print(format_claims(claims))
        print(format_status("attitude2018", summary["status"]))
        if ch is not None:
            print("\nSun 2011's chaser, control law unknown (mean of per-run RMS over axes, 95 % interval):")
            print(format_chaser_table(ch))
        print(f"\npaper 002 (attitude): done in {rep.elapsed_s:.0f} s")
    return summary
