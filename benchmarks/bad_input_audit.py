"""Bad-input audit (issue 36): hundreds of mistakes a user makes, each classified.

Usage::

    python benchmarks/bad_input_audit.py [--json OUT.json] [--surface NAME ...] [--skip NAME ...] [--timeout S] [--list]

Every case is a small call through the public API (user models, noise matrices,
core options through ``build_estimator``, absurd readings, system TOML files,
campaign specs, GRACE data files, saved designs, writers, the command line)
with what a correct answer is: ``refuse`` (an error of hinfnav naming the given
words) or ``valid`` (no error; the case checks its own answer). The verdicts:

* ``refused-clearly`` — a hinfnav error (HinfnavError) whose message names the words;
* ``valid`` — an expected-valid case that ran and passed its own check;
* ``silent`` — a bad input that gave an answer without a word (or a valid case whose check failed);
* ``hang`` — no answer within ``--timeout`` seconds (SIGALRM);
* ``unclear`` — an error, but a raw one (not hinfnav's) or one that does not name the words.

The script prints the counts per verdict and per surface and every case that
is not ``refused-clearly`` or ``valid``; its exit status is 1 when any case is
silent, hangs or is unclear.
"""

from __future__ import annotations

import argparse
import contextlib
import gzip
import io
import json
import re
import signal
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hinfnav.core.exceptions import HinfnavError  # noqa: E402

CASES = []
TMP = Path(tempfile.mkdtemp(prefix="hinfnav-audit-"))


def case(surface, name, expect="refuse", words=()):
    """Register ``fn`` as a case: ``expect`` "refuse" (with ``words`` in the message) or "valid"."""
    def deco(fn):
        CASES.append({"surface": surface, "name": name, "expect": expect, "words": tuple(words), "fn": fn})
        return fn
    return deco


# ---------------------------------------------------------------------------------------------------------------
# user models (item 1)
# ---------------------------------------------------------------------------------------------------------------

def _model_cases():
    from hinfnav.estimators import ExtendedKalmanFilter, SigmaPointFilter
    from hinfnav.systems import (ContinuousDynamics, DiscreteDynamics, DynamicsModel, LinearMeasurement,
                                 MeasurementModel, StateSpec)

    dt = 0.5
    F = np.array([[1.0, dt], [0.0, 1.0]])
    spec = StateSpec(labels=("p", "v"), units=("m", "m/s"))
    Q = 0.01 * np.eye(2)
    sensor = LinearMeasurement([[1.0, 0.0]], [[0.5]])
    filters = {"ekf": lambda m, s=sensor: ExtendedKalmanFilter(m, s, P0=np.eye(2)),
               "ukf": lambda m, s=sensor: SigmaPointFilter(m, s, P0=np.eye(2))}

    def run(model, make, runs, sens=sensor):
        est = make(model, sens)
        y = np.random.default_rng(0).normal(size=(runs, 4, sens.n_meas))
        return est.estimate(y, np.zeros((runs, 4, 0)), np.zeros(2)).xhat

    def reference(make, runs, jac=None):
        return run(DiscreteDynamics(lambda x, u, t: x @ F.T, spec, dt, Q, jacobian=jac), make, runs)

    good_f = lambda x, u, t: x @ F.T
    bad_f = {
        "f transposed (n, runs)": (lambda x, u, t: (x @ F.T).T, ["f(x, u, t)"]),
        "f returns (runs, 1)": (lambda x, u, t: x[:, :1], ["f(x, u, t)", "shape"]),
        "f returns (runs,)": (lambda x, u, t: x[:, 0], ["f(x, u, t)", "shape"]),
        "f returns a scalar": (lambda x, u, t: 1.0, ["f(x, u, t)", "shape"]),
        "f returns (n,)": (lambda x, u, t: np.ones(2), ["f(x, u, t)", "shape"]),
        "f returns (runs, n, 1)": (lambda x, u, t: (x @ F.T)[..., None], ["f(x, u, t)", "shape"]),
        "f returns NaN": (lambda x, u, t: x @ F.T + np.nan, ["f(x, u, t)", "NaN"]),
        "f returns inf": (lambda x, u, t: x @ F.T + np.inf, ["f(x, u, t)", "inf"]),
        "f raises ZeroDivisionError": (lambda x, u, t: 1 / 0, ["f(x, u, t)", "ZeroDivisionError", "step"]),
        "f raises KeyError": (lambda x, u, t: {}["k"], ["f(x, u, t)", "KeyError", "step"]),
        "f returns None": (lambda x, u, t: None, ["f(x, u, t)"]),
        "f returns a string": (lambda x, u, t: "x", ["f(x, u, t)"]),
        "f mixes the runs (reversed)": (lambda x, u, t: (x @ F.T)[::-1], ["f(x, u, t)"]),
        "f uses F @ x (columns)": (lambda x, u, t: F @ x, ["f(x, u, t)"]),
        "f sums over the batch": (lambda x, u, t: x @ F.T + x.sum(axis=0), ["f(x, u, t)"]),
        "f returns a list of wrong length": (lambda x, u, t: [[1.0]] * len(x), ["f(x, u, t)", "shape"]),
    }
    bad_jac = {
        "jacobian scalar": (lambda x, u, t: 1.0, ["jacobian", "shape"]),
        "jacobian vector": (lambda x, u, t: np.ones(2), ["jacobian", "shape"]),
        "jacobian transposed": (lambda x, u, t: F.T, ["jacobian", "entry"]),
        "jacobian (runs, n)": (lambda x, u, t: np.ones((len(x), 2)), ["jacobian", "shape"]),
        "jacobian (n, n+1)": (lambda x, u, t: np.ones((2, 3)), ["jacobian", "shape"]),
        "jacobian NaN": (lambda x, u, t: F + np.nan, ["jacobian", "NaN"]),
        "jacobian twice too large": (lambda x, u, t: 2 * F, ["jacobian", "entry"]),
        "jacobian identity (wrong)": (lambda x, u, t: np.eye(2), ["jacobian", "entry"]),
        "jacobian raises": (lambda x, u, t: [][1], ["jacobian", "IndexError"]),
        "jacobian returns None": (lambda x, u, t: None, ["jacobian"]),
    }
    for fname, make in filters.items():
        for runs in (1, 2, 3):
            for label, (fun, words) in bad_f.items():
                if label == "f uses F @ x (columns)" and runs != 2:
                    continue  # a shape error otherwise, covered by the transposed case
                case("user model", f"{fname} runs={runs}: {label}", words=words)(
                    lambda fun=fun, make=make, runs=runs: run(DiscreteDynamics(fun, spec, dt, Q), make, runs))
            if fname == "ekf":
                for label, (jac, words) in bad_jac.items():
                    case("user model", f"{fname} runs={runs}: {label}", words=words)(
                        lambda jac=jac, make=make, runs=runs: run(DiscreteDynamics(good_f, spec, dt, Q, jacobian=jac),
                                                                  make, runs))

            def inplace(x, u, t):
                x[:, 0] += dt * x[:, 1]
                return x

            def check_inplace(make=make, runs=runs):
                got = run(DiscreteDynamics(inplace, spec, dt, Q), make, runs)
                np.testing.assert_allclose(got, reference(make, runs), rtol=1e-12, atol=1e-12)

            case("user model", f"{fname} runs={runs}: f modifies its input in place", "valid")(check_inplace)

            def check_good(make=make, runs=runs):
                got = run(DiscreteDynamics(good_f, spec, dt, Q, jacobian=lambda x, u, t: F), make, runs)
                # the reference: a copy of the model built the same way (an independent object, same numbers)
                ref = reference(make, runs, jac=lambda x, u, t: F.copy())
                np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)

            case("user model", f"{fname} runs={runs}: correct f and Jacobian", "valid")(check_good)

    # continuous derivatives
    a_ok = lambda x, u, t: np.column_stack([x[:, 1], -x[:, 0]])
    A = np.array([[0.0, 1.0], [-1.0, 0.0]])
    bad_a = {
        "derivative (runs, 1)": (lambda x, u, t: x[:, 1:2], ["derivative", "shape"]),
        "derivative transposed": (lambda x, u, t: a_ok(x, u, t).T, ["derivative"]),
        "derivative (n,)": (lambda x, u, t: np.ones(2), ["derivative", "shape"]),
        "derivative NaN": (lambda x, u, t: a_ok(x, u, t) * np.nan, ["derivative", "NaN"]),
        "derivative raises": (lambda x, u, t: np.linalg.inv(np.zeros((2, 2))), ["derivative", "LinAlgError"]),
    }
    bad_A = {
        "derivative_jacobian transposed": (lambda x, u, t: A.T, ["derivative_jacobian", "entry"]),
        "derivative_jacobian scalar": (lambda x, u, t: 0.0, ["derivative_jacobian", "shape"]),
        "derivative_jacobian (runs, n)": (lambda x, u, t: np.zeros((len(x), 2)), ["derivative_jacobian", "shape"]),
    }
    for runs in (1, 2, 3):
        for label, (a, words) in bad_a.items():
            case("user model", f"continuous runs={runs}: {label}", words=words)(
                lambda a=a, runs=runs: run(ContinuousDynamics(a, spec, dt, Q, substeps=2), filters["ekf"], runs))
        for label, (Aj, words) in bad_A.items():
            case("user model", f"continuous runs={runs}: {label}", words=words)(
                lambda Aj=Aj, runs=runs: run(ContinuousDynamics(a_ok, spec, dt, Q, derivative_jacobian=Aj),
                                             filters["ekf"], runs))
    for sub in (0, -1, 10**6, 2.5, True):
        case("user model", f"continuous substeps={sub!r}", words=["substeps"])(
            lambda sub=sub: ContinuousDynamics(a_ok, spec, dt, Q, substeps=sub))

    # user subclasses (dynamics and measurement)
    class WrongShape(DynamicsModel):
        def f(self, x, u=None, t=0.0):
            return x.T

    class Raises(DynamicsModel):
        def f(self, x, u=None, t=0.0):
            raise RuntimeError("lookup table exhausted")

    class BadJac(DynamicsModel):
        def f(self, x, u=None, t=0.0):
            return x @ F.T

        def jacobian(self, x, u=None, t=0.0):
            return np.broadcast_to(F.T, (len(x), 2, 2))

    for cls, words in ((WrongShape, ["f(x, u, t)"]), (Raises, ["RuntimeError", "step"]), (BadJac, ["entry"])):
        for runs in (1, 3):
            case("user model", f"subclass {cls.__name__} runs={runs}", words=words)(
                lambda cls=cls, runs=runs: run(cls(spec, dt, Q, name="mine"), filters["ekf"], runs))

    def meas(function, jacobian=None):
        attrs = {"__init__": lambda self: MeasurementModel.__init__(self, 2, [[1.0]], ("r",), ("m",)),
                 "function": lambda self, x: function(x)}
        if jacobian is not None:
            attrs["jacobian"] = lambda self, x: jacobian(x)
        return type("UserSensor", (MeasurementModel,), attrs)()

    h_ok = lambda x: x[..., :1] ** 2 / 2
    H_ok = lambda x: np.concatenate([x[..., :1], np.zeros_like(x[..., :1])], axis=-1)[..., None, :]
    bad_h = {
        "h returns (runs,)": (lambda x: x[..., 0], H_ok, ["function h", "shape"]),
        "h returns (runs, 2)": (lambda x: x, H_ok, ["function h", "shape"]),
        "h transposed": (lambda x: h_ok(x).T, H_ok, ["function h"]),
        "h NaN": (lambda x: h_ok(x) * np.nan, H_ok, ["function h", "NaN"]),
        "h raises": (lambda x: x["a"], H_ok, ["function h", "IndexError"]),
        "H transposed": (h_ok, lambda x: np.swapaxes(H_ok(x), -1, -2), ["jacobian", "shape"]),
        "H wrong values": (h_ok, lambda x: 3 * H_ok(x) + 1, ["jacobian", "entry"]),
        "H scalar": (h_ok, lambda x: 1.0, ["jacobian", "shape"]),
        "H vector": (h_ok, lambda x: np.ones(2), ["jacobian", "shape"]),
    }
    for fname, make in filters.items():
        for runs in (1, 3):
            for label, (h, H, words) in bad_h.items():
                if fname == "ukf" and label.startswith("H "):
                    continue  # a sigma-point filter does not use the Jacobian
                case("user model", f"{fname} runs={runs}: {label}", words=words)(
                    lambda h=h, H=H, make=make, runs=runs: run(
                        DiscreteDynamics(good_f, spec, dt, Q), make, runs, meas(h, H)))
            case("user model", f"{fname} runs={runs}: correct h and H", "valid")(
                lambda make=make, runs=runs: run(DiscreteDynamics(good_f, spec, dt, Q), make, runs, meas(h_ok, H_ok)))

    # noise matrices set after construction
    bad_noise = {"Q": [-np.eye(2), np.ones((3, 3)), [[1.0, np.nan], [0.0, 1.0]], [[1.0, 2.0], [0.0, 1.0]], "x"],
                 "R": [[[0.0]], [[-1.0]], np.eye(2), [[np.inf]]],
                 "P0": [np.zeros((2, 2)), -np.eye(2), np.ones((2, 2)), np.eye(3), [[1.0, 0.0], [1.0, 1.0]]]}
    for fname, make in filters.items():
        for key, values in bad_noise.items():
            for i, value in enumerate(values):
                def set_bad(make=make, key=key, value=value):
                    est = make(DiscreteDynamics(good_f, spec, dt, Q))
                    setattr(est, key, value)
                case("noise matrices", f"{fname}.{key} = bad #{i}", words=[key])(set_bad)


# ---------------------------------------------------------------------------------------------------------------
# core options through build_estimator (item 6), absurd readings and diagnostics (items 5, 8)
# ---------------------------------------------------------------------------------------------------------------

def _scenario_of(name):
    from hinfnav.estimators import registered_estimators
    from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
    from hinfnav.papers.shi2018 import Scenario as ShiScenario
    from hinfnav.papers.sun2011 import Scenario
    from hinfnav.papers.yang2020 import SUBSYSTEM_OF
    from hinfnav.papers.yang2020 import Scenario as YangScenario

    if not hasattr(_scenario_of, "cache"):
        _scenario_of.cache = [Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0)),
                              ShiScenario(duration_s=40.0, rms_window_s=(4.0, 40.0), maneuver_time_s=20.0),
                              AttitudeScenario(orbits=0.05)]
        _scenario_of.yang = YangScenario(n_steps=300)
    for sc in _scenario_of.cache:
        if name in registered_estimators(sc):
            return sc
    return _scenario_of.yang.linear_truth(SUBSYSTEM_OF[name])


def _registry_cases():
    import hinfnav.papers  # noqa: F401
    from hinfnav.estimators import build_estimator, registered_estimators

    for name in registered_estimators():
        def skip(name=name):
            est = build_estimator(_scenario_of(name), name, missing="skip")
            assert est.missing == "skip"
        case("core options", f"{name}: missing='skip'", "valid")(skip)
        case("core options", f"{name}: missing='sometimes'", words=["missing"])(
            lambda name=name: build_estimator(_scenario_of(name), name, missing="sometimes"))
        case("core options", f"{name}: misspelt option", words=["hbff"])(
            lambda name=name: build_estimator(_scenario_of(name), name, hbff=1))


def _absurd_cases():
    import hinfnav.papers  # noqa: F401
    from hinfnav.estimators import build_estimator
    from hinfnav.sim import simulate_truth

    truths = {}
    for name in ("ukf", "stekf", "huber_stekf", "ekf_converted", "ekf", "hbf"):
        for value in (1e300, -1e300, 1e200, 1e160):
            for backend in ("numpy", "auto"):
                def absurd(name=name, value=value, backend=backend):
                    sc = _scenario_of(name)
                    if id(sc) not in truths:
                        truths[id(sc)] = simulate_truth(sc.truth_model(), runs=2, seed=1)
                    tr = truths[id(sc)]
                    y = tr.y[:, :20].copy()
                    y[1, 5, 0] = value
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        build_estimator(sc, name).estimate(y, tr.u[:, :20], sc.xhat0, backend=backend)
                case("absurd readings", f"{name} {backend}: reading {value:g}", words=["magnitude"])(absurd)


def _diagnostic_cases():
    from hinfnav.estimators import ExtendedKalmanFilter, SigmaPointFilter
    from hinfnav.systems import LinearMeasurement, LinearSystem, StateSpec

    sys_ = LinearSystem(np.array([[1.0, 0.1], [0.0, 1.0]]), np.zeros((2, 0)), 0.1 * np.eye(2), 0.1,
                        StateSpec(labels=("p", "v"), units=("m", "m/s")))
    sensor = LinearMeasurement([[1.0, 0.0]], [[1.0]])
    for cls in (ExtendedKalmanFilter, SigmaPointFilter):
        for bad in ("innovatoin", "gain", "nis", "Innovation", ""):
            case("diagnostics", f"{cls.__name__}: diagnostics=[{bad!r}]", words=["diagnostic"])(
                lambda cls=cls, bad=bad: cls(sys_, sensor, P0=np.eye(2)).estimate(
                    np.zeros((1, 3, 1)), np.zeros((1, 3, 0)), np.zeros(2), diagnostics=[bad]))
        case("diagnostics", f"{cls.__name__}: diagnostics=['innovation']", "valid")(
            lambda cls=cls: cls(sys_, sensor, P0=np.eye(2)).estimate(
                np.zeros((1, 3, 1)), np.zeros((1, 3, 0)), np.zeros(2), diagnostics=["innovation"]))


# ---------------------------------------------------------------------------------------------------------------
# files: system TOML, campaign specs, GRACE data (item 2)
# ---------------------------------------------------------------------------------------------------------------

NOMINAL = "dt = 0.1\n[nominal]\nA = [[0.5]]\nB = [[1.0]]\nC = [[1.0]]\nD = [[1.0]]\nL = [[1.0]]\n"
NORM = NOMINAL + '[uncertainty]\nkind = "norm-bounded"\nH = [[0.1]]\nE = [[1.0]]\n'
POLY = NOMINAL + '[uncertainty]\nkind = "polytope"\n[[uncertainty.vertices]]\nA = [[0.4]]\n[[uncertainty.vertices]]\nA = [[0.6]]\n'


def _write(name, data):
    path = TMP / name
    path.write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
    return path


def _toml_cases():
    from hinfnav.systems import read_system_file

    n = [0]

    def sysfile(label, text, words, expect="refuse"):
        n[0] += 1
        case("system file", label, expect, words)(lambda text=text, i=n[0]: read_system_file(_write(f"s{i}.toml", text)))

    for base_name, base in (("nominal", NOMINAL), ("norm-bounded", NORM), ("polytope", POLY)):
        sysfile(f"{base_name}: as written", base, (), "valid")
        for key in ("A", "B", "C", "D", "L"):
            sysfile(f"{base_name}: boolean in {key}", base.replace(f"{key} = [[", f"{key} = [[true, ", 1)
                    if key != "A" else base.replace("A = [[0.5]]", "A = [[true]]"), ["boolean"] if key == "A" else [key])
            sysfile(f"{base_name}: missing {key}", re.sub(rf"(?m)^{key} = .*\n", "", base, count=1), [key])
            sysfile(f"{base_name}: string in {key}", base.replace(f"{key} = [[", f'{key} = [["1", ', 1), [key])
        sysfile(f"{base_name}: unknown top-level key", "units = 1\n" + base, ["units"])
        sysfile(f"{base_name}: unknown key in [nominal]", base.replace("[nominal]\n", "[nominal]\nM = [[1.0]]\n"), ["M"])
        sysfile(f"{base_name}: dt given twice", base.replace("dt = 0.1", "dt = 0.1\ndt = 0.2"), ["TOML"])
        sysfile(f"{base_name}: [nominal] twice", base + "[nominal]\nA = [[0.3]]\n", ["TOML"])
        sysfile(f"{base_name}: dt boolean", base.replace("dt = 0.1", "dt = true"), ["dt"])
        sysfile(f"{base_name}: dt negative", base.replace("dt = 0.1", "dt = -0.1"), ["dt"])
        sysfile(f"{base_name}: dt string", base.replace("dt = 0.1", 'dt = "0.1"'), ["dt"])
        sysfile(f"{base_name}: dt missing", base.replace("dt = 0.1\n", ""), ["dt"])
        sysfile(f"{base_name}: nan in A", base.replace("A = [[0.5]]", "A = [[nan]]"), ["A"])
        sysfile(f"{base_name}: inf in A", base.replace("A = [[0.5]]", "A = [[inf]]"), ["A"])
        sysfile(f"{base_name}: ragged A", base.replace("A = [[0.5]]", "A = [[0.5], [0.1, 0.2]]"), ["A"])
        sysfile(f"{base_name}: A not square", base.replace("A = [[0.5]]", "A = [[0.5, 0.1]]"), ["A"])
        sysfile(f"{base_name}: UTF-8 BOM", b"\xef\xbb\xbf" + base.encode(), ["byte-order mark"])
        sysfile(f"{base_name}: UTF-16", base.encode("utf-16"), ["UTF-16"])
        sysfile(f"{base_name}: Latin-1 comment", ("# décalage\n" + base).encode("latin-1"), ["UTF-8", "line 1"])
        sysfile(f"{base_name}: CRLF line ends", base.replace("\n", "\r\n"), (), "valid")
        sysfile(f"{base_name}: not TOML", base + "A = \n", ["TOML"])
    sysfile("norm-bounded: unknown key in [uncertainty] (dt)", NORM + "dt = 0.2\n", ["dt"])
    sysfile("norm-bounded: lyapunov in [uncertainty]", NORM + 'lyapunov = "common"\n', ["lyapunov"])
    sysfile("norm-bounded: vertices given", NORM + "[[uncertainty.vertices]]\nA = [[0.4]]\n", ["vertices"])
    sysfile("norm-bounded: boolean in H", NORM.replace("H = [[0.1]]", "H = [[false]]"), ["boolean"])
    sysfile("norm-bounded: missing E", NORM.replace("E = [[1.0]]\n", ""), ["E"])
    sysfile("polytope: H given", POLY.replace('kind = "polytope"', 'kind = "polytope"\nH = [[0.1]]'), ["H"])
    sysfile("polytope: unknown key in a vertex", POLY + "Q = [[1.0]]\n", ["Q"])
    sysfile("polytope: boolean in a vertex", POLY.replace("A = [[0.4]]", "A = [[true]]"), ["boolean"])
    sysfile("polytope: no vertices", NOMINAL + '[uncertainty]\nkind = "polytope"\n', ["vertices"])
    sysfile("uncertainty: unknown kind", NOMINAL + '[uncertainty]\nkind = "cube"\n', ["kind"])
    sysfile("uncertainty: kind missing", NOMINAL + "[uncertainty]\nH = [[0.1]]\nE = [[1.0]]\n", ["kind"])
    sysfile("empty file", "", ["dt"])
    case("system file", "missing file", words=["does not exist"])(lambda: read_system_file(TMP / "nope.toml"))
    case("system file", "a folder", words=["not a file"])(lambda: read_system_file(TMP))

    from hinfnav.campaign import Campaign, load_campaign
    spec = ('runs = 2\n[grid]\nscenario = "sun2011"\nestimator = ["ekf"]\nduration_s = [20.0]\n'
            'rms_window_s = [[0.0, 20.0]]\n[windows]\nall = [0.0, 20.0]\n')
    import hinfnav.papers  # noqa: F401
    specs = {
        "as written": (spec, (), "valid"),
        "options for an estimator not in the grid": (spec + "[estimator_options.hbff]\ngamma = 2.0\n", ["hbff"], "refuse"),
        "unknown field": ("rnus = 3\n" + spec, ["rnus"], "refuse"),
        "BOM": (b"\xef\xbb\xbf" + spec.encode(), ["byte-order mark"], "refuse"),
        "UTF-16": (spec.encode("utf-16"), ["UTF-16"], "refuse"),
        "Latin-1": (("# é\n" + spec).encode("latin-1"), ["UTF-8"], "refuse"),
        "runs given twice": ("runs = 3\n" + spec, ["TOML"], "refuse"),
        "grid twice": (spec + "[grid]\nseed = 1\n", ["TOML"], "refuse"),
        "runs zero": (spec.replace("runs = 2", "runs = 0"), ["runs"], "refuse"),
        "runs boolean": (spec.replace("runs = 2", "runs = true"), ["runs"], "refuse"),
        "unknown grid key": (spec.replace("[grid]\n", "[grid]\nwind = [1]\n"), ["wind"], "refuse"),
        "unknown estimator": (spec.replace('["ekf"]', '["ekff"]'), ["ekff"], "refuse"),
        "window after the end": (spec.replace("all = [0.0, 20.0]", "all = [0.0, 50.0]"), ["windows"], "refuse"),
    }
    for i, (label, (text, words, expect)) in enumerate(specs.items()):
        case("campaign spec", label, expect, words)(
            lambda text=text, i=i: load_campaign(_write(f"c{i}.toml", text)).cells())
    case("campaign spec", "options dict for an estimator not in the grid", words=["hbff"])(
        lambda: Campaign(grid={"scenario": "sun2011", "estimator": ["ekf"], "duration_s": [20.0],
                               "rms_window_s": [[0.0, 20.0]]}, runs=2, windows={"all": [0.0, 20.0]},
                         estimator_options={"hbff": {}}))


GOOD_ORBIT = ("27/7/2010,00:00:00,2046.25,270.77,6513.38,-72393.98,-6729.94,23093.89\n"
              "27/7/2010,00:00:10,1973.72,264.07,6536.07,-72652.59,-6657.28,22280.33\n")


def _data_cases():
    from hinfnav.papers.grace2010.dataset import read_orbit_file, read_range_file

    n = [0]

    def orbit(label, data, words, expect="refuse", gz=False, reader=None):
        n[0] += 1
        name = f"orbit{n[0]}.csv" + (".gz" if gz else "")
        read = reader or read_orbit_file
        case("data file", label, expect, list(words) + ([name] if expect == "refuse" else []))(
            lambda data=data, name=name: read(_write(name, data)))

    orbit("as written", GOOD_ORBIT, (), "valid")
    orbit("gzip as written", gzip.compress(GOOD_ORBIT.encode()), (), "valid", gz=True)
    for token in ("nan", "NaN", "inf", "-inf", "1e999"):
        orbit(f"{token} among the numbers", GOOD_ORBIT.replace("2046.25", token), ["line 1"])
    for bad in ("2046.2x", "", " ", "1,5", "--1", "0x10"):
        orbit(f"number {bad!r}", GOOD_ORBIT.replace("1973.72", bad), ["line 2"])
    for date in ("31/2/2010", "27-7-2010", "2010/7/27", "27/13/2010", "x", ""):
        orbit(f"date {date!r}", GOOD_ORBIT.replace("27/7/2010,00:00:10", f"{date},00:00:10"), ["line 2"])
    for tod in ("25:00:00", "00:61:00", "00:00", "a:b:c"):
        orbit(f"time {tod!r}", GOOD_ORBIT.replace("00:00:10", tod), ["line 2"])
    orbit("time going back", GOOD_ORBIT.replace("00:00:10", "00:00:00"), ["line 2"])
    orbit("Latin-1 comment", (GOOD_ORBIT + "# décalé\n").encode("latin-1"), ["line 3"])
    orbit("UTF-8 BOM", b"\xef\xbb\xbf" + GOOD_ORBIT.encode(), ["line 1"])
    orbit("empty", "", ["no data"])
    orbit("blank lines only", "\n\n\n", ["no data"])
    orbit("too few fields", GOOD_ORBIT.replace(",23093.89", ""), ["line 1"])
    orbit("too many fields", GOOD_ORBIT.replace("23093.89", "23093.89,1"), ["line 1"])
    orbit("truncated gzip", gzip.compress(GOOD_ORBIT.encode())[:-10], ["gzip"], gz=True)
    orbit("fake gzip (plain text)", GOOD_ORBIT, ["gzip"], gz=True)
    orbit("empty gzip", b"", ["no data"], gz=True)
    orbit("gzip of nothing", gzip.compress(b""), ["no data"], gz=True)
    orbit("range file with 2 numbers", "27/7/2010,00:00:00,1.0,2.0\n", ["line 1"], reader=read_range_file)
    orbit("range file nan", "27/7/2010,00:00:00,nan\n", ["line 1"], reader=read_range_file)
    case("data file", "missing file", words=["readable"])(lambda: read_orbit_file(TMP / "none.csv"))


# ---------------------------------------------------------------------------------------------------------------
# saved designs, writers, the command line (items 4, 7, 8)
# ---------------------------------------------------------------------------------------------------------------

def _design_cases():
    from hinfnav.design import design_from_system_file, recertify
    from hinfnav.design.io import content_fingerprint, save_design
    from hinfnav.design.polytopic import COVERS
    from hinfnav.systems import read_system_file

    state = {}

    def designed():
        if "r" not in state:
            state["r"] = design_from_system_file(ROOT / "examples" / "two_mass_spring_30pct.toml")[0]
        return state["r"]

    def other_system(dt):
        text = (ROOT / "examples" / "two_mass_spring_30pct.toml").read_text()
        return read_system_file(_write(f"sys_dt{dt}.toml", re.sub(r"(?m)^dt = 0\.1$", f"dt = {dt}", text)))

    for dt in (0.05, 0.2, 1.0):
        case("saved design", f"save with the system at dt = {dt}", words=["designed for"])(
            lambda dt=dt: save_design(designed(), other_system(dt), TMP / "wrong.json"))
    case("saved design", "save with its own system", "valid")(lambda: save_design(designed(), designed().system,
                                                                                 TMP / "ok.json"))

    def forged(label):
        path = save_design(designed(), designed().system, TMP / "pd.json")
        d = json.loads(path.read_text())
        d["certificate"]["lyapunov"] = label
        d["certificate"]["covers"] = COVERS["common"]
        d["fingerprint"] = content_fingerprint(d)
        f = _write("forged.json", json.dumps(d))
        rep = recertify(f)
        if not rep["ok"]:
            raise HinfnavError("NOT RECERTIFIED: " + "; ".join(rep["reasons"]))
        return rep

    case("saved design", "parameter-dependent relabelled common", words=["proves 'parameter-dependent'"])(
        lambda: forged("common"))
    case("saved design", "recertify as saved", "valid")(lambda: recertify(save_design(designed(), designed().system,
                                                                                      TMP / "pd2.json")))
    for label, text in (("not JSON", "{"), ("empty", ""), ("JSON list", "[]"), ("Latin-1", "\xe9")):
        case("saved design", f"recertify a file that is {label}", words=["design file"])(
            lambda text=text: recertify(_write("bad_design.json", text.encode("latin-1"))))


def _writer_cases():
    from hinfnav.core.validation import check_new_file
    from hinfnav.io.outputs import check_output_dir

    blocker = _write("blocker", "x")
    for label, fn, words in (
        ("--save under a file", lambda: check_new_file("--save", blocker / "d.json"), ["blocker"]),
        ("--save into a missing folder", lambda: check_new_file("--save", TMP / "no" / "d.json"), ["does not exist"]),
        ("--save is a folder", lambda: check_new_file("--save", TMP), ["directory"]),
        ("--save empty", lambda: check_new_file("--save", ""), ["empty"]),
        ("--out is a file", lambda: check_output_dir(blocker), ["is a file"]),
        ("--out under a file", lambda: check_output_dir(blocker / "out"), ["is a file"]),
        ("--out empty", lambda: check_output_dir(""), ["empty"]),
        ("--out under /proc", lambda: check_output_dir("/proc/hinfnav/out"), ["cannot write"]),
        ("--save under /proc", lambda: check_new_file("--save", "/proc/self/x.json"), ["cannot write"]),
    ):
        case("writers", label, words=words)(fn)


def _cli_cases():
    from hinfnav import cli

    def run(argv, want_rc=2):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()) as out:
            try:
                rc = cli.main(argv)
            except SystemExit as exc:
                rc = exc.code
        if rc == 0:
            return out.getvalue()
        lines = err.getvalue().strip().splitlines()
        raise HinfnavError(f"exit {rc}: {' | '.join(lines)}" + (" (traceback)" if "Traceback" in err.getvalue() else ""))

    system = str(ROOT / "examples" / "double_integrator.toml")
    for argv, words in (
        (["design", "--system", system, "--delta-bar", "0.1"], ["--delta-bar"]),
        (["design", "--system", system, "--points", "4"], ["--points"]),
        (["design", "--system", system, "--gamma", "2"], ["--gamma"]),
        (["design", "--recertify", "x.json", "--solver", "SCS"], ["--solver"]),
        (["design", "--recertify", "x.json", "--lyapunov", "common"], ["--lyapunov"]),
        (["design", "--recertify", "x.json", "--form", "observer"], ["--form"]),
        (["design", "--recertify", "x.json", "--objective", "h2"], ["--objective"]),
        (["design", "--lyapunov", "common"], ["--lyapunov"]),
        (["design", "--delta-bar", "-1"], ["--delta-bar"]),
        (["design", "--delta-bar", "nan"], ["--delta-bar"]),
        (["simulate", "--runs", "0"], ["--runs"]),
        (["simulate", "--seed", "-1"], ["--seed"]),
        (["reproduce", "--jobs", "0"], ["--jobs"]),
        (["design", "--system", str(TMP / "none.toml")], ["does not exist"]),
        (["design", "--save", str(TMP)], ["directory"]),
    ):
        case("command line", " ".join(a if "/" not in a else Path(a).name for a in argv), words=words)(
            lambda argv=argv: run(argv))
    case("command line", "--version", "valid")(lambda: run(["--version"]))


def _solve_cases():
    """Designs that must end (no hang past 120 s), scale with the noise and say their cost (issue 36, this round)."""
    import os
    import subprocess
    import tomllib

    from hinfnav.design import SolverOptions, synthesize
    from hinfnav.papers.sun2011 import Scenario
    from hinfnav.systems.uncertain import UncertainSystem

    def cli(argv, timeout=150):
        env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
        out = subprocess.run([sys.executable, "-m", "hinfnav", *argv], cwd=ROOT, env=env, capture_output=True,
                             text=True, timeout=timeout)
        if "Traceback" in out.stderr:
            raise RuntimeError("traceback: " + out.stderr[-300:])
        if out.returncode:
            lines = [ln for ln in out.stderr.strip().splitlines() if not ln.startswith(("design (", "note:"))]
            raise HinfnavError(f"exit {out.returncode}: " + " ⏎ ".join(lines))
        assert "--json" in argv or "certified" in out.stdout, out.stdout
        return out

    def scs(argv):
        # a clear outcome within the time: a certified design, or one line that names SCS and what to use instead
        # (SCS's points certify or not depending on how far it gets in its time budget, so either can happen)
        try:
            return cli(argv)
        except HinfnavError as exc:
            text = str(exc)
            assert "exit 1" in text and "SCS ran" in text and "--solver CLARABEL" in text and " ⏎ " not in text, \
                text[-300:]

    examples = ROOT / "examples"
    for name, form in (("double_integrator", "observer"), ("double_integrator_position", "observer"),
                       ("two_mass_spring_30pct", "general"), ("two_mass_spring_30pct", "observer"),
                       ("mass_spring_damper_continuous", "observer"), ("flexible_attitude_20pct", "observer")):
        case("solver", f"design --system {name} --form {form} --solver SCS: certified, or one line naming SCS",
             "valid")(lambda name=name, form=form: scs(["design", "--system", str(examples / f"{name}.toml"), "--form",
                                                        form, "--solver", "SCS"]))
    case("solver", "design --system double_integrator --form general --solver SCS",
         words=["not robustly schur stable"])(
        lambda: cli(["design", "--system", str(examples / "double_integrator.toml"), "--solver", "SCS"]))
    case("solver", "design (built-in scenario) --solver SCS: certified, or one line naming SCS", "valid")(
        lambda: scs(["design", "--solver", "SCS"]))
    case("solver", "design --time-limit 0.001 refused before solving", words=["exceeds the limit"])(
        lambda: cli(["design", "--system", str(examples / "two_mass_spring_30pct.toml"), "--time-limit", "0.001"]))
    case("solver", "design --time-limit -1", words=["--time-limit"])(
        lambda: cli(["design", "--system", str(examples / "two_mass_spring_30pct.toml"), "--time-limit", "-1"]))

    def stacked_file(k):
        s = Scenario().design_model(0.05)
        import scipy.linalg

        bd = lambda M: scipy.linalg.block_diag(*([M] * k))
        mat = lambda M: "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in M) + "]"
        text = "\n".join([f"dt = {s.dt!r}", "[nominal]"] + [f"{m} = {mat(bd(getattr(s, m)))}" for m in "ABCDL"]
                         + ["[uncertainty]", 'kind = "norm-bounded"'] + [f"{m} = {mat(bd(getattr(s, m)))}" for m in "HE"])
        return _write(f"stacked{6 * k}.toml", text + "\n")

    for k in (8, 12):
        case("solver", f"design of {6 * k} states refused up front (estimate above the limit)",
             words=["estimated", "exceeds the limit"])(lambda k=k: cli(["design", "--system", str(stacked_file(k))]))

    chaser = Scenario().design_model(0.05)
    units = SolverOptions(state_scaling="units")
    ref = {}

    def gamma0():
        if "g" not in ref:
            ref["g"] = synthesize(chaser, structure="full", options=units).gamma
        return ref["g"]

    def noise_scaled(k):
        s = UncertainSystem(chaser.A, chaser.B * k, chaser.C, chaser.D * k, chaser.L, chaser.H, chaser.E, dt=chaser.dt)
        g = synthesize(s, structure="full", options=units).gamma
        assert abs(g / (k * gamma0()) - 1) <= 1e-6, (g, k * gamma0())

    for k in (1e-6, 1e-3, 1e3, 1e6):
        case("noise scaling", f"chaser, B and D x {k:g}: gamma x {k:g} to 1e-6", "valid")(lambda k=k: noise_scaled(k))

    def file_noise(name, k, form):
        text = (examples / f"{name}.toml").read_text()
        d = tomllib.loads(text)
        nom = d["nominal"]
        for key in ("B", "D"):
            nom[key] = [[v * k for v in row] for row in nom[key]]
        out_lines, in_nom = [], False
        for ln in text.splitlines():
            if ln.strip().startswith("[") and not ln.strip().startswith("[["):
                in_nom = ln.strip() == "[nominal]"
            if in_nom and re.match(r"^(B|D) = ", ln):
                key = ln[0]
                ln = f"{key} = " + "[" + ", ".join("[" + ", ".join(repr(v) for v in row) + "]" for row in nom[key]) + "]"
            out_lines.append(ln)
        path = _write(f"{name}_noise{k:g}.toml", "\n".join(out_lines) + "\n")
        if (name, form) not in ref:
            ref[name, form] = json.loads(cli(["design", "--system", str(examples / f"{name}.toml"), "--form", form,
                                              "--json"]).stdout)["gamma"]
        g0 = ref[name, form]
        g = json.loads(cli(["design", "--system", str(path), "--form", form, "--json"]).stdout)["gamma"]
        assert abs(g / (k * g0) - 1) <= 1e-6, (g, k * g0)

    for k in (1e-6, 1e6):
        case("noise scaling", f"double_integrator file (observer), B and D x {k:g}: gamma x {k:g} to 1e-6", "valid")(
            lambda k=k: file_noise("double_integrator", k, "observer"))


def _interrupt_cases():
    """Ctrl-C through a real signal to the process group, as a terminal sends it (issue 36 item 7)."""
    import os
    import subprocess

    def interrupted(argv, wait_s):
        env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg", HINFNAV_BACKEND="numpy")
        proc = subprocess.Popen([sys.executable, "-m", "hinfnav", *argv], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, start_new_session=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        time.sleep(wait_s)
        for _ in range(4):
            os.killpg(proc.pid, signal.SIGINT)
            try:
                proc.wait(timeout=15)
                break
            except subprocess.TimeoutExpired:
                pass
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate(timeout=60)
        ours = [ln for ln in err.splitlines() if "resource_tracker" not in ln and "warnings.warn" not in ln]
        assert proc.returncode == 130 and len(ours) == 1 and "interrupted" in ours[0], (proc.returncode, err[-400:])

    spec = _write("ctrlc.toml", 'runs = 20000\nbatch_size = 50\n[grid]\nscenario = "sun2011"\n'
                  'estimator = ["ekf", "published"]\nduration_s = [100.0]\nrms_window_s = [[0, 100.0]]\n'
                  '[windows]\nall = [0, 100.0]\n')
    case("interrupts", "Ctrl-C during a 2-worker campaign: exit 130, one line", "valid")(
        lambda: interrupted(["campaign", str(spec), "--out", str(TMP / "cc_out"), "--workers", "2"], 25.0))
    case("interrupts", "Ctrl-C during reproduce sun2011: exit 130, one line", "valid")(
        lambda: interrupted(["reproduce", "--paper", "sun2011", "--out", str(TMP / "rp_out"), "--jobs", "1"], 12.0))
    case("interrupts", "Ctrl-C during a design with SCS: exit 130, one line", "valid")(
        lambda: interrupted(["design", "--system", str(ROOT / "examples" / "two_mass_spring_30pct.toml"), "--form",
                             "observer", "--solver", "SCS"], 12.0))


# ---------------------------------------------------------------------------------------------------------------

class _Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise _Timeout


def classify(c, timeout):
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(int(timeout))
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            c["fn"]()
        err = None
    except _Timeout:
        return "hang", f"no answer in {timeout} s"
    except (Exception, SystemExit) as exc:
        err = exc
    finally:
        signal.alarm(0)
    seconds = time.perf_counter() - t0
    if err is None:
        return ("valid", f"{seconds:.2f} s") if c["expect"] == "valid" else ("silent", "no error")
    msg = f"{type(err).__name__}: {err}"
    if c["expect"] == "valid":
        return ("silent" if isinstance(err, AssertionError) else "unclear"), msg[:300]
    if isinstance(err, HinfnavError) and all(w.lower() in str(err).lower() for w in c["words"]):
        return "refused-clearly", msg[:300]
    return "unclear", msg[:300]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--json", metavar="OUT", help="write every case with its verdict to OUT (JSON)")
    p.add_argument("--surface", action="append", help="run only these surfaces")
    p.add_argument("--skip", action="append", default=[],
                   help="leave out these surfaces (the slow test leaves out 'solver', 'noise scaling' and 'interrupts', "
                        "minutes of designs and campaigns that tests/test_design_cost.py, test_design_scale.py and "
                        "test_cli_edges.py cover)")
    p.add_argument("--timeout", type=float, default=120.0, help="seconds before a case counts as a hang (120)")
    p.add_argument("--list", action="store_true", help="list the cases and exit")
    args = p.parse_args(argv)
    for make in (_model_cases, _registry_cases, _absurd_cases, _diagnostic_cases, _toml_cases, _data_cases,
                 _design_cases, _writer_cases, _cli_cases, _solve_cases, _interrupt_cases):
        make()
    cases = [c for c in CASES if (not args.surface or c["surface"] in args.surface) and c["surface"] not in args.skip]
    if args.list:
        for c in cases:
            print(f"{c['surface']}: {c['name']} [{c['expect']}]")
        print(f"{len(cases)} cases")
        return 0
    counts, by_surface, rows = {}, {}, []
    for c in cases:
        verdict, detail = classify(c, args.timeout)
        counts[verdict] = counts.get(verdict, 0) + 1
        by_surface.setdefault(c["surface"], {}).setdefault(verdict, 0)
        by_surface[c["surface"]][verdict] += 1
        rows.append({"surface": c["surface"], "case": c["name"], "expect": c["expect"], "verdict": verdict,
                     "detail": detail})
        if verdict not in ("refused-clearly", "valid"):
            print(f"[{verdict}] {c['surface']}: {c['name']}: {detail}")
    print(f"\n{len(cases)} cases: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for surface, cnt in by_surface.items():
        print(f"  {surface}: " + ", ".join(f"{k} {v}" for k, v in sorted(cnt.items())))
    if args.json:
        Path(args.json).write_text(json.dumps({"counts": counts, "by_surface": by_surface, "cases": rows}, indent=1))
    return 1 if any(counts.get(k) for k in ("silent", "hang", "unclear")) else 0


if __name__ == "__main__":
    sys.exit(main())
