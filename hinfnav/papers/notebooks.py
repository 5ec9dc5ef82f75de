"""Executing a paper's notebooks into an output folder: what ``reproduce(notebooks=True)`` does.

Every paper's ``reproduce`` can also execute its chapter of the workbook (the
notebooks whose names match its decade, e.g. ``1[0-9]_*.ipynb`` for Shi &
Wang 2018) and write them, with their outputs, beside its figures.
"""

import ast
from pathlib import Path

from tqdm import tqdm

from ..core.exceptions import InputError
from ..io.progress import bar_disabled

__all__ = ["NOTEBOOK_DIR", "run_notebooks", "sequence_parameter"]

#: The repository's notebooks (next to the package in a source checkout).
NOTEBOOK_DIR = Path(__file__).resolve().parents[2] / "notebooks"


def run_notebooks(out_dir, pattern, *, timeout=900, progress=True):
    """Execute the notebooks of :data:`NOTEBOOK_DIR` matching ``pattern`` and write them into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
    pattern : str
        Glob of the notebook names (``"[0-9][0-9]_*.ipynb"``: all of them).
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
        When no notebook matches (an installed package has no notebooks folder).
    """
    import nbformat  # heavy optional libraries: only when notebooks are asked for
    from nbclient import NotebookClient

    paths = sorted(NOTEBOOK_DIR.glob(pattern)) if NOTEBOOK_DIR.is_dir() else []
    if not paths:
        raise InputError(f"notebooks=True needs the repository's notebooks/ folder next to the package; no {pattern} "
                         f"in {NOTEBOOK_DIR}")
    written = []
    for path in tqdm(paths, disable=bar_disabled(progress), desc="notebooks", unit="nb"):
        nb = nbformat.read(path, as_version=4)
        NotebookClient(nb, timeout=timeout, kernel_name="python3",
                       resources={"metadata": {"path": str(NOTEBOOK_DIR)}}).execute()
        target = Path(out_dir) / path.name
        nbformat.write(nb, target)
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
