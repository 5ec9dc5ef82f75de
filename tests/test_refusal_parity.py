"""The step interface refuses what the batch ``estimate`` refuses, and the reverse (issue 17, item 4).

For every registered estimator the same bad input (a NaN or an infinite
reading, a reading with a channel missing, a NaN or short x̂₀, a NaN applied input)
is given to ``estimate`` and to ``start``/``update``/``predict``: both must
raise :class:`~hinfnav.core.exceptions.InputError`, and a good input must pass
both. Expected behaviour: the contract of :class:`hinfnav.estimators.base.Estimator`
(no number is computed or compared).
"""

import numpy as np
import pytest
from test_step_interface import RUNS, built

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import registered_estimators

N_SAMPLES = 5


def _data(est):
    y = np.zeros((RUNS, N_SAMPLES, est.measurement.n_meas)) + 0.5
    return y, np.zeros((RUNS, N_SAMPLES, est.n_input))  # the applied input, as the simulation gives it


def _with(a, index, value):
    a = a.copy()
    a[index] = value
    return a


def _cases(est, x0):
    """name -> (batch call, step call); each None case is the good input."""
    y, u = _data(est)
    u0 = u[:, 0]
    start = lambda xhat0=x0: est.start(xhat0, runs=RUNS)
    first = lambda: est.update(start(), y[:, 0])[0]
    cases = {
        "good": (lambda: est.estimate(y, u, x0), lambda: est.update(est.predict(first(), u0), y[:, 1])),
        "y_nan": (lambda: est.estimate(_with(y, (0, 2, 0), np.nan), u, x0),
                  lambda: est.update(est.predict(first(), u0), _with(y[:, 2], (0, 0), np.nan))),
        "y_inf": (lambda: est.estimate(_with(y, (0, 2, 0), np.inf), u, x0),
                  lambda: est.update(start(), _with(y[:, 2], (0, 0), np.inf))),
        "y_channel_missing": (lambda: est.estimate(y[:, :, 1:], u, x0), lambda: est.update(start(), y[:, 0, 1:])),
        "xhat0_nan": (lambda: est.estimate(y, u, np.full_like(x0, np.nan)),
                      lambda: start(np.full_like(x0, np.nan))),
        "xhat0_short": (lambda: est.estimate(y, u, x0[:-1]), lambda: start(x0[:-1])),
    }
    if est.n_input:
        cases["u_nan"] = (lambda: est.estimate(y, _with(u, (0, 1, 0), np.nan), x0),
                          lambda: est.predict(first(), _with(u[:, 1], (0, 0), np.nan)))
    return cases


def _refused(call):
    try:
        call()
    except InputError:
        return True
    return False


@pytest.mark.parametrize("name", registered_estimators())
def test_step_interface_refuses_what_estimate_refuses(name):
    est, x0 = built(name)
    for case, (batch, step) in _cases(est, x0).items():
        expected = case != "good"
        assert _refused(batch) is expected, f"{name}: estimate with {case}"
        assert _refused(step) is expected, f"{name}: step interface with {case}"
