"""The estimator contract, run over every registered estimator.

Every estimator on the step contract (``start``/``update``/``predict``,
batch ``estimate``) must: return histories of the right shape with the
system's state labels; give the same numbers for the same seed; give the same
numbers run by run as for the whole batch; give the same numbers stepped one
step at a time as through ``estimate``; converge to the truth when there is
no noise on a stable problem; and refuse bad input with an error that names
the parameter. Expected values are identities (same computation two ways) or
limits (zero error without noise), not fitted numbers.
"""

import numpy as np
import pytest

import hinfnav as hn
import hinfnav.papers  # noqa: F401 - registers every paper's estimators, whatever the test order
from hinfnav.estimators import build_estimator, registered_estimators
from hinfnav.noise import NoiseModel
from hinfnav.papers.sun2011 import Scenario
from hinfnav.sim import simulate_truth

SCENARIO = Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0))
NAMES = registered_estimators(SCENARIO)


class ZeroNoise(NoiseModel):
    """w = v = 0: the truth and the measurements are noise free."""

    name = "zero"

    def _sample(self, rng, shape):
        return np.zeros(shape)


@pytest.fixture(scope="module", params=NAMES)
def estimator(request):
    return build_estimator(request.param, SCENARIO)


@pytest.fixture(scope="module")
def truth():
    return simulate_truth(SCENARIO.truth_model(maneuver=True), runs=3, seed=7)


def test_every_sun2011_filter_is_registered():
    assert set(hn.FILTER_NAMES) <= set(NAMES)


def test_shapes_and_labels(estimator, truth):
    hist = estimator.estimate(truth.y, truth.u, SCENARIO.xhat0)
    assert hist.xhat.shape == truth.x.shape
    assert hist.labels == SCENARIO.system().state.labels == ("x", "y", "z", "vx", "vy", "vz")
    assert hist.units == ("m", "m", "m", "m/s", "m/s", "m/s")
    if hist.P is not None:
        assert hist.P.shape == truth.x.shape + (6,)
    assert np.all(np.isfinite(hist.xhat))


def test_same_seed_same_numbers(estimator):
    a = hn.simulate(SCENARIO, estimator, runs=2, seed=3, maneuver=True)
    b = hn.simulate(SCENARIO, estimator, runs=2, seed=3, maneuver=True)
    np.testing.assert_array_equal(a.xhat, b.xhat)


def test_run_by_run_equals_vectorized(estimator, truth):
    batch = estimator.estimate(truth.y, truth.u, SCENARIO.xhat0).xhat
    for r in range(truth.x.shape[0]):
        single = estimator.estimate(truth.y[r : r + 1], truth.u[r : r + 1], SCENARIO.xhat0).xhat[0]
        # identity (same computation); tolerance covers BLAS blocking differences
        np.testing.assert_allclose(single, batch[r], rtol=1e-12, atol=1e-9)


def test_step_loop_equals_batch_estimate(estimator, truth):
    batch = estimator.estimate(truth.y, truth.u, SCENARIO.xhat0)
    state = estimator.start(SCENARIO.xhat0, None, truth.x.shape[0])
    n1 = truth.x.shape[1]
    xhat = np.empty_like(batch.xhat)
    for k in range(n1):
        state, out = estimator.update(state, truth.y[:, k])
        xhat[:, k] = out.xhat
        assert "innovation" in out.diagnostics or out.P is None  # Kalman-type filters report their innovation
        if k < n1 - 1:
            state = estimator.predict(state, truth.u[:, k])
    np.testing.assert_allclose(xhat, batch.xhat, rtol=1e-12, atol=1e-9)


def test_converges_without_noise_on_a_stable_problem(estimator):
    # with maneuver the closed loop is stable; without noise every filter's error must vanish
    sc = Scenario(duration_s=1500.0, rms_window_s=(1400.0, 1500.0))
    est = build_estimator(estimator.name, sc)
    res = hn.simulate(sc, est, runs=1, seed=0, noise=ZeroNoise(), maneuver=True)
    final = np.abs(res.error[0, -1])
    # limit 0 (no noise); 1 mm and 1 mm/s leave room for the slowest transient (the unaware EKF's)
    assert np.all(final[:3] < 1e-3), (estimator.name, final)
    assert np.all(final[3:] < 1e-3), (estimator.name, final)


@pytest.mark.parametrize(
    "change, word",
    [
        (lambda y, u, x0: (y[:, :, :2], u, x0), "y"),
        (lambda y, u, x0: (y[0], u, x0), "y"),
        (lambda y, u, x0: (np.where(np.arange(y.shape[1])[None, :, None] == 3, np.nan, y), u, x0), "y"),
        (lambda y, u, x0: (y, u[:, :-1], x0), "u"),
        (lambda y, u, x0: (y, u, x0[:5]), "xhat0"),
        (lambda y, u, x0: (y, u, np.full(6, np.inf)), "xhat0"),
    ],
    ids=["y-channels", "y-2d", "y-nan", "u-length", "xhat0-size", "xhat0-inf"],
)
def test_bad_input_names_the_parameter(estimator, truth, change, word):
    y, u, x0 = change(truth.y, truth.u, SCENARIO.xhat0)
    with pytest.raises(hn.InputError, match=rf"\b{word}\b"):
        estimator.estimate(y, u, x0)


def test_unknown_name_lists_the_registered_ones():
    with pytest.raises(hn.InputError, match="published"):
        build_estimator("kalmann", SCENARIO)
