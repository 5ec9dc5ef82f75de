"""Reproduction of the paper's Table 1 and Figs 2–7: one function per table or figure.

The notebooks ``04_table1``, ``05_figs_2_to_6``, ``06_fig7_uncertainty_and_non_gaussian``
and ``python -m hinfnav reproduce`` call the same functions.

Conventions (the paper does not state them; see the notebooks for why):

* error measure: per-axis RMS of x − x̂ over ``scenario.rms_window_s``
  (100–1000 s); a table cell is the RMS over the three axes of those
  per-axis values (all three are close to each other);
* single run: run 0 of the Monte Carlo set (the paper shows one run);
* Monte Carlo: mean over runs of the per-run value, with the 95 % confidence
  interval of that mean, and the 2.5–97.5 % spread of single runs;
* noise: white Gaussian w, v (the paper's Table 1 text), Fig 7 with the
  Gaussian mixture of paper 001 and δ = 1;
* all filters see the same truth and measurements in each case;
* the H∞ filters run exactly as (12) with maneuver (the closed loop u = Kx
  they were designed on) and are told the applied thrust without maneuver
  (see :func:`hinfnav.filters.lti_from_matrices`).
"""

import csv
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .exceptions import InputError
from .filters import lti_from_matrices, make_estimator
from .metrics import rms_per_run, window_mask
from .plotting import new_figure, plot_errors, plot_thrust
from .scenario import Scenario, published_filter
from .simulation import run_estimator, simulate, simulate_truth
from .validation import as_int_at_least

__all__ = [
    "PAPER_TABLE1",
    "CITATION",
    "axes_rms",
    "Table1",
    "table1",
    "table1_rows",
    "format_table1",
    "write_table1",
    "figure_errors",
    "fig2",
    "fig3",
    "fig4",
    "fig5",
    "fig6",
    "fig7",
    "fig7_result",
    "robustness_table",
    "format_robustness_table",
    "paper_runs",
    "reproduce",
]

CITATION = (
    "Sun Zhao-wei, Deng Hong, Liu Hao, Zhong Wei-chao, \"Relative navigation algorithm for chaser satellite "
    "based on robust H-infinity filtering\", Journal of Astronautics 32(7):1462-1470, 2011, "
    "doi:10.3873/j.issn.1000-1328.2011.07.005"
)

#: Table 1 of the paper (None where it prints "—").
PAPER_TABLE1 = {
    "no_maneuver": {"ekf": {"pos_m": 0.04, "vel_mps": 0.001}, "hinf": {"pos_m": 0.2, "vel_mps": 0.8}},
    "maneuver": {"ekf": {"pos_m": None, "vel_mps": None}, "hinf": {"pos_m": 0.2, "vel_mps": 0.8}},
}

#: Filters of the reproduced table: key -> (label, builder name)
TABLE_FILTERS = {
    "ekf": "EKF (paper: control law unknown)",
    "ekf_known_input": "EKF (knows the thrust)",
    "hinf_published": "H∞, published A_F, B_F, C_F",
    "hinf_designed": "H∞, designed here (δ̄ = 0.05)",
    "hinf_observer": "H∞, designed in observer form (extension)",
}

CASES = {"no_maneuver": False, "maneuver": True}


def axes_rms(values):
    """One number from per-axis values: ``sqrt(mean(v²))`` over x, y, z (how a Table 1 cell is formed)."""
    return float(np.sqrt(np.mean(np.square(values))))


def _estimators(scenario, designed, maneuver, observer=None):
    """The filters of the table; H∞ filters verbatim (12) with maneuver, told the thrust without."""
    pub = published_filter()
    told = not maneuver
    est = {
        "ekf": make_estimator("ekf", scenario),
        "ekf_known_input": make_estimator("ekf_known_input", scenario),
        "hinf_published": lti_from_matrices(pub.A_F, pub.B_F, pub.C_F, scenario, name="published", uses_input=told),
    }
    if designed is not None:
        est["hinf_designed"] = lti_from_matrices(designed.A_F, designed.B_F, designed.C_F, scenario, name="designed",
                                                 uses_input=told)
    if observer is not None:
        est["hinf_observer"] = lti_from_matrices(observer.A_F, observer.B_F, observer.C_F, scenario,
                                                 name="designed_observer", uses_input=told)
    return est


@dataclass(frozen=True, eq=False)
class Table1:
    """Reproduced Table 1.

    Attributes
    ----------
    cells : dict
        ``cells[case][filter]`` → dict with ``pos_m``, ``vel_mps`` (single
        run, RMS over axes of the per-axis RMS), ``pos_axes_m``,
        ``vel_axes_mps`` (3 each), ``mc_mean_pos_m``, ``mc_ci95_pos_m``
        ([lo, hi]), ``mc_spread95_pos_m``, and the same for velocity.
        ``case`` is ``no_maneuver`` or ``maneuver``.
    ekf_windows : dict
        The paper-variant EKF with maneuver over 0–500 s and 500–1000 s.
    kalman_limit : dict
        Steady-state Kalman (Riccati) error per case (see :mod:`hinfnav.kalman`).
    settings : dict
    """

    cells: dict
    ekf_windows: dict
    kalman_limit: dict
    settings: dict = field(default_factory=dict)


def _cell(result, t, window):
    per_run = rms_per_run(result.error, t, window)  # (runs, 6)
    pos_run = np.sqrt(np.mean(per_run[:, :3] ** 2, axis=1))
    vel_run = np.sqrt(np.mean(per_run[:, 3:] ** 2, axis=1))
    out = {
        "pos_m": float(pos_run[0]),
        "vel_mps": float(vel_run[0]),
        "pos_axes_m": [float(v) for v in per_run[0, :3]],
        "vel_axes_mps": [float(v) for v in per_run[0, 3:]],
    }
    for key, vals in (("pos_m", pos_run), ("vel_mps", vel_run)):
        n = vals.size
        mean = float(vals.mean())
        half = float(1.96 * vals.std(ddof=1) / np.sqrt(n)) if n > 1 else 0.0
        out[f"mc_mean_{key}"] = mean
        out[f"mc_ci95_{key}"] = [mean - half, mean + half]
        out[f"mc_spread95_{key}"] = [float(v) for v in np.percentile(vals, [2.5, 97.5])]
    return out


def table1(scenario=None, *, runs=100, seed=0, designed=None, observer=None, progress=False):
    """Compute the reproduced Table 1.

    Parameters
    ----------
    scenario : Scenario, optional
        Defaults to the paper's.
    runs : int
        Monte Carlo runs per case (≥ 1; 100 or more for the interval).
    seed : int
    designed : SynthesisResult, optional
        The δ̄ = 0.05 filter from :func:`hinfnav.synthesize`; designed here when
        None (about a second).
    observer : SynthesisResult, optional
        The δ̄ = 0.05 filter designed in observer form (an extension of the
        paper); designed here when None.
    progress : bool

    Returns
    -------
    Table1
    """
    from .kalman import kalman_limit
    from .synthesis import design_for_scenario

    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    if designed is None:
        designed = design_for_scenario(scenario, delta_bar=0.05)
    if observer is None:
        observer = design_for_scenario(scenario, delta_bar=0.05, form="observer")
    win = scenario.rms_window_s
    cells, ekf_windows, klim = {}, {}, {}
    total = len(CASES) * len(_estimators(scenario, designed, True, observer))
    with tqdm(total=total, disable=not progress, desc="Table 1", unit="filter") as bar:
        for case, maneuver in CASES.items():
            truth = simulate_truth(scenario, maneuver=maneuver, runs=runs, seed=seed)
            cells[case] = {}
            for key, est in _estimators(scenario, designed, maneuver, observer).items():
                res = run_estimator(est, truth, scenario.xhat0)
                cells[case][key] = _cell(res, truth.t, win)
                if case == "maneuver" and key == "ekf":
                    for label, w in (("0-500 s", (0.0, 500.0)), ("100-500 s", (100.0, 500.0)), ("500-1000 s", (500.0, 1000.0))):
                        ekf_windows[label] = _cell(res, truth.t, w)
                del res
                bar.update(1)
            for key, paper_key in (("paper_ekf", "ekf"), ("paper_hinf", "hinf")):
                cells[case][key] = dict(PAPER_TABLE1[case][paper_key])
            klim[case] = kalman_limit(scenario, maneuver=maneuver).as_dict()
    settings = {
        "runs": runs,
        "seed": seed,
        "dt_s": scenario.dt,
        "duration_s": scenario.duration_s,
        "window_s": list(win),
        "noise": "gaussian (white, unit variance, scaled by B and D)",
        "truth_discretization": "exact (zero-order hold)",
        "error_measure": (
            "per-axis RMS of x - xhat over window_s; a cell is the RMS over x, y, z of the per-axis values; "
            "pos_m/vel_mps: single run (run 0, as the paper reports); mc_*: over all runs"
        ),
        "hinf_input": "H-inf filters run verbatim as (12) with maneuver, told the applied thrust without",
        "designed_gamma": float(designed.gamma),
        "designed_lmi_gamma": float(designed.lmi_gamma),
        "observer_gamma": float(observer.gamma),
    }
    return Table1(cells=cells, ekf_windows=ekf_windows, kalman_limit=klim, settings=settings)


def _kl_axes(kl, predicted=False):
    """(pos_m, vel_mps) scalars (RMS over axes) of a kalman_limit record (filtered or predicted)."""
    suffix = "_predicted" if predicted else ""
    return axes_rms(kl["pos_m" + suffix]), axes_rms(kl["vel_mps" + suffix])


def table1_rows(tab):
    """Rows (list of dicts) of the reproduced table, paper values beside them."""
    rows = []
    for case in CASES:
        for key, label in [("paper_ekf", "paper: EKF"), ("paper_hinf", "paper: H∞")] + list(TABLE_FILTERS.items()):
            c = tab.cells[case].get(key)
            if c is None:
                continue
            row = {"case": case.replace("_", " "), "filter": label, "pos_m": c["pos_m"], "vel_mps": c["vel_mps"]}
            if "mc_mean_pos_m" in c:
                row.update(
                    mc_pos_m=c["mc_mean_pos_m"], mc_pos_ci95=c["mc_ci95_pos_m"],
                    mc_vel_mps=c["mc_mean_vel_mps"], mc_vel_ci95=c["mc_ci95_vel_mps"],
                )
            rows.append(row)
        for predicted, label in ((False, "Kalman limit, filtered (uses y(k))"), (True, "Kalman limit, predicted (y up to k-1, like (12))")):
            kp, kv = _kl_axes(tab.kalman_limit[case], predicted)
            rows.append({"case": case.replace("_", " "), "filter": label, "pos_m": kp, "vel_mps": kv})
    return rows


def _fmt(v, digits=3):
    if v is None:
        return "—"
    if isinstance(v, (list, tuple)):
        return f"[{_fmt(v[0], digits)}, {_fmt(v[1], digits)}]"
    return f"{v:.{digits}g}"


def format_table1(tab, markdown=False):
    """Paper-vs-reproduced Table 1 as text (plain or Markdown)."""
    rows = table1_rows(tab)
    runs = tab.settings.get("runs")
    head = ["case", "filter", "pos (m), 1 run", "vel (m/s), 1 run", f"pos (m), mean of {runs} [95% CI]",
            f"vel (m/s), mean of {runs} [95% CI]"]
    body = []
    for r in rows:
        mc_p = f"{_fmt(r['mc_pos_m'])} {_fmt(r['mc_pos_ci95'])}" if "mc_pos_m" in r else ""
        mc_v = f"{_fmt(r['mc_vel_mps'])} {_fmt(r['mc_vel_ci95'])}" if "mc_vel_mps" in r else ""
        body.append([r["case"], r["filter"], _fmt(r["pos_m"]), _fmt(r["vel_mps"]), mc_p, mc_v])
    if markdown:
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(b) + " |" for b in body]
        return "\n".join(lines)
    widths = [max(len(str(x)) for x in col) for col in zip(head, *body)]
    fmt = lambda cells: "  ".join(str(c).ljust(w) for c, w in zip(cells, widths))  # noqa: E731
    return "\n".join([fmt(head), fmt(["-" * w for w in widths])] + [fmt(b) for b in body])


def write_table1(tab, out_dir):
    """Write ``table1.csv`` and ``table1.md`` into ``out_dir``; return their paths."""
    out_dir = Path(out_dir)
    rows = table1_rows(tab)
    csv_path = out_dir / "table1.csv"
    with open(csv_path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "filter", "pos_m_single_run", "vel_mps_single_run", "pos_m_mc_mean", "pos_m_mc_ci95_lo",
                    "pos_m_mc_ci95_hi", "vel_mps_mc_mean", "vel_mps_mc_ci95_lo", "vel_mps_mc_ci95_hi"])
        for r in rows:
            mc = [r.get("mc_pos_m"), *(r.get("mc_pos_ci95") or [None, None]), r.get("mc_vel_mps"),
                  *(r.get("mc_vel_ci95") or [None, None])]
            w.writerow([r["case"], r["filter"], r["pos_m"], r["vel_mps"], *mc])
    md_path = out_dir / "table1.md"
    md_path.write_text(
        "# Table 1: relative navigation accuracy, paper vs reproduced\n\n"
        + format_table1(tab, markdown=True)
        + "\n\nError measure: " + tab.settings["error_measure"] + ".\n"
        + f"Window {tab.settings['window_s'][0]:g}-{tab.settings['window_s'][1]:g} s, T = {tab.settings['dt_s']:g} s, "
        + f"{tab.settings['runs']} Monte Carlo runs, seed {tab.settings['seed']}.\n"
    )
    return csv_path, md_path


# ---------------------------------------------------------------- figures


def figure_errors(result, title, *, run=0, t_zoom_from=5.0):
    """Per-axis position and velocity errors of one run (the layout of Figs 2–5, 7).

    The y limits leave out the first ``t_zoom_from`` seconds (the 30–40 m
    initial error), as the paper's figures do.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(2, 3, figsize=(12, 5.5))
    m = result.t >= t_zoom_from
    err = result.error[run][m]
    lim = lambda a: 1.15 * max(np.max(np.abs(a)), 1e-6)  # noqa: E731
    lp, lv = lim(err[:, :3]), lim(err[:, 3:])
    plot_errors(result, axes=axes, run=run, ylim_pos=(-lp, lp), ylim_vel=(-lv, lv), title=title)
    return fig


def paper_runs(scenario=None, *, seed=0, progress=False):
    """The single runs behind Figs 2–6: each filter with and without maneuver.

    Returns
    -------
    dict
        ``{(filter_key, maneuver): SimulationResult}`` for filter keys
        ``ekf``, ``ekf_known_input``, ``hinf_published``.
    """
    scenario = Scenario() if scenario is None else scenario
    out = {}
    for maneuver in (False, True):
        truth = simulate_truth(scenario, maneuver=maneuver, runs=1, seed=seed)
        for key, name in (("ekf", "ekf"), ("ekf_known_input", "ekf_known_input"), ("hinf_published", "published")):
            out[(key, maneuver)] = run_estimator(make_estimator(name, scenario), truth, scenario.xhat0)
    return out


def fig2(runs):
    """Fig 2: EKF errors without maneuver."""
    return figure_errors(runs[("ekf", False)], "Fig 2 — EKF, no orbit maneuver: position (m) and velocity (m/s) errors")


def fig3(runs):
    """Fig 3: robust H∞ filter (published matrices) errors without maneuver."""
    return figure_errors(runs[("hinf_published", False)], "Fig 3 — robust H∞ filter (published), no orbit maneuver")


def fig4(runs):
    """Fig 4: EKF errors with maneuver; the paper's variant (control law unknown)
    in colour, the variant that knows the thrust in grey."""
    res = runs[("ekf", True)]
    fig = figure_errors(res, "Fig 4 — EKF with orbit maneuver: control law unknown (colour) vs known thrust (grey)")
    known = runs[("ekf_known_input", True)]
    for i, ax in enumerate(fig.axes[:6]):
        ax.plot(known.t, known.error[0, :, i], color="0.45", lw=0.6, zorder=3)
        ax.axvline(500.0, color="k", ls=":", lw=0.8)
    return fig


def fig5(runs):
    """Fig 5: robust H∞ filter (published matrices) errors with maneuver."""
    return figure_errors(runs[("hinf_published", True)], "Fig 5 — robust H∞ filter (published), with orbit maneuver")


def fig6(runs):
    """Fig 6: the chaser's thrust u = K x with maneuver."""
    fig, axes = new_figure(1, 1, figsize=(7, 3.6))
    plot_thrust(runs[("hinf_published", True)], ax=axes[0, 0])
    axes[0, 0].set_title("Fig 6 — orbit thrust of the chaser, u = K x")
    return fig


def fig7_result(scenario=None, *, seed=0, delta=1.0, noise="mixture"):
    """The run behind Fig 7: published H∞ filter, δ = 1, non-Gaussian noise, with maneuver."""
    scenario = Scenario() if scenario is None else scenario
    return simulate(scenario, "published", maneuver=True, delta=delta, noise=noise, runs=1, seed=seed)


def fig7(result):
    """Fig 7: robust H∞ filter with δ = 1 and non-Gaussian (Gaussian-mixture) noise."""
    d = result.settings["delta"]
    return figure_errors(result, f"Fig 7 — robust H∞ filter (published), δ = {d:g}, {result.settings['noise']} noise, with maneuver")


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
    for f, d, n in tqdm(combos, disable=not progress, desc="robustness", unit="case"):
        res = simulate(scenario, f, maneuver=maneuver, delta=d, noise=n, runs=runs, seed=seed)
        per = rms_per_run(res.error, res.t, scenario.rms_window_s)
        pooled = np.sqrt(np.mean(per**2, axis=0))
        rows.append({"filter": f, "delta": float(d), "noise": n, "runs": runs,
                     "pos_m": axes_rms(pooled[:3]), "vel_mps": axes_rms(pooled[3:])})
    return rows


def format_robustness_table(rows):
    """The rows of :func:`robustness_table` as aligned text."""
    lines = [f"{'filter':18}{'delta':>7}  {'noise':11}{'pos (m)':>10}{'vel (m/s)':>11}"]
    for r in rows:
        lines.append(f"{r['filter']:18}{r['delta']:7g}  {r['noise']:11}{r['pos_m']:10.4f}{r['vel_mps']:11.4f}")
    return "\n".join(lines)


# ---------------------------------------------------------------- everything


def _save(fig, out_dir, name):
    paths = []
    for ext in ("png", "pdf"):
        p = Path(out_dir) / f"{name}.{ext}"
        fig.savefig(p, dpi=130)
        paths.append(p)
    return paths


def _summary(tab, designed, observer, fig7_res, scenario):
    t1 = {}
    for case in CASES:
        t1[case] = {}
        for key, c in tab.cells[case].items():
            t1[case][key] = c
    kp, kv = _kl_axes(tab.kalman_limit["no_maneuver"])
    kpp, kvp = _kl_axes(tab.kalman_limit["no_maneuver"], predicted=True)
    win = scenario.rms_window_s
    per = rms_per_run(fig7_res.error, fig7_res.t, win)[0]
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
                 "pos_axes_m": [float(v) for v in per[:3]], "vel_axes_mps": [float(v) for v in per[3:]]},
        "designed_filter": {"delta_bar": 0.05, "gamma": float(designed.gamma), "lmi_gamma": float(designed.lmi_gamma)},
        "observer_filter": {"delta_bar": 0.05, "gamma": float(observer.gamma), "lmi_gamma": float(observer.lmi_gamma),
                            "note": "extension: LMI (20) with C_F = -L and A_F = A + B_F C (observer form)"},
    }


def _to_json(obj):
    if isinstance(obj, dict):
        return {str(k): _to_json(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_to_json(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _to_json(obj.tolist())
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    return obj


def execute_notebooks(out_dir, timeout=900):
    """Execute every ``notebooks/NN_*.ipynb`` of the repository into ``out_dir``."""
    import nbformat
    from nbclient import NotebookClient

    nb_dir = Path(__file__).resolve().parents[1] / "notebooks"
    if not nb_dir.is_dir():
        raise InputError(f"--notebooks needs the repository's notebooks/ folder next to the package; not found at {nb_dir}")
    written = []
    for path in tqdm(sorted(nb_dir.glob("[0-9][0-9]_*.ipynb")), desc="notebooks", unit="nb"):
        nb = nbformat.read(path, as_version=4)
        NotebookClient(nb, timeout=timeout, kernel_name="python3", resources={"metadata": {"path": str(nb_dir)}}).execute()
        target = Path(out_dir) / path.name
        nbformat.write(nb, target)
        written.append(target)
    return written


def reproduce(out_dir="results", *, seed=0, runs=100, notebooks=False, progress=True, scenario=None):
    """Regenerate Table 1 and Figs 2–7 into ``out_dir``.

    Writes ``fig2`` … ``fig7`` (PNG and PDF), ``fig4`` with both EKF variants,
    ``table1.csv``, ``table1.md`` and ``summary.json``, prints the
    paper-vs-reproduced table, and with ``notebooks=True`` also executes the
    notebooks into ``out_dir``.

    Returns
    -------
    dict
        The summary written to ``summary.json``.
    """
    from .synthesis import design_for_scenario

    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    say = (lambda msg: tqdm.write(msg)) if progress else (lambda msg: None)
    say("designing the robust H∞ filter at δ̄ = 0.05 (Corollary 1) ...")
    designed = design_for_scenario(scenario, delta_bar=0.05)
    say(f"  certified γ = {designed.gamma:.4g} (LMI: {designed.lmi_gamma:.4g})")
    observer = design_for_scenario(scenario, delta_bar=0.05, form="observer")
    say(f"  in observer form (extension): certified γ = {observer.gamma:.4g}")
    tab = table1(scenario, runs=runs, seed=seed, designed=designed, observer=observer, progress=progress)
    write_table1(tab, out)
    runs_ = paper_runs(scenario, seed=seed)
    f7 = fig7_result(scenario, seed=seed)
    figs = {"fig2": fig2(runs_), "fig3": fig3(runs_), "fig4": fig4(runs_), "fig5": fig5(runs_), "fig6": fig6(runs_),
            "fig7": fig7(f7)}
    for name, fig in tqdm(figs.items(), disable=not progress, desc="figures", unit="fig"):
        _save(fig, out, name)
    summary = _to_json(_summary(tab, designed, observer, f7, scenario))
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    if notebooks:
        execute_notebooks(out)
    if progress:
        print()
        print("Table 1, paper vs reproduced (" + tab.settings["error_measure"] + ")")
        print(format_table1(tab))
        print(f"\nwrote {out.resolve()} in {time.perf_counter() - t0:.0f} s")
    return summary
