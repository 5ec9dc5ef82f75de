"""The slow list is measured: ``tests/update_slow_markers.py`` on a made-up ``--durations`` report (issue 37, item 8).

The expected lists follow from the rule written in the script's docstring (at least the threshold:
listed; measured under it: dropped; unmeasured and still collected: kept), applied by hand below.
"""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("update_slow_markers", ROOT / "tests" / "update_slow_markers.py")
usm = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(usm)

REPORT = """
============================= slowest durations ==============================
2.50s call     tests/test_a.py::test_slow_one
0.60s setup    tests/test_a.py::test_split
0.50s call     tests/test_a.py::test_split
0.30s call     tests/test_a.py::test_fast
1.20s call     tests/test_b.py::test_p[x-1]
0.10s call     tests/test_b.py::test_p[y-2]
3.00s call     tests/test_r.py::test_reproduce_all

(120 durations < 0.005s hidden.  Use -vv to show these durations.)
"""


def test_durations_are_summed_over_setup_call_and_teardown():
    d = usm.parse_durations(REPORT)
    assert d["tests/test_a.py::test_split"] == 1.1  # 0.60 + 0.50
    assert d["tests/test_b.py::test_p[x-1]"] == 1.2 and len(d) == 6


def test_regenerate_adds_drops_keeps_and_prunes():
    listed = {"tests/test_a.py::test_fast",        # measured at 0.3 s: dropped
              "tests/test_c.py::test_unmeasured",  # not in the run, still collected: kept
              "tests/test_gone.py::test_old",      # not in the run, no longer collected: pruned
              "tests/test_b.py::test_p"}           # a function's id, its parametrisations measured: their times decide
    existing = {"tests/test_c.py::test_unmeasured", "tests/test_a.py::test_fast"}
    new = usm.regenerate(usm.parse_durations(REPORT), listed, existing, threshold=1.0, elsewhere=("tests/test_r.py",))
    assert new == ["tests/test_a.py::test_slow_one", "tests/test_a.py::test_split", "tests/test_b.py::test_p[x-1]",
                   "tests/test_c.py::test_unmeasured"]


def test_the_committed_list_is_what_conftest_reads():
    # tests/conftest.py itself, not whichever module named conftest was imported first

    spec = importlib.util.spec_from_file_location("_tests_conftest", Path(__file__).with_name("conftest.py"))
    conftest = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conftest)
    assert conftest.SLOW == frozenset(usm.read_list()) and conftest.SLOW
