"""The public unchecked step (issue 37, item 3): bitwise the checked step, and no private step calls across modules.

Expected values: the checked ``update``/``predict``/``feed_input`` of the same filter on the same arrays
(the unchecked methods must return the very same numbers, compared with ``==``).
"""

import ast
from pathlib import Path

import numpy as np

from hinfnav.papers.yang2020 import Scenario, build_fused
from hinfnav.papers.yang2020.filters import build_alg1

ROOT = Path(__file__).resolve().parents[1]
PRIVATE_STEPS = {"_update", "_predict", "_feed_input", "_start"}


def _run(est, runs, y, u, checked):
    s = est.start(np.zeros(est.n_state), None, runs)
    xs = []
    for k in range(y.shape[0]):
        if hasattr(est, "feed_input"):
            s = est.feed_input(s, u[k]) if checked else est.feed_input_unchecked(s, u[k])
        s, out = est.update(s, y[k]) if checked else est.update_unchecked(s, y[k])
        s = est.predict(s, u[k]) if checked else est.predict_unchecked(s, u[k])
        xs.append(out.xhat)
    return np.array(xs), s.P


def test_unchecked_steps_are_bitwise_the_checked_ones():
    sc = Scenario(n_steps=50)
    rng = np.random.default_rng(3)
    for est in (build_alg1(sc), build_fused(sc)):
        runs = 2
        y = rng.normal(scale=1e-7, size=(20, runs, est.measurement.n_meas))
        u = rng.normal(scale=1e-6, size=(20, runs, est.n_input))
        x1, P1 = _run(est, runs, y, u, True)
        x2, P2 = _run(est, runs, y, u, False)
        assert np.array_equal(x1, x2) and np.array_equal(P1, P2), type(est).__name__


def test_no_module_outside_the_estimators_calls_a_filters_private_step():
    offenders = []
    for path in sorted((ROOT / "hinfnav").rglob("*.py")):
        if "estimators" in path.parts:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in PRIVATE_STEPS
                    and not (isinstance(node.func.value, ast.Name) and node.func.value.id == "self")
                    and not (isinstance(node.func.value, ast.Call) and getattr(node.func.value.func, "id", "") == "super")):
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno} .{node.func.attr}")
    assert not offenders, offenders

