"""Papers layer: one sub-package per reproduced paper.

Each paper folder holds its constants, scenario, registered estimators,
designs, studies, tables, figures and its ``reproduce``. Importing this
package registers every paper's estimators.

=========  ====================================================================
key        paper
=========  ====================================================================
sun2011    Sun, Deng, Liu, Zhong, robust H∞ filtering for a chaser satellite,
           Journal of Astronautics 32(7), 2011 (the workbook's base)
=========  ====================================================================
"""

from pathlib import Path

from ..core.exceptions import InputError
from . import sun2011

__all__ = ["PAPERS", "reproduce", "sun2011"]

#: Reproducible papers: key -> its ``reproduce(out_dir, seed=, runs=, notebooks=, progress=)``.
#: The primary paper (sun2011) writes into the output folder itself, as it always has;
#: the others will write into ``<out>/<key>/``.
PAPERS = {"sun2011": sun2011.reproduce}


def reproduce(paper="all", out_dir="results", **options):
    """Reproduce one paper, or every paper with ``paper="all"``.

    Returns
    -------
    dict
        Paper key → the summary its ``reproduce`` wrote.
    """
    if paper != "all" and paper not in PAPERS:
        raise InputError(f"unknown paper {paper!r}; choose one of: all, {', '.join(PAPERS)}")
    keys = list(PAPERS) if paper == "all" else [paper]
    out = {}
    for key in keys:
        target = Path(out_dir) if key == "sun2011" else Path(out_dir) / key
        out[key] = PAPERS[key](target, **options)
    return out
