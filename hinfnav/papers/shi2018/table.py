"""The results table (the lost Table 2 of Shi & Wang 2018, rebuilt), from the reproduction's summary.

One row per case and filter: the paper's number where one survives, run 0
(the paper's single simulation), the Monte Carlo mean with its 95 %
interval, and the Kalman (Riccati) limit for the Gaussian case. Written as
CSV and Markdown by :func:`write_table`.
"""

import csv
import io
from pathlib import Path

from ...core.exceptions import InputError
from ...io.outputs import atomic_write_text
from ...metrics.intervals import format_interval

__all__ = ["TABLE_FILTERS", "table_rows", "format_table", "write_table"]

#: Rows of each case: (filter key in the summary, label).
TABLE_FILTERS = {
    "gaussian": (("ekf", "EKF"), ("hbf", "HBF")),
    "mixture": (("ekf", "EKF"), ("hbf", "HBF"), ("ekf_tuned", "EKF told the mixture's variance")),
    "maneuver": (("ekf", "EKF"), ("hbf", "HBF")),
}

_COLUMNS = ("case", "filter", "paper_pos_m", "paper_vel_mps", "run0_pos_m", "run0_vel_mps", "mc_mean_pos_m",
            "mc_ci95_pos_low_m", "mc_ci95_pos_high_m", "mc_mean_vel_mps", "mc_ci95_vel_low_mps",
            "mc_ci95_vel_high_mps", "kalman_limit_pos_m", "kalman_limit_vel_mps")


def table_rows(summary):
    """Rows (dicts with the CSV columns) of the results table from a reproduction summary."""
    try:
        paper = summary["paper"]
        limit = summary["kalman_limit"]
    except (KeyError, TypeError):
        raise InputError("summary must be the dict written by hinfnav.papers.shi2018.reproduce") from None
    rows = []
    for case, filters in TABLE_FILTERS.items():
        for key, label in filters:
            s = summary[case].get(key)
            if s is None:
                continue
            published = paper.get("results", {}).get(case, {}).get(key, {})
            rows.append({
                "case": case, "filter": label,
                "paper_pos_m": published.get("pos_m"), "paper_vel_mps": published.get("vel_mps"),
                "run0_pos_m": s["pos_m"], "run0_vel_mps": s["vel_mps"],
                "mc_mean_pos_m": s["mc_mean_pos_m"], "mc_ci95_pos_low_m": s["mc_ci95_pos_m"][0],
                "mc_ci95_pos_high_m": s["mc_ci95_pos_m"][1], "mc_mean_vel_mps": s["mc_mean_vel_mps"],
                "mc_ci95_vel_low_mps": s["mc_ci95_vel_mps"][0], "mc_ci95_vel_high_mps": s["mc_ci95_vel_mps"][1],
                "kalman_limit_pos_m": limit["pos_m"] if case == "gaussian" else None,
                "kalman_limit_vel_mps": limit["vel_mps"] if case == "gaussian" else None,
            })
    return rows


def _f(v, digits=3):
    return "—" if v is None else f"{v:.{digits}g}"


def format_table(summary):
    """The results table as Markdown (paper beside reproduced)."""
    lines = [
        "| case | filter | paper pos (m) | paper vel (m/s) | run 0 pos (m) | run 0 vel (m/s) | "
        "MC pos (m) [95 %] | MC vel (m/s) [95 %] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in table_rows(summary):
        lines.append(
            f"| {r['case']} | {r['filter']} | {_f(r['paper_pos_m'])} | {_f(r['paper_vel_mps'])} | "
            f"{_f(r['run0_pos_m'])} | {_f(r['run0_vel_mps'])} | "
            f"{_f(r['mc_mean_pos_m'])} [{format_interval(r['mc_ci95_pos_low_m'], r['mc_ci95_pos_high_m'], sep=', ')}] | "
            f"{_f(r['mc_mean_vel_mps'])} [{format_interval(r['mc_ci95_vel_low_mps'], r['mc_ci95_vel_high_mps'], sep=', ')}] |")
    lim = summary["kalman_limit"]
    lines.append(f"| gaussian | Kalman (Riccati) limit | | | | | {_f(lim['pos_m'])} | {_f(lim['vel_mps'])} |")
    lines.append("")
    lines.append(f"Statistic: {summary['statistic']}. Monte Carlo: {summary['settings']['runs']} runs, "
                 f"seed {summary['settings']['seed']}.")
    return "\n".join(lines) + "\n"


def write_table(summary, out_dir, name="results"):
    """Write ``<name>.csv`` and ``<name>.md`` into ``out_dir`` (each atomically); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = table_rows(summary)
    csv_path = out / f"{name}.csv"
    fh = io.StringIO(newline="")
    writer = csv.DictWriter(fh, fieldnames=_COLUMNS)
    writer.writeheader()
    for r in rows:
        writer.writerow({k: ("" if v is None else v) for k, v in r.items()})
    atomic_write_text(csv_path, fh.getvalue(), newline="")
    md_path = out / f"{name}.md"
    atomic_write_text(md_path, "# Shi & Wang (2018), results (Table 2 rebuilt)\n\n" + format_table(summary))
    return csv_path, md_path
