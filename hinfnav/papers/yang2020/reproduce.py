"""``python -m hinfnav reproduce --paper yang2020``: the closed loop of Section 3, Figs 5-12, summary.json, claims.csv/md.

Runs, with the scenario's readings (``Scenario()``: 3×10⁵ steps):

1. the ADRC loop with the standalone estimators alongside (Figs 6-8, 10-12);
2. the tuned PID and the ADRC built on it (Fig 9, Fig 12, the ADRC-vs-PID claim);
3. the drag-free loop open (F_Csc = 0), where the accelerometers saturate (Fig 5, L1/L2/L3);
4. the ADRC under the other readings the 3×10⁻¹⁴ claim depends on (noise density conversion,
   ω_d, timing; 10⁵ steps each) and under the printed integral terms (3×10⁴ steps).
"""

import time
from dataclasses import replace

import numpy as np
from tqdm import tqdm

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least
from ...io.progress import bar_disabled
from ..claims_table import write_claims_table
from ..verdicts import format_status, paper_status
from ..skeleton import Reproduction
from .claims import evaluate_claims
from .constants import CITATION, READING_REASONS, REQUIREMENT_ASD, TABLE2
from .figures import fig5, fig6, fig7, fig8, fig9, fig10, fig11, fig12
from .loop import run_closed_loop, run_closed_loops
from .scenario import Scenario, check_scenario
from .studies import (
    NPERSEG,
    SENSITIVITY_NPERSEG,
    asd_sensitivity,
    estimation_errors,
    periodic_amplitude,
    residual_spectrum,
    saturation_summary,
    step_response,
    theta_readings_study,
    truncated,
)

__all__ = ["NOTEBOOKS", "reproduce", "READING_RUNS", "reading_study", "integral_study",
           "algorithm_windows"]

#: This paper's chapter of the workbook (``reproduce(notebooks=True)``).
NOTEBOOKS = (
    "30_yang2020_model.ipynb",
    "31_yang2020_algorithm2.ipynb",
    "32_yang2020_closed_loop.ipynb",
    "33_yang2020_claims.ipynb",
)

#: Largest runs × steps of one reproduction (the histories of a 3×10⁵-step run take ~0.2 GB).
MAX_RUN_STEPS = 2_400_000

#: The readings the Fig 12 claim is re-run under (name → Scenario changes).
READING_RUNS = {
    "noise_two_sided": {"noise": "two_sided"},
    "noise_per_sample": {"noise": "per_sample"},
    "omega_d_rad_s": {"omega_d": "rad_s"},
    "timing_prior": {"timing": "prior"},
}


def algorithm_windows(n_passive, dt, early_s=300.0, late_s=2000.0, skip_s=10.0):
    """Windows of the Figs 6-8 claims over the standalone span: after the first ``skip_s`` (the initial jump of
    every estimate from 0 to the disturbance), the next ``early_s``, and the last ``late_s`` (at most a third)."""
    k0 = min(n_passive - 1, int(skip_s / dt))
    k_e = min(n_passive, k0 + int(early_s / dt))
    k_l = max(k0, n_passive - min(int(late_s / dt), n_passive // 3))
    return {"all": (k0, n_passive), "early": (k0, k_e), "late": (k_l, n_passive)}


def reading_study(scenario, changes, *, n_steps, seed=0, runs=1, settle_s=None, result=None):
    """The ADRC loop under changed readings: the Fig 12 statistics of the test-mass residual.

    Also ``max_by_nperseg``: the band maximum for each of :data:`SENSITIVITY_NPERSEG` (same record).
    ``result``: a longer loop of these readings to cut to ``n_steps`` instead of running one.
    """
    sc = replace(check_scenario(scenario), n_steps=n_steps, **changes)
    if result is None:
        res = run_closed_loop(sc, controller="adrc", runs=runs, seed=seed, passive=False)
    else:
        res = truncated(result, n_steps)
    settle = sc.settle_s if settle_s is None else settle_s
    sp = residual_spectrum(res, sc.residual, settle_s=settle)
    sens = asd_sensitivity(res, sc.residual, settle_s=settle, npersegs=SENSITIVITY_NPERSEG)
    return dict(sp["stats"], n_steps=n_steps, changes=changes, window_s=sp["window_s"], nperseg=sp["nperseg"],
                max_by_nperseg={str(r["nperseg"]): r["max"] for r in sens["rows"]})


def reading_studies(scenario, readings, *, n_steps, seed=0, runs=1, progress=False):
    """:func:`reading_study` of each ``name → changes`` in ``readings``, the loops that share a timing batched
    into one (:func:`~hinfnav.papers.yang2020.loop.run_closed_loops`: the same numbers, each its own estimator)."""
    base = replace(check_scenario(scenario), n_steps=n_steps)
    scs = {name: replace(base, **changes) for name, changes in readings.items()}
    out = {}
    for timing in tqdm(sorted({s.timing for s in scs.values()}), disable=bar_disabled(progress), desc="readings",
                       leave=False):
        names = [name for name, s in scs.items() if s.timing == timing]
        loops = run_closed_loops([(scs[name], "adrc") for name in names], runs=runs, seed=seed, passive=False)
        for name, res in zip(names, loops):
            out[name] = reading_study(base, readings[name], n_steps=n_steps, seed=seed, runs=runs, result=res)
    return {name: out[name] for name in readings}


def integral_study(scenario, integral, *, n_steps, seed=0):
    """The ADRC loop with the NLPID integral read ``integral``: does it stay put?

    Run alone, not batched with other loops: under the printed reading the loop is unstable, so a
    round-off difference (a matrix product over more rows) grows to 10 % of its second-half displacement.
    """
    sc = replace(check_scenario(scenario), n_steps=n_steps, integral=integral)
    res = run_closed_loop(sc, controller="adrc", seed=seed, passive=False)
    k = res.x.shape[1] // 2
    att_err = np.abs(res.x[:, k:, 0:3] - res.reference[k:]).max()
    return {"integral": integral, "n_steps": n_steps,
            "max_abs_r_second_half_m": float(np.abs(res.x[:, k:, 6:9]).max()),
            "max_abs_attitude_error_second_half_rad": float(att_err),
            "saturated_steps": saturation_summary(res)["saturated_steps"],
            "clipped_input_steps": int(res.settings["clipped_input_steps"])}


def reproduce(out_dir="results/yang2020", *, seed=0, runs=1, notebooks=False, progress=True, scenario=None,
              open_loop_steps=20_000, reading_steps=100_000, integral_steps=30_000, formats=("png", "pdf")):
    """Run the closed loops and write Figs 5-12 (PNG and PDF), ``summary.json`` and ``claims.csv``/``.md`` into ``out_dir``.

    Parameters
    ----------
    out_dir : path
    seed : int
    runs : int
        Monte Carlo runs of every loop (1 by default: the paper shows single runs); at most
        ``MAX_RUN_STEPS / n_steps`` (8 at full length), for memory.
    notebooks : bool
        Also execute :data:`NOTEBOOKS` into ``out_dir``.
    progress : bool
    scenario : Scenario, optional
        Default ``Scenario()`` (3×10⁵ steps, default readings).
    open_loop_steps, reading_steps, integral_steps : int
        Lengths of the Fig 5 run, of the reading studies and of the integral studies.
    formats : tuple of str
        Figure file formats.

    Returns
    -------
    dict
        The summary written to ``summary.json``.
    """
    sc = Scenario() if scenario is None else check_scenario(scenario)
    runs = as_int_at_least("runs", runs, 1)
    if runs * sc.n_steps > MAX_RUN_STEPS:
        raise InputError(f"runs = {runs} of {sc.n_steps} steps would keep {runs * sc.n_steps:.3g} steps of history "
                         f"(about 0.6 kB a step); at most {MAX_RUN_STEPS:.3g}: use runs <= "
                         f"{max(1, MAX_RUN_STEPS // sc.n_steps)} (the paper shows single runs)")
    rep = Reproduction(out_dir, "yang2020", notebooks=NOTEBOOKS if notebooks else (),
                       progress=progress, formats=formats, seed=seed, runs=runs, n_steps=sc.n_steps)
    say = rep.say
    timings = {}

    say(f"yang2020: the ADRC, the tuned PID and the ADRC on the PID, one batch of closed loops, {sc.n_steps} steps ...")
    t0 = time.perf_counter()
    kinds = ("adrc", "pid", "adrc_pid")
    main, *others = run_closed_loops([(sc, kind) for kind in kinds], runs=runs, seed=seed, passive=(True, False, False),
                                     progress=progress)
    timings["adrc_pid_adrc_pid_loops_with_standalone_filters_s"] = time.perf_counter() - t0
    n_p = main.passive["L1"].shape[1]
    algorithms = estimation_errors(main, windows=algorithm_windows(n_p, sc.dt))
    closed_l = estimation_errors(main, windows={"all": (0, n_p), "first_100s": (0, min(n_p, 1000))})
    spectra = {r: residual_spectrum(main, r, sc.settle_s) for r in ("test_mass", "relative", "accelerometer")}
    step = step_response(main)
    k_settle = int(sc.settle_s / sc.dt)
    per = {"adrc": periodic_amplitude(main.x[:, k_settle:, 6], main.t[k_settle:], sc.w_d)}
    sat_main = saturation_summary(main)
    n_rec = min(reading_steps, sc.n_steps)  # the one record length every reading of the 3e-14 claim is stated at
    asd_sens = asd_sensitivity(main, sc.residual, settle_s=sc.settle_s,
                               lengths=sorted({n_rec, (n_rec + sc.n_steps) // 2, sc.n_steps}))
    by_reading = {"default": reading_study(sc, {}, n_steps=n_rec, seed=seed, result=main)}
    for r in ("relative", "accelerometer"):
        by_reading[f"residual_{r}"] = reading_study(sc, {"residual": r}, n_steps=n_rec, seed=seed, result=main)
    steady_from = main.settings["fused_steady_from_step"]
    rep.save_figures({"fig6": fig6(main), "fig7": fig7(main), "fig8": fig8(main), "fig10": fig10(main),
                      "fig11": fig11(main)})
    main_r = main

    loops9 = {"ADRC (NLPID, Section 3)": main_r}
    for kind, label, res in zip(kinds[1:], ("PID (5.55, 0, 9)", "ADRC (same PID + compensation)"), others):
        k0 = int(sc.settle_s / sc.dt)
        per[kind] = periodic_amplitude(res.x[:, k0:, 6], res.t[k0:], sc.w_d)
        spectra[f"{kind}_test_mass"] = residual_spectrum(res, sc.residual, sc.settle_s)
        loops9[label] = res
    rep.save_figure(fig9(loops9), "fig9")
    rep.save_figure(fig12({"PID": spectra["pid_test_mass"], "ADRC on the PID": spectra["adrc_pid_test_mass"],
                           "ADRC (NLPID)": spectra[sc.residual]}), "fig12")
    del loops9, res, main, others

    say(f"yang2020: drag-free loop open (Fig 5), {open_loop_steps} steps ...")
    t0 = time.perf_counter()
    open_ = run_closed_loop(replace(sc, n_steps=open_loop_steps), controller="dragfree_off", runs=runs, seed=seed,
                            passive=True, passive_steps=open_loop_steps + 1, progress=progress)
    timings["open_loop_s"] = time.perf_counter() - t0
    est_open = estimation_errors(open_)
    theta_open = theta_readings_study(sc, open_)
    rep.save_figure(fig5(open_), "fig5")
    sat_open = saturation_summary(open_)
    del open_

    say("yang2020: the 3e-14 claim under the other readings ...")
    t0 = time.perf_counter()
    by_reading.update(reading_studies(sc, READING_RUNS, n_steps=n_rec, seed=seed, runs=runs, progress=rep.progress))
    integral = {i: integral_study(sc, i, n_steps=min(integral_steps, sc.n_steps), seed=seed) for i in ("printed", "dt")}
    timings["reading_studies_s"] = time.perf_counter() - t0

    st = spectra[sc.residual]["stats"]
    summary = {
        "paper": CITATION,
        "settings": {"n_steps": sc.n_steps, "dt_s": sc.dt, "seed": seed, "runs": runs, "readings": sc.readings,
                     "reading_reasons": READING_REASONS, "nperseg": NPERSEG, "settle_s": sc.settle_s,
                     "steady_tol": sc.steady_tol, "fused_gains_frozen_from_step": steady_from,
                     "open_loop_steps": open_loop_steps, "reading_steps": reading_steps,
                     "integral_steps": integral_steps, "standalone_filter_steps": n_p},
        "table2": TABLE2,
        "theta_star": {"algorithm1": float(main_r.settings["theta_alg1"]),
                       "algorithm2": [float(v) for v in main_r.settings["theta_alg2"]]},
        "estimation": {
            **{k: est_open[k]["all"] for k in ("L1", "L2", "L3")},
            "fused": est_open["fused"]["all"],
            "setting": f"drag-free loop open (F_Csc = 0), x axis, {open_loop_steps} steps",
            "saturation": sat_open,
            "theta_readings": theta_open,
            "closed_loop": {k: v for k, v in closed_l.items()},
        },
        "algorithms": algorithms,
        "asd": {
            "unit": "m s^-2/sqrt(Hz)", "reading": sc.residual, "noise": sc.noise, "nperseg": NPERSEG,
            "adrc_max_1_30mHz": st["max"], "adrc_f_at_max_hz": st["f_at_max_hz"], "adrc_median_1_30mHz": st["median"],
            "adrc_floor_max_1_30mHz": st["floor_max"],
            "pid_max_1_30mHz": spectra["pid_test_mass"]["stats"]["max"],
            "pid_median_1_30mHz": spectra["pid_test_mass"]["stats"]["median"],
            "adrc_pid_max_1_30mHz": spectra["adrc_pid_test_mass"]["stats"]["max"],
            "requirement": REQUIREMENT_ASD,
            "record_steps": n_rec,
            "by_reading": by_reading,
            "sensitivity": asd_sens,
        },
        "requirement": REQUIREMENT_ASD,
        "periodic": per,
        "step_response": step,
        "saturation": sat_main,
        "integral_readings": integral,
    }
    summary["claims"] = evaluate_claims(summary)
    summary["status"] = paper_status("yang2020", summary)
    timings["total_s"] = rep.elapsed_s
    summary["timing_s"] = timings
    summary = rep.write_summary(summary, strict=True)
    write_claims_table(summary["claims"], rep.out, "Yang et al. (2020): the claims, their statistics and verdicts")
    if notebooks:
        rep.run_notebooks()
    if progress:
        print(f"\nYang et al. 2020: done in {timings['total_s']:.0f} s")
        for c in summary["claims"]:
            print(f"  [{c['verdict']}] {c['figure']}: {c['claim']}")
        print(format_status("yang2020", summary["status"]))
    return summary
