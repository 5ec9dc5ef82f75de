"""Papers layer: one sub-package per reproduced paper.

Each paper folder holds its constants, scenario, registered estimators,
designs, studies, tables, figures and its ``reproduce``. Importing this
package loads no paper: a paper loads when it is first used (``hinfnav.papers.yang2020``
imports that paper alone), and :func:`register` (called by the registry through the
``hinfnav.providers`` entry point, and by :func:`reproduce`) imports every paper, registering
their estimators and scenarios in one fixed order.

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

import importlib
import importlib.util
import inspect
from pathlib import Path

from ..core.exceptions import InputError
from ..core.validation import check_keywords
from ..io.outputs import MARKER, atomic_output_dir
from ..io.processes import check_jobs, one_blas_thread, run_jobs
__all__ = ["PAPERS", "SELECTIONS", "COST_S", "register", "reproduce", "sun2011", "shi2018", "attitude2018", "yang2020",
           "grace2010", "benchmark"]

#: A paper's modules that register campaign scenarios and estimators as they are imported.
REGISTERING_MODULES = ("campaign", "filters")
#: The paper sub-packages, in the order :func:`register` imports them (the registration order).
PAPER_PACKAGES = ("attitude2018", "benchmark", "grace2010", "shi2018", "sun2011", "yang2020")


def register():
    """Import every paper (registering its estimators and campaign scenarios), in :data:`PAPER_PACKAGES` order.

    The registry calls this through the ``hinfnav.providers`` entry point (``hinfnav.papers``: see
    :func:`hinfnav.estimators.registry.load_providers`) on its first query; importing one paper
    registers only that paper's names.
    """
    for name in PAPER_PACKAGES:
        package = importlib.import_module(f".{name}", __name__)
        for module in REGISTERING_MODULES:  # a lazy paper (yang2020) registers only when these load
            if importlib.util.find_spec(f"{package.__name__}.{module}") is not None:
                importlib.import_module(f"{package.__name__}.{module}")


def __getattr__(name):
    if name in PAPER_PACKAGES:  # a paper loads on first use (importing it sets it as an attribute)
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _PaperReproduce:
    """A paper's ``reproduce``, loaded when called (every paper registered first) or inspected; picklable."""

    def __init__(self, key):
        self.key = key

    def _function(self):
        register()
        return importlib.import_module(f".{self.key}", __name__).reproduce

    @property
    def __signature__(self):
        return inspect.signature(self._function())

    def __call__(self, *args, **kwargs):
        return self._function()(*args, **kwargs)

    def __repr__(self):
        return f"<reproduce of hinfnav.papers.{self.key}>"


#: Reproducible papers: key -> its ``reproduce(out_dir, seed=, runs=, notebooks=, progress=)``.
#: The primary paper (sun2011) writes into the output folder itself, as it always has;
#: the others will write into ``<out>/<key>/``.
PAPERS = {key: _PaperReproduce(key) for key in ("sun2011", "shi2018", "attitude2018", "yang2020", "grace2010",
                                                 "benchmark")}

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
    register()
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
