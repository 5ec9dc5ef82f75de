"""Issue 23, item 1: every paper's ``reproduce`` goes through one skeleton (hinfnav.papers.skeleton).

(a) Every figure file and every ``summary.json`` of every paper carries the run's provenance. shi2018,
    yang2020, grace2010 and benchmark are run for real at a reduced size and their files read back;
    sun2011 and attitude2018 cost too much to run small (their designs and Monte Carlo tables), so their
    ``reproduce`` runs with the skeleton's figure writer replaced by a counter (no drawing) and any
    ``Figure.savefig`` outside it fails the test.
(b) ``reproduce --notebooks`` executes each notebook exactly once for ``--paper papers`` and ``--paper all``:
    the executor is replaced by a counter of paths.
(c) Every notebook of notebooks/ belongs to exactly one paper's ``NOTEBOOKS`` or to the cross-paper list.
The expected values are the paper keys, the file names the papers write and the notebooks folder's listing.
"""

import collections
import functools
import importlib
import json

import matplotlib.figure
import pytest

import hinfnav.papers as papers
import hinfnav.papers.notebooks as nbmod
from hinfnav import cli
from hinfnav.papers import skeleton
from hinfnav.plotting.save import read_provenance

KEYS = ("sun2011", "shi2018", "attitude2018", "yang2020", "grace2010", "benchmark")
MODULES = {k: importlib.import_module(f"hinfnav.papers.{k}.reproduce") for k in KEYS}
#: Papers whose reproduce is too long to run small inside the ~30 s budget of this file.
COUNTED = ("sun2011", "attitude2018")
SEED = 3


def _small_options(key, monkeypatch):
    """The options of a reduced run of ``key`` (and the patches it needs)."""
    if key == "shi2018":
        from hinfnav.papers.shi2018 import Scenario

        sc = Scenario(duration_s=60.0, maneuver_time_s=30.0, rms_window_s=(10.0, 60.0))
        return {"runs": 2, "workers": 1, "scenario": sc}
    if key == "yang2020":
        from hinfnav.papers.yang2020 import Scenario

        return {"scenario": Scenario(n_steps=400, settle_s=5.0), "open_loop_steps": 100, "reading_steps": 400,
                "integral_steps": 100}
    if key == "grace2010":  # the real day, cut to 400 epochs, two variants, one filter, no LMI design
        mod = MODULES[key]
        monkeypatch.setattr(mod, "run_study", functools.partial(mod.run_study, n_epochs=400, designs=False,
                                                                variants=("gnss", "kband_angles"),
                                                                filters=("ekf_hill",)))
        return {}
    if key == "benchmark":
        return {"runs": 1, "client": "serial", "scenarios": ("sun2011",), "bound_runs": 1,
                "grids": {"sun2011": {"maneuver": [False], "delta": [0.0], "noise": ["gaussian"]}},
                "estimators": {"sun2011": ("published",)}}
    if key == "attitude2018":
        from hinfnav.papers.attitude2018 import Scenario

        return {"runs": 2, "scenario": Scenario(orbits=0.25), "chaser": False}
    return {"runs": 1}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Each paper's reproduce with notebooks=True: its folder, its summary, the notebooks and figures it sent."""
    out = {}
    mp = pytest.MonkeyPatch()
    executed = []
    mp.setattr(nbmod, "execute_notebook", lambda path, target, timeout=900: executed.append(path.name) or target)
    try:
        for key in KEYS:
            counted = []
            with pytest.MonkeyPatch.context() as m:
                if key in COUNTED:
                    m.setattr(skeleton, "save_figure", lambda fig, d, name, prov, formats, dpi, c=counted:
                              c.append((name, prov)) or [])
                    m.setattr(matplotlib.figure.Figure, "savefig",
                              lambda *a, **k: pytest.fail("a figure saved outside the skeleton"))
                d = tmp_path_factory.mktemp(key)
                start = len(executed)
                summary = papers.PAPERS[key](d, seed=SEED, notebooks=True, progress=False, **_small_options(key, m))
            out[key] = {"dir": d, "summary": summary, "notebooks": executed[start:], "counted": counted}
    finally:
        mp.undo()
    return out


@pytest.mark.parametrize("key", KEYS)
def test_summary_json_carries_the_provenance(runs, key):
    r = runs[key]
    on_disk = json.loads((r["dir"] / "summary.json").read_text())
    prov = on_disk["provenance"]
    assert prov["paper"] == key and prov["seed"] == SEED and prov["hinfnav"] and prov["date_utc"]
    assert set(prov["libraries"]) >= {"numpy", "scipy", "matplotlib"}
    assert json.dumps(r["summary"]) == json.dumps(on_disk)  # what reproduce returns is what it wrote (NaN too)
    assert not list(r["dir"].glob(".*.tmp"))  # the atomic write left no temporary file


@pytest.mark.parametrize("key", [k for k in KEYS if k not in COUNTED])
def test_every_figure_file_carries_the_provenance(runs, key):
    r = runs[key]
    prov = json.loads((r["dir"] / "summary.json").read_text())["provenance"]
    files = sorted(r["dir"].glob("*.png")) + sorted(r["dir"].glob("*.pdf"))
    assert len(files) >= 2
    for f in files:
        assert read_provenance(f) == prov, f  # the same run's provenance in every file


@pytest.mark.parametrize("key", COUNTED)
def test_every_figure_goes_through_the_skeleton(runs, key):
    r = runs[key]
    prov = r["summary"]["provenance"]
    names = [n for n, _ in r["counted"]]
    expected = {"sun2011": [f"fig{i}" for i in range(2, 8)],
                "attitude2018": [f"fig{i}" for i in range(1, 10)] + ["fig10_q_sweep", "fig11_tuning"]}[key]
    assert names == expected  # the figures the paper's docstring lists, each once
    assert all(p == prov for _, p in r["counted"])
    assert not list(r["dir"].glob("*.png")) and not list(r["dir"].glob("*.pdf"))  # none written around it


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
    cli.main(["reproduce", "--paper", selection, "--notebooks", "--out", str(tmp_path / "out")])
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
