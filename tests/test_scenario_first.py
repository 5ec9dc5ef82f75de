"""Issue 23: ``scenario`` first everywhere, the earlier argument order accepted with a warning until 0.3.

One test per family of decorated functions: the present order raises no
DeprecationWarning, the earlier order gives the same result (the same function
underneath, so the expected values are exact equality with the present order's)
and warns naming the function. Sun 2011's own functions are in
tests/test_sun2011_api.py. A last test scans the package: no public function
has a positional ``scenario`` that is not first (independent count: the AST).
"""

import ast
import pathlib
import warnings

import numpy as np
import pandas as pd
import pytest

import hinfnav
from hinfnav.campaign.registry import build_scenario, registered_scenarios
from hinfnav.design.result import DesignResult
from hinfnav.estimators.registry import build_estimator, fit_reason
from hinfnav.papers import attitude2018, benchmark, shi2018, sun2011, yang2020
from hinfnav.papers.attitude2018.chaser import run_passes
from hinfnav.papers.attitude2018.studies import filter_stats, run_batched, run_filter
from hinfnav.papers.benchmark.estimators import build_generic
from hinfnav.papers.shi2018.studies import CaseResult, FilterStats
from hinfnav.papers.yang2020.studies import theta_readings_study
from hinfnav.sim.engine import _names_estimators, resolve_estimator, resolve_estimators
from hinfnav.sim.nonlinear import simulate_nonlinear_truth

SUN = sun2011.Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))
ATT = attitude2018.Scenario(orbits=0.01)  # a few dozen steps of 1 s


def new_order(func, *args, **kwargs):
    """Call in the present order, failing on any DeprecationWarning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        return func(*args, **kwargs)


def old_order(func, *args, **kwargs):
    """Call in the earlier order, requiring the warning that names the function."""
    with pytest.warns(DeprecationWarning, match=rf"{func.__name__}\(.*earlier argument order.*0\.3"):
        return func(*args, **kwargs)


def test_registry_build_estimator_and_fit_reason():
    assert old_order(build_estimator, "ekf", SUN).name == new_order(build_estimator, SUN, "ekf").name == "ekf"
    assert old_order(hinfnav.build_estimator, "hbf", SUN, gamma=2.0).name == "hbf"
    att = build_scenario("attitude2018")
    assert old_order(fit_reason, "ukf", att) == new_order(fit_reason, att, "ukf")
    assert "quaternion" in new_order(fit_reason, att, "ukf")
    assert new_order(fit_reason, SUN, "ekf") is None and new_order(fit_reason, scenario=SUN, name="ekf") is None
    with pytest.raises(TypeError, match="at most 2 positional"):
        build_estimator("ekf", SUN, "extra")
    # a name in both places is read in the present order: a scenario wrongly given as a str is named as such
    with pytest.raises(hinfnav.InputError, match=r"does not fit this scenario \(str"):
        new_order(build_estimator, "sun2011", "ekf")


def test_engine_resolve_estimator_and_estimators():
    ekf = build_estimator(SUN, "ekf")
    for given in ("ekf", ekf):
        assert old_order(resolve_estimator, given, SUN).name == new_order(resolve_estimator, SUN, given).name == "ekf"
    for given in (["ekf", "published"], {"a": "ekf", "b": ekf}):
        assert list(old_order(resolve_estimators, given, SUN)) == list(new_order(resolve_estimators, SUN, given))
    # a design as the earlier first argument is recognised (its module is loaded whenever a design exists)
    design = DesignResult(A_F=np.eye(1), B_F=np.eye(1), C_F=np.eye(1), gamma=1.0, lmi_gamma=1.0, verified_norm=1.0,
                             sample_norms=np.array([1.0]), worst_sample=0, spectral_radius=0.5, solver="x",
                             solve_time_s=0.0, total_time_s=0.0, method="minimize", uncertainty_bound=0.0,
                             sample_values=np.array([0.0]))
    assert _names_estimators(design)


def test_no_scenario_looks_like_an_earlier_first_argument():
    # the earlier-order tests must never take a scenario for what came first before (a name, a builder,
    # estimators, a table or a result): every registered campaign scenario and every paper's own
    scenarios = [build_scenario(k) for k in registered_scenarios()]
    scenarios += [SUN, ATT, shi2018.Scenario(), yang2020.Scenario(n_steps=10)]
    for sc in scenarios:
        assert not isinstance(sc, (str, pd.DataFrame, CaseResult, yang2020.LoopResult)), type(sc)
        assert not callable(sc) and not _names_estimators(sc), type(sc)


def test_attitude2018_builders_and_statistics():
    assert old_order(attitude2018.build_attitude_filter, "aekf", ATT).name == "aekf"
    assert new_order(attitude2018.build_attitude_filter, ATT, "aekf").name == "aekf"
    truth = simulate_nonlinear_truth(ATT.truth_model(), runs=2, seed=3)
    est = attitude2018.build_aekf(ATT)
    new = new_order(run_filter, ATT, "aekf", est, truth)
    old = old_order(run_filter, "aekf", est, truth, ATT)
    np.testing.assert_array_equal(old.euler_rms_deg, new.euler_rms_deg)
    err = truth.state.error(truth.x, est.estimate(truth.y, truth.u, ATT.xhat0).xhat)
    a, b = new_order(filter_stats, ATT, "x", err, truth.t), old_order(filter_stats, "x", err, truth.t, ATT)
    np.testing.assert_array_equal(a.torque_rms_Nm, b.torque_rms_Nm)
    a = new_order(run_batched, ATT, attitude2018.build_aekf, "Q", [1e-14, 1e-12], truth)
    b = old_order(run_batched, attitude2018.build_aekf, "Q", [1e-14, 1e-12], truth, ATT)
    assert [s.label for s in a] == [s.label for s in b] == ["Q=1e-14", "Q=1e-12"]
    np.testing.assert_array_equal(a[1].euler_rms_deg, b[1].euler_rms_deg)
    passes = [(truth, {"Q": 1e-14})]
    a = new_order(run_passes, ATT, attitude2018.build_aekf, passes)[0]
    b = old_order(run_passes, attitude2018.build_aekf, passes, ATT)[0]
    np.testing.assert_array_equal(a[0], b[0])


def _maneuver_case(sc):
    """A made-up maneuver case: every filter's mean x-velocity error falls from Δv to 0 linearly over 100 s."""
    t = np.arange(0.0, sc.maneuver_time_s + 400.0, 10.0)
    err = np.zeros((t.size, 6))
    dv = float(sc.maneuver_dv()[3])
    err[:, 3] = np.where(t < sc.maneuver_time_s, 0.0, dv * np.clip(1 - (t - sc.maneuver_time_s) / 100.0, 0.0, 1.0))
    stats = FilterStats(per_run=np.zeros((1, 6)), windows={}, jitter=np.zeros((1, 6)), max_abs=np.zeros((1, 6)),
                        mean_error=err, rms_error=np.abs(err), single=err)
    return CaseResult(case="maneuver", t=t, runs=1, seed=0, window_s=(0.0, 1.0), filters={"ekf": stats, "hbf": stats})


def test_shi2018_maneuver_functions():
    sc = shi2018.Scenario()
    case = _maneuver_case(sc)
    new = new_order(shi2018.maneuver_reaction, sc, case)
    assert old_order(shi2018.maneuver_reaction, case, sc) == new
    # closed form of the made-up case: the error is Δv/2 at 50 s after the maneuver, so the first sample
    # strictly below it (10 s samples) is at 60 s
    assert new["ekf"]["t_half_s"] == pytest.approx(60.0, abs=1e-9)
    fig = new_order(shi2018.maneuver_figure, sc, case)
    assert len(fig.axes) == 2
    assert len(old_order(shi2018.maneuver_figure, case, sc).axes) == 2


def test_yang2020_theta_readings_study():
    sc = yang2020.Scenario(n_steps=60)
    loop = yang2020.run_closed_loop(sc, controller="dragfree_off", passive=True, passive_steps=60)
    new = new_order(theta_readings_study, sc, loop)
    old = old_order(theta_readings_study, loop, sc)
    assert new.keys() == old.keys() and new["saturated_fraction"] == old["saturated_fraction"]


def test_benchmark_functions():
    shi = shi2018.Scenario()
    assert old_order(build_generic, "ekf", shi).name == new_order(build_generic, shi, "ekf").name == "model_ekf"
    table = pd.DataFrame({"scenario": ["s"] * 2, "quantity": ["pos"] * 2, "estimator": ["a", "b"],
                          "condition": ["c"] * 2, "ratio": [1.0, 2.0], "bound_kind": ["riccati"] * 2})
    assert new_order(benchmark.plot_scenario_heatmap, "s", table).axes[0].get_title().startswith("s: pos")
    assert old_order(benchmark.plot_scenario_heatmap, table, "s").axes[0].get_title().startswith("s: pos")
    # benchmark_table's optional scenario is keyword-only; positional (earlier) still reaches the function
    empty = pd.DataFrame({"kind": []})
    with pytest.raises(hinfnav.InputError, match="no cell"):
        new_order(benchmark.benchmark_table, empty, scenario=SUN)
    with pytest.raises(hinfnav.InputError, match="no cell"):
        old_order(benchmark.benchmark_table, empty, SUN)


def test_no_public_function_has_a_positional_scenario_after_another_parameter():
    root = pathlib.Path(hinfnav.__file__).parent
    late = []
    for path in root.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
                pos = [a.arg for a in node.args.posonlyargs + node.args.args if a.arg not in ("self", "cls")]
                if "scenario" in pos[1:]:
                    late.append(f"{path.relative_to(root)}:{node.lineno} {node.name}")
    assert late == []
