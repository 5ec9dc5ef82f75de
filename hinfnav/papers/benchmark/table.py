"""The cross-paper table: per cell, RMS position and velocity per window with 95 % intervals, as ratios to the Kalman limit.

:func:`benchmark_table` turns a campaign's tidy results into one row per
cell (estimator, maneuver, δ, noise); :func:`format_markdown` writes it as
Markdown (the ratios of the pooled RMS, one table per window and
maneuver, and the best estimator of each column); :func:`plot_heatmap`
draws the ratios as a heat map.
"""

import numpy as np
import pandas as pd

from ...core.exceptions import InputError
from ...plotting.errors import new_figure
from ..sun2011.scenario import Scenario
from .grid import NOISES, WINDOWS
from .limits import cell_kalman_limit

__all__ = ["benchmark_table", "format_markdown", "plot_heatmap", "best_by_condition", "QUANTITIES"]

#: Table quantity → (state group, key of the Kalman limit, unit).
QUANTITIES = {"pos": ("position", "pos_m", "m"), "vel": ("velocity", "vel_mps", "m/s")}
_KEYS = ["estimator", "maneuver", "delta", "noise"]


def benchmark_table(results, *, scenario=None):
    """One row per cell with the RMS per window, its 95 % interval, the cell's Kalman limit and the ratios.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy campaign results (:func:`hinfnav.run_campaign`), one or several campaigns concatenated.
    scenario : Scenario, optional
        Sun 2011's chaser (default: the paper's).

    Returns
    -------
    pandas.DataFrame
        Columns ``estimator``, ``maneuver``, ``delta``, ``noise``, ``runs``,
        ``status``, ``kalman_pos_m``, ``kalman_vel_mps`` (filtered limit, RMS
        over axes), ``kalman_pos_m_predicted``, ``kalman_vel_mps_predicted``,
        then for q in (pos, vel) and w in (early, steady): ``{q}_{w}`` (RMS
        over x, y, z, pooled over the runs and the window's samples; m or m/s
        — the quantity a standard deviation such as the Kalman limit predicts),
        ``{q}_{w}_ci_low``, ``{q}_{w}_ci_high`` (its 95 % interval from the
        runs' mean squares), ``{q}_{w}_ratio`` and ``{q}_{w}_ratio_low`` /
        ``_high`` (the same divided by the cell's filtered Kalman limit),
        ``{q}_{w}_mc_mean`` (the Monte Carlo mean of the per-run RMS, smaller by
        Jensen's inequality), and ``convergence_median_s``, ``convergence_fraction``.
    """
    scenario = Scenario() if scenario is None else scenario
    if results.empty:
        raise InputError("results hold no cell; run the benchmark campaign first")
    groups = results[results["kind"] == "group"]
    rows = []
    limits = {}
    for cell_id, cell in groups.groupby("cell_id", sort=False):
        first = cell.iloc[0]
        row = {k: first[k] for k in _KEYS}
        row.update(runs=int(first["runs"]), status=first["status"], cell_id=cell_id)
        key = (bool(first["maneuver"]), float(first["delta"]))
        if key not in limits:
            limits[key] = cell_kalman_limit(scenario, maneuver=key[0], delta=key[1])
        lim = limits[key]
        for name in ("pos_m", "vel_mps", "pos_m_predicted", "vel_mps_predicted"):
            row[f"kalman_{name}"] = lim[name]
        stat = {(r.window, r.quantity, r.statistic): r.value for r in cell.itertuples()}
        for q, (group, lkey, _) in QUANTITIES.items():
            for w in WINDOWS:
                mean, lo, hi, mc = (stat.get((w, group, s), np.nan)
                                    for s in ("rms_pooled", "rms_ci95_low", "rms_ci95_high", "mc_mean"))
                row[f"{q}_{w}"], row[f"{q}_{w}_ci_low"], row[f"{q}_{w}_ci_high"] = mean, lo, hi
                row[f"{q}_{w}_mc_mean"] = mc
                row[f"{q}_{w}_ratio"] = mean / lim[lkey]
                row[f"{q}_{w}_ratio_low"] = lo / lim[lkey]
                row[f"{q}_{w}_ratio_high"] = hi / lim[lkey]
        rows.append(row)
    table = pd.DataFrame(rows)
    conv = results[results["kind"] == "run"].pivot_table(index="cell_id", columns="statistic", values="value",
                                                         aggfunc="first")
    for col in ("convergence_median_s", "convergence_fraction"):
        table[col] = table["cell_id"].map(conv[col]) if col in conv else np.nan
    return table.drop(columns="cell_id")


def _sorted(conds):
    """Conditions in the benchmark's order: maneuver first, δ ascending, noises as in :data:`NOISES`."""
    order = {n: i for i, n in enumerate(NOISES)}
    key = conds.assign(_n=conds["noise"].map(lambda n: order.get(n, len(order))), _d=conds["delta"].astype(float))
    cols = (["maneuver"] if "maneuver" in conds else []) + ["_d", "_n"]
    asc = ([False] if "maneuver" in conds else []) + [True, True]
    return conds.loc[key.sort_values(cols, ascending=asc, kind="stable").index]


def _condition(row):
    return f"δ={row['delta']:g} {row['noise']}"


def best_by_condition(table, window="steady"):
    """Per (maneuver, δ, noise): the estimator with the smallest position ratio and the one with the smallest velocity ratio."""
    out = []
    for (man, delta, noise), cell in table.groupby(["maneuver", "delta", "noise"], sort=False):
        entry = {"maneuver": bool(man), "delta": float(delta), "noise": noise}
        for q in QUANTITIES:
            col = f"{q}_{window}_ratio"
            ok = cell[np.isfinite(cell[col])]
            if ok.empty:
                entry[f"best_{q}"], entry[f"best_{q}_ratio"] = None, np.nan
                continue
            best = ok.loc[ok[col].idxmin()]
            entry[f"best_{q}"], entry[f"best_{q}_ratio"] = best["estimator"], float(best[col])
        out.append(entry)
    return out


def format_markdown(table, *, note=""):
    """The table as Markdown: per window and maneuver, estimators × (δ, noise), 'position / velocity' ratios."""
    lines = ["# Cross-paper benchmark on Sun 2011's chaser", ""]
    if note:
        lines += [note, ""]
    lines += ["Each entry: RMS error over x, y, z pooled over the runs and the window, divided by the cell's "
              "steady-state Kalman (Riccati) limit (filtered, the cell's true model) — position / velocity. 1 is the best a linear "
              "filter can do on white noise; `—`: cell not run. The 95 % intervals, the absolute errors (m, m/s), "
              "the limits and the convergence times are in `table.csv`.", ""]
    conds = _sorted(table[["delta", "noise"]].drop_duplicates())
    estimators = list(dict.fromkeys(table["estimator"]))
    for w, (a, b) in WINDOWS.items():
        for man in (True, False):
            sub = table[table["maneuver"] == man]
            if sub.empty:
                continue
            lines += [f"## {'With' if man else 'Without'} maneuver, RMS over {a:g}–{b:g} s", ""]
            head = [_condition(r) for _, r in conds.iterrows()]
            lines += ["| estimator | " + " | ".join(head) + " |", "|---|" + "---|" * len(head)]
            for est in estimators:
                cells = []
                for _, c in conds.iterrows():
                    m = sub[(sub["estimator"] == est) & (sub["delta"] == c["delta"]) & (sub["noise"] == c["noise"])]
                    if m.empty:
                        cells.append("—")
                    else:
                        r = m.iloc[0]
                        cells.append(f"{r[f'pos_{w}_ratio']:.3g} / {r[f'vel_{w}_ratio']:.3g}")
                lines.append(f"| `{est}` | " + " | ".join(cells) + " |")
            lines.append("")
    lines += ["## Best estimator per cell (RMS over 100–1000 s)", "",
              "| maneuver | δ | noise | best in position (ratio) | best in velocity (ratio) |", "|---|---|---|---|---|"]
    for e in best_by_condition(table):
        lines.append(f"| {'yes' if e['maneuver'] else 'no'} | {e['delta']:g} | {e['noise']} | `{e['best_pos']}` "
                     f"({e['best_pos_ratio']:.3g}) | `{e['best_vel']}` ({e['best_vel_ratio']:.3g}) |")
    return "\n".join(lines) + "\n"


def plot_heatmap(table, *, axes=None, windows=tuple(WINDOWS)):
    """Heat map of log₁₀ of the ratios: one panel per (quantity, window), estimators × (maneuver, δ, noise).

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`benchmark_table`.
    axes : array of matplotlib.axes.Axes, optional
        ``len(QUANTITIES) * len(windows)`` axes; a new figure when not given.
    windows : sequence of str

    Returns
    -------
    matplotlib.figure.Figure
    """
    estimators = list(dict.fromkeys(table["estimator"]))
    conds = _sorted(table[["maneuver", "delta", "noise"]].drop_duplicates())
    labels = [f"{'M' if m else 'free'} δ={d:g} {n}" for m, d, n in conds.itertuples(index=False)]
    panels = [(q, w) for q in QUANTITIES for w in windows]
    if axes is None:
        fig, axes = new_figure(len(panels), 1, figsize=(1.0 + 0.42 * len(labels), 1.2 + 0.32 * len(estimators) * len(panels)))
    axes = np.ravel(axes)
    if axes.size != len(panels):
        raise InputError(f"axes must hold {len(panels)} axes (quantity × window); got {axes.size}")
    index = {(e, bool(m), float(d), n): i for i, (e, m, d, n) in
             enumerate(table[["estimator", "maneuver", "delta", "noise"]].itertuples(index=False))}
    for ax, (q, w) in zip(axes, panels):
        values = np.full((len(estimators), len(labels)), np.nan)
        col = table[f"{q}_{w}_ratio"].to_numpy()
        for i, e in enumerate(estimators):
            for j, (m, d, n) in enumerate(conds.itertuples(index=False)):
                k = index.get((e, bool(m), float(d), n))
                if k is not None:
                    values[i, j] = col[k]
        img = ax.imshow(np.log10(values), aspect="auto", cmap="viridis", interpolation="nearest")
        ax.set_yticks(range(len(estimators)), estimators, fontsize=7)
        ax.set_xticks(range(len(labels)), labels, rotation=60, ha="right", fontsize=6)
        group, _, unit = QUANTITIES[q]
        a, b = WINDOWS[w]
        ax.set_title(f"{group} RMS over {a:g}–{b:g} s / Kalman limit", fontsize=9)
        ax.figure.colorbar(img, ax=ax, label="log₁₀ ratio (–)")
    return axes[0].figure
