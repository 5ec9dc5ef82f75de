"""The notebooks as test items: each executes in its own folder, as a reader's JupyterLab would.

Every notebook is one test item (markers ``notebook`` and ``slow``, see ``tests/conftest.py``). It is
executed by the documentation build's own function (``docs/build.py``: nbclient, the inline matplotlib
backend, 900 s per cell), and its executed copy is written to ``build/executed/``, so that
``python docs/build.py`` after the tests renders those copies instead of executing every notebook again.
A failing cell fails the item with the cell's source and traceback.
"""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


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
        _docs_build().execute_notebook(self.path)

    def repr_failure(self, excinfo):
        return str(excinfo.value)

    def reportinfo(self):
        return self.path, 0, f"notebook {self.path.name}"
