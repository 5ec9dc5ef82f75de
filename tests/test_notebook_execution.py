"""No silent waits: a notebook executes in the time its cells take, and a stall fails loudly (issue 37, item 7).

Notebook 91 used to hold the test suite and the documentation build for 900 s: nbclient's client slept
through a cell's reply whenever the cell wrote into an ``ipywidgets.Output`` (see
:mod:`hinfnav.papers.notebook_kernel`). The notebook below reproduces that: with nbclient's own client
and a 10 s cell timeout, its five cells took 34–43 s in three runs instead of 3 s (each stalled cell
waits the whole timeout); with the package's client, 4.2–4.8 s (measured on 2 shared cores).
"""

import nbclient
import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook

from hinfnav.papers.notebooks import NotebookStallError, execute_notebook

pytestmark = pytest.mark.slow  # each starts a kernel (2–5 s)

#: A cell that clears and fills an Output widget with 3 MB: nbclient sends the widget's state back to the
#: kernel on the shell socket while it waits for the cell's reply on that socket.
WIDGET_CELL = ("import ipywidgets as w\nfrom IPython.display import display, clear_output\n"
               "out = w.Output(); display(out)\nwith out:\n    clear_output(wait=True)\n    print('x' * 3_000_000)\n")


def _write(tmp_path, cells):
    nb = new_notebook(cells=[new_code_cell(c) for c in cells])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    path = tmp_path / "nb.ipynb"
    nbformat.write(nb, path)
    return path


def test_widget_output_does_not_stall_the_client(tmp_path):
    # A stalled cell waits its whole timeout (60 s here), so five cells that each risk a stall finishing in
    # under 60 s means none stalled. The overhead guard is off: this times the channel alone.
    path = _write(tmp_path, [WIDGET_CELL] * 5)
    nb, seconds = execute_notebook(path, tmp_path / "out.ipynb", timeout=60, cwd=tmp_path, max_overhead_s=1e9)
    assert seconds < 60, f"{seconds:.0f} s: a cell's reply was read only at its timeout"
    assert (tmp_path / "out.ipynb").is_file()
    assert "x" * 100 in str(nb.metadata.widgets)  # the widget's output was recorded


def test_a_kernel_that_does_not_go_idle_fails_loudly(tmp_path, monkeypatch):
    # The client never sees the kernel's idle status (dropped here): nbclient only warns by default and
    # goes on; the package's execution raises after iopub_timeout.
    real = nbclient.NotebookClient.process_message

    def drop_idle(self, msg, cell, cell_index):
        if msg["msg_type"] == "status" and msg["content"].get("execution_state") == "idle":
            return None
        return real(self, msg, cell, cell_index)

    monkeypatch.setattr(nbclient.NotebookClient, "process_message", drop_idle)
    path = _write(tmp_path, ["1 + 1"])
    with pytest.raises(nbclient.exceptions.CellTimeoutError, match="IOPub"):
        execute_notebook(path, tmp_path / "out.ipynb", timeout=60, cwd=tmp_path, iopub_timeout=2)
    assert not (tmp_path / "out.ipynb").exists()


def test_a_run_much_longer_than_its_cells_fails_loudly(tmp_path):
    # Kernel start-up alone exceeds a zero allowance: the guard that turns a silent wait into an error.
    path = _write(tmp_path, ["1 + 1"])
    with pytest.raises(NotebookStallError, match="more than its cells"):
        execute_notebook(path, tmp_path / "out.ipynb", timeout=60, cwd=tmp_path, max_overhead_s=0.0)
    assert not (tmp_path / "out.ipynb").exists()
