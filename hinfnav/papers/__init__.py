"""Papers layer: one sub-package per reproduced paper.

Each paper folder holds its constants, scenario, registered estimators,
designs, studies, tables, figures and its ``reproduce``. Importing this
package registers every paper's estimators.

=========  ====================================================================
key        paper
=========  ====================================================================
sun2011       Sun, Deng, Liu, Zhong, robust H∞ filtering for a chaser satellite,
              Journal of Astronautics 32(7), 2011 (the workbook's base)
shi2018       Shi & Wang, Huber-based filtering in relative navigation of a
              non-cooperative spacecraft, Aerospace Control 2018 (5)
attitude2018  star-sensor (gyroless) attitude estimation with augmented, adaptive
              and strong-tracking EKFs, Navigation Positioning and Timing 2018 (1)
yang2020      Yang, Tan, Xue, Guo, Zhao, extended-state filtering with saturated
              observations and ADRC for drag-free satellites, Acta Automatica
              Sinica 46(11), 2020
grace2010     not a paper: every filter on the real GRACE-A/B formation of 27 July
              2010 against its precise-orbit truth (issue 20; LEOGPS data, MIT)
benchmark     every registered estimator on every scenario where it fits, run as
              a Dask campaign (not a paper: part of ``--paper all`` only)
=========  ====================================================================
"""

import inspect
from pathlib import Path

from ..core.exceptions import InputError
from ..core.validation import check_keywords
from ..io.outputs import MARKER, atomic_output_dir
from ..io.processes import check_jobs, one_blas_thread, run_jobs
from . import attitude2018, benchmark, grace2010, shi2018, sun2011, yang2020

__all__ = ["PAPERS", "SELECTIONS", "COST_S", "reproduce", "sun2011", "shi2018", "attitude2018", "yang2020", "grace2010", "benchmark"]

#: Reproducible papers: key -> its ``reproduce(out_dir, seed=, runs=, notebooks=, progress=)``.
#: The primary paper (sun2011) writes into the output folder itself, as it always has;
#: the others will write into ``<out>/<key>/``.
PAPERS = {
    "sun2011": sun2011.reproduce,
    "shi2018": shi2018.reproduce,
    "attitude2018": attitude2018.reproduce,
    "yang2020": yang2020.reproduce,
    "grace2010": grace2010.reproduce,
    "benchmark": benchmark.reproduce,
}

#: Named selections: ``papers`` (the default of ``reproduce``) is the four papers and the GRACE real-data
#: study; ``all`` adds the cross-paper benchmark campaign.
SELECTIONS = {"papers": ("sun2011", "shi2018", "attitude2018", "yang2020", "grace2010"), "all": tuple(PAPERS)}


#: The paper that writes into the output folder itself (the others into sub-folders).
PRIMARY = "sun2011"

#: Rough CPU seconds of each paper's default ``reproduce`` (one core, idle): the order in which the worker
#: processes take them, longest first, so that they finish together (an unknown key counts as 0).
COST_S = {"benchmark": 500, "yang2020": 100, "grace2010": 40, "attitude2018": 35, "shi2018": 30, "sun2011": 11}


def reproduce(paper="papers", out_dir="results", *, jobs=None, **options):
    """Reproduce one paper, the four papers and the GRACE study (``"papers"``), or those and the benchmark (``"all"``), atomically.

    ``runs=None`` (or leaving it out) uses each paper's own default (a single
    closed-loop run for yang2020, 100 Monte Carlo runs for sun2011, …).

    ``out_dir`` is checked before any work; everything is written into a
    temporary folder beside it, which replaces it only when every paper has
    finished (:func:`hinfnav.io.outputs.atomic_output_dir`): an interrupted
    run, or one paper failing, leaves the previous folder as it was, and a
    second run into the same folder is refused while the first is writing.
    Redoing one paper keeps the other papers' sub-folders.

    ``jobs`` worker processes (default ``None``: one per core, ``os.cpu_count()``)
    run the papers of a selection side by side, the longest first (:data:`COST_S`),
    each into its own sub-folder (:func:`hinfnav.io.processes.run_jobs`: one BLAS
    thread per worker, each printed line prefixed with ``[paper]``, the first
    failure stops the others and is raised). ``jobs=1``, or a single paper, runs
    them here one after another in the selection's order, also on one BLAS
    thread: the numbers are the same whatever ``jobs`` (each paper seeds its own
    runs). A paper whose ``reproduce`` takes ``workers`` (shi2018) gets
    ``workers=1`` in a worker process unless told otherwise: the pool fills the
    cores already.

    Returns
    -------
    dict
        Paper key → the summary its ``reproduce`` wrote, in the selection's order.
    """
    if not isinstance(paper, str) or (paper not in SELECTIONS and paper not in PAPERS):
        raise InputError(f"unknown paper {paper!r}; choose one of: {', '.join(SELECTIONS)}, {', '.join(PAPERS)}")
    jobs = check_jobs(jobs)
    keys = list(SELECTIONS[paper]) if paper in SELECTIONS else [paper]
    if options.get("runs", 0) is None:
        options = {k: v for k, v in options.items() if k != "runs"}
    params = {}
    for key in keys:
        params[key] = inspect.signature(PAPERS[key]).parameters
        check_keywords(f"option of reproduce({key!r})", options, [p for p in params[key] if p != "out_dir"])
    if paper == "all":
        keep = ()
    elif paper == "papers":
        keep = ("benchmark",)
    elif paper == PRIMARY:
        keep = tuple(k for k in PAPERS if k != PRIMARY)
    else:
        existing = Path(out_dir)
        keep = tuple(e.name for e in existing.iterdir() if e.name not in (paper, MARKER)) if existing.is_dir() else ()
    progress = options.get("progress", True)
    workers = min(jobs, len(keys))
    with atomic_output_dir(out_dir, keep=keep, name="out") as tmp:
        targets = {key: tmp if key == PRIMARY else tmp / key for key in keys}
        for target in targets.values():
            target.mkdir(parents=True, exist_ok=True)
        if workers == 1:
            with one_blas_thread():
                out = {key: PAPERS[key](targets[key], **options) for key in keys}
        else:
            order = sorted(keys, key=lambda k: -COST_S.get(k, 0))  # stable: the selection's order among equals
            tasks = [(key, PAPERS[key], (targets[key],),
                      dict({"workers": 1} if "workers" in params[key] else {}, **options)) for key in order]
            if progress:
                print(f"reproducing {', '.join(order)} on {workers} worker processes", flush=True)
            out = run_jobs(tasks, workers, done=_report_done if progress else None)
            out = {key: out[key] for key in keys}
    if progress:
        print(f"wrote {Path(out_dir).expanduser().absolute()}")
    return out


def _report_done(key, wall_s, cpu_s):
    print(f"{key}: finished in {wall_s:.0f} s ({cpu_s:.0f} CPU-s)", flush=True)
