"""Campaigns on Dask (issue 13): determinism across workers, resume, clear errors for bad specs.

Every campaign here runs Sun 2011's chaser shortened to 20 s (200 steps), so
the whole file takes seconds; the full-size benchmark is
``python -m hinfnav reproduce --paper benchmark``.
"""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import hinfnav.papers  # noqa: F401 - registers Sun 2011's scenario and estimators
from hinfnav.campaign import Campaign, load_campaign, run_campaign
from hinfnav.cli import main
from hinfnav.core.exceptions import InputError
from hinfnav.estimators.registry import _REGISTRY, build_estimator, register_estimator
from hinfnav.metrics.streaming import monte_carlo_statistics
from hinfnav.papers.benchmark import benchmark_campaign, benchmark_table, cell_kalman_limit, format_markdown
from hinfnav.papers.sun2011 import Scenario, kalman_limit

SHORT = {"duration_s": [20.0], "rms_window_s": [[0.0, 20.0]]}
WINDOWS = {"early": [0.0, 10.0], "late": [5.0, 20.0]}


def _spec(**changes):
    grid = {"scenario": "sun2011", "estimator": ["published", "ekf"], "maneuver": [True, False],
            "noise": ["gaussian", "mixture"], **SHORT}
    grid.update(changes.pop("grid", {}))
    return Campaign(**{"grid": grid, "runs": 5, "batch_size": 2, "windows": WINDOWS, "seed": 3,
                       "tol": [5, 5, 5, 1, 1, 1], **changes})


def test_two_worker_cluster_gives_bitwise_the_serial_numbers(tmp_path):
    spec = _spec()
    serial = run_campaign(spec, client="serial", progress=False)
    cluster = run_campaign(spec, workers=2, out_dir=tmp_path / "c", progress=False)
    assert len(serial) > 0 and serial.attrs["computed"] == len(spec.cells()) == 8
    # bitwise: the same spec and seed give the same numbers whatever the number of workers or the order of completion
    pd.testing.assert_frame_equal(serial, cluster, check_exact=True)
    # and whether the estimators of a grid point share one truth task or run one task each
    apart = run_campaign(_spec(share_truth=False), client="serial", progress=False)
    pd.testing.assert_frame_equal(serial, apart, check_exact=True)
    # the CSV written by the cluster run holds the same numbers (shortest round-trip floats)
    csv = pd.read_csv(tmp_path / "c" / "results.csv")
    assert np.array_equal(csv["value"].to_numpy(), serial["value"].to_numpy(), equal_nan=True)


def test_cell_statistics_equal_the_streaming_monte_carlo():
    """Independent path: hinfnav.monte_carlo_statistics on the cell's seed gives the same numbers.

    Per-run RMS (hence the Monte Carlo mean and interval) and maxima bitwise; the pooled RMS to 1e-14 relative
    (the sums over a window run in another order: over a view here, over a copy there).
    """
    spec = _spec(grid={"estimator": ["ekf"], "maneuver": [True], "noise": ["mixture"]})
    table = run_campaign(spec, client="serial", progress=False)
    cell = spec.cells()[0]
    ref = monte_carlo_statistics(Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0)), "ekf", windows=spec.windows,
                                 runs=5, seed=cell.seed, noise="mixture", batch_size=2, maneuver=True)
    for w in WINDOWS:
        sub = table[(table.window == w) & (table.kind == "component")]
        for stat, ours in (("mc_mean", ref[w].mean), ("max_abs", ref[w].max_abs), ("ci95_low", ref[w].ci95[0])):
            assert np.array_equal(sub[sub.statistic == stat].value.to_numpy(), ours), (w, stat)
        np.testing.assert_allclose(sub[sub.statistic == "rms_pooled"].value.to_numpy(), ref[w].pooled, rtol=1e-14)


def test_seeds_come_from_the_cell_not_from_the_grid_or_the_estimator():
    small = {(c.estimator, c.params["maneuver"]): c for c in _spec(grid={"noise": ["gaussian"]}).cells()}
    large = {(c.estimator, c.params["noise"], c.params["maneuver"]): c for c in _spec().cells()}
    ekf = large[("ekf", "gaussian", True)]
    assert small[("ekf", True)].cell_id == ekf.cell_id and small[("ekf", True)].seed == ekf.seed
    assert large[("published", "gaussian", True)].seed == ekf.seed  # common random numbers across estimators
    assert large[("ekf", "mixture", True)].seed != ekf.seed
    assert _spec(seed=4).cells()[0].seed != _spec().cells()[0].seed


@pytest.fixture
def counting():
    """A registered estimator that counts its runs (the published filter inside) and can stop the campaign."""
    calls = {"n": 0, "stop_at": None}

    class Counting:
        def __init__(self, inner):
            self.inner, self.measurement, self.name = inner, inner.measurement, "test_counting"

        def estimate(self, *args, **kwargs):
            calls["n"] += 1
            if calls["stop_at"] == calls["n"]:
                raise KeyboardInterrupt  # what Ctrl-C does in the middle of a campaign
            return self.inner.estimate(*args, **kwargs)

    register_estimator("test_counting", lambda sc, **kw: Counting(build_estimator(sc, "published")),
                       fits=lambda sc: isinstance(sc, Scenario))
    yield calls
    _REGISTRY.pop("test_counting", None)


def test_interrupted_campaign_resumes_without_recomputing_finished_cells(tmp_path, counting):
    # 4 cells, one truth each, one batch each: one estimate() call per cell
    spec = _spec(grid={"estimator": ["test_counting"], "maneuver": [True], "delta": [0.0, 1.0],
                       "noise": ["gaussian", "student_t"]}, batch_size=5)
    counting["stop_at"] = 3
    with pytest.raises(KeyboardInterrupt):
        run_campaign(spec, client="serial", out_dir=tmp_path / "run", progress=False)
    assert len(list((tmp_path / "run" / "cells").glob("*.json"))) == 2  # the two finished cells, whole
    assert not list((tmp_path / "run" / "cells").glob(".*"))  # no half-written file
    counting.update(n=0, stop_at=None)
    resumed = run_campaign(spec, client="serial", out_dir=tmp_path / "run", progress=False)
    assert counting["n"] == 2 and resumed.attrs["computed"] == 2 and resumed.attrs["reused"] == 2
    again = run_campaign(spec, client="serial", out_dir=tmp_path / "run", progress=False)
    assert counting["n"] == 2 and again.attrs["computed"] == 0  # a finished campaign computes nothing
    fresh = run_campaign(spec, client="serial", out_dir=tmp_path / "fresh", progress=False)
    pd.testing.assert_frame_equal(resumed, fresh, check_exact=True)


@pytest.mark.parametrize("change, field", [
    ({"grid": {"estimator": ["no_such_filter"]}}, "grid.estimator"),
    ({"grid": {"scenario": "no_such_scenario"}}, "grid.scenario"),
    ({"grid": {"no_such_parameter": [1, 2]}}, "grid.no_such_parameter"),
    ({"grid": {"delta": []}}, "grid.delta"),
    ({"grid": {"noise": ["pink"]}}, "grid.noise"),
    ({"grid": {"delta": [-2.0]}}, "delta"),
    ({"runs": 0}, "runs"),
    ({"windows": {"late": [5.0, 50.0]}}, "windows.late"),
    ({"windows": {}}, "windows"),
    ({"tol": [1.0, 2.0]}, "tol"),
])
def test_bad_specs_are_refused_naming_the_field(change, field):
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        run_campaign(_spec(**change), client="serial", progress=False)


def test_bad_spec_files_and_clients(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("runs = 5\n[grid]\nscenario = 'sun2011'\nestimator = 'ekf'\n[windows]\nall = [0, 20]\nfoo = 1\n")
    with pytest.raises(InputError, match="windows.foo"):
        load_campaign(path)
    path.write_text("runs = [\n")
    with pytest.raises(InputError, match="spec.*not valid TOML"):
        load_campaign(path)
    with pytest.raises(InputError, match="spec: no campaign file"):
        load_campaign(tmp_path / "missing.toml")
    with pytest.raises(InputError, match="unknown field 'colour'"):
        Campaign.from_dict({"grid": {"scenario": "sun2011", "estimator": "ekf"}, "runs": 1, "windows": WINDOWS,
                            "colour": 1})
    with pytest.raises(InputError, match="scheduler: cannot connect"):  # nothing listens on port 1 of loopback
        run_campaign(_spec(), client="tcp://127.0.0.1:1", connect_timeout=1, progress=False)
    with pytest.raises(InputError, match="workers"):
        run_campaign(_spec(), client="serial", workers=2, progress=False)


def test_toml_spec_and_command_line(tmp_path, capsys):
    path = tmp_path / "c.toml"
    path.write_text(
        'name = "cli"\nruns = 5\nseed = 3\nbatch_size = 2\ntol = [5, 5, 5, 1, 1, 1]\n'
        '[grid]\nscenario = "sun2011"\nestimator = ["published", "ekf"]\nmaneuver = [true, false]\n'
        'noise = ["gaussian", "mixture"]\nduration_s = [20]\nrms_window_s = [[0, 20]]\n'
        '[windows]\nearly = [0, 10]\nlate = [5, 20]\n')
    assert [c.cell_id for c in load_campaign(path).cells()] == [c.cell_id for c in _spec().cells()]
    assert main(["campaign", str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial"]) == 0
    assert "8 cells (8 computed, 0 reused)" in capsys.readouterr().out
    table = pd.read_csv(tmp_path / "out" / "results.csv")
    assert set(table["estimator"]) == {"published", "ekf"} and len(table) == 8 * (2 * 8 * 9 + 3 + 2 + 2 * 2 * 5)  # + diverged, diverged_runs; NEES/NIS x 5 per window
    cell = json.loads(next((tmp_path / "out" / "cells").glob("*.json")).read_text())
    assert cell["status"] == "ok" and cell["runs"] == 5
    with pytest.raises(SystemExit):  # argparse: --workers applies to the LocalCluster only
        main(["campaign", str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial", "--workers", "2"])


def test_benchmark_limits_and_table():
    sc = Scenario()
    for maneuver in (True, False):
        ref = kalman_limit(sc, maneuver=maneuver)  # the workbook's own limit at delta = 0
        lim = cell_kalman_limit(sc, maneuver=maneuver, delta=0.0)
        assert lim["pos_m"] == pytest.approx(np.sqrt(np.mean(ref.pos_m ** 2)), rel=1e-12)
        assert lim["vel_mps"] == pytest.approx(np.sqrt(np.mean(ref.vel_mps ** 2)), rel=1e-12)
    # README: filtered limit 0.0626 m, 0.0224 m/s per axis without maneuver
    assert cell_kalman_limit(sc, maneuver=False, delta=5.0)["pos_m"] == pytest.approx(0.0626, abs=2e-3)
    camp = benchmark_campaign(runs=200, estimators=["published", "ekf", "hbf"])
    assert len(camp.cells()) == 3 * 24  # every estimator on every cell: 2 maneuvers x 3 deltas x 4 noises (issue 13)
    spec = _spec(grid={"delta": [0.0, 1.0]}, windows={"early": [0.0, 10.0], "steady": [5.0, 20.0]})
    table = benchmark_table(run_campaign(spec, client="serial", progress=False), scenario=Scenario())
    assert len(table) == 16 and np.all(table["pos_steady_ratio"] > 0)
    assert "| `published` |" in format_markdown(table)


def test_example_campaign_file_is_valid():
    spec = load_campaign(Path(__file__).resolve().parents[1] / "benchmarks" / "campaign_example.toml")
    assert len(spec.cells()) == 5 * 2 * 2 * 2 and spec.runs == 200


def test_table_attrs_cells_are_not_copied_with_the_table():
    # pandas deep-copies attrs on every new frame (a selection, a row of itertuples): the cell results are
    # read-only records kept as one object, so iterating a benchmark-size table stays fast (issue 13)
    import copy

    from hinfnav.campaign.registry import PROVIDER_GROUP, providers

    table = run_campaign(_spec(grid={"estimator": ["ekf"], "maneuver": [True], "noise": ["gaussian"]}),
                         client="serial", progress=False)
    cells = table.attrs["cells"]
    assert len(cells) == 1 and cells[0]["status"] == "ok"
    assert copy.deepcopy(cells) is cells and table.iloc[:2].attrs["cells"] is cells
    # scenarios come from the providers declared under the entry-point group (pyproject.toml), not by a name
    # hard-wired in the campaign layer
    assert PROVIDER_GROUP == "hinfnav.providers" and "hinfnav.papers" in providers()
