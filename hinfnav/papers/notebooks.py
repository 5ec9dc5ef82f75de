"""Executing a paper's notebooks into an output folder: what ``reproduce(notebooks=True)`` does.

Every paper's ``reproduce`` can also execute its chapter of the workbook and
write it, with its outputs, beside its figures. A chapter is the explicit
tuple ``NOTEBOOKS`` of the paper's ``reproduce`` module (never a file-name
pattern: each notebook belongs to exactly one paper, or to
:data:`CROSS_PAPER`, which the primary paper runs), so ``reproduce --paper
all --notebooks`` executes every notebook once.
"""

import ast
from pathlib import Path

from tqdm import tqdm

from ..core.exceptions import InputError
from ..io.progress import bar_disabled

__all__ = ["CROSS_PAPER", "NOTEBOOK_DIR", "check_notebooks", "execute_notebook", "run_notebooks",
           "sequence_parameter"]

#: The repository's notebooks (next to the package in a source checkout).
NOTEBOOK_DIR = Path(__file__).resolve().parents[2] / "notebooks"

#: Notebooks of no single paper (a reader's own system); the primary paper (sun2011, whose output is the
#: folder's root) executes them after its own.
CROSS_PAPER = ("80_your_own_system.ipynb", "81_robust_filters_huang2017.ipynb", "82_marginal_plants_flexible_mode.ipynb")


def execute_notebook(path, target, *, timeout=900):
    """Execute the notebook ``path`` (in :data:`NOTEBOOK_DIR`, as a reader would) and write it to ``target``."""
    import nbformat  # heavy optional libraries: only when notebooks are asked for
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=timeout, kernel_name="python3",
                   resources={"metadata": {"path": str(NOTEBOOK_DIR)}}).execute()
    nbformat.write(nb, target)
    return Path(target)


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


def run_notebooks(out_dir, names, *, timeout=900, progress=True):
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
        written.append(execute_notebook(NOTEBOOK_DIR / name, Path(out_dir) / name, timeout=timeout))
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
