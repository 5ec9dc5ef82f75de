"""``reproduce(notebooks=True)``: each paper executes its chapter (its ``NOTEBOOKS``) through one helper."""

import nbformat
import pytest

import hinfnav.papers.notebooks as nbmod
from hinfnav.core.exceptions import InputError


def test_run_notebooks_executes_the_named_notebooks_into_the_folder(tmp_path, monkeypatch):
    src = tmp_path / "notebooks"
    src.mkdir()
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("print(6 * 7)")])
    nbformat.write(nb, src / "91_tiny.ipynb")
    nbformat.write(nb, src / "10_other.ipynb")
    monkeypatch.setattr(nbmod, "NOTEBOOK_DIR", src)
    out = tmp_path / "out"
    out.mkdir()
    written = nbmod.run_notebooks(out, ("91_tiny.ipynb",), timeout=120, progress=False)
    assert written == [out / "91_tiny.ipynb"] and not (out / "10_other.ipynb").exists()
    done = nbformat.read(written[0], as_version=4)
    assert done.cells[0].outputs[0]["text"] == "42\n"  # executed: the output the cell prints


def test_run_notebooks_with_a_missing_notebook_says_which_and_where(tmp_path):
    with pytest.raises(InputError, match=r"70_missing\.ipynb not in .*notebooks"):
        nbmod.run_notebooks(tmp_path, ("70_missing.ipynb",))
    with pytest.raises(InputError, match="names must be a sequence of notebook file names"):
        nbmod.run_notebooks(tmp_path, "7[0-9]_*.ipynb")  # a pattern is no longer a list of names
