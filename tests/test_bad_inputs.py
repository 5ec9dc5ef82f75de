"""Bad and unusual inputs through the public API and the command line (issue 8, items 5 and 6).

Every row checks the exception type (an :class:`hinfnav.InputError` or a
subclass for the API; exit status 2, a message on stderr and no traceback for
the command line) and that the message names the parameter the user gave
(``D`` rather than the internal ``R``, ``L`` rather than ``C_F`` ...). The
rows marked "was:" failed before issue 8 with the error named there.

The second half has one test per silent wrong answer listed in issue 8
(each now gives a correct result or an early, clear error).
"""

import json
import re
import subprocess
import sys
from functools import cached_property

import numpy as np
import pytest

import hinfnav as hn
from hinfnav import InputError, UnstablePlantError
from hinfnav.analysis import observer_form, worst_case_norm
from hinfnav.cli import MAX_RUNS, main
from hinfnav.metrics import convergence_time
from hinfnav.noise import ColoredNoise, make_noise
from hinfnav.papers import reproduce
from hinfnav.papers import sun2011 as sun
from hinfnav.papers.sun2011.report import MAX_RUNS as REPORT_MAX_RUNS
from hinfnav.papers.sun2011.report import simulate_report
from hinfnav.sim.truth import noise_models
from hinfnav.systems import position_from_range_angles

#: 20 samples of the paper's scenario: every row that simulates stays cheap.
SHORT = sun.Scenario(duration_s=2.0, rms_window_s=(0.0, 2.0))
#: A small stable plant for synthesize rows (no solver runs in any row).
A2, B2, C2, D2, L2 = 0.5 * np.eye(2), np.eye(2), np.eye(1, 2), np.eye(1), np.eye(2)
T5 = np.arange(5.0)
E0 = np.zeros((2, 5, 3))


class Ctx:
    """What the rows need beyond constants: a temporary folder, one design (built once), files."""

    _design = None

    def __init__(self, tmp_path):
        self.tmp = tmp_path

    @property
    def design(self):
        if Ctx._design is None:
            Ctx._design = sun.design_for_scenario(None, 0.05)
        return Ctx._design

    @cached_property
    def design_file(self):
        return str(sun.save_design(self.design, self.tmp / "d.json"))

    @cached_property
    def a_file(self):
        path = self.tmp / "a_file"
        path.write_text("not a folder\n")
        return str(path)

    def text_file(self, name, text):
        path = self.tmp / name
        path.write_text(text)
        return str(path)

    def edited_design(self, edit):
        d = json.loads(open(self.design_file).read())
        edit(d)
        return self.text_file("edited.json", json.dumps(d))


@pytest.fixture
def ctx(tmp_path):
    return Ctx(tmp_path)


def _row(id_, call, pattern, exc=InputError):
    return pytest.param(call, exc, pattern, id=id_)


def _del(key):
    return lambda d: d.pop(key)


def _bump_A(d):
    d["system"]["A"][0][0] += 1e-6


API_ROWS = [
    # -- seeds -------------------------------------------------------------------------------------------
    _row("seed-negative", lambda c: hn.simulate(SHORT, "published", seed=-1), r"\bseed\b"),
    _row("seed-float", lambda c: hn.simulate(SHORT, "published", seed=2.5), r"\bseed\b"),
    _row("seed-bool", lambda c: hn.simulate(SHORT, "published", seed=True), r"\bseed\b"),
    _row("seed-str", lambda c: hn.simulate(SHORT, "published", seed="3"), r"\bseed\b"),
    # was: numpy SeedSequence ValueError / TypeError
    _row("synthesize-seed-negative", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, L2), seed=-1), r"\bseed\b"),
    _row("synthesize-seed-str", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, L2), seed="x"), r"\bseed\b"),
    # -- runs and batch_size ------------------------------------------------------------------------------
    _row("runs-0", lambda c: hn.simulate(SHORT, "published", runs=0), r"\bruns\b"),
    _row("runs-float", lambda c: hn.simulate(SHORT, "published", runs=2.5), r"\bruns\b"),
    _row("runs-str", lambda c: hn.simulate(SHORT, "published", runs="3"), r"\bruns\b"),
    _row("runs-bool", lambda c: hn.simulate(SHORT, "published", runs=True), r"\bruns\b"),
    _row("runs-1e12", lambda c: hn.simulate(sun.Scenario(), "published", runs=10**12), r"\bruns\b"),
    _row("report-runs-1e12", lambda c: simulate_report(runs=10**12), r"\bruns\b"),
    _row("batch_size-0", lambda c: hn.simulate(SHORT, "published", batch_size=0), r"\bbatch_size\b"),
    _row("batch_size-float", lambda c: hn.simulate(SHORT, "published", batch_size=2.5), r"\bbatch_size\b"),
    # -- the truth's conditions ---------------------------------------------------------------------------
    _row("delta-nan", lambda c: hn.simulate(SHORT, "published", delta=np.nan), r"\bdelta\b"),
    _row("delta-inf", lambda c: hn.simulate(SHORT, "published", delta=np.inf), r"\bdelta\b"),
    _row("delta--1", lambda c: hn.simulate(SHORT, "published", delta=-1), r"\bdelta\b"),
    _row("delta-1e6", lambda c: hn.simulate(SHORT, "published", delta=1e6), r"\bdelta\b"),
    # was: OverflowError in hill_matrices
    _row("delta-1e308", lambda c: hn.simulate(SHORT, "published", delta=1e308), r"\bdelta\b"),
    _row("delta-str", lambda c: hn.simulate(SHORT, "published", delta="x"), r"\bdelta\b"),
    _row("maneuver-str", lambda c: hn.simulate(SHORT, "published", maneuver="yes"), r"\bmaneuver\b"),
    _row("discretization", lambda c: hn.simulate(SHORT, "published", discretization="rk4"), r"\bdiscretization\b"),
    # was: TypeError "truth_model() got an unexpected keyword argument"
    _row("condition-unknown", lambda c: hn.simulate(SHORT, "published", maneuvre=False), r"maneuvre"),
    # was: AttributeError 'NoneType' object has no attribute 'truth_model'
    _row("scenario-None", lambda c: hn.simulate(None, "published"), r"\bscenario\b"),
    _row("closed-loop-scenario-str", lambda c: hn.simulate_closed_loop("sun2011", "published"), r"\bscenario\b"),
    # -- Scenario fields -----------------------------------------------------------------------------------
    _row("dt-0", lambda c: sun.Scenario(dt=0), r"\bdt\b"),
    _row("dt-negative", lambda c: sun.Scenario(dt=-0.1), r"\bdt\b"),
    _row("mass-0", lambda c: sun.Scenario(mass=0), r"\bmass\b"),
    _row("K-shape", lambda c: sun.Scenario(K=np.zeros((3, 5))), r"\bK\b"),
    _row("x0-length", lambda c: sun.Scenario(x0=np.zeros(5)), r"\bx0\b"),
    _row("B-nan", lambda c: sun.Scenario(B=np.full((6, 6), np.nan)), r"\bB\b"),
    _row("delta_bar-negative", lambda c: sun.Scenario(delta_bar=-1), r"\bdelta_bar\b"),
    _row("rms_window-outside-run", lambda c: sun.Scenario(rms_window_s=(0, 2000)), r"\brms_window_s\b"),
    _row("rms_window-not-a-pair", lambda c: sun.Scenario(rms_window_s=5), r"\brms_window_s\b"),
    # was: "R must be positive definite" (R = D Dᵀ is internal)
    _row("D-singular-ekf", lambda c: hn.simulate(sun.Scenario(D=np.zeros((3, 3)), duration_s=2.0,
                                                             rms_window_s=(0, 2)), "ekf"), r"\bD\b"),
    _row("D-singular-kalman-limit", lambda c: sun.kalman_limit(sun.Scenario(D=np.diag([0.1, 0.1, 0.0]))), r"\bD\b"),
    # was: "C_F must be invertible" (C_F is the designed filter's; the user gave L)
    _row("L-singular-designed", lambda c: sun.make_estimator(sun.Scenario(L=np.zeros((6, 6))), "designed"), r"\bL\b"),
    _row("L-3x6-designed", lambda c: sun.make_estimator(sun.Scenario(L=np.eye(3, 6)), "designed"), r"\bL\b"),
    _row("L-singular-observer", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, np.zeros((2, 2))), form="observer"), r"\bL\b"),
    # -- noise ---------------------------------------------------------------------------------------------
    _row("noise-name", lambda c: hn.simulate(SHORT, "published", noise="pink"), r"\bnoise\b"),
    _row("noise-int", lambda c: hn.simulate(SHORT, "published", noise=3), r"\bnoise\b"),
    _row("measurement_noise-name", lambda c: hn.simulate(SHORT, "published", measurement_noise="pink"), r"noise"),
    _row("noise-colored-other-T", lambda c: hn.simulate(SHORT, "published", noise=ColoredNoise(dt=1.0)), r"\bdt\b"),
    # was: ValueError could not convert string to float
    _row("mixture-eps-str", lambda c: make_noise("mixture", eps="a"), r"\beps\b"),
    _row("mixture-eps-2", lambda c: make_noise("mixture", eps=2), r"\beps\b"),
    _row("student_t-dof-4", lambda c: make_noise("student_t", dof=4), r"\bdof\b"),
    _row("colored-tau-0", lambda c: make_noise("colored", tau_s=0), r"\btau_s\b"),
    _row("noise-unknown-param", lambda c: make_noise("gaussian", sigma=2), r"\bsigma\b"),
    # was: MemoryError
    _row("sample-shape-huge", lambda c: make_noise("gaussian").sample(np.random.default_rng(0), (10**9, 10**9)),
         r"\bshape\b"),
    _row("sample-rng-int", lambda c: make_noise("gaussian").sample(0, (2, 3)), r"\brng\b"),
    # -- estimators ----------------------------------------------------------------------------------------
    _row("filter-unknown", lambda c: hn.simulate(SHORT, "kalmann"), r"\bfilter\b"),
    _row("estimator-int", lambda c: hn.simulate(SHORT, 3), r"\bestimator\b"),
    # was: TypeError EKF() got an unexpected keyword argument
    _row("ekf-option-unknown", lambda c: sun.make_estimator(SHORT, "ekf", foo=1), r"\bfoo\b"),
    # was: accepted and silently ignored
    _row("published-option", lambda c: sun.make_estimator(SHORT, "published", delta_bar=0.3), r"\bdelta_bar\b"),
    # was: TypeError unhashable type
    _row("build_estimator-list", lambda c: hn.build_estimator(SHORT, ["ekf"]), r"\bfilter\b"),
    # was: accepted, failing later with TypeError
    _row("register-builder-int", lambda c: hn.register_estimator("test_bad_builder", 5), r"\bbuilder\b"),
    _row("lti-unstable-A_F", lambda c: hn.LTIFilter(3 * np.eye(6), np.zeros((6, 3)), np.eye(6), SHORT.system(),
                                                    SHORT.measurement), r"\bA_F\b"),
    _row("lti-C_F-singular", lambda c: hn.LTIFilter(0.5 * np.eye(6), np.zeros((6, 3)), np.zeros((6, 6)),
                                                    SHORT.system(), SHORT.measurement), r"\bC_F\b"),
    _row("ekf-P0-negative", lambda c: sun.EKF(SHORT, P0=-np.eye(6)), r"\bP0\b"),
    _row("ekf-output", lambda c: sun.EKF(SHORT, output="smoothed"), r"\boutput\b"),
    # -- designs -------------------------------------------------------------------------------------------
    _row("synthesize-A-nonsquare", lambda c: hn.synthesize(hn.UncertainSystem(np.zeros((2, 3)), B2, C2, D2, L2)), r"\bA\b"),
    _row("synthesize-D-rows", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, np.eye(2), L2)), r"\bD\b"),
    _row("synthesize-L-cols", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, np.eye(2, 3))), r"\bL\b"),
    _row("synthesize-unstable-plant", lambda c: hn.synthesize(hn.UncertainSystem(2 * np.eye(2), B2, C2, D2, L2)), r"\bA\b",
         UnstablePlantError),
    _row("synthesize-H-without-E", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, L2, H=np.eye(2))), r"\bE\b"),
    _row("synthesize-solver", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, L2), solver="MOSEK"), r"\bsolver\b"),
    _row("synthesize-options-dict", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, L2), options={"solvers": ["CLARABEL"]}),
         r"\boptions\b"),
    _row("synthesize-structure", lambda c: hn.synthesize(hn.UncertainSystem(A2, B2, C2, D2, L2), structure="block"), r"\bstructure\b"),
    # was: TypeError synthesize() got an unexpected keyword argument
    _row("design-option-unknown", lambda c: sun.design_for_scenario(None, 0.05, foo=1), r"\bfoo\b"),
    _row("design-delta_bar-nan", lambda c: sun.design_for_scenario(None, np.nan), r"\bdelta_bar\b"),
    # was: OverflowError in uncertainty_structure
    _row("design-delta_bar-1e200", lambda c: sun.design_for_scenario(None, 1e200), r"\bdelta_bar\b"),
    _row("design-delta_bar-1e9", lambda c: sun.design_for_scenario(None, 1e9), r"\bdelta_bar\b", UnstablePlantError),
    # was: an empty sweep returned
    _row("gamma-sweep-empty", lambda c: sun.gamma_sweep(None, []), r"\bdelta_bars\b"),
    _row("gamma-sweep-scalar", lambda c: sun.gamma_sweep(None, 0.05), r"\bdelta_bars\b"),
    # was: LinAlgError Singular matrix
    _row("observer-form-C_F-singular", lambda c: observer_form(0.5 * np.eye(2), np.eye(2, 1), np.zeros((2, 2)),
                                                                  0.5 * np.eye(2), np.eye(1, 2)), r"\bC_F\b"),
    # was: AttributeError 'str' object has no attribute 'dt'
    _row("worst-case-norm-system-str", lambda c: worst_case_norm("x", np.eye(2), np.eye(2, 1), np.eye(2)),
         r"\bsystem\b"),
    _row("design-delta_points", lambda c: sun.design_for_scenario(None, 0.05, delta_points=1), r"\bdelta_points\b"),
    # -- design files --------------------------------------------------------------------------------------
    _row("load-missing", lambda c: sun.load_design(c.tmp / "nope.json"), r"nope\.json"),
    _row("load-not-json", lambda c: sun.load_design(c.text_file("bad.json", "{not json")), r"JSON"),
    _row("load-json-list", lambda c: sun.load_design(c.text_file("list.json", "[1, 2]")), r"design file"),
    # was: TypeError expected str, bytes or os.PathLike object
    _row("load-path-None", lambda c: sun.load_design(None), r"\bpath\b"),
    _row("load-edited", lambda c: sun.load_design(c.edited_design(_bump_A)), r"edited"),
    # was: KeyError 'gamma'
    _row("load-no-certificate", lambda c: sun.load_design(c.edited_design(_del("certificate"))), r"design file"),
    _row("load-another-T", lambda c: sun.load_design(c.design_file, scenario=sun.Scenario(dt=0.2)), r"\bT\b"),
    _row("load-scenario-str", lambda c: sun.load_design(c.design_file, scenario="paper"), r"\bscenario\b"),
    # was: AttributeError 'str' object has no attribute 'delta_bar'
    _row("save-not-a-design", lambda c: sun.save_design("x", c.tmp / "x.json"), r"\bresult\b"),
    # was: NotADirectoryError
    _row("save-under-a-file", lambda c: sun.save_design(c.design, c.a_file + "/x.json"), r"\bpath\b"),
    _row("save-path-None", lambda c: sun.save_design(c.design, None), r"\bpath\b"),
    _row("save-scenario-str", lambda c: sun.save_design(c.design, c.tmp / "x.json", scenario="x"), r"\bscenario\b"),
    _row("simulate-design-another-T", lambda c: hn.simulate(sun.Scenario(dt=0.2, duration_s=2.0, rms_window_s=(0, 2)),
                                                            c.design), r"\bT\b"),
    # was: TypeError expected str, bytes or os.PathLike object
    _row("report-design-int", lambda c: simulate_report(design=5), r"\bpath\b"),
    # was: AttributeError 'int' object has no attribute 'A_F'
    _row("compare-design-int", lambda c: sun.compare_with_published(design=5), r"\bdesign\b"),
    # -- metrics -------------------------------------------------------------------------------------------
    _row("rms-nan", lambda c: hn.rms_error(np.full((2, 5, 3), np.nan), T5, (0, 4)), r"\berror\b"),
    _row("rms-shape", lambda c: hn.rms_error(np.zeros(5), T5, (0, 4)), r"\berror\b"),
    _row("rms-t-shape", lambda c: hn.rms_error(E0, np.arange(4.0), (0, 4)), r"\bt\b"),
    _row("rms-window-empty", lambda c: hn.rms_error(E0, T5, (10, 20)), r"\bwindow\b"),
    # was: ValueError could not convert string to float
    _row("rms-error-str", lambda c: hn.rms_error("abc", T5, (0, 4)), r"\berror\b"),
    # was: RuntimeWarning and NaN
    _row("summary-zero-runs", lambda c: hn.monte_carlo_summary(np.zeros((0, 5, 3)), T5, (0, 4)), r"\berror\b"),
    # was: ValueError operands could not be broadcast
    _row("convergence-tol-shape", lambda c: convergence_time(E0, T5, [1.0, 2.0]), r"\btol\b"),
    _row("convergence-tol-0", lambda c: convergence_time(E0, T5, 0.0), r"\btol\b"),
    _row("statistics-windows", lambda c: hn.monte_carlo_statistics(SHORT, "published", windows=5), r"\bwindows\b"),
    # -- measurement models and systems ---------------------------------------------------------------------
    _row("saturated-lower-ge-upper", lambda c: hn.Saturated(SHORT.measurement, [1, 1, 1], [0, 0, 0]), r"\blower\b"),
    # was: ValueError operands could not be broadcast
    _row("saturated-shape", lambda c: hn.Saturated(SHORT.measurement, [0, 0], [1, 1]), r"\blower\b"),
    _row("rae-sigma_range-0", lambda c: hn.RangeAzimuthElevation(6, 0.0, 1e-3), r"\bsigma_range\b"),
    _row("rae-sigma_angle-negative", lambda c: hn.RangeAzimuthElevation(6, 1.0, -1.0), r"\bsigma_angle\b"),
    # was: accepted (the first three components must be the position)
    _row("rae-n_state-2", lambda c: hn.RangeAzimuthElevation(2, 1.0, 1e-3), r"\bn_state\b"),
    _row("rae-zero-range", lambda c: hn.RangeAzimuthElevation(6, 1.0, 1e-3).function(np.zeros(6)), r"\bx\b"),
    # was: NaN returned silently
    _row("position-from-angles-nan", lambda c: position_from_range_angles([np.nan, 0.0, 0.0]), r"\bm\b"),
    # was: TypeError 'int' object is not iterable
    _row("statespec-groups-int", lambda c: hn.StateSpec(("a", "b"), ("m", "s"), groups=5), r"\bgroups\b"),
    # was: AttributeError 'str' object has no attribute 'n'
    _row("truthmodel-system-str", lambda c: hn.TruthModel("s", SHORT.measurement, np.zeros(6), 10), r"\bsystem\b"),
    _row("feedback-source", lambda c: hn.LinearFeedback(np.zeros((3, 6)), source="oracle"), r"\bsource\b"),
    # -- reproduce -----------------------------------------------------------------------------------------
    _row("reproduce-paper", lambda c: reproduce("nope", c.tmp / "o", runs=1, progress=False), r"\bpaper\b"),
    _row("reproduce-out-empty", lambda c: reproduce("sun2011", "", runs=1, progress=False), r"\bout\b"),
    _row("reproduce-out-file", lambda c: reproduce("sun2011", c.a_file, runs=1, progress=False), r"\bout\b"),
    _row("reproduce-out-under-file", lambda c: reproduce("sun2011", c.a_file + "/sub", runs=1, progress=False),
         r"\bout\b"),
    # was: TypeError reproduce() got an unexpected keyword argument
    _row("reproduce-option-unknown", lambda c: reproduce("sun2011", c.tmp / "o", foo=1, progress=False), r"\bfoo\b"),
    # was: refused only after both designs (~5 s)
    _row("sun2011-reproduce-seed", lambda c: sun.reproduce(c.tmp / "o", runs=1, seed=-1, progress=False), r"\bseed\b"),
    _row("table1-seed", lambda c: sun.table1(runs=1, seed=-1), r"\bseed\b"),
    # was: AttributeError 'str' object has no attribute 'A_F' (after a design)
    _row("table1-designed-str", lambda c: sun.table1(runs=1, designed="x"), r"\bdesigned\b"),
]


@pytest.mark.parametrize("call, exc, pattern", API_ROWS)
def test_api_bad_input(call, exc, pattern, ctx):
    with pytest.raises(exc) as info:
        call(ctx)
    assert isinstance(info.value, InputError)
    assert re.search(pattern, str(info.value)), f"{pattern!r} not named in: {info.value}"


def run_main(argv, capsys):
    """``main(argv)`` in-process: (exit status, stdout, stderr); argparse's own errors exit with 2."""
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    out, err = capsys.readouterr()
    return rc, out, err


CLI_ROWS = [
    (["simulate", "--runs", "0"], r"--runs"),
    (["simulate", "--runs", "-1"], r"--runs"),
    (["simulate", "--runs", "abc"], r"--runs"),
    (["simulate", "--runs", str(10**12)], r"--runs"),  # was: refused after the heavy imports
    (["simulate", "--delta", "nan"], r"--delta"),
    (["simulate", "--delta", "inf"], r"--delta"),
    (["simulate", "--delta", "-1"], r"\bdelta\b"),
    (["simulate", "--delta", "1e6"], r"\bdelta\b"),
    (["simulate", "--delta", "1e308"], r"\bdelta\b"),  # was: OverflowError traceback
    (["simulate", "--seed", "-1"], r"--seed"),
    (["simulate", "--seed", "1.5"], r"--seed"),
    (["simulate", "--design", "{tmp}/missing.json"], r"missing\.json"),
    (["simulate", "--design", "{bad_json}"], r"JSON"),
    (["simulate", "--design", "{tmp}"], r"design file"),
    (["simulate", "--design", ""], r"--design"),
    (["simulate", "--verbatim"], r"--verbatim"),
    (["simulate", "--filter", "nope"], r"--filter"),
    (["simulate", "--noise", "pink"], r"--noise"),
    (["simulate", "--discretization", "rk4"], r"--discretization"),
    (["design", "--delta-bar", "-1"], r"--delta-bar"),
    (["design", "--delta-bar", "nan"], r"--delta-bar"),
    (["design", "--delta-bar", "1e200"], r"delta_bar"),  # was: OverflowError traceback
    (["design", "--delta-bar", "1e9"], r"delta_bar"),
    (["design", "--solver", "MOSEK"], r"--solver"),
    (["design", "--form", "kalman"], r"--form"),
    (["design", "--gamma", "1"], r"--gamma"),
    (["design", "--save", ""], r"--save"),  # was: exit 0, nothing saved
    (["design", "--save", "{a_file}/d.json"], r"--save"),  # was: NotADirectoryError traceback
    (["design", "--save", "{tmp}/missing/d.json"], r"--save"),  # was: refused after the design
    (["design", "--save", "{tmp}"], r"--save"),
    (["reproduce", "--out", ""], r"\bout\b"),
    (["reproduce", "--out", "{a_file}"], r"\bout\b"),
    (["reproduce", "--out", "{a_file}/sub"], r"\bout\b"),
    (["reproduce", "--paper", "nope"], r"--paper"),
    (["reproduce", "--runs", "0"], r"--runs"),
    (["reproduce", "--seed", "-1"], r"--seed"),
    (["nope"], r"COMMAND"),
    (["simulate", "--nope"], r"--nope"),
]


@pytest.mark.parametrize("argv, pattern", CLI_ROWS, ids=[" ".join(a) or "''" for a, _ in CLI_ROWS])
def test_cli_bad_input(argv, pattern, ctx, capsys):
    subs = {"tmp": str(ctx.tmp), "a_file": ctx.a_file, "bad_json": ctx.text_file("bad.json", "{bad")}
    argv = [a.format(**subs) for a in argv]
    rc, out, err = run_main(argv, capsys)
    assert rc == 2, (rc, err)
    assert "Traceback" not in err and "error" in err
    assert re.search(pattern, err), f"{pattern!r} not named in: {err}"


@pytest.mark.parametrize("argv, pattern", [
    (["simulate", "--delta", "1e308"], r"\bdelta\b"),
    (["design", "--save", "{a_file}/d.json"], r"--save"),
    (["reproduce", "--out", "{a_file}"], r"\bout\b"),
], ids=["delta-1e308", "save-under-a-file", "out-a-file"])
def test_cli_subprocess_has_no_traceback(argv, pattern, ctx):
    argv = [a.format(a_file=ctx.a_file) for a in argv]
    run = subprocess.run([sys.executable, "-m", "hinfnav", *argv], capture_output=True, text=True, timeout=120,
                         cwd=ctx.tmp)
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr and re.search(pattern, run.stderr), run.stderr
    assert run.stdout == ""


def test_huge_seed_is_valid_and_reproducible():
    # an unusual but valid input: numpy seeds accept any integer >= 0; same seed, same numbers
    a = hn.simulate(SHORT, "published", seed=10**30)
    b = hn.simulate(SHORT, "published", seed=10**30)
    assert np.array_equal(a.xhat, b.xhat) and not np.array_equal(a.xhat, hn.simulate(SHORT, "published").xhat)


def test_cli_run_bound_is_the_reports():
    # the command line checks --runs before importing the report; the two bounds must agree
    assert MAX_RUNS == REPORT_MAX_RUNS


# -- one test per silent wrong answer of issue 8 -------------------------------------------------------------


def test_unstable_closed_loop_delta_is_refused_and_a_stable_one_runs():
    # was: `simulate --delta 1e6` printed RMS errors of 1e20–1e56 m. The paper's K keeps u = K x stable up to
    # δ ≈ 376 (spectral radius of Φ(δ) + Γ K, computed by truth_model itself); beyond it the truth is refused
    with pytest.raises(InputError, match=r"unstable at delta = 1000 "):
        SHORT.truth_model(delta=1e3)
    res = hn.simulate(SHORT, "published", delta=300.0)
    assert np.all(np.isfinite(res.error)) and np.max(np.abs(res.x)) < 2e3  # starts at |x0| ≈ 1330 m, bounded


def test_destabilizing_gain_is_refused():
    # was: accepted. Φ + Γ K with K = 1e6 has spectral radius ≈ 316 at T = 0.1 s
    sc = sun.Scenario(K=np.full((3, 6), 1e6), duration_s=2.0, rms_window_s=(0.0, 2.0))
    with pytest.raises(InputError, match=r"\bK\b.*unstable|unstable.*\bK\b"):
        hn.simulate(sc, "published")


def test_filter_designed_for_another_T_is_refused(ctx):
    # was: the published filter (T = 0.1 s) ran at T = 1 s without a word
    sc = sun.Scenario(dt=1.0, duration_s=20.0, rms_window_s=(0.0, 20.0))
    with pytest.raises(InputError, match=r"T = 0\.1 s.*dt = 1 s"):
        hn.simulate(sc, "published")
    with pytest.raises(InputError, match=r"sampling time T = 0\.1 s .* T = 1 s"):
        sun.load_design(ctx.design_file, scenario=sc)


def test_colored_noise_follows_the_scenario_T():
    # was: 'colored' was built at T = 0.1 s whatever the system. At dt = 0.5 s the one-step correlation must be
    # exp(−dt/τ) = exp(−0.5) = 0.6065 (closed form); measured on 20 000 steps × 10 channels (standard error ≈ 0.002)
    w_model, v_model = noise_models("colored", dt=0.5)
    assert w_model.dt == 0.5 and v_model.dt == 0.5
    x = w_model.sample(np.random.default_rng(1), (20_000, 10))
    assert abs(np.mean(x[:-1] * x[1:]) / np.mean(x * x) - np.exp(-0.5)) < 0.01
    with pytest.raises(InputError, match=r"dt = 1 s .* dt = 0\.1 s"):
        hn.simulate(SHORT, "published", noise=ColoredNoise(dt=1.0))


def test_unstable_filter_is_refused_before_it_runs():
    # was: NaN RMS with numpy overflow warnings only
    with pytest.raises(InputError, match=r"A_F must be Schur stable.*1\.01"):
        hn.LTIFilter(1.01 * np.eye(6), np.zeros((6, 3)), np.eye(6), SHORT.system(), SHORT.measurement)


def test_nan_in_metrics_is_an_error():
    # was: rms_error of NaN data returned NaN
    err = np.zeros((1, 5, 3))
    err[0, 3, 1] = np.nan
    with pytest.raises(InputError, match=r"run 0, sample 3, component 1"):
        hn.rms_error(err, T5, (0, 4))


def test_non_integer_sizes_are_refused():
    # was: a sample shape of 2.7 became 2
    with pytest.raises(InputError, match=r"\bshape\b"):
        make_noise("gaussian").sample(np.random.default_rng(0), (2.7, 3))
    with pytest.raises(InputError, match=r"\bruns\b"):
        hn.simulate(SHORT, "published", runs=2.7)


def test_range_angle_ekf_is_not_fed_positions():
    # was: 670–1300 m RMS (the range/azimuth/elevation EKF fed Cartesian positions)
    ekf = sun.build_ekf(SHORT, measurement="range_angles")
    with pytest.raises(InputError, match=r"range \(m\), azimuth \(rad\), elevation \(rad\).*x \(m\), y \(m\), z \(m\)"):
        hn.simulate(SHORT, ekf)


def test_reproduce_out_empty_writes_nothing(tmp_path, monkeypatch):
    # was: `reproduce --out ''` wrote into the current folder
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"\bout\b"):
        reproduce("sun2011", "", runs=1, progress=False)
    assert list(tmp_path.iterdir()) == []
