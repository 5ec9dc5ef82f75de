"""The peer papers' chapters follow their ``parameters`` cell (issue 35 item 8; Sun 2011's: test_notebook_parameters).

One notebook per chapter is executed with papermill with parameters other than the stored ones, and what it
prints is checked against the same computation done here directly with the new values (the independent
reference): a cell that ignored a parameter (as notebook 11's last section ignored ``GAMMA`` before issue 35)
prints the stored value's numbers and fails. Marked slow (about 30 s of CPU); the statically checkable part,
every parameter read by some later code cell, runs always.
"""

import ast
import re
from pathlib import Path

import nbformat
import numpy as np
import papermill
import pytest

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"


def _source(cell):
    return "\n".join(ln for ln in cell.source.splitlines() if not ln.lstrip().startswith(("%", "!")))


def test_every_parameter_is_read_after_the_parameters_cell():
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        idx = [i for i, c in enumerate(nb.cells) if "parameters" in c.metadata.get("tags", [])]
        assert len(idx) == 1, path.name
        names = [t.id for n in ast.parse(_source(nb.cells[idx[0]])).body if isinstance(n, ast.Assign)
                 for t in n.targets if isinstance(t, ast.Name)]
        used = {n.id for c in nb.cells[idx[0] + 1:] if c.cell_type == "code"
                for n in ast.walk(ast.parse(_source(c))) if isinstance(n, ast.Name)}
        assert names and not [n for n in names if n not in used], (path.name, names)


def _run(name, parameters, folder):
    out = folder / f"{name}.ipynb"
    papermill.execute_notebook(str(NOTEBOOKS / f"{name}.ipynb"), str(out), parameters=parameters,
                               kernel_name="python3", cwd=str(folder), progress_bar=False, log_output=False)
    nb = nbformat.read(out, as_version=4)
    return "\n".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
                     if o.get("output_type") == "stream")


@pytest.mark.slow
def test_shi2018_chapter_follows_gamma(tmp_path):
    from hinfnav.papers.shi2018 import EKF, HBF, Scenario, run_case
    from hinfnav.papers.shi2018.mestimation import huber_efficiency

    text = _run("11_shi2018_huber_m_estimation", {"GAMMA": 2.5, "RUNS": 2, "SEED": 3}, tmp_path)
    assert f"gamma = 2.5: {huber_efficiency(2.5):.4f}" in text
    sc = Scenario()
    for case in ("gaussian", "mixture"):
        res = run_case(sc, case, {"hbf": HBF(sc, gamma=2.5), "ekf": EKF(sc)}, runs=2, seed=3)
        assert (f"{case:9}: HBF (gamma = 2.5) down-weights {100 * res.filters['hbf'].down_weighted:.1f} %"
                in text), text


@pytest.mark.slow
def test_yang2020_chapter_follows_axis_and_length(tmp_path):
    from hinfnav.papers.yang2020 import Scenario, estimation_errors, run_closed_loop

    text = _run("31_yang2020_algorithm2", {"N_STEPS": 600, "SEED": 2, "AXIS": 1}, tmp_path)
    res = run_closed_loop(Scenario(n_steps=600), controller="dragfree_off", seed=2, passive=True, passive_steps=601)
    e = estimation_errors(res, axis=1)["L1"]["all"]
    assert re.search(rf"L1 +disturbance bias +{e['disturbance_bias'] * 1e3:9.3f} mN", text), text


@pytest.mark.slow
def test_attitude2018_chapter_follows_runs_seed_orbits(tmp_path):
    from hinfnav.papers.attitude2018 import Scenario, sweep_study

    text = _run("21_aekf_q_tradeoff", {"RUNS": 1, "SEED": 3, "ORBITS": 1.5}, tmp_path)
    study = sweep_study(Scenario(orbits=1.5), runs=1, seed=3, filters=("aekf",))
    q, s = study.q_sweep["Q"][0], study.q_sweep["aekf"][0]
    assert f"{q:8.0e}{s.euler_deg:17.3e}" in text, text
    assert np.isfinite(s.euler_deg)
