"""The cross-paper table: per scenario, every fitting estimator's RMS as a ratio to the cell's bound.

:func:`cross_table` turns one scenario's campaign results and its bounds
(:func:`~.limits.cell_bound`) into one row per (cell, quantity): RMS pooled
over runs, samples and the group's components in the ``steady`` window, its
95 % interval (the campaign's, :func:`hinfnav.campaign.stats.rms_interval`),
the bound, the ratio RMS/bound with the interval divided by the same bound,
and the cell's NEES and NIS (:mod:`hinfnav.metrics.consistency`).
:func:`winners` says which estimator wins where, :func:`format_cross_markdown`
writes both as Markdown; :func:`plot_scenario_heatmap` draws one scenario's ratios.
"""

import numpy as np
import pandas as pd

from ...core.exceptions import InputError
from ...plotting.errors import new_figure

__all__ = ["cross_table", "winners", "format_cross_markdown", "plot_scenario_heatmap", "condition_label", "WINDOW"]

#: The table's window (every scenario of :data:`~.grid.SCENARIOS` has one of this name).
WINDOW = "steady"


def condition_label(conditions, noise):
    """``"maneuver=True delta=0 gaussian"``: a cell's conditions and settings, then its noise."""
    return " ".join([f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in conditions.items()] + [noise])


def cross_table(cells, scenario_name, quantities, bound_of, window=WINDOW):
    """One row per (cell, quantity) of one scenario's campaign.

    Parameters
    ----------
    cells : sequence of dict
        The campaign's cell results (``table.attrs["cells"]`` of :func:`hinfnav.run_campaign`).
    scenario_name : str
    quantities : sequence of str
        State groups of the table.
    bound_of : callable
        ``bound_of(conditions, noise) -> dict`` as :func:`~.limits.cell_bound` returns.
    window : str

    Returns
    -------
    pandas.DataFrame
        Columns ``scenario``, ``estimator``, ``condition``, ``conditions`` (dict), ``noise``, ``quantity``,
        ``unit``, ``rms``, ``rms_low``, ``rms_high``, ``bound``, ``bound_kind``, ``ratio``, ``ratio_low``,
        ``ratio_high``, ``nees``, ``nees_low``, ``nees_high`` (its 95 % χ² band), ``nis``, ``status``, ``runs``.
    """
    rows = []
    for c in cells:
        params = dict(c["params"])
        est, noise = params.pop("estimator"), params.pop("noise")
        params.pop("scenario", None)
        stats = c["statistics"]
        bound = bound_of(params, noise)
        groups = stats["windows"][window]["groups"]
        cons = stats["consistency"]
        cw = cons["windows"].get(window, {})
        nees_band = cons.get("nees_bounds") or (np.nan, np.nan)  # an estimator without covariance has none
        for q in quantities:
            if q not in groups:
                raise InputError(f"quantities: the state of {scenario_name!r} has no group {q!r}")
            g = groups[q]
            b = bound["windows"][window][q]
            rows.append({"scenario": scenario_name, "estimator": est, "condition": condition_label(params, noise),
                         "conditions": params, "noise": noise, "quantity": q, "unit": stats["groups"][q]["unit"],
                         "rms": g["pooled"], "rms_low": g["rms_ci95_low"], "rms_high": g["rms_ci95_high"],
                         "bound": b, "bound_kind": bound["kind"], "ratio": g["pooled"] / b,
                         "ratio_low": g["rms_ci95_low"] / b, "ratio_high": g["rms_ci95_high"] / b,
                         "nees": cw.get("nees", np.nan), "nees_low": nees_band[0],
                         "nees_high": nees_band[1], "nis": cw.get("nis", np.nan), "status": c["status"],
                         "runs": c["runs"]})
    return pd.DataFrame(rows)


def winners(table):
    """Which estimator wins where: per (scenario, condition, quantity) the smallest finite ratio.

    Returns
    -------
    list of dict
        ``scenario``, ``condition``, ``quantity``, ``best``, ``ratio``, ``ratio_low``, ``ratio_high``,
        ``runner_up``, ``runner_up_ratio`` and ``separated`` (the two 95 % intervals do not overlap).
    """
    out = []
    for (sc, cond, q), cell in table.groupby(["scenario", "condition", "quantity"], sort=False):
        ok = cell[np.isfinite(cell["ratio"]) & (cell["status"] == "ok")].sort_values("ratio")
        if ok.empty:
            continue
        best = ok.iloc[0]
        entry = {"scenario": sc, "condition": cond, "quantity": q, "best": best["estimator"],
                 "ratio": float(best["ratio"]), "ratio_low": float(best["ratio_low"]),
                 "ratio_high": float(best["ratio_high"]), "runner_up": None, "runner_up_ratio": np.nan,
                 "separated": None}
        if len(ok) > 1:
            second = ok.iloc[1]
            entry.update(runner_up=second["estimator"], runner_up_ratio=float(second["ratio"]),
                         separated=bool(best["ratio_high"] < second["ratio_low"]))
        out.append(entry)
    return out


def plot_scenario_heatmap(scenario, table, *, axes=None):
    """Heat map of log₁₀(RMS/bound) of one scenario: estimators × conditions, one panel per quantity.

    Returns
    -------
    matplotlib.figure.Figure
    """
    sub = table[table["scenario"] == scenario]
    if sub.empty:
        raise InputError(f"scenario: the table has no row of {scenario!r}")
    quantities = list(dict.fromkeys(sub["quantity"]))
    estimators = list(dict.fromkeys(sub["estimator"]))
    conds = list(dict.fromkeys(sub["condition"]))
    if axes is None:
        _, axes = new_figure(len(quantities), 1, figsize=(2.5 + 0.9 * len(conds), 1.0 + 0.35 * len(estimators) * len(quantities)))
    axes = np.ravel(axes)
    for ax, q in zip(axes, quantities):
        piv = sub[sub["quantity"] == q].pivot_table(index="estimator", columns="condition", values="ratio",
                                                    sort=False).reindex(index=estimators, columns=conds)
        img = ax.imshow(np.log10(piv.to_numpy(dtype=float)), aspect="auto", cmap="viridis", interpolation="nearest")
        ax.set_yticks(range(len(estimators)), estimators, fontsize=7)
        ax.set_xticks(range(len(conds)), conds, rotation=30, ha="right", fontsize=7)
        kind = sub["bound_kind"].iloc[0]
        ax.set_title(f"{scenario}: {q} RMS / {'Riccati limit' if kind == 'riccati' else 'posterior CRB'}", fontsize=9)
        ax.figure.colorbar(img, ax=ax, label="log₁₀ ratio (–)")
    return axes[0].figure


def format_cross_markdown(table, best, note):
    """``table.md`` of the benchmark: per scenario and quantity, estimators × conditions, ratio [95 % interval];
    then :func:`winners`' ``best`` (which estimator wins where). ``note`` goes under the title."""
    lines = ["# Cross-paper benchmark", "", note, "",
             "Each entry: RMS error (pooled over runs, samples of the steady window and the group's components) "
             "divided by the cell's bound — the Riccati limit of a linear-Gaussian cell, the posterior Cramér–Rao "
             "bound of the others — with its 95 % interval. 1: at the bound. NEES, NIS and absolute errors are in "
             "`table.csv` and `summary.json`.", ""]
    for sc, sub in table.groupby("scenario", sort=False):
        for q, part in sub.groupby("quantity", sort=False):
            conds = list(dict.fromkeys(part["condition"]))
            lines += [f"## {sc}: {q} ({part['unit'].iloc[0]}), bound: {part['bound_kind'].iloc[0]}", "",
                      "| estimator | " + " | ".join(conds) + " |", "|---|" + "---|" * len(conds)]
            for est, rows in part.groupby("estimator", sort=False):
                by = {r.condition: r for r in rows.itertuples()}
                cells = [f"{by[c].ratio:.3g} [{by[c].ratio_low:.3g}, {by[c].ratio_high:.3g}]" if c in by else "—"
                         for c in conds]
                lines.append(f"| `{est}` | " + " | ".join(cells) + " |")
            lines.append("")
    lines += ["## Which estimator wins where", "", "| scenario | condition | quantity | best (ratio) | runner-up (ratio) "
              "| intervals separate |", "|---|---|---|---|---|---|"]
    for b in best:
        lines.append(f"| {b['scenario']} | {b['condition']} | {b['quantity']} | `{b['best']}` ({b['ratio']:.3g}) | "
                     f"`{b['runner_up']}` ({b['runner_up_ratio']:.3g}) | {b['separated']} |")
    return "\n".join(lines) + "\n"
