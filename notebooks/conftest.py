"""The notebooks as test items: each executes in its own folder, as a reader's JupyterLab would.

Every notebook is one test item (markers ``notebook`` and ``slow``, see ``tests/conftest.py``). It is
executed by the documentation build's own function (``docs/build.py``: nbclient, the inline matplotlib
backend, 900 s per cell), and its executed copy is written to ``build/executed/``, so that
``python docs/build.py`` after the tests renders those copies instead of executing every notebook again.
A failing cell fails the item with the cell's source and traceback; a run much longer than its cells
fails it too (``hinfnav.papers.notebooks.NotebookStallError``), and the notebooks of :data:`BUDGET_S`
must finish within their budget (issue 37: notebook 91 once waited 900 s after 4 s of cells).
"""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Wall-time budget (s, kernel start included, on 2 shared cores) of notebooks that once stalled.
BUDGET_S = {"91_interactive_design_and_errors.ipynb": 60.0}


def _docs_build():
    spec = importlib.util.spec_from_file_location("hinfnav_docs_build", ROOT / "docs" / "build.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def pytest_collect_file(file_path, parent):
    if file_path.suffix == ".ipynb" and ".ipynb_checkpoints" not in file_path.parts:
        return NotebookFile.from_parent(parent, path=file_path)
    return None


class NotebookFile(pytest.File):
    def collect(self):
        yield NotebookItem.from_parent(self, name=self.path.name)


class NotebookItem(pytest.Item):
    def runtest(self):
        name, seconds = _docs_build().execute_notebook(self.path)
        budget = BUDGET_S.get(name)
        assert budget is None or seconds < budget, f"{name} took {seconds:.0f} s (budget {budget:.0f} s)"

    def repr_failure(self, excinfo):
        return str(excinfo.value)

    def reportinfo(self):
        return self.path, 0, f"notebook {self.path.name}"
