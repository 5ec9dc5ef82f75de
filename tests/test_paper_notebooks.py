"""``reproduce(notebooks=True)``: each paper executes its chapter through one helper (hinfnav.papers.notebooks)."""

import nbformat
import pytest

import hinfnav.papers.notebooks as nbmod
from hinfnav.core.exceptions import InputError


def test_run_notebooks_executes_the_matching_notebooks_into_the_folder(tmp_path, monkeypatch):
    src = tmp_path / "notebooks"
    src.mkdir()
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("print(6 * 7)")])
    nbformat.write(nb, src / "91_tiny.ipynb")
    nbformat.write(nb, src / "10_other.ipynb")
    monkeypatch.setattr(nbmod, "NOTEBOOK_DIR", src)
    out = tmp_path / "out"
    out.mkdir()
    written = nbmod.run_notebooks(out, "9[0-9]_*.ipynb", timeout=120, progress=False)
    assert written == [out / "91_tiny.ipynb"] and not (out / "10_other.ipynb").exists()
    done = nbformat.read(written[0], as_version=4)
    assert done.cells[0].outputs[0]["text"] == "42\n"  # executed: the output the cell prints


def test_run_notebooks_without_a_match_says_which_pattern_and_folder(tmp_path):
    with pytest.raises(InputError, match=r"no 7\[0-9\]_\*\.ipynb in .*notebooks"):
        nbmod.run_notebooks(tmp_path, "7[0-9]_*.ipynb")
