"""The Sun 2011 notebooks follow their ``parameters`` cell (issue 8, item 9).

Notebooks 01, 03, 04 and 06 are executed with papermill with parameters other
than the stored ones (another seed, few runs, δ̄ = 0.2, another noise, δ̄ lists
that the stored sweep does not hold) into a temporary folder. Each must run,
and the labels it prints must name the new values, not the stored ones. The
expected strings are the parameters themselves: a label that hard-coded the
stored value (δ̄ = 0.05, 20 runs, seed 0, mixture noise) fails these checks.
The normal run (notebooks/conftest.py) executes every notebook as stored.

The four executions run two at a time: about 40 s of CPU in all (small runs).
"""

import ast
import re
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from types import SimpleNamespace

import nbformat
import numpy as np
import papermill
import pytest
from papermill.translators import PythonTranslator

from hinfnav.core.exceptions import InputError
from hinfnav.papers.sun2011 import sweep_result
from hinfnav.papers.sun2011.table1 import TABLE_FILTERS, filter_labels, row_command

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
SUN2011 = sorted(NOTEBOOKS.glob("0[1-7]_*.ipynb"))

#: Parameters of the executions, all different from the stored ones.
PARAMETERS = {
    "01_model_and_scenario": {"SEED": 7, "RUNS": 3, "DELTA_BAR": 0.2, "NOISE": "laplace"},
    "03_design_vs_delta": {
        "DELTA_BARS": "[0.0, 1.0]",          # as `papermill -p` passes a list (a string; issue 22); δ̄ = 0.2 is
                                             # not in the sweep: the notebook must add it
        "DELTA_BAR": 0.2,
        "SIGMA_DELTA_BARS": [0.0, 0.2],
        "WORST_CASE_DELTA_BARS": [1.0],
        "PRINTED_DELTA_BARS": [0.2],
        "OBSERVER_DELTA_BARS": [0.2],
        "WHAT_IF_VEL_NOISE": 0.2,
        "RUNS": 2,
        "SEED": 3,
    },
    "04_table1": {"RUNS": 3, "SEED": 5, "DELTA_BAR": 0.2},
    "06_fig7_uncertainty_and_non_gaussian": {
        "SEED": 4, "RUNS": 2, "DELTA": 0.5, "NOISE": "uniform", "DELTAS": "0.5", "NOISES": "gaussian, laplace",
    },
}


def _texts(nb):
    """Printed text of each code cell (streams and text/plain results), in order."""
    out = []
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        parts = []
        for o in cell.get("outputs", []):
            if o.output_type == "stream":
                parts.append(o.text)
            elif o.output_type in ("execute_result", "display_data"):
                parts.append(o.get("data", {}).get("text/plain", ""))
            elif o.output_type == "error":
                parts.append(f"{o.ename}: {o.evalue}")
        out.append("".join(parts))
    return out


def _execute(name, folder):
    out = folder / f"{name}.ipynb"
    papermill.execute_notebook(str(NOTEBOOKS / f"{name}.ipynb"), str(out), parameters=PARAMETERS[name],
                               kernel_name="python3", cwd=str(folder), progress_bar=False, log_output=False)
    return nbformat.read(out, as_version=4)


@pytest.fixture(scope="module")
def executions(tmp_path_factory):
    """Every notebook of :data:`PARAMETERS` executed, two kernels at a time (CI has 2 cores)."""
    folder = tmp_path_factory.mktemp("notebook_parameters")
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {name: pool.submit(_execute, name, folder) for name in PARAMETERS}
    return {name: f.exception() or f.result() for name, f in futures.items()}


@pytest.fixture(params=sorted(PARAMETERS))
def executed(request, executions):
    """(name, printed lines) of a notebook executed with :data:`PARAMETERS`."""
    nb = executions[request.param]
    if isinstance(nb, BaseException):
        pytest.fail(f"{request.param} failed with parameters {PARAMETERS[request.param]}: {nb}")
    injected = [c for c in nb.cells if "injected-parameters" in c.metadata.get("tags", [])]
    assert len(injected) == 1
    return request.param, "\n".join(_texts(nb)).splitlines()


def _has(lines, pattern):
    return [ln for ln in lines if re.search(pattern, ln)]


def test_notebook_labels_follow_the_parameters(executed):
    name, lines = executed
    text = "\n".join(lines)
    if name == "01_model_and_scenario":
        assert _has(lines, r"^δ̄ = 0\.2: largest identity gap .*largest \|\|F\|\| 1\.000000")  # ‖F(±δ̄)‖ = 1 (vertex)
        assert _has(lines, r"^published filter, laplace noise, 3 runs, seed 7$")
        assert len(_has(lines, r"maneuver: RMS pos")) == 2 and len(_has(lines, r"^published_closed_loop ")) == 2
        assert "δ̄ = 0.05" not in text and "gaussian" not in text
    elif name == "03_design_vs_delta":
        assert _has(lines, r"^added to the sweep for the look-ups below: δ̄ = 0\.2$")
        sweep = [ln.split()[2] for ln in _has(lines, r"^δ̄ = \S+ +γ\* = .*solver γ")]
        assert sweep == ["0", "0.2", "1"]                    # DELTA_BARS plus the δ̄ the look-ups need
        assert len(_has(lines, r"^δ̄ = 0\.2 +balanced γ\* = ")) == 1     # PRINTED_DELTA_BARS
        assert len(_has(lines, r"^δ̄ = 0\.2 +γ\* = .*γ_observer = ")) == 1  # OBSERVER_DELTA_BARS
        assert _has(lines, r"^optimum designed at δ̄ = 0\.2; both evaluated on the published filter's design model "
                           r"\(δ̄ = 0\.05\)$")
        assert _has(lines, r"^B velocity entries 0\.2, δ̄ = 0\.2: γ\* = ")
        assert len(_has(lines, r"at δ̄ = 0\.2; 2 runs, seed 3$")) == 2
        # δ̄ = 0.05 appears only where it is the published filter's own bound
        assert all("published" in ln for ln in _has(lines, r"δ̄ = 0\.05"))
    elif name == "04_table1":
        assert _has(lines, r"^designed at δ̄ = 0\.2: certified gamma")
        assert _has(lines, r"^Table 1 reproduced: 3 runs, seed 5, .* at δ̄ = 0\.2$")
        assert _has(lines, r"pos m, 3 runs +vel m/s, 3 runs")
        assert "δ̄ = 0.05" not in text and "100 runs" not in text
    else:
        assert _has(lines, r"^seed 4: Fig 7 — robust H∞ filter \(published\), δ = 0\.5, uniform noise, with maneuver$")
        assert _has(lines, r"^2 runs per row, seed 4$")
        rows = [ln.split() for ln in lines if ln.split()[:1] in (["published"], ["ekf_known_input"])]
        assert [(r[1], r[2]) for r in rows] == [("0.5", "gaussian"), ("0.5", "laplace")] * 2
        assert "mixture" not in text and "δ = 1" not in text


def test_sun2011_notebooks_are_stored_without_outputs():
    assert len(SUN2011) == 7
    for path in SUN2011:
        nb = nbformat.read(path, as_version=4)
        tagged = [c for c in nb.cells if "parameters" in c.metadata.get("tags", [])]
        assert len(tagged) == 1 and tagged[0].cell_type == "code", path.name
        for cell in nb.cells:
            if cell.cell_type == "code":
                assert cell.execution_count is None and cell.outputs == [], path.name


def test_papermill_reads_every_parameter():
    """``papermill --help-notebook`` and ``-p NAME VALUE`` see every assignment of the parameters cells."""
    for path in SUN2011:
        nb = nbformat.read(path, as_version=4)
        cell = next(c for c in nb.cells if "parameters" in c.metadata.get("tags", []))
        assigned = [n.targets[0].id for n in ast.parse(cell.source).body if isinstance(n, ast.Assign)]
        assert [p.name for p in PythonTranslator.inspect(cell)] == assigned, path.name


def test_sweep_lookup_names_the_missing_bound_and_those_it_has():
    sweep = SimpleNamespace(delta_bars=np.array([0.0, 1.0]), results=["at 0", "at 1"])  # what sweep_result reads
    assert sweep_result(sweep, 1.0) == "at 1"
    with pytest.raises(InputError, match=r"delta_bar = 0\.2; it has 0, 1"):
        sweep_result(sweep, 0.2)


def test_table1_labels_and_commands_follow_the_design_bound():
    assert filter_labels()["hinf_designed"] == TABLE_FILTERS["hinf_designed"] == "H∞, designed here (δ̄ = 0.05)"
    assert filter_labels(0.2)["hinf_designed"] == "H∞, designed here (δ̄ = 0.2)"
    # the default command is unchanged (reproduce's summary.json holds it)
    assert row_command("hinf_designed", True, 100, 0) == (
        "python -m hinfnav simulate --filter designed_closed_loop --runs 100 --seed 0 --json")
    assert row_command("hinf_observer", False, 3, 5, 0.2) == (
        "python -m hinfnav design --delta-bar 0.2 --form observer --save observer.json && "
        "python -m hinfnav simulate --design observer.json --no-maneuver --runs 3 --seed 5 --json")
    assert row_command("hinf_published", True, 3, 5, 0.2) == (
        "python -m hinfnav simulate --filter published_closed_loop --runs 3 --seed 5 --json")


#: A number with a unit, a percentage or "≈ number" in prose (the quoted results a parameter can change).
_QUOTED = re.compile(r"(?<![\w$\\^_{])\d+\.\d+\s*(?:m/s|m\b|%|mN|×|s\b)|\d+\s*%|≈\s*\d[\d.]*")


def test_prose_after_the_parameters_says_it_describes_the_defaults():
    """Issue 22: prose that quotes results computes them or says it describes the default parameters."""
    offending = []
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        start = next((i for i, c in enumerate(nb.cells) if "parameters" in c.metadata.get("tags", [])), None)
        if start is None:
            continue
        for i, cell in enumerate(nb.cells[start + 1:], start=start + 1):
            if cell.cell_type == "markdown" and _QUOTED.search(cell.source) and "default parameters" not in cell.source:
                offending.append(f"{path.name} cell {i}")
    assert not offending, offending
