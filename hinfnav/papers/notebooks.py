"""Executing a paper's notebooks into an output folder: what ``reproduce(notebooks=True)`` does.

Every paper's ``reproduce`` can also execute its chapter of the workbook (the
notebooks whose names match its decade, e.g. ``1[0-9]_*.ipynb`` for Shi &
Wang 2018) and write them, with their outputs, beside its figures.
"""

from pathlib import Path

from tqdm import tqdm

from ..core.exceptions import InputError
from ..core.progress import bar_disabled

__all__ = ["NOTEBOOK_DIR", "run_notebooks"]

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
