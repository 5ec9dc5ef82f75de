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
from ..core.outputs import MARKER, atomic_output_dir
from . import sun2011

__all__ = ["PAPERS", "reproduce", "sun2011"]

#: Reproducible papers: key -> its ``reproduce(out_dir, seed=, runs=, notebooks=, progress=)``.
#: The primary paper (sun2011) writes into the output folder itself, as it always has;
#: the others will write into ``<out>/<key>/``.
PAPERS = {"sun2011": sun2011.reproduce}


#: The paper that writes into the output folder itself (the others into sub-folders).
PRIMARY = "sun2011"


def reproduce(paper="all", out_dir="results", **options):
    """Reproduce one paper, or every paper with ``paper="all"``, atomically.

    ``out_dir`` is checked before any work; everything is written into a
    temporary folder beside it, which replaces it only when every paper has
    finished (:func:`hinfnav.core.outputs.atomic_output_dir`): an interrupted
    run leaves the previous folder as it was, and a second run into the same
    folder is refused while the first is writing. Redoing one paper keeps the
    other papers' sub-folders.

    Returns
    -------
    dict
        Paper key → the summary its ``reproduce`` wrote.
    """
    if paper != "all" and paper not in PAPERS:
        raise InputError(f"unknown paper {paper!r}; choose one of: all, {', '.join(PAPERS)}")
    keys = list(PAPERS) if paper == "all" else [paper]
    if paper == "all":
        keep = ()
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
