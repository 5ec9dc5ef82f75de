"""The estimator contract (as in tests/test_contract.py) for Yang et al. (2020)'s registered estimators.

Each runs on the linear truth of its subsystem (``Scenario.linear_truth``):
Algorithm 1 on the extended system measured by Y, Algorithm 2 (L1, L2, L3) on
the drag-free axes measured by the accelerometers, Algorithm 3 on both. The
checks: shapes and labels; same seed, same numbers; run by run = batch; the
step loop = the batch estimate; convergence without noise on a stable
problem (the loop closed by the linear ADRC on the true state); bad input
refused naming the parameter. Expected values are identities or limits.
"""

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.estimators import build_estimator, registered_estimators
from hinfnav.noise import NoiseModel
from hinfnav.papers.sun2011 import Scenario as SunScenario
from hinfnav.papers.yang2020 import ESTIMATOR_NAMES, SUBSYSTEM_OF, Scenario
from hinfnav.sim import simulate_truth

SCENARIO = Scenario(n_steps=300)


class ZeroNoise(NoiseModel):
    """w = v = 0: the truth and the measurements are noise free."""

    name = "zero"

    def _sample(self, rng, shape):
        return np.zeros(shape)


@pytest.fixture(scope="module", params=ESTIMATOR_NAMES)
def case(request):
    name = request.param
    lt = SCENARIO.linear_truth(SUBSYSTEM_OF[name])
    truth = simulate_truth(lt.truth_model(), runs=3, seed=7)
    return name, lt, build_estimator(name, lt), truth


def test_registered_for_the_paper_and_only_there():
    assert set(ESTIMATOR_NAMES) <= set(registered_estimators(SCENARIO))
    assert not set(ESTIMATOR_NAMES) & set(registered_estimators(SunScenario()))
    assert registered_estimators(SCENARIO.linear_truth("position")) == ("yang2020_alg1",)
    with pytest.raises(hn.InputError, match="does not fit"):
        build_estimator("yang2020_fused", SunScenario())


def test_shapes_and_labels(case):
    name, lt, est, truth = case
    hist = est.estimate(truth.y, truth.u, lt.xhat0)
    n = truth.x.shape[-1]
    assert hist.xhat.shape == truth.x.shape and np.all(np.isfinite(hist.xhat))
    assert hist.labels == lt.truth_model().system.state.labels
    assert hist.units == lt.truth_model().system.state.units
    assert hist.P is not None and hist.P.shape == truth.x.shape + (n,)


def test_same_seed_same_numbers(case):
    name, lt, est, _ = case
    a = hn.simulate(lt, est, runs=2, seed=3)
    b = hn.simulate(lt, est, runs=2, seed=3)
    np.testing.assert_array_equal(a.xhat, b.xhat)


def test_run_by_run_equals_vectorized(case):
    name, lt, est, truth = case
    batch = est.estimate(truth.y, truth.u, lt.xhat0).xhat
    for r in range(truth.x.shape[0]):
        single = est.estimate(truth.y[r:r + 1], truth.u[r:r + 1], lt.xhat0).xhat[0]
        # identity (same computation); tolerance covers BLAS blocking differences
        np.testing.assert_allclose(single, batch[r], rtol=1e-10, atol=1e-12 * np.abs(batch).max())


def test_step_loop_equals_batch_estimate(case):
    name, lt, est, truth = case
    batch = est.estimate(truth.y, truth.u, lt.xhat0)
    state = est.start(lt.xhat0, None, truth.x.shape[0])
    n1 = truth.x.shape[1]
    xhat = np.empty_like(batch.xhat)
    for k in range(n1):
        state, out = est.update(state, truth.y[:, k])
        xhat[:, k] = out.xhat
        assert "innovation" in out.diagnostics and "theta" in out.diagnostics
        if k < n1 - 1:
            state = est.predict(state, truth.u[:, k])
    np.testing.assert_allclose(xhat, batch.xhat, rtol=1e-12, atol=1e-15 * np.abs(batch.xhat).max())


def test_saturation_flags_in_the_diagnostics():
    lt = SCENARIO.linear_truth("dragfree")
    tr = simulate_truth(lt.truth_model(disturbance=-12.8e-3, feedback=False, n_steps=50), runs=1, seed=0)
    hist = build_estimator("yang2020_alg2", lt).estimate(tr.y, tr.u, lt.xhat0, diagnostics=True)
    np.testing.assert_array_equal(hist.diagnostics["saturated"], tr.y <= -6e-6)


def test_converges_without_noise_on_a_stable_problem(case):
    # the loop closed on the true state by the linear ADRC is stable; without noise the error must vanish:
    # each group 100x below its prior error x0 - xhat0 (below 1e-9 where that is 0) after 300 s. Exception,
    # a property of Algorithm 2 (Fig 6): the accelerometers see r only through K r / m_tm = 1e-6 r, so its
    # displacement error does not converge in 300 s; it must stay within 10x its prior error
    name, lt, est, _ = case
    res = hn.simulate(lt, est, runs=1, seed=0, noise=ZeroNoise(), n_steps=3000)
    model = lt.truth_model()
    prior = np.abs(model.x0 - lt.xhat0)
    final = np.abs(res.error[0, -1])
    st = model.system.state
    for group in st.groups:
        e0, e = st.select(prior, group).max(), st.select(final, group).max()
        if name.startswith("yang2020_alg2") and group == "displacement":
            assert e < 10 * e0, (name, group, e, e0)
        elif e0 > 0:
            assert e <= 1e-2 * e0, (name, group, e, e0)
        else:
            assert e < 1e-9, (name, group, e)


@pytest.mark.parametrize(
    "change, word",
    [
        (lambda y, u, x0: (y[:, :, :2], u, x0), "y"),
        (lambda y, u, x0: (y[0], u, x0), "y"),
        (lambda y, u, x0: (np.where(np.arange(y.shape[1])[None, :, None] == 3, np.nan, y), u, x0), "y"),
        (lambda y, u, x0: (y, u[:, :-1], x0), "u"),
        (lambda y, u, x0: (y, u[:, :, :1], x0), "u"),
        (lambda y, u, x0: (y, u, x0[:5]), "xhat0"),
        (lambda y, u, x0: (y, u, np.full(x0.size, np.inf)), "xhat0"),
    ],
    ids=["y-channels", "y-2d", "y-nan", "u-length", "u-channels", "xhat0-size", "xhat0-inf"],
)
def test_bad_input_names_the_parameter(case, change, word):
    name, lt, est, truth = case
    y, u, x0 = change(truth.y, truth.u, lt.xhat0)
    with pytest.raises(hn.InputError, match=rf"\b{word}\b"):
        est.estimate(y, u, x0)
