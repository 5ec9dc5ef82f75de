"""``python -m hinfnav reproduce --paper benchmark``: the cross-paper table on Sun 2011's chaser, as a Dask campaign."""

from pathlib import Path

from ...campaign.runner import run_campaign
from ...core.exceptions import InputError
from ...core.validation import as_int_at_least
from ..skeleton import Reproduction, atomic_write_text
from .grid import DELTAS, NOISES, TOL, WINDOWS, benchmark_campaign, fit_matrix, load_papers
from .table import benchmark_table, best_by_condition, format_markdown, plot_heatmap

__all__ = ["NOTEBOOKS", "reproduce"]

#: The comparison chapter of the workbook (``reproduce(notebooks=True)``).
NOTEBOOKS = ("90_cross_paper_benchmark.ipynb",)

#: Fewer runs than this is a quick look, not the benchmark (said in the summary).
BENCHMARK_RUNS = 200


def _note(runs):
    parts = [f"{runs} Monte Carlo runs per cell (seeds from the cell, common to every estimator of a cell)."]
    if runs < BENCHMARK_RUNS:
        parts.append(f"**Quick look**: the benchmark proper has at least {BENCHMARK_RUNS} runs per cell.")
    return " ".join(parts)


def reproduce(out_dir="results/benchmark", *, seed=0, runs=BENCHMARK_RUNS, notebooks=False, progress=True,
              client=None, campaign_dir=None, estimators=None):
    """Run the cross-paper benchmark and write its table, heat map and summary into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
    seed : int
    runs : int
        Monte Carlo runs per cell (the benchmark: ≥ 200).
    notebooks : bool
        Also execute :data:`NOTEBOOKS` into ``out_dir``.
    progress : bool
    client : None, "serial", str or distributed.Client
        Where the campaign runs (:func:`hinfnav.run_campaign`); default a LocalCluster on this machine's cores.
    campaign_dir : str or Path, optional
        Keep the campaign's cells there (resumable across calls); default ``out_dir/campaign``.
    estimators : sequence of str, optional
        Default: every registered estimator that fits the chaser.

    Returns
    -------
    dict
        The summary written to ``summary.json``: ``cells`` (one object per cell with its parameters and
        statistics), ``estimators`` (the list run), ``kalman_limits``, ``best``, ``fit_matrix``,
        ``papers`` (which imported), ``elapsed_s`` and ``provenance``.
    """
    runs = as_int_at_least("runs", runs, 1)
    rep = Reproduction(out_dir, "benchmark", notebooks=NOTEBOOKS if notebooks else (),
                       progress=progress, seed=seed, runs=runs)
    out = rep.out
    papers = load_papers()
    for key, err in papers.items():
        if err is not None:
            rep.say(f"paper {key} could not be imported, its estimators are left out: {err}")
    campaign = benchmark_campaign(runs=runs, seed=seed, estimators=estimators)
    cdir = Path(campaign_dir) if campaign_dir is not None else out / "campaign"
    results = run_campaign(campaign, client=client, out_dir=cdir / campaign.name, progress=progress)
    errors = dict(results.attrs["errors"])
    table = benchmark_table(results)
    names = list(dict.fromkeys(table["estimator"]))
    note = _note(runs)
    atomic_write_text(out / "table.csv", table.to_csv(index=False), newline="")
    atomic_write_text(out / "table.md", format_markdown(table, note=note))
    rep.save_figure(plot_heatmap(table), "heatmap")
    cells = [{**c["params"], "cell_id": c["cell_id"], "seed": c["seed"], "runs": c["runs"], "status": c["status"],
              "statistics": c["statistics"], "timing": c["timing"]} for c in results.attrs["cells"]]
    ratios = table.to_dict(orient="records")
    limits = {f"maneuver={m} delta={d:g}": {"pos_m": p, "vel_mps": v, "pos_m_predicted": pp, "vel_mps_predicted": vp}
              for m, d, p, v, pp, vp in table[["maneuver", "delta", "kalman_pos_m", "kalman_vel_mps",
                                               "kalman_pos_m_predicted", "kalman_vel_mps_predicted"]]
              .drop_duplicates(["maneuver", "delta"]).itertuples(index=False)}
    elapsed = rep.elapsed_s
    summary = {
        "title": "Cross-paper benchmark on Sun et al. (2011)'s chaser (issue 13)",
        "note": note,
        "grid": {"maneuver": [True, False], "delta": list(DELTAS), "noise": list(NOISES), "windows_s": WINDOWS,
                 "tol": list(TOL)},
        "estimators": names,
        "cells": cells,
        "table": ratios,
        "kalman_limits": limits,
        "best": best_by_condition(table),
        "fit_matrix": fit_matrix(papers),
        "papers": papers,
        "errors": errors,
        "cpu_s": sum(c["timing"]["estimator_cpu_s"] + c["timing"]["truth_cpu_s"] / c["timing"]["unit_cells"]
                     for c in cells),
        "elapsed_s": elapsed,
    }
    summary = rep.write_summary(summary)
    if errors:
        raise InputError(f"{len(errors)} benchmark cells failed: " + "; ".join(f"{k}: {v}" for k, v in errors.items()))
    if notebooks:
        rep.run_notebooks()
    if progress:
        print(f"\nbenchmark: {len(cells)} cells, {len(names)} estimators, {elapsed:.0f} s; table in {out / 'table.md'}")
    return summary
