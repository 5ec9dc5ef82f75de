"""Issue 21, item 3: ``reproduce`` runs the papers of a selection in worker processes (``jobs``).

Two stand-in papers (tests/_parallel_papers.py, stdlib only: a spawned worker starts in well under a second)
replace the registry. Checked: the summaries equal those of ``jobs=1`` (same seed, same numbers; the
expected values are the serial run's), come back in the selection's order whatever order the workers take
the papers in, and were computed in other processes on one BLAS thread; every printed line of a worker
carries its paper's prefix; a paper that fails fails the whole run with its own error, stops the other
worker at once and leaves the previous output folder as it was; a bad ``jobs`` is refused before any work,
naming the parameter (function and command line).
"""

import json
import os
import time

import pytest

import hinfnav.papers as papers
from hinfnav import cli
from hinfnav.core.exceptions import InputError
from hinfnav.io.processes import PrefixedLines

import _parallel_papers as stand_in


@pytest.fixture
def two_papers(monkeypatch):
    monkeypatch.setattr(papers, "PAPERS", {"a": stand_in.paper_a, "b": stand_in.paper_b})
    monkeypatch.setattr(papers, "SELECTIONS", {"pair": ("a", "b")})
    monkeypatch.setattr(papers, "COST_S", {"b": 10, "a": 1})  # b is handed out first


def _files(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_parallel_summaries_equal_the_serial_ones_in_the_selection_order(two_papers, tmp_path, capfd):
    serial = papers.reproduce("pair", tmp_path / "serial", jobs=1, seed=7, progress=False)
    capfd.readouterr()
    par = papers.reproduce("pair", tmp_path / "par", jobs=2, seed=7, progress=True)
    printed = capfd.readouterr().out.splitlines()
    assert list(par) == ["a", "b"]  # the selection's order, though b was started first
    for key in ("a", "b"):
        assert {k: v for k, v in par[key].items() if k != "pid"} == {k: v for k, v in serial[key].items() if k != "pid"}
        assert serial[key]["pid"] == os.getpid() and par[key]["pid"] != os.getpid()
        assert par[key]["blas_threads"] == [1] and serial[key]["blas_threads"] == [1]
    assert _files(tmp_path / "serial") == _files(tmp_path / "par")  # the same files, byte for byte
    assert printed[0] == "reproducing b, a on 2 worker processes"
    for key in ("a", "b"):  # each paper's lines whole and prefixed, in its own order
        mine = [line for line in printed if line.startswith(f"[{key}] ")]
        assert mine == [f"[{key}] {key}: start", f"[{key}] {key}: half a line and the rest", f"[{key}] {key}: done"]
    assert sum(line.endswith("CPU-s)") for line in printed) == 2 and printed[-1].startswith("wrote ")


def test_a_failing_paper_fails_the_run_and_keeps_the_previous_folder(two_papers, tmp_path):
    out = tmp_path / "out"
    papers.reproduce("pair", out, jobs=2, seed=1, progress=False)
    before = _files(out)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="b failed on purpose") as err:
        papers.reproduce("pair", out, jobs=2, seed=2, progress=False, fail="b", slow="a")
    # a sleeps a minute: it was stopped, not waited for (the bound leaves room for a loaded machine)
    assert time.perf_counter() - t0 < 30.0
    assert any("'b'" in note for note in err.value.__notes__)
    assert _files(out) == before  # nothing replaced, nothing half written
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no temporary folder left beside it
    assert json.loads((out / "a" / "summary.json").read_text())["numbers"] == \
        papers.reproduce("a", tmp_path / "again", seed=1, progress=False)["a"]["numbers"]


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True, "2"])
def test_bad_jobs_is_refused_before_any_work(two_papers, tmp_path, jobs):
    with pytest.raises(InputError, match=r"\bjobs\b"):
        papers.reproduce("pair", tmp_path / "o", jobs=jobs, progress=False)
    assert not (tmp_path / "o").exists()


def test_bad_jobs_on_the_command_line_names_the_option(tmp_path, capsys):
    with pytest.raises(SystemExit):
        cli.main(["reproduce", "--jobs", "0", "--out", str(tmp_path / "o")])
    assert "--jobs" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_prefixed_lines_keep_whole_lines_and_drop_bar_redraws(capsys):
    import sys

    w = PrefixedLines("[x] ", sys.stdout)
    w.write("one\ntw")
    w.write("o\r 10%\r 100%\nlast")
    w.close()
    assert capsys.readouterr().out == "[x] one\n[x]  100%\n[x] last\n"
