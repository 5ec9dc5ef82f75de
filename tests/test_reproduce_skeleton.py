"""Issue 23, item 1: every paper's ``reproduce`` goes through one skeleton (hinfnav.papers.skeleton).

(a) Every paper (sun2011, shi2018, attitude2018, yang2020, grace2010, benchmark) runs its ``reproduce`` once
    at a reduced size with ``notebooks=True``; its ``summary.json`` is read back for the provenance block.
    Drawing the figures would cost most of this file's time, so the skeleton's figure writer is replaced
    by a recorder (every figure the paper hands over, with the provenance it would write) and any
    ``Figure.savefig`` outside it fails the test. That the skeleton's writer puts the provenance into the
    PNG and PDF files is checked here on a small figure, read back from the files; the paper-size files
    are checked in the papers' own reproduce tests (tests/test_<key>_reproduce.py).
(b) ``reproduce --notebooks`` executes each notebook exactly once for ``--paper papers`` and ``--paper all``:
    the executor is replaced by a counter of paths.
(c) Every notebook of notebooks/ belongs to exactly one paper's ``NOTEBOOKS`` or to the cross-paper list.

The expected values are the paper keys, the figure names each paper's ``reproduce`` docstring lists and the
notebooks folder's listing.
"""

import collections
import importlib
import json
import os

import matplotlib.backend_bases
import matplotlib.figure
import numpy as np
import pytest

import hinfnav.papers as papers
import hinfnav.papers.notebooks as nbmod
from hinfnav import cli
from hinfnav.core.exceptions import InputError
from hinfnav.papers import skeleton
from hinfnav.plotting.errors import new_figure
from hinfnav.plotting.save import read_provenance

KEYS = ("sun2011", "shi2018", "attitude2018", "yang2020", "grace2010", "benchmark")
MODULES = {k: importlib.import_module(f"hinfnav.papers.{k}.reproduce") for k in KEYS}
SEED = 3
#: The figures each paper's ``reproduce`` docstring lists (attitude2018 without its chaser study, fig12).
FIGURES = {
    "sun2011": [f"fig{i}" for i in range(2, 8)],
    "shi2018": ["fig3", "fig4", "fig5", "fig6", "maneuver_reaction", "mixture_position", "mixture_velocity", "sweeps"],
    "attitude2018": [f"fig{i}" for i in range(1, 10)] + ["fig10_q_sweep", "fig11_tuning"],
    "yang2020": [f"fig{i}" for i in range(5, 13)],
    "grace2010": ["errors_gnss", "errors_kband_angles", "mismatch", "truth"],
    "benchmark": ["heatmap_sun2011"],
}


def _small_options(key, monkeypatch):
    """The options of a reduced run of ``key`` (and the patches it needs): CPU seconds, not the paper's size."""
    if key == "sun2011":  # the EKF windows of Table 1 end at 1000 s and the published filter needs T = 0.1 s
        return {"runs": 1}
    if key == "shi2018":
        from hinfnav.papers.shi2018 import Scenario

        sc = Scenario(duration_s=40.0, maneuver_time_s=20.0, rms_window_s=(10.0, 40.0))
        return {"runs": 2, "workers": 1, "scenario": sc}
    if key == "attitude2018":
        from hinfnav.papers.attitude2018 import Scenario

        return {"runs": 2, "scenario": Scenario(orbits=0.25), "chaser": False}
    if key == "yang2020":
        from hinfnav.papers.yang2020 import Scenario

        return {"scenario": Scenario(n_steps=400, settle_s=5.0), "open_loop_steps": 100, "reading_steps": 400,
                "integral_steps": 100}
    if key == "grace2010":  # the real day, cut to 400 epochs, two variants, one filter, no LMI design
        mod = MODULES[key]
        run_study = mod.run_study
        monkeypatch.setattr(mod, "run_study", lambda data, **kw: run_study(
            data, **kw, n_epochs=400, designs=False, variants=("gnss", "kband_angles"), filters=("ekf_hill",)))
        return {}
    return {"runs": 1, "client": "serial", "scenarios": ("sun2011",), "bound_runs": 1,  # benchmark
            "grids": {"sun2011": {"maneuver": [False], "delta": [0.0], "noise": ["gaussian"]}},
            "estimators": {"sun2011": ("published",)}}


def _no_drawing(*args, **kwargs):
    pytest.fail("a figure was saved outside the skeleton's figure writer")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Each paper's reproduce with notebooks=True: its folder, its summary, the notebooks and figures it sent."""
    out = {}
    executed = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(nbmod, "execute_notebook", lambda path, target, timeout=900: executed.append(path.name) or target)
        mp.setattr(matplotlib.figure.Figure, "savefig", _no_drawing)
        mp.setattr(matplotlib.backend_bases.FigureCanvasBase, "print_figure", _no_drawing)
        for key in KEYS:
            figures = []
            mp.setattr(skeleton, "save_figure", lambda fig, d, name, prov, formats, dpi, f=figures:
                       f.append((name, fig, prov, tuple(formats))) or [])
            with pytest.MonkeyPatch.context() as m:
                d = tmp_path_factory.mktemp(key)
                start = len(executed)
                summary = papers.PAPERS[key](d, seed=SEED, notebooks=True, progress=False, **_small_options(key, m))
            out[key] = {"dir": d, "summary": summary, "notebooks": executed[start:], "figures": figures}
    return out


@pytest.mark.parametrize("key", KEYS)
def test_summary_json_carries_the_provenance(runs, key):
    r = runs[key]
    on_disk = json.loads((r["dir"] / "summary.json").read_text())
    prov = on_disk["provenance"]
    assert prov["paper"] == key and prov["seed"] == SEED and prov["hinfnav"] and prov["date_utc"]
    assert set(prov["libraries"]) >= {"numpy", "scipy", "matplotlib"}
    assert json.dumps(r["summary"]) == json.dumps(on_disk)  # what reproduce returns is what it wrote (NaN too)
    assert not list(r["dir"].glob(".*.tmp"))  # the atomic writes left no temporary file


@pytest.mark.parametrize("key", KEYS)
def test_every_figure_goes_through_the_skeleton_with_the_provenance(runs, key):
    r = runs[key]
    prov = r["summary"]["provenance"]
    names = [name for name, *_ in r["figures"]]
    assert sorted(names) == sorted(FIGURES[key]) and len(set(names)) == len(names)  # each listed figure, once
    for name, fig, p, formats in r["figures"]:
        assert isinstance(fig, matplotlib.figure.Figure), name
        assert p == prov and set(formats) >= {"png"}, name  # the summary's provenance goes into every file
    assert not list(r["dir"].glob("*.png")) and not list(r["dir"].glob("*.pdf"))  # nothing written around it


def test_the_skeleton_writes_the_provenance_into_png_pdf_and_summary(tmp_path):
    rep = skeleton.Reproduction(tmp_path / "out", "sun2011", progress=False, seed=7, runs=2)
    fig, axes = new_figure()
    ax = axes.flat[0]
    ax.plot([0.0, 1.0], [0.0, 1.0], label="a line")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("e (m)")
    ax.legend()
    paths = rep.save_figure(fig, "tiny")
    assert [p.name for p in paths] == ["tiny.png", "tiny.pdf"]
    for p in paths:
        assert read_provenance(p) == rep.provenance, p  # read back from the file's metadata
    assert rep.provenance["paper"] == "sun2011" and rep.provenance["seed"] == 7 and rep.provenance["runs"] == 2
    written = rep.write_summary({"x": np.float64(1.5), "bad": float("nan"), "provenance": "stale"}, strict=True)
    on_disk = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert on_disk == written == {"x": 1.5, "bad": None, "provenance": rep.provenance}  # strict: NaN → null
    assert rep.written == [*paths, tmp_path / "out" / "summary.json"]


def test_an_interrupted_summary_write_leaves_the_previous_file(tmp_path, monkeypatch):
    rep = skeleton.Reproduction(tmp_path, "shi2018", progress=False)
    rep.write_summary({"run": 1})

    def crash(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError, match="disk full"):
        rep.write_summary({"run": 2})
    assert json.loads((tmp_path / "summary.json").read_text())["run"] == 1  # never half a file


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"paper": ""}, "paper must be"),
    ({"paper": "sun2011", "formats": "png"}, "formats must be"),
    ({"paper": "sun2011", "notebooks": "01_model_and_scenario.ipynb"}, "names must be a sequence"),
    ({"paper": "sun2011", "notebooks": ("no_such_notebook.ipynb",)}, "no_such_notebook.ipynb not in"),
])
def test_bad_skeleton_input_is_refused_before_any_work(tmp_path, kwargs, match):
    with pytest.raises(InputError, match=match):
        skeleton.Reproduction(tmp_path / "never", **kwargs)
    assert not (tmp_path / "never").exists()


def test_a_summary_that_is_not_a_dict_is_refused(tmp_path):
    with pytest.raises(InputError, match="summary must be a dict"):
        skeleton.Reproduction(tmp_path, "sun2011", progress=False).write_summary([1, 2])


@pytest.mark.parametrize("key", KEYS)
def test_each_paper_executes_its_own_notebook_list_once(runs, key):
    expected = MODULES[key].NOTEBOOKS + (nbmod.CROSS_PAPER if key == papers.PRIMARY else ())
    assert runs[key]["notebooks"] == list(expected)


@pytest.mark.parametrize("selection", ["papers", "all"])
def test_reproduce_notebooks_executes_each_notebook_once(runs, selection, tmp_path, monkeypatch):
    # the papers' own calls (measured above, each paper for real) add up over the selection ...
    per_notebook = collections.Counter(n for k in papers.SELECTIONS[selection] for n in runs[k]["notebooks"])
    assert per_notebook and set(per_notebook.values()) == {1}, per_notebook
    if selection == "all":
        assert set(per_notebook) == {p.name for p in nbmod.NOTEBOOK_DIR.glob("*.ipynb")}
    # ... and the command runs each paper of the selection once with --notebooks, each calling its list
    calls = collections.Counter()

    def stand_in(key):
        def reproduce(out_dir, *, seed=0, runs=None, notebooks=False, progress=True):
            assert notebooks
            names = MODULES[key].NOTEBOOKS + (nbmod.CROSS_PAPER if key == papers.PRIMARY else ())
            skeleton.Reproduction(out_dir, key, notebooks=names, progress=False).run_notebooks()
            return {}
        return reproduce

    monkeypatch.setattr(nbmod, "execute_notebook", lambda path, target, timeout=900: calls.update([path]) or target)
    monkeypatch.setattr(papers, "PAPERS", {k: stand_in(k) for k in KEYS})
    # --jobs 1: the stand-ins and the counter live in this process (worker processes would not see them)
    cli.main(["reproduce", "--paper", selection, "--notebooks", "--jobs", "1", "--out", str(tmp_path / "out")])
    assert calls and set(calls.values()) == {1}
    assert {p.name for p in calls} == set(per_notebook)


def test_every_notebook_belongs_to_exactly_one_list():
    lists = {k: MODULES[k].NOTEBOOKS for k in KEYS} | {"cross_paper": nbmod.CROSS_PAPER}
    owners = collections.defaultdict(list)
    for owner, names in lists.items():
        assert isinstance(names, tuple), owner
        for n in names:
            owners[n].append(owner)
    on_disk = {p.name for p in nbmod.NOTEBOOK_DIR.glob("*.ipynb")}
    assert set(owners) == on_disk  # no notebook left out, none listed that does not exist
    assert {n: o for n, o in owners.items() if len(o) != 1} == {}
