"""The one skeleton of every paper's ``reproduce``: figures and ``summary.json`` with provenance, notebooks, progress.

Every ``hinfnav.papers.<key>.reproduce`` opens a :class:`Reproduction` on its
output folder and writes through it, so that every paper

* saves each figure with the run's provenance in the file's metadata
  (:meth:`Reproduction.save_figure`, :func:`hinfnav.plotting.save.save_figure`);
* writes ``summary.json`` atomically (a temporary file renamed over the target)
  with a ``provenance`` block (:meth:`Reproduction.write_summary`,
  :func:`hinfnav.io.provenance.provenance`);
* executes exactly the notebooks its package lists (its ``NOTEBOOKS`` tuple, checked
  before any work, run by :meth:`Reproduction.run_notebooks`), never a file-name pattern;
* follows one progress policy: with ``progress=True``, messages through
  ``tqdm.write`` and bars that show on a terminal only
  (:func:`hinfnav.io.progress.bar_disabled`); with ``progress=False``, silence.
"""

import time
from collections.abc import Mapping, Sequence
from pathlib import Path

from tqdm import tqdm

from ..core.exceptions import InputError
from ..io.outputs import atomic_write_text, write_json
from ..io.progress import bar_disabled
from ..io.provenance import provenance
from ..plotting.save import save_figure
from .notebooks import check_notebooks, run_notebooks

__all__ = ["Reproduction", "atomic_write_text"]  # atomic_write_text: re-exported from hinfnav.io.outputs


class Reproduction:
    """One paper's reproduction into one output folder.

    Parameters
    ----------
    out_dir : str or Path
        The folder (created if missing).
    paper : str
        The paper's key (``"sun2011"``, …), recorded in the provenance.
    notebooks : sequence of str
        The notebooks :meth:`run_notebooks` will execute (the paper's ``NOTEBOOKS`` when
        ``reproduce(notebooks=True)``, else empty); checked here, before any work.
    progress : bool
        Messages and progress bars (see the module's policy).
    formats : sequence of str
        Figure file formats.
    dpi : int
        Resolution of the raster formats, dots per inch.
    **extra
        Further provenance fields (``seed=``, ``runs=``, ``n_steps=``…).

    Attributes
    ----------
    out : Path
    provenance : dict
        The JSON-ready provenance every figure and the summary carry.
    written : list of Path
        Every file written through this object, in order.
    """

    def __init__(self, out_dir, paper, *, notebooks=(), progress=True, formats=("png", "pdf"), dpi=130, **extra):
        if not isinstance(paper, str) or not paper:
            raise InputError(f"paper must be a paper's key (a non-empty string); got {paper!r}")
        self.notebooks = check_notebooks(notebooks)
        if isinstance(formats, str) or not formats:
            raise InputError(f"formats must be a non-empty sequence of file formats such as ('png', 'pdf'); "
                             f"got {formats!r}")
        self.out = Path(out_dir)
        self.out.mkdir(parents=True, exist_ok=True)
        self.paper = paper
        self.progress = bool(progress)
        self.formats = tuple(formats)
        self.dpi = dpi
        self.provenance = provenance(paper=paper, **extra)
        self.written = []
        self._t0 = time.perf_counter()

    # -- progress -----------------------------------------------------------------------

    def say(self, message):
        """Print ``message`` (through ``tqdm.write``, so that it does not break a bar) when progress is on."""
        if self.progress:
            tqdm.write(message)

    def bar(self, iterable, desc, unit="it", **kwargs):
        """``iterable`` wrapped in a tqdm bar that shows on a terminal only, and only with progress on."""
        return tqdm(iterable, disable=bar_disabled(self.progress), desc=desc, unit=unit, **kwargs)

    @property
    def elapsed_s(self):
        """Wall-clock seconds since the reproduction opened."""
        return time.perf_counter() - self._t0

    # -- files ---------------------------------------------------------------------------

    def save_figure(self, fig, name, *, formats=None):
        """Save ``fig`` as ``<out>/<name>.<format>`` with the provenance in its metadata; return the paths."""
        paths = save_figure(fig, self.out, name, self.provenance, formats=self.formats if formats is None else formats,
                            dpi=self.dpi)
        self.written.extend(paths)
        return paths

    def save_figures(self, figures: Mapping[str, object], *, formats: Sequence[str] | None = None):
        """Save every figure of ``{name: Figure or zero-argument callable returning one}`` (a bar over them).

        A callable is drawn only when its turn comes, so that one figure at a
        time is held in memory.
        """
        paths = []
        for name, fig in self.bar(figures.items(), "figures", "fig"):
            paths += self.save_figure(fig() if callable(fig) else fig, name, formats=formats)
        return paths

    def write_summary(self, summary, *, strict=True, name="summary.json"):
        """Write ``summary`` with a ``provenance`` block to ``<out>/summary.json`` atomically; return what was written.

        Parameters
        ----------
        summary : dict
            JSON-ready after :func:`hinfnav.io.outputs.to_json` (numpy values allowed). A
            ``provenance`` key it already has is replaced by this run's.
        strict : bool
            NaN and infinities written as null (strict JSON; the default since issue 36, so
            that ``reproduce --runs 1``, whose undefined statistics are NaN, writes JSON any reader takes).
        name : str
            File name.
        """
        if not isinstance(summary, Mapping):
            raise InputError(f"summary must be a dict; got {type(summary).__name__}")
        path = self.out / name
        data = write_json(path, {**summary, "provenance": self.provenance}, strict=strict)
        self.written.append(path)
        return data

    def run_notebooks(self, *, timeout=900):
        """Execute the notebooks given at the start (none: nothing) into the folder; return their paths."""
        paths = run_notebooks(self.out, self.notebooks, timeout=timeout, progress=self.progress)
        self.written.extend(paths)
        return paths
