"""The tidy results table of a campaign: one row per cell, window, quantity and statistic.

Columns: ``cell_id``, the cell's parameters (``scenario``, ``estimator``,
``noise``, then its conditions and settings), ``runs``, ``seed``, ``status``,
``window``, ``window_start_s``, ``window_end_s``, ``quantity`` (a state
component such as ``x``, or a group such as ``position``), ``kind``
(``component``, ``group`` or ``run``), ``unit``, ``statistic`` and ``value``.

Statistics per window and quantity: ``rms_pooled`` (over all runs and
samples) with ``rms_ci95_low`` / ``rms_ci95_high`` (its 95 % interval,
:func:`hinfnav.campaign.stats.rms_interval`), ``mc_mean`` (mean over runs of each run's RMS) with ``ci95_low`` /
``ci95_high`` (its 95 % confidence interval), ``spread95_low`` /
``spread95_high`` (2.5 and 97.5 % of the runs' RMS: what one run may give),
``max_abs``. Per cell (window ``""``, quantity ``"all"``):
``convergence_median_s`` and ``convergence_fraction`` when the campaign has
tolerances, ``nonfinite_runs``, ``diverged`` (1 or 0) and ``diverged_runs``; for a gated filter
(:mod:`hinfnav.estimators.gate`) ``gate_rejected_readings``, ``gate_rejected_channels`` and
``gate_rejected_fraction`` (its rejections over every run and step of the cell).
Consistency per window (quantity ``nees`` or ``nis``, kind
``consistency``): ``mean`` (window mean of the run-averaged statistic),
``inside_fraction`` (steps inside the 95 % χ² bounds), ``bound_low``,
``bound_high``, ``dof``; NaN for a filter without a covariance / without S. A group's RMS is the root mean square of its
components' RMS (Table 1 of Sun 2011 reports position and velocity so).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import pandas as pd

__all__ = ["results_table", "STATISTICS"]

#: Statistics per window and quantity, with the key of the cell JSON they come from.
STATISTICS = (("rms_pooled", "pooled"), ("rms_ci95_low", "rms_ci95_low"), ("rms_ci95_high", "rms_ci95_high"),
              ("mc_mean", "mean"), ("ci95_low", "ci95_low"), ("ci95_high", "ci95_high"),
              ("spread95_low", "spread95_low"), ("spread95_high", "spread95_high"), ("max_abs", "max_abs"))
#: Columns that follow the parameter columns.
COLUMNS = ("runs", "seed", "status", "window", "window_start_s", "window_end_s", "quantity", "kind", "unit",
           "statistic", "value")


def _num(v):
    return float("nan") if v is None else float(v)


def _rows(cell):
    base = {"cell_id": cell["cell_id"], **cell["params"], "runs": cell["runs"], "seed": cell["seed"],
            "status": cell["status"]}
    st = cell["statistics"]
    for wname, w in st["windows"].items():
        wb = dict(base, window=wname, window_start_s=float(w["window"][0]), window_end_s=float(w["window"][1]))
        for i, (label, unit) in enumerate(zip(st["labels"], st["units"])):
            for stat, key in STATISTICS:
                yield dict(wb, quantity=label, kind="component", unit=unit, statistic=stat, value=_num(w[key][i]))
        for g, gs in w["groups"].items():
            unit = st["groups"][g]["unit"]
            for stat, key in STATISTICS:
                yield dict(wb, quantity=g, kind="group", unit=unit, statistic=stat, value=_num(gs[key]))
    rb = dict(base, window="", window_start_s=float("nan"), window_end_s=float("nan"), quantity="all", kind="run")
    conv = st.get("convergence")
    if conv is not None:
        yield dict(rb, unit="s", statistic="convergence_median_s", value=_num(conv["median_s"]))
        yield dict(rb, unit="", statistic="convergence_fraction", value=_num(conv["fraction"]))
    yield dict(rb, unit="", statistic="nonfinite_runs", value=float(st["nonfinite_runs"]))
    gate = st.get("gate")
    if gate is not None:  # a gated filter's rejections (hinfnav.estimators.gate)
        for stat in ("rejected_readings", "rejected_channels", "rejected_fraction"):
            yield dict(rb, unit="", statistic=f"gate_{stat}", value=float(gate[stat]))
    cons = st.get("consistency")
    if cons is None:  # a cell written before the consistency statistics
        return
    yield dict(rb, unit="", statistic="diverged", value=float(bool(cons["diverged"])))
    yield dict(rb, unit="", statistic="diverged_runs", value=float(cons["diverged_runs"]))
    for wname, cw in cons["windows"].items():
        wb = dict(base, window=wname, window_start_s=float(cw["window"][0]), window_end_s=float(cw["window"][1]),
                  kind="consistency", unit="")
        for key in ("nees", "nis"):
            bounds = cons[f"{key}_bounds"] or (None, None)
            for stat, value in (("mean", cw[key]), ("inside_fraction", cw[f"{key}_inside"]), ("bound_low", bounds[0]),
                                ("bound_high", bounds[1]), ("dof", cons[f"{key}_dof"])):
                yield dict(wb, quantity=key, statistic=stat, value=_num(value))


def results_table(cells: Iterable[Mapping[str, Any]]) -> pd.DataFrame:
    """The tidy :class:`pandas.DataFrame` of a list of cell results (see the module docstring)."""
    params = []
    for cell in cells:
        for key in cell["params"]:
            if key not in params:
                params.append(key)
    columns = ["cell_id"] + params + list(COLUMNS)
    rows = [r for cell in cells for r in _rows(cell)]
    return pd.DataFrame(rows, columns=columns)
