"""``python -m hinfnav reproduce --paper sun2011``: Table 1 and Figs 2–7 of Sun et al. (2011) into a folder."""

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_seed
from ...metrics.errors import rms_per_run
from ..notebooks import CROSS_PAPER
from ..skeleton import Reproduction
from .constants import CITATION
from .designs import design_for_scenario
from .figures import fig2, fig3, fig4, fig5, fig6, fig7, fig7_result, paper_runs
from .scenario import Scenario
from .table1 import CASES, _kl_axes, format_table1, table1, write_table1
from .timing import step_times

__all__ = ["NOTEBOOKS", "reproduce"]

#: This paper's chapter of the workbook (``reproduce(notebooks=True)`` also runs
#: :data:`hinfnav.papers.notebooks.CROSS_PAPER`: sun2011 writes into the output folder's root).
NOTEBOOKS = (
    "01_model_and_scenario.ipynb",
    "02_derivation.ipynb",
    "03_design_vs_delta.ipynb",
    "04_table1.ipynb",
    "05_figs_2_to_6.ipynb",
    "06_fig7_uncertainty_and_non_gaussian.ipynb",
    "07_closed_loop.ipynb",
    "08_mixed_h2_hinf.ipynb",
    "09_your_own_plant_polytopes.ipynb",
    "91_interactive_design_and_errors.ipynb",
)


def _summary(scenario, tab, designed, observer, fig7_res):
    t1 = {}
    for case in CASES:
        t1[case] = {}
        for key, c in tab.cells[case].items():
            t1[case][key] = c
    kp, kv = _kl_axes(tab.kalman_limit["no_maneuver"])
    kpp, kvp = _kl_axes(tab.kalman_limit["no_maneuver"], predicted=True)
    win = scenario.rms_window_s
    per = rms_per_run(fig7_res.error, fig7_res.t, win)[0]
    pos, vel = fig7_res.state.select(per, "position"), fig7_res.state.select(per, "velocity")
    return {
        "paper": CITATION,
        "settings": tab.settings,
        "table1": t1,
        "kalman_limit": {
            "pos_m": kp,
            "vel_mps": kv,
            "pos_m_predicted": kpp,
            "vel_mps_predicted": kvp,
            "note": "steady-state Kalman filter (Riccati) error for the stated white noise, no maneuver, RMS over "
            "axes; pos_m/vel_mps filtered (uses y(k), like the EKF), *_predicted one step ahead (like the H-inf "
            "filter (12)); per case and per axis under 'cases' (with maneuver: a filter that knows u = Kx)",
            "cases": tab.kalman_limit,
        },
        "ekf_maneuver_windows": tab.ekf_windows,
        "fig7": {"delta": fig7_res.settings["delta"], "noise": fig7_res.settings["noise"],
                 "pos_axes_m": [float(v) for v in pos], "vel_axes_mps": [float(v) for v in vel]},
        "designed_filter": {"delta_bar": 0.05, "gamma": float(designed.gamma), "lmi_gamma": float(designed.lmi_gamma)},
        "observer_filter": {"delta_bar": 0.05, "gamma": float(observer.gamma), "lmi_gamma": float(observer.lmi_gamma),
                            "note": "extension: LMI (20) with C_F = -L and A_F = A + B_F C (observer form)"},
    }


def reproduce(out_dir="results", *, seed=0, runs=100, notebooks=False, progress=True, scenario=None):
    """Regenerate Table 1 and Figs 2–7 into ``out_dir``.

    Writes ``fig2`` … ``fig7`` (PNG and PDF), ``fig4`` with both EKF variants,
    ``table1.csv``, ``table1.md`` and ``summary.json``, prints the
    paper-vs-reproduced table, and with ``notebooks=True`` also executes
    :data:`NOTEBOOKS` and the cross-paper notebooks into ``out_dir``.

    Returns
    -------
    dict
        The summary written to ``summary.json``.
    """
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    runs = as_int_at_least("runs", runs, 1)
    as_seed("seed", seed)  # before the designs, not after them
    rep = Reproduction(out_dir, "sun2011", notebooks=NOTEBOOKS + CROSS_PAPER if notebooks else (),
                       progress=progress, seed=seed, runs=runs)
    out, prov, say = rep.out, rep.provenance, rep.say
    say("designing the robust H∞ filter at δ̄ = 0.05 (Corollary 1) ...")
    designed = design_for_scenario(scenario, delta_bar=0.05)
    say(f"  certified γ = {designed.gamma:.4g} (LMI: {designed.lmi_gamma:.4g})")
    observer = design_for_scenario(scenario, delta_bar=0.05, form="observer")
    say(f"  in observer form (extension): certified γ = {observer.gamma:.4g}")
    tab = table1(scenario, runs=runs, seed=seed, designed=designed, observer=observer, progress=progress)
    write_table1(tab, out, provenance=prov)
    runs_ = paper_runs(scenario, seed=seed)
    f7 = fig7_result(scenario, seed=seed)
    figs = {"fig2": fig2(runs_), "fig3": fig3(runs_), "fig4": fig4(runs_), "fig5": fig5(runs_), "fig6": fig6(runs_),
            "fig7": fig7(f7)}
    rep.save_figures(figs)
    summary = _summary(scenario, tab, designed, observer, f7)
    summary["computation"] = {
        "claim": "the LMI filter needs no recursive coefficient matrices, which greatly reduces the computation (§1)",
        "timing_s": step_times(scenario, seed=seed)}
    summary = rep.write_summary(summary)
    if notebooks:
        rep.run_notebooks()
    if progress:
        print()
        print("Table 1, paper vs reproduced: per-axis RMS over the window, RMS over x, y, z; 1 run and mean ± 95% CI")
        print(format_table1(tab))
        tm = summary["computation"]["timing_s"]
        print("per step (update + predict): " + ", ".join(f"{k} {v['step_time_s'] * 1e6:.0f} us"
                                                        for k, v in tm["filters"].items())
              + f"; EKF/LTI {tm['ratio_ekf_over_lti']['step']:.1f}x, recursive H-inf/LTI "
              f"{tm['ratio_recursive_hinf_over_lti']['step']:.1f}x")
        print(f"\nSun 2011 reproduced in {rep.elapsed_s:.0f} s")
    return summary
