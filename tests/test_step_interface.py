"""The step interface trusts nothing (issue 17, item 4), for every registered estimator.

``start``, ``update`` and ``predict`` check shapes, finiteness and the
required input as the batch ``estimate`` does, and the call order (start, then
update and predict alternately): each bad call below must raise an
:class:`~hinfnav.core.exceptions.InputError` whose message names the
parameter (``y``, ``u``, ``xhat0``, ``P0``) and, for y and u, the step, or the
word "order". Expected behaviour: the contract of
:class:`hinfnav.estimators.base.Estimator` (no number is computed).
"""

import numpy as np
import pytest

import hinfnav.papers  # noqa: F401 - registers every paper's estimators
from hinfnav.core.exceptions import InputError
from hinfnav.estimators import build_estimator, registered_estimators
from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
from hinfnav.papers.shi2018 import Scenario as ShiScenario
from hinfnav.papers.sun2011 import Scenario as SunScenario
from hinfnav.papers.yang2020 import SUBSYSTEM_OF
from hinfnav.papers.yang2020 import Scenario as YangScenario

RUNS = 2
_SCENARIOS = (SunScenario(duration_s=30.0, rms_window_s=(5.0, 30.0)), ShiScenario(), AttitudeScenario())
_YANG = YangScenario(n_steps=50)
_BUILT = {}


def scenario_for(name):
    """A scenario the registered estimator ``name`` fits (the first of the papers' that does)."""
    for sc in _SCENARIOS:
        if name in registered_estimators(sc):
            return sc
    return _YANG.linear_truth(SUBSYSTEM_OF[name])


def built(name):
    """``(estimator, xhat0)`` built once per test module."""
    if name not in _BUILT:
        sc = scenario_for(name)
        _BUILT[name] = build_estimator(sc, name), np.asarray(sc.xhat0, dtype=float)
    return _BUILT[name]


def good_y(est):
    return np.zeros((RUNS, est.measurement.n_meas)) + 0.5


def good_u(est):
    return np.zeros((RUNS, est.n_input))


def after_update(est, x0):
    state, _ = est.update(est.start(x0, runs=RUNS), good_y(est))
    return state


def _y_nan(est, x0):
    y = good_y(est)
    y[1, 0] = np.nan
    est.update(est.start(x0, runs=RUNS), y)


def _y_inf(est, x0):
    y = good_y(est)
    y[0, -1] = np.inf
    est.update(est.start(x0, runs=RUNS), y)


def _y_channels(est, x0):
    est.update(est.start(x0, runs=RUNS), np.zeros((RUNS, est.measurement.n_meas + 1)))


def _y_runs(est, x0):
    est.update(est.start(x0, runs=RUNS), np.zeros((RUNS + 1, est.measurement.n_meas)))


def _y_later_step(est, x0):
    # a NaN reading at step 1, after a good first step
    state = est.predict(after_update(est, x0), good_u(est))
    y = good_y(est)
    y[:] = np.nan
    est.update(state, y)


def _u_nan(est, x0):
    u = np.zeros((RUNS, max(est.n_input, 1)))
    u[0, 0] = np.nan
    est.predict(after_update(est, x0), u)


def _u_runs(est, x0):
    est.predict(after_update(est, x0), np.zeros((RUNS + 1, max(est.n_input, 1))))


def _xhat0_nan(est, x0):
    bad = x0.copy()
    bad[0] = np.nan
    est.start(bad, runs=RUNS)


def _xhat0_length(est, x0):
    est.start(x0[:-1], runs=RUNS)


def _p0_nan(est, x0):
    est.start(x0, P0=np.full((3, 3), np.nan), runs=RUNS)


def _update_twice(est, x0):
    est.update(after_update(est, x0), good_y(est))


def _predict_first(est, x0):
    est.predict(est.start(x0, runs=RUNS), good_u(est))


def _update_before_start(est, x0):
    est.update(None, good_y(est))


#: (bad call, the word its error must contain, whether the message names the step)
CASES = {
    "y-nan": (_y_nan, "y", True),
    "y-inf": (_y_inf, "y", True),
    "y-channels": (_y_channels, "y", True),
    "y-runs": (_y_runs, "y", True),
    "y-nan-step1": (_y_later_step, "y", True),
    "u-nan": (_u_nan, "u", True),
    "u-runs": (_u_runs, "u", True),
    "xhat0-nan": (_xhat0_nan, "xhat0", False),
    "xhat0-length": (_xhat0_length, "xhat0", False),
    "P0-nan": (_p0_nan, "P0", False),
    "update-twice": (_update_twice, "order", False),
    "predict-before-update": (_predict_first, "order", False),
    "update-before-start": (_update_before_start, "order", False),
}

ROWS = [(name, case) for name in registered_estimators() for case in CASES]


def test_enough_rows_over_every_registered_estimator():
    assert len(ROWS) >= 30 and len(registered_estimators()) >= 20


@pytest.mark.parametrize("name, case", ROWS, ids=[f"{n}-{c}" for n, c in ROWS])
def test_bad_step_call_names_the_parameter(name, case):
    est, x0 = built(name)
    call, word, names_step = CASES[case]
    with pytest.raises(InputError, match=rf"\b{word}\b") as info:
        call(est, x0)
    if names_step:
        assert "step" in str(info.value)


@pytest.mark.parametrize("name", [n for n in registered_estimators() if built(n)[0].uses_input])
def test_missing_input_names_u(name):
    est, x0 = built(name)
    with pytest.raises(InputError, match=r"\bu\b.*|needs u"):
        est.predict(after_update(est, x0), None)


@pytest.mark.parametrize("name", registered_estimators())
def test_good_steps_pass_and_alternate(name):
    # the same calls with good arguments run, and a predicted state accepts the next update
    est, x0 = built(name)
    state = est.predict(after_update(est, x0), good_u(est))
    state, out = est.update(state, good_y(est))
    assert out.xhat.shape == (RUNS, est.n_state) and np.all(np.isfinite(out.xhat))
