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
from . import attitude2018, benchmark, grace2010, shi2018, sun2011, yang2020

__all__ = ["PAPERS", "SELECTIONS", "reproduce", "sun2011", "shi2018", "attitude2018", "yang2020", "grace2010", "benchmark"]

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


def reproduce(paper="papers", out_dir="results", **options):
    """Reproduce one paper, the four papers and the GRACE study (``"papers"``), or those and the benchmark (``"all"``), atomically.

    ``runs=None`` (or leaving it out) uses each paper's own default (a single
    closed-loop run for yang2020, 100 Monte Carlo runs for sun2011, …).

    ``out_dir`` is checked before any work; everything is written into a
    temporary folder beside it, which replaces it only when every paper has
    finished (:func:`hinfnav.io.outputs.atomic_output_dir`): an interrupted
    run leaves the previous folder as it was, and a second run into the same
    folder is refused while the first is writing. Redoing one paper keeps the
    other papers' sub-folders.

    Returns
    -------
    dict
        Paper key → the summary its ``reproduce`` wrote.
    """
    if not isinstance(paper, str) or (paper not in SELECTIONS and paper not in PAPERS):
        raise InputError(f"unknown paper {paper!r}; choose one of: {', '.join(SELECTIONS)}, {', '.join(PAPERS)}")
    keys = list(SELECTIONS[paper]) if paper in SELECTIONS else [paper]
    if options.get("runs", 0) is None:
        options = {k: v for k, v in options.items() if k != "runs"}
    for key in keys:
        params = inspect.signature(PAPERS[key]).parameters
        check_keywords(f"option of reproduce({key!r})", options, [p for p in params if p != "out_dir"])
    if paper == "all":
        keep = ()
    elif paper == "papers":
        keep = ("benchmark",)
    elif paper == PRIMARY:
        keep = tuple(k for k in PAPERS if k != PRIMARY)
    else:
        existing = Path(out_dir)
        keep = tuple(e.name for e in existing.iterdir() if e.name not in (paper, MARKER)) if existing.is_dir() else ()
    out = {}
    with atomic_output_dir(out_dir, keep=keep, name="out") as tmp:
        for key in keys:
            target = tmp if key == PRIMARY else tmp / key
            target.mkdir(parents=True, exist_ok=True)
            out[key] = PAPERS[key](target, **options)
    if options.get("progress", True):
        print(f"wrote {Path(out_dir).expanduser().absolute()}")
    return out
