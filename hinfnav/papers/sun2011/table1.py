"""Table 1 of Sun et al. (2011), reproduced: EKF and H∞ filters with and without maneuver.

Conventions (the paper does not state them; see the notebooks for why):

* error measure: per-axis RMS of x − x̂ over ``scenario.rms_window_s``
  (100–1000 s); a table cell is the RMS over the three axes of those
  per-axis values (all three are close to each other);
* single run: run 0 of the Monte Carlo set (the paper shows one run);
* Monte Carlo: mean over runs of the per-run value, with the 95 % confidence
  interval of that mean, and the 2.5–97.5 % spread of single runs;
* noise: white Gaussian w, v (the paper's Table 1 text);
* all filters see the same truth and measurements in each case;
* the H∞ filters run exactly as (12) with maneuver (the closed loop u = Kx
  they were designed on) and are told the applied thrust without maneuver
  (see :func:`hinfnav.papers.sun2011.filters.lti_from_matrices`).
"""

import csv
import io
import json
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_seed
from ...io.outputs import atomic_write_text
from ...io.progress import bar_disabled
from ...design.result import DesignResult
from ...metrics.errors import axes_rms, rms_per_run
from ...metrics.intervals import format_interval, mean_interval
from ...sim.engine import Sink, batch_result, run_monte_carlo
from .constants import PAPER_TABLE1, published_filter
from .designs import design_for_scenario
from .filters import lti_from_matrices, make_estimator
from .limits import kalman_limit
from .scenario import Scenario

__all__ = ["TABLE_FILTERS", "filter_labels", "CASES", "Table1", "table1", "table1_rows",
           "format_table1", "write_table1", "row_command"]

#: Filters of the reproduced table: key -> (label, builder name)
TABLE_FILTERS = {
    "ekf": "EKF (paper: control law unknown)",
    "ekf_known_input": "EKF (knows the thrust)",
    "hinf_published": "H∞, published A_F, B_F, C_F",
    "hinf_designed": "H∞, designed here (δ̄ = 0.05)",
    "hinf_observer": "H∞, designed in observer form (extension)",
}

CASES = {"no_maneuver": False, "maneuver": True}


def filter_labels(delta_bar=0.05):
    """:data:`TABLE_FILTERS` with the designed filter's label at its uncertainty bound ``delta_bar``."""
    labels = dict(TABLE_FILTERS)
    labels["hinf_designed"] = f"H∞, designed here (δ̄ = {float(delta_bar):g})"
    return labels


def _estimators(scenario, designed, maneuver, observer=None):
    """The filters of the table; H∞ filters verbatim (12) with maneuver, told the thrust without."""
    pub = published_filter()
    told = not maneuver
    est = {
        "ekf": make_estimator(scenario, "ekf"),
        "ekf_known_input": make_estimator(scenario, "ekf_known_input"),
        "hinf_published": lti_from_matrices(scenario, pub.A_F, pub.B_F, pub.C_F, name="published", uses_input=told),
    }
    if designed is not None:
        est["hinf_designed"] = lti_from_matrices(scenario, designed.A_F, designed.B_F, designed.C_F, name="designed",
                                                 uses_input=told)
    if observer is not None:
        est["hinf_observer"] = lti_from_matrices(scenario, observer.A_F, observer.B_F, observer.C_F,
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


def cell_values(result, t, window):
    """Per-run position and velocity statistics of a result: ``(pos_run, vel_run, pos_axes, vel_axes)``.

    ``pos_run``/``vel_run`` (runs,): RMS over x, y, z of each run's per-axis RMS
    over ``window``; ``pos_axes``/``vel_axes`` (runs, 3): the per-axis values.
    """
    per_run = rms_per_run(result.error, t, window)  # (runs, n)
    state = result.state
    pos_axes, vel_axes = state.select(per_run, "position"), state.select(per_run, "velocity")
    return np.sqrt(np.mean(pos_axes**2, axis=1)), np.sqrt(np.mean(vel_axes**2, axis=1)), pos_axes, vel_axes


def cell_from_values(pos_run, vel_run, pos_axes0, vel_axes0):
    """One Table 1 cell from the per-run values (run 0 is the single run the paper shows)."""
    out = {
        "pos_m": float(pos_run[0]),
        "vel_mps": float(vel_run[0]),
        "pos_axes_m": [float(v) for v in pos_axes0],
        "vel_axes_mps": [float(v) for v in vel_axes0],
    }
    for key, vals in (("pos_m", pos_run), ("vel_mps", vel_run)):
        mean, low, high = mean_interval(vals)  # Student t; NaN bounds with one run
        out[f"mc_mean_{key}"] = mean
        out[f"mc_ci95_{key}"] = [low, high]
        out[f"mc_spread95_{key}"] = [float(v) for v in np.percentile(vals, [2.5, 97.5])]
    return out


#: The ``simulate --filter`` name that reproduces each row, per case (maneuver: the H∞
#: filters run verbatim as (12); no maneuver: told the applied thrust).
ROW_FILTERS = {
    "ekf": {False: "ekf", True: "ekf"},
    "ekf_known_input": {False: "ekf_known_input", True: "ekf_known_input"},
    "hinf_published": {False: "published", True: "published_closed_loop"},
    "hinf_designed": {False: "designed", True: "designed_closed_loop"},
    "hinf_observer": {False: "designed_observer", True: "designed_observer_closed_loop"},
}

#: Footnotes of the reproduced table.
FOOTNOTES = {
    ("no_maneuver", "hinf_designed"): (
        "biased: the LMI optimum is not in observer form, so the thrust correction C_F^-1 T G0 (u - K z) that "
        "tells it u = 0 is not exact and its error follows the drifting free-motion state (15 m/s); the "
        "observer-form filter below has no such bias"
    ),
}

EKF_WINDOWS = (("0-500 s", (0.0, 500.0)), ("100-500 s", (100.0, 500.0)), ("500-1000 s", (500.0, 1000.0)))


def row_command(key, maneuver, runs, seed, delta_bar=0.05):
    """The command line that reproduces a row of the table (same seed, same numbers).

    ``delta_bar`` is the uncertainty bound of the designed rows; away from the
    CLI's default 0.05 they are designed and saved first, then run with ``--design``.
    """
    name = ROW_FILTERS[key][bool(maneuver)]
    flag = "" if maneuver else " --no-maneuver"
    tail = f"{flag} --runs {runs} --seed {seed} --json"
    if key in ("hinf_designed", "hinf_observer") and float(delta_bar) != 0.05:
        form, file = (" --form observer", "observer.json") if key == "hinf_observer" else ("", "designed.json")
        verbatim = " --verbatim" if maneuver else ""
        return (f"python -m hinfnav design --delta-bar {float(delta_bar)!r}{form} --save {file} && "
                f"python -m hinfnav simulate --design {file}{verbatim}{tail}")
    return f"python -m hinfnav simulate --filter {name}{tail}"


class _CellSink(Sink):
    """What :func:`table1` keeps of each batch of the Monte Carlo engine: the per-run :func:`cell_values` of each
    filter over ``window`` (and of the EKF over each of ``ekf_windows``); ``bar`` counts filter batches."""

    def __init__(self, keys, xhat0, window, ekf_windows, bar):
        self.xhat0, self.window, self.ekf_windows, self.bar = xhat0, window, tuple(ekf_windows), bar
        self.values = {(key, w): [] for key in keys for w in ["main"] + [label for label, _ in EKF_WINDOWS]}

    def add(self, name, start, truth, history):
        res = batch_result(name, truth, history, self.xhat0)
        self.values[name, "main"].append(cell_values(res, truth.t, self.window))
        if name == "ekf":
            for label, w in self.ekf_windows:
                self.values[name, label].append(cell_values(res, truth.t, w))
        self.bar.update(1)

    def result(self):
        return self.values


def table1(scenario=None, *, runs=100, seed=0, designed=None, observer=None, progress=False, batch_size=100,
           delta_bar=None):
    """Compute the reproduced Table 1.

    Parameters
    ----------
    scenario : Scenario, optional
        Defaults to the paper's.
    runs : int
        Monte Carlo runs per case (≥ 1; 100 or more for the interval).
    seed : int
    designed : DesignResult, optional
        The filter from :func:`hinfnav.synthesize` (Corollary 1); designed here
        at ``delta_bar`` when None (about a second).
    observer : DesignResult, optional
        The filter designed in observer form (an extension of the paper);
        designed here at ``delta_bar`` when None.
    progress : bool
    batch_size : int
        Runs simulated together; memory is that of one batch (about 50 MB per
        100 runs), whatever ``runs``; the numbers do not depend on it.
    delta_bar : float, optional
        Uncertainty bound δ̄ of (5) of the filters designed here; default
        ``scenario.delta_bar`` (0.05, the published filter's). The labels and
        commands of the designed rows follow the δ̄ of the filters used.

    Returns
    -------
    Table1
        Each filter cell also holds ``cli``, the command that reproduces it.
    """
    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    batch_size = as_int_at_least("batch_size", batch_size, 1)
    as_seed("seed", seed)
    delta_bar = scenario.delta_bar if delta_bar is None else delta_bar  # checked by design_for_scenario
    for key, f in (("designed", designed), ("observer", observer)):
        if f is not None and not isinstance(f, DesignResult):
            raise InputError(f"{key} must be a hinfnav DesignResult (from design_for_scenario); got {type(f).__name__}")
    if designed is None:
        designed = design_for_scenario(scenario, delta_bar=delta_bar)
    if observer is None:
        observer = design_for_scenario(scenario, delta_bar=delta_bar, form="observer")
    bounds = {k: float(delta_bar if getattr(f, "uncertainty_bound", None) is None else f.uncertainty_bound)
              for k, f in (("hinf_designed", designed), ("hinf_observer", observer))}
    win = scenario.rms_window_s
    cells, ekf_windows, klim = {}, {}, {}
    keys = list(_estimators(scenario, designed, True, observer))
    total = len(CASES) * len(keys) * -(-runs // batch_size)
    with tqdm(total=total, disable=bar_disabled(progress), desc="Table 1", unit="filter") as bar:
        for case, maneuver in CASES.items():
            ests = _estimators(scenario, designed, maneuver, observer)
            sink = _CellSink(keys, scenario.xhat0, win, EKF_WINDOWS if case == "maneuver" else (), bar)
            values = run_monte_carlo(scenario, ests, sink=sink, runs=runs, seed=seed, batch_size=batch_size,
                                     keep_covariance=False, maneuver=maneuver)
            cells[case] = {}
            for (key, w), parts in values.items():
                if not parts:
                    continue
                joined = [np.concatenate([p[i] for p in parts]) for i in range(4)]
                cell = cell_from_values(joined[0], joined[1], joined[2][0], joined[3][0])
                if w == "main":
                    cell["cli"] = row_command(key, maneuver, runs, seed, bounds.get(key, 0.05))
                    if (case, key) in FOOTNOTES:
                        cell["note"] = FOOTNOTES[case, key]
                    cells[case][key] = cell
                else:
                    ekf_windows[w] = cell
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
        "designed_delta_bar": bounds["hinf_designed"],
        "observer_delta_bar": bounds["hinf_observer"],
    }
    return Table1(cells=cells, ekf_windows=ekf_windows, kalman_limit=klim, settings=settings)


def _kl_axes(kl, predicted=False):
    """(pos_m, vel_mps) scalars (RMS over axes) of a kalman_limit record (filtered or predicted)."""
    suffix = "_predicted" if predicted else ""
    return axes_rms(kl["pos_m" + suffix]), axes_rms(kl["vel_mps" + suffix])


#: Short filter labels for the terminal table (at most 100 columns).
SHORT_LABELS = {
    "paper_ekf": "paper: EKF",
    "paper_hinf": "paper: H∞",
    "ekf": "EKF, u unknown (paper)",
    "ekf_known_input": "EKF, knows u",
    "hinf_published": "H∞ published",
    "hinf_designed": "H∞ designed here",
    "hinf_observer": "H∞ observer form",
    "kalman": "Kalman limit, filtered",
    "kalman_predicted": "Kalman limit, predicted",
}


def table1_rows(tab):
    """Rows (list of dicts) of the reproduced table, paper values beside them.

    Each row has ``case``, ``key``, ``filter`` (label), ``pos_m``, ``vel_mps``
    (single run), and where they apply the Monte Carlo means and intervals,
    ``cli`` (the command that reproduces the row) and ``note`` (a footnote).
    """
    rows = []
    for case in CASES:
        labels = filter_labels(tab.settings.get("designed_delta_bar", 0.05))
        for key, label in [("paper_ekf", "paper: EKF"), ("paper_hinf", "paper: H∞")] + list(labels.items()):
            c = tab.cells[case].get(key)
            if c is None:
                continue
            row = {"case": case.replace("_", " "), "key": key, "filter": label, "pos_m": c["pos_m"],
                   "vel_mps": c["vel_mps"]}
            if "mc_mean_pos_m" in c:
                row.update(
                    mc_pos_m=c["mc_mean_pos_m"], mc_pos_ci95=c["mc_ci95_pos_m"],
                    mc_vel_mps=c["mc_mean_vel_mps"], mc_vel_ci95=c["mc_ci95_vel_mps"],
                )
            for extra in ("cli", "note"):
                if extra in c:
                    row[extra] = c[extra]
            rows.append(row)
        for predicted, key, label in ((False, "kalman", "Kalman limit, filtered (uses y(k))"),
                                      (True, "kalman_predicted", "Kalman limit, predicted (y up to k-1, like (12))")):
            kp, kv = _kl_axes(tab.kalman_limit[case], predicted)
            rows.append({"case": case.replace("_", " "), "key": key, "filter": label, "pos_m": kp, "vel_mps": kv})
    return rows


def _fmt(v, digits=3):
    if v is None:
        return "—"
    if isinstance(v, (list, tuple)):
        return f"[{format_interval(v[0], v[1], f'.{digits}g', ', ')}]"
    return f"{v:.{digits}g}"


def _pm(mean, ci):
    if not np.all(np.isfinite(ci)):
        return f"{mean:.3g} ± {format_interval(*ci)}"
    return f"{mean:.3g} ± {0.5 * (ci[1] - ci[0]):.1g}"


def format_table1(tab, markdown=False):
    """Paper-vs-reproduced Table 1 as text (plain, at most 100 columns, or Markdown with the commands)."""
    rows = table1_rows(tab)
    runs = tab.settings.get("runs")
    notes = [r for r in rows if "note" in r]
    mark = lambda r: f" [{notes.index(r) + 1}]" if r in notes else ""
    if markdown:
        head = ["case", "filter", "pos (m), 1 run", "vel (m/s), 1 run", f"pos (m), mean of {runs} [95% CI]",
                f"vel (m/s), mean of {runs} [95% CI]", "reproduce with"]
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for r in rows:
            mc_p = f"{_fmt(r['mc_pos_m'])} {_fmt(r['mc_pos_ci95'])}" if "mc_pos_m" in r else ""
            mc_v = f"{_fmt(r['mc_vel_mps'])} {_fmt(r['mc_vel_ci95'])}" if "mc_vel_mps" in r else ""
            cli = f"`{r['cli']}`" if "cli" in r else ""
            lines.append("| " + " | ".join([r["case"], r["filter"] + mark(r), _fmt(r["pos_m"]), _fmt(r["vel_mps"]),
                                            mc_p, mc_v, cli]) + " |")
        lines += [""] + [f"[{i + 1}] {r['filter']}, {r['case']}: {r['note']}." for i, r in enumerate(notes)]
        return "\n".join(lines)
    head = ["case", "filter", "pos m", "vel m/s", f"pos m, {runs} runs", f"vel m/s, {runs} runs"]
    body = []
    for r in rows:
        mc_p = _pm(r["mc_pos_m"], r["mc_pos_ci95"]) if "mc_pos_m" in r else ""
        mc_v = _pm(r["mc_vel_mps"], r["mc_vel_ci95"]) if "mc_vel_mps" in r else ""
        body.append([r["case"], SHORT_LABELS[r["key"]] + mark(r), _fmt(r["pos_m"]), _fmt(r["vel_mps"]), mc_p, mc_v])
    widths = [max(len(str(x)) for x in col) for col in zip(head, *body)]
    fmt = lambda cells: "  ".join(str(c).ljust(w) for c, w in zip(cells, widths)).rstrip()
    out = [fmt(head), fmt(["-" * w for w in widths])] + [fmt(b) for b in body]
    out += [f"[{i + 1}] {r['note']}" for i, r in enumerate(notes)]
    return "\n".join(_wrap(line, 100) for line in out)


def _wrap(line, width):
    if len(line) <= width:
        return line
    return "\n".join(textwrap.wrap(line, width, subsequent_indent="    "))


def write_table1(tab, out_dir, provenance=None):
    """Write ``table1.csv`` and ``table1.md`` into ``out_dir`` (each atomically); return their paths.

    The CSV starts with ``#`` comment lines holding the provenance (read it
    with ``pandas.read_csv(path, comment="#")``); the Markdown ends with it.
    """
    out_dir = Path(out_dir)
    rows = table1_rows(tab)
    prov = provenance or {}
    csv_path = out_dir / "table1.csv"
    fh = io.StringIO(newline="")
    for k, v in prov.items():
        fh.write(f"# {k}: {json.dumps(v)}\n")
    w = csv.writer(fh)
    w.writerow(["case", "filter", "pos_m_single_run", "vel_mps_single_run", "pos_m_mc_mean", "pos_m_mc_ci95_lo",
                "pos_m_mc_ci95_hi", "vel_mps_mc_mean", "vel_mps_mc_ci95_lo", "vel_mps_mc_ci95_hi", "cli", "note"])
    for r in rows:
        mc = [r.get("mc_pos_m"), *(r.get("mc_pos_ci95") or [None, None]), r.get("mc_vel_mps"),
              *(r.get("mc_vel_ci95") or [None, None])]
        w.writerow([r["case"], r["filter"], r["pos_m"], r["vel_mps"], *mc, r.get("cli", ""), r.get("note", "")])
    atomic_write_text(csv_path, fh.getvalue(), newline="")
    md_path = out_dir / "table1.md"
    atomic_write_text(
        md_path,
        "# Table 1: relative navigation accuracy, paper vs reproduced\n\n"
        + format_table1(tab, markdown=True)
        + "\n\nError measure: " + tab.settings["error_measure"] + ".\n"
        + f"Window {tab.settings['window_s'][0]:g}-{tab.settings['window_s'][1]:g} s, T = {tab.settings['dt_s']:g} s, "
        + f"{tab.settings['runs']} Monte Carlo runs, seed {tab.settings['seed']}.\n"
        + ("\nProvenance: " + json.dumps(prov) + "\n" if prov else "")
    )
    return csv_path, md_path
