"""Executing a paper's notebooks into an output folder: what ``reproduce(notebooks=True)`` does.

Every paper's ``reproduce`` can also execute its chapter of the workbook and
write it, with its outputs, beside its figures. A chapter is the explicit
tuple ``NOTEBOOKS`` of the paper's ``reproduce`` module (never a file-name
pattern: each notebook belongs to exactly one paper, or to
:data:`CROSS_PAPER`, which the primary paper runs), so ``reproduce --paper
all --notebooks`` executes every notebook once.
"""

import ast
import os
import time
from datetime import datetime
from pathlib import Path

from tqdm import tqdm

from ..core.exceptions import HinfnavError, InputError
from ..io.progress import bar_disabled

__all__ = ["CROSS_PAPER", "NOTEBOOK_DIR", "NotebookStallError", "check_notebooks",
           "execute_notebook", "run_notebooks", "sequence_parameter"]

#: The repository's notebooks (next to the package in a source checkout).
NOTEBOOK_DIR = Path(__file__).resolve().parents[2] / "notebooks"

#: Notebooks of no single paper (a reader's own system); the primary paper (sun2011, whose output is the
#: folder's root) executes them after its own.
CROSS_PAPER = ("80_your_own_system.ipynb", "81_robust_filters_huang2017.ipynb", "82_marginal_plants_flexible_mode.ipynb")


#: The kernel manager of every execution (a dotted name: nbclient imports it, with jupyter_client, only then).
KERNEL_MANAGER = "hinfnav.papers.notebook_kernel.KernelManager"
#: Seconds a cell may run (the documentation build and the test suite use the same).
CELL_TIMEOUT_S = 900
#: Seconds the kernel may take to report idle after a cell's reply; past it the run fails.
IOPUB_TIMEOUT_S = 30
#: Seconds a run may take beyond its cells' own time (kernel start-up and shutdown included); past it
#: the run fails with :class:`NotebookStallError` instead of passing slowly.
MAX_OVERHEAD_S = 60.0


class NotebookStallError(HinfnavError):
    """A notebook's run took much longer than its cells: the client waited on something silently."""


def _cells_seconds(nb):
    """Sum over code cells of the kernel's busy → idle time (nbclient's ``execution`` timing metadata)."""
    total = 0.0
    for cell in nb.cells:
        timing = cell.get("metadata", {}).get("execution", {})
        if "iopub.status.busy" in timing and "iopub.status.idle" in timing:
            start, end = (datetime.fromisoformat(timing[k].replace("Z", "+00:00"))
                          for k in ("iopub.status.busy", "iopub.status.idle"))
            total += (end - start).total_seconds()
    return total


def execute_notebook(path, target=None, *, timeout=CELL_TIMEOUT_S, cwd=None, extra_arguments=(), env=None,
                     iopub_timeout=IOPUB_TIMEOUT_S, max_overhead_s=MAX_OVERHEAD_S):
    """Execute the notebook ``path`` in ``cwd`` and write it, with its outputs, to ``target``.

    The kernel's client polls its shell socket in slices (:mod:`hinfnav.papers.notebook_kernel`), so a
    cell's reply is read when it arrives; a kernel that does not report idle within ``iopub_timeout``
    after a reply raises nbclient's ``CellTimeoutError``, and a run longer than its cells by more than
    ``max_overhead_s`` raises :class:`NotebookStallError`: no silent waits.

    Parameters
    ----------
    path : str or Path
    target : str or Path, optional
        Where the executed notebook is written (atomically); None writes nothing.
    timeout : float
        Seconds a cell may run.
    cwd : str or Path, optional
        The kernel's working folder (default: :data:`NOTEBOOK_DIR`, as a reader would run it).
    extra_arguments : sequence of str
        Arguments of the kernel (``["--matplotlib=inline"]``).
    env : dict, optional
        The kernel's environment (default: this process's).
    iopub_timeout : float
    max_overhead_s : float

    Returns
    -------
    (nbformat.NotebookNode, float)
        The executed notebook and the run's wall time in seconds.

    Raises
    ------
    NotebookStallError
        See above. A failing cell raises nbclient's ``CellExecutionError``; either writes nothing.
    """
    import nbformat  # heavy optional libraries: only when notebooks are asked for
    from nbclient import NotebookClient

    path = Path(path)
    nb = nbformat.read(path, as_version=4)
    start = time.perf_counter()
    client = NotebookClient(nb, timeout=timeout, kernel_name="python3", kernel_manager_class=KERNEL_MANAGER,
                            iopub_timeout=iopub_timeout, raise_on_iopub_timeout=True, record_timing=True,
                            resources={"metadata": {"path": str(cwd or NOTEBOOK_DIR)}},
                            extra_arguments=list(extra_arguments))
    client.execute(**({} if env is None else {"env": env}))
    seconds = time.perf_counter() - start
    overhead = seconds - _cells_seconds(nb)
    if overhead > max_overhead_s:
        raise NotebookStallError(f"{path.name}: the run took {seconds:.0f} s, {overhead:.0f} s more than its cells "
                                 f"(limit {max_overhead_s:.0f} s): the notebook client waited on something silently")
    if target is not None:
        target = Path(target)
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.parent / f".{target.name}.{os.getpid()}.tmp"
        nbformat.write(nb, tmp)
        os.replace(tmp, target)
    return nb, seconds


def check_notebooks(names):
    """``names`` as a tuple of notebook file names that all exist in :data:`NOTEBOOK_DIR` (before any work).

    Raises
    ------
    InputError
        When ``names`` is not a sequence of names, or one is missing (an installed package has no
        notebooks folder).
    """
    if isinstance(names, str) or not all(isinstance(n, str) for n in names):
        raise InputError(f"names must be a sequence of notebook file names; got {names!r}")
    missing = [n for n in names if not (NOTEBOOK_DIR / n).is_file()]
    if missing:
        raise InputError(f"notebooks=True needs the repository's notebooks/ folder next to the package; "
                         f"{', '.join(missing)} not in {NOTEBOOK_DIR}")
    return tuple(names)


def run_notebooks(out_dir, names, *, timeout=CELL_TIMEOUT_S, progress=True):
    """Execute the notebooks ``names`` of :data:`NOTEBOOK_DIR` and write them into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
    names : sequence of str
        File names (``"01_model_and_scenario.ipynb"``, …): a paper's ``NOTEBOOKS``.
    timeout : float
        Seconds a cell may run.
    progress : bool

    Returns
    -------
    list of Path
        The executed notebooks written.

    Raises
    ------
    InputError
        See :func:`check_notebooks`.
    """
    names = check_notebooks(names)
    written = []
    for name in tqdm(names, disable=bar_disabled(progress), desc="notebooks", unit="nb"):
        target = Path(out_dir) / name
        execute_notebook(NOTEBOOK_DIR / name, target, timeout=timeout)
        written.append(target)
    return written


def sequence_parameter(name, value, kind=float):
    """A list-valued notebook parameter as a tuple, however it was passed.

    ``papermill -p NAME VALUE`` injects a list as the string it was given
    (papermill only converts numbers, booleans and None), so a notebook
    reads its list parameters through this: a sequence, a scalar, or a
    string ``"0, 1"``, ``"[0.0, 1.0]"``, ``"(0.5,)"``, ``"gaussian, laplace"``
    (Python literals, or comma-separated words).

    Parameters
    ----------
    name : str
        The parameter's name (for the error message).
    value : sequence, scalar or str
    kind : callable
        Applied to every entry (``float``, ``int``, ``str``).

    Returns
    -------
    tuple
    """
    if isinstance(value, str):
        text = value.strip()
        try:
            value = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            value = [w.strip() for w in text.strip("[]()").split(",") if w.strip()]
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        value = [value]
    try:
        return tuple(kind(v) for v in value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a list of {getattr(kind, '__name__', kind)} values; got {value!r}: {exc}") from None
