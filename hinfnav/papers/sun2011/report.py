"""``python -m hinfnav simulate`` for Sun et al. (2011)'s scenario: one filter, Monte Carlo, one report.

The report keeps running statistics only (:func:`hinfnav.metrics.monte_carlo_statistics`):
its memory does not grow with the number of runs. Its ``cell_*`` fields are
Table 1's statistic (RMS over x, y, z of each run's per-axis RMS: run 0, and
the mean over runs with its 95 % interval), so each Table 1 row is reproduced
by the command it names.
"""

import numpy as np

from ...core.exceptions import InputError
from ...io.provenance import provenance
from ...core.validation import as_int_at_least
from ...metrics.intervals import mean_interval
from ...metrics.streaming import monte_carlo_statistics
from .designs import load_design
from ...estimators.registry import build_estimator
from .filters import FILTER_NAMES, make_estimator
from .scenario import Scenario

__all__ = ["MAX_RUNS", "simulate_report", "format_simulate_report"]

#: Largest ``--runs`` accepted (memory is bounded; this bounds the time: ~4 ms a run for an LTI filter).
MAX_RUNS = 1_000_000


def _axes_rms(values):
    return np.sqrt(np.mean(np.square(values), axis=-1))


def simulate_report(filter="published", *, maneuver=True, delta=0.0, noise="gaussian", seed=0, runs=1,
                    discretization="exact", scenario=None, progress=False, design=None, verbatim=False):
    """Simulate the paper's scenario with one filter and summarize the errors.

    Parameters
    ----------
    filter : str
        A registered filter name (ignored when ``design`` is given).
    maneuver, delta, noise, seed, runs, discretization
        As in :func:`hinfnav.simulate`.
    scenario : Scenario, optional
    progress : bool
    design : str or path-like or DesignResult, optional
        A design file (``design --save``) or object to run instead of ``filter``;
        a file made for another system (another T …) is refused.
    verbatim : bool
        With ``design``: run (12) exactly, assuming u = K x (default: told the thrust).

    Returns
    -------
    dict
        JSON-ready: ``filter``, ``maneuver``, ``delta``, ``noise``, ``runs``,
        ``seed``, ``window_s``, ``rms_pos_m`` (x, y, z), ``rms_vel_mps``
        (x, y, z), ``max_pos_m``, ``max_vel_mps``, over runs ``mc_mean_pos_m``
        etc. (per-run RMS averaged, with a 95 % interval), Table 1's
        ``cell_pos_m``/``cell_vel_mps`` (run 0) and ``cell_mc_mean_*`` with
        ``cell_mc_ci95_*``; the consistency over ``window_s``
        (:mod:`hinfnav.metrics.consistency`): ``nees`` and ``nis`` (window
        mean of the run-averaged NEES/NIS, null for a filter without a
        covariance / without S, ``consistency_notes`` says why), their 95 %
        χ² bounds ``nees_bounds``/``nis_bounds`` and the fraction of steps
        inside ``nees_inside``/``nis_inside``, ``diverged`` (with
        ``diverged_reasons``); and ``provenance``.
    """
    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    if runs > MAX_RUNS:
        raise InputError(f"runs must be at most {MAX_RUNS}; got {runs}")
    if design is not None:
        result = design if not isinstance(design, (str, bytes)) and hasattr(design, "A_F") else load_design(design, scenario=scenario)
        est = scenario.estimator_from_design(result, verbatim=verbatim, name="design")
        label = "design" + (" (verbatim)" if verbatim else "")
    else:
        if verbatim:
            raise InputError("verbatim applies to --design only (the registered names say how each filter runs)")
        est = make_estimator(scenario, filter) if filter in FILTER_NAMES else build_estimator(scenario, filter)
        label = filter
    win = scenario.rms_window_s
    stats = monte_carlo_statistics(scenario, est, windows={"main": win}, runs=runs, seed=seed, noise=noise,
                                   progress=progress, maneuver=maneuver, delta=delta, discretization=discretization)
    w, st = stats["main"], stats.state
    P, V = list(st.indices("position")), list(st.indices("velocity"))
    r = lambda a: [float(v) if np.isfinite(v) else None for v in np.asarray(a)]
    cell_p, cell_v = _axes_rms(w.per_run[:, P]), _axes_rms(w.per_run[:, V])

    def mc(vals):
        mean, low, high = mean_interval(vals)  # Student t; no interval (None, strict JSON) with one run
        return mean, r([low, high])

    (mp, cp), (mv, cv) = mc(cell_p), mc(cell_v)
    cs = stats.consistency_summary
    cw = cs["windows"]["main"]
    return {
        "filter": label,
        "maneuver": bool(maneuver),
        "delta": float(delta),
        "noise": stats.settings["noise"],
        "runs": int(runs),
        "seed": int(seed),
        "discretization": discretization,
        "dt_s": scenario.dt,
        "duration_s": scenario.duration_s,
        "window_s": list(win),
        "rms_pos_m": r(w.pooled[P]),
        "rms_vel_mps": r(w.pooled[V]),
        "max_pos_m": r(w.max_abs[P]),
        "max_vel_mps": r(w.max_abs[V]),
        "mc_mean_pos_m": r(w.mean[P]),
        "mc_mean_vel_mps": r(w.mean[V]),
        "mc_ci95_pos_m": [r(w.ci95[0, P]), r(w.ci95[1, P])],
        "mc_ci95_vel_mps": [r(w.ci95[0, V]), r(w.ci95[1, V])],
        "cell_pos_m": float(cell_p[0]),
        "cell_vel_mps": float(cell_v[0]),
        "cell_mc_mean_pos_m": mp,
        "cell_mc_ci95_pos_m": cp,
        "cell_mc_mean_vel_mps": mv,
        "cell_mc_ci95_vel_mps": cv,
        "error_measure": "per-axis RMS of x - xhat over window_s, pooled over runs; cell_*: Table 1's statistic "
                         "(RMS over x, y, z of each run's per-axis RMS; run 0, and mean over runs)",
        "nees": cw["nees"], "nees_dof": cs["nees_dof"], "nees_bounds": cs["nees_bounds"], "nees_inside": cw["nees_inside"],
        "nis": cw["nis"], "nis_dof": cs["nis_dof"], "nis_bounds": cs["nis_bounds"], "nis_inside": cw["nis_inside"],
        "diverged": cs["diverged"], "diverged_level": cs["diverged_level"], "diverged_reasons": cs["diverged_reasons"], "consistency_notes": cs["notes"],
        "provenance": provenance(seed=int(seed), runs=int(runs)),
    }


def format_simulate_report(rep):
    """A readable table of :func:`simulate_report`'s output (at most 100 columns)."""
    runs = rep["runs"]
    lines = [
        f"filter {rep['filter']}  maneuver {'yes' if rep['maneuver'] else 'no'}  delta {rep['delta']:g}  "
        f"noise {rep['noise']}  runs {runs}  seed {rep['seed']}",
        f"per-axis RMS error over t = {rep['window_s'][0]:g} .. {rep['window_s'][1]:g} s (T = {rep['dt_s']:g} s)",
        "",
        f"{'':22}{'x':>16}{'y':>16}{'z':>16}",
    ]
    for label, key in (("position (m)", "rms_pos_m"), ("velocity (m/s)", "rms_vel_mps"),
                       ("max |pos| (m)", "max_pos_m"), ("max |vel| (m/s)", "max_vel_mps")):
        lines.append(f"{label:22}" + "".join(f"{v:16.4f}" for v in rep[key]))
    if runs > 1:
        for label, key in (("position (m)", "pos_m"), ("velocity (m/s)", "vel_mps")):
            lo, hi = rep[f"mc_ci95_{key}"]
            lines.append(f"{'95% CI of mean, ' + label.split()[0][:3]:22}"
                         + "".join(f"{f'{a:.3g}–{b:.3g}':>16}" for a, b in zip(lo, hi)))
    lines.append(f"Table 1 cell: {rep['cell_pos_m']:.4g} m, {rep['cell_vel_mps']:.4g} m/s (run 0)"
                 + (f"; mean of {runs}: {rep['cell_mc_mean_pos_m']:.4g} m, {rep['cell_mc_mean_vel_mps']:.4g} m/s"
                    if runs > 1 else ""))
    for key in ("nees", "nis"):
        if rep.get(key) is not None:
            lo, hi = rep[f"{key}_bounds"]
            lines.append(f"{key.upper()} (mean over runs, dof {rep[f'{key}_dof']}): {rep[key]:.4g} over the window, "
                         f"95 % bounds {lo:.3g}..{hi:.3g}, {100 * rep[f'{key}_inside']:.0f} % of steps inside")
    for note in rep.get("consistency_notes", []):
        lines.append(f"note: {note}")
    if rep.get("diverged"):
        lines.append("DIVERGED: " + "; ".join(rep["diverged_reasons"]))
    return "\n".join(lines)
