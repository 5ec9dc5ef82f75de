"""``python -m hinfnav reproduce --paper benchmark``: every fitting estimator on every registered scenario, as Dask campaigns."""

from pathlib import Path

import time

import pandas as pd

from ...campaign.registry import build_scenario, scenario_parameters
from ...campaign.runner import campaign_client, run_campaign
from ...core.exceptions import InputError
from ...core.validation import as_int_at_least
from ...io.outputs import atomic_write_text
from ..skeleton import Reproduction
from .cross import WINDOW, cross_table, format_cross_markdown, plot_scenario_heatmap, winners
from .grid import SCENARIOS, load_papers, non_fitting, scenario_campaign
from .limits import cell_bound

__all__ = ["NOTEBOOKS", "reproduce"]

#: The comparison chapter of the workbook (``reproduce(notebooks=True)``).
NOTEBOOKS = ("90_cross_paper_benchmark.ipynb",)

#: Monte Carlo runs per cell of the benchmark (fewer: a quick look, said in the summary). 50 keeps the whole
#: benchmark within 5 minutes on 2 cores (README); the 95 % intervals of the ratios are then a few per cent wide.
BENCHMARK_RUNS = 50
#: Truth runs of the Monte Carlo mean in a posterior CRB (independent of the cells' draws).
BOUND_RUNS = 20


def reproduce(out_dir="results/benchmark", *, seed=0, runs=BENCHMARK_RUNS, notebooks=False, progress=True,
              client=None, campaign_dir=None, scenarios=None, grids=None, estimators=None, bound_runs=BOUND_RUNS,
              workers=None):
    """Run the cross-paper benchmark and write its tables, heat maps and summary into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
    seed : int
    runs : int
        Monte Carlo runs per cell.
    notebooks : bool
        Also execute :data:`NOTEBOOKS` into ``out_dir``.
    progress : bool
    client : None, "serial", str or distributed.Client
        Where the campaigns run (:func:`hinfnav.run_campaign`); default one LocalCluster for all of them.
    campaign_dir : str or Path, optional
        Keep the campaigns' cells there (resumable); default ``out_dir/campaign``.
    scenarios : sequence of str, optional
        Default: every scenario of :data:`~.grid.SCENARIOS`.
    grids : dict, optional
        Scenario → grid entries replacing the benchmark's (a smaller grid for a quick look).
    estimators : dict, optional
        Scenario → estimator names (default: every registered estimator that fits it).
    bound_runs : int
        Truth runs of each posterior CRB.
    workers : int, optional
        Worker processes of the LocalCluster (default one per core).

    Returns
    -------
    dict
        The summary written to ``summary.json``: ``scenarios``, ``estimators`` (per scenario), ``cells`` (scenario,
        estimator, conditions, noise, quantity, RMS, bound, ratio, interval, NEES…), ``non_fitting`` (scenario →
        estimator → reason), ``best`` (which estimator wins where), ``errors``, ``cpu_s`` (the cells', in the
        workers), ``main_cpu_s`` (this process: bounds, tables, figures), ``elapsed_s``, ``provenance``.
    """
    runs = as_int_at_least("runs", runs, 1)
    bound_runs = as_int_at_least("bound_runs", bound_runs, 1)
    keys = list(SCENARIOS) if scenarios is None else list(scenarios)
    for key in keys:
        if key not in SCENARIOS:
            raise InputError(f"scenarios: the benchmark has no scenario {key!r}; choose from {', '.join(SCENARIOS)}")
    rep = Reproduction(out_dir, "benchmark", notebooks=NOTEBOOKS if notebooks else (), progress=progress, seed=seed,
                       runs=runs)
    out = rep.out
    c0 = time.process_time()
    papers = load_papers()
    for key, err in papers.items():
        if err is not None:
            rep.say(f"paper {key} could not be imported, its scenario and estimators are left out: {err}")
    cdir = Path(campaign_dir) if campaign_dir is not None else out / "campaign"
    chosen = dict(estimators or {})
    tables, errors, estimators, unfit, cpu = [], {}, {}, {}, 0.0
    with campaign_client(client, workers=workers) as dask_client:
        for key in keys:
            campaign = scenario_campaign(key, runs=runs, seed=seed, grid=(grids or {}).get(key),
                                         estimators=chosen.get(key))
            settings = {k: v[0] for k, v in campaign.grid.items() if k in scenario_parameters(key)}
            estimators[key] = list(campaign.grid["estimator"])
            unfit[key] = non_fitting(key, settings)
            results = run_campaign(campaign, client=dask_client, out_dir=cdir / campaign.name, progress=progress)
            errors.update(results.attrs["errors"])
            spec = SCENARIOS[key]
            scenarios_built, bounds = {}, {}

            def bound_of(params, noise, key=key, spec=spec, scenarios_built=scenarios_built, bounds=bounds):
                sets = {k: v for k, v in params.items() if k in scenario_parameters(key)}
                conds = {k: v for k, v in params.items() if k not in sets}
                skey = repr(sorted(sets.items()))
                if skey not in scenarios_built:
                    scenarios_built[skey] = build_scenario(key, **sets)
                bkey = (skey, repr(sorted(conds.items())), noise)
                if bkey not in bounds:
                    bounds[bkey] = cell_bound(scenarios_built[skey], conds, noise, spec["windows"],
                                              spec["quantities"], runs=bound_runs, seed=seed)
                return bounds[bkey]

            cells = results.attrs["cells"]
            cpu += sum(c["timing"]["estimator_cpu_s"] + c["timing"]["truth_cpu_s"] / c["timing"]["unit_cells"]
                       for c in cells)
            tables.append(cross_table(cells, key, spec["quantities"], bound_of))
    table = pd.concat(tables, ignore_index=True)
    best = winners(table)
    note = (f"{runs} Monte Carlo runs per cell (seeds from the cell, common to every estimator of a grid point); "
            f"ratios over the `{WINDOW}` window of each scenario.")
    atomic_write_text(out / "table.csv", table.drop(columns="conditions").to_csv(index=False), newline="")
    atomic_write_text(out / "table.md", format_cross_markdown(table, best, note))
    for key in dict.fromkeys(table["scenario"]):
        rep.save_figure(plot_scenario_heatmap(key, table), f"heatmap_{key}")
    elapsed = rep.elapsed_s
    summary = {
        "title": "Cross-paper benchmark: every fitting estimator on every registered scenario (issue 18)",
        "note": note,
        "scenarios": keys,
        "grids": {k: {**SCENARIOS[k]["grid"], **(grids or {}).get(k, {})} for k in keys},
        "windows_s": {k: SCENARIOS[k]["windows"][WINDOW] for k in keys},
        "estimators": estimators,
        "cells": table.to_dict(orient="records"),
        "non_fitting": unfit,
        "best": best,
        "papers": papers,
        "errors": errors,
        "cpu_s": cpu,
        "main_cpu_s": time.process_time() - c0,
        "elapsed_s": elapsed,
    }
    summary = rep.write_summary(summary)
    if errors:
        raise InputError(f"{len(errors)} benchmark cells failed: " + "; ".join(f"{k}: {v}" for k, v in errors.items()))
    if notebooks:
        rep.run_notebooks()
    if progress:
        print(f"\nbenchmark: {len(table)} rows on {len(keys)} scenarios, {elapsed:.0f} s; the table is table.md of the output "
              "folder")
    return summary
