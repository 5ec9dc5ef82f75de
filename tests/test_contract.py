"""The estimator contract, run over EVERY registered estimator (one suite for all papers).

Every estimator on the step contract (``start``/``update``/``predict``,
batch ``estimate``) must: return histories of the right shape with the
system's state labels; give the same numbers for the same seed; give the same
numbers run by run as for the whole batch; give the same numbers stepped one
step at a time as through ``estimate``; converge to the truth when there is
no noise on a stable problem; and refuse bad input with an error that names
the parameter. Each estimator runs on a short version of the scenario of the
paper that registers it (Sun 2011's chaser, Shi & Wang 2018's, paper 002's
attitude, Yang 2020's subsystems). Expected values are identities (same
computation two ways) or limits (zero error without noise), not fitted numbers.
"""

from dataclasses import dataclass

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.papers import sun2011
import hinfnav.papers
from hinfnav.estimators import build_estimator, registered_estimators
from hinfnav.noise import NoiseModel
from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
from hinfnav.papers.shi2018 import Scenario as ShiScenario
from hinfnav.papers.sun2011 import Scenario
from hinfnav.papers.yang2020 import ESTIMATOR_NAMES as YANG_NAMES
from hinfnav.papers.yang2020 import SUBSYSTEM_OF
from hinfnav.papers.yang2020 import Scenario as YangScenario
from hinfnav.sim import simulate_truth

SCENARIO = Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0))
SHI = ShiScenario(duration_s=40.0, rms_window_s=(4.0, 40.0), maneuver_time_s=20.0)
ATTITUDE = AttitudeScenario(orbits=0.05)  # 293 steps of 1 s
YANG = YangScenario(n_steps=300)
NAMES = registered_estimators()


class ZeroNoise(NoiseModel):
    """w = v = 0: the truth and the measurements are noise free."""

    name = "zero"

    def _sample(self, rng, shape):
        return np.zeros(shape)


@dataclass
class Case:
    """An estimator on its paper's scenario: ``simulate(runs, seed, **kw)`` closes the loop around it."""

    name: str
    paper: str
    scenario: object
    estimator: object
    truth: object
    simulate: object


_TRUTHS = {}


def _truth(key, make):
    if key not in _TRUTHS:
        _TRUTHS[key] = make()
    return _TRUTHS[key]


def make_case(name):
    if name in registered_estimators(SCENARIO):
        est = build_estimator(SCENARIO, name)
        truth = _truth("sun2011", lambda: simulate_truth(SCENARIO.truth_model(maneuver=True), runs=3, seed=7))
        return Case(name, "sun2011", SCENARIO, est, truth,
                    lambda e, **kw: hn.simulate(SCENARIO, e, maneuver=True, **kw))
    if name in registered_estimators(SHI):
        est = build_estimator(SHI, name)
        truth = _truth("shi2018", lambda: simulate_truth(SHI.truth_model(), runs=3, seed=7))
        return Case(name, "shi2018", SHI, est, truth, lambda e, **kw: hn.simulate(SHI, e, **kw))
    if name in registered_estimators(ATTITUDE):
        est = build_estimator(ATTITUDE, name)
        truth = _truth("attitude2018", lambda: hn.simulate_truth(ATTITUDE.truth_model(), runs=3, seed=11))
        return Case(name, "attitude2018", ATTITUDE, est, truth, lambda e, **kw: hn.simulate(ATTITUDE, e, keep_covariance=False, diagnostics=False, **kw))
    lt = YANG.linear_truth(SUBSYSTEM_OF[name])
    truth = _truth(name, lambda: simulate_truth(lt.truth_model(), runs=3, seed=7))
    return Case(name, "yang2020", lt, build_estimator(lt, name), truth, lambda e, **kw: hn.simulate(lt, e, **kw))


@pytest.fixture(scope="module", params=NAMES)
def case(request):
    return make_case(request.param)


def test_every_paper_filter_is_registered():
    assert set(sun2011.FILTER_NAMES) <= set(registered_estimators(SCENARIO))
    assert set(YANG_NAMES) <= set(registered_estimators(YANG))
    assert {"aekf", "astekf", "aaekf"} <= set(registered_estimators(ATTITUDE))
    assert {"hbf", "ekf_converted"} <= set(registered_estimators(SHI))
    # the Kalman-core variants (issue 17): strong tracking and Huber x strong tracking where a Kalman filter fits
    for sc in (SCENARIO, SHI):
        assert {"ukf", "stekf", "huber_stekf"} <= set(registered_estimators(sc))
    assert not {"stekf", "huber_stekf"} & set(registered_estimators(ATTITUDE) + registered_estimators(YANG))
    # the robust filters of issue 33 (Student-t, VB noise-adaptive, maximum correntropy) on every Kalman model
    for sc in (SCENARIO, SHI):
        assert {"model_stkf", "model_vbakf", "model_mckf"} <= set(registered_estimators(sc))


def test_yang2020_registered_for_the_paper_and_only_there():
    assert not set(YANG_NAMES) & set(registered_estimators(Scenario()))
    assert registered_estimators(YANG.linear_truth("position")) == ("yang2020_alg1",)
    with pytest.raises(hn.InputError, match="does not fit"):
        build_estimator(Scenario(), "yang2020_fused")


def test_shapes_and_labels(case):
    sc, est, truth = case.scenario, case.estimator, case.truth
    hist = est.estimate(truth.y, truth.u, sc.xhat0)
    assert hist.xhat.shape == truth.x.shape and np.all(np.isfinite(hist.xhat))
    assert hist.labels == est.system.state.labels  # (attitude: Euler-angle labels of the stored quaternion)
    assert hist.units == est.system.state.units
    if case.paper == "sun2011":
        assert hist.labels == ("x", "y", "z", "vx", "vy", "vz")
        assert hist.units == ("m", "m", "m", "m/s", "m/s", "m/s")
    if hist.P is not None:
        assert hist.P.shape[:2] == truth.x.shape[:2] and hist.P.shape[-1] == hist.P.shape[-2]


def test_same_seed_same_numbers_whatever_the_batch(case):
    a = case.simulate(case.estimator, runs=2, seed=3)
    b = case.simulate(case.estimator, runs=2, seed=3)
    np.testing.assert_array_equal(a.xhat, b.xhat)
    c = case.simulate(case.estimator, runs=2, seed=3, batch_size=1)  # the same runs, one at a time
    # identity (same computation) up to rounding: BLAS blocks a batch of 1 and of 2 differently, and ~300 steps
    # (a loop closed on the estimate carries it into the true state) grow that to at most ~1e-12 of each
    # component's scale (measured 7e-13); a different seed or run order would differ at O(1) of it
    for new, old in ((c.x, a.x), (c.xhat, a.xhat)):
        scale = np.abs(old).max(axis=(0, 1))
        assert np.all(np.abs(new - old) <= 1e-11 * scale), (case.name, np.abs(new - old).max(axis=(0, 1)), scale)


def test_run_by_run_equals_vectorized(case):
    sc, est, truth = case.scenario, case.estimator, case.truth
    batch = est.estimate(truth.y, truth.u, sc.xhat0).xhat
    for r in range(truth.x.shape[0]):
        single = est.estimate(truth.y[r:r + 1], truth.u[r:r + 1], sc.xhat0).xhat[0]
        # identity (same computation); tolerance covers BLAS blocking differences
        np.testing.assert_allclose(single, batch[r], rtol=1e-10, atol=1e-12 * np.abs(batch).max())


def test_step_loop_equals_batch_estimate(case):
    sc, est, truth = case.scenario, case.estimator, case.truth
    # the step interface is the NumPy path's (the compiled default equals it to 1e-10: tests/test_compiled.py)
    batch = est.estimate(truth.y, truth.u, sc.xhat0, backend="numpy")
    state = est.start(sc.xhat0, None, truth.x.shape[0])
    n1 = truth.x.shape[1]
    xhat = np.empty_like(batch.xhat)
    P = None if batch.P is None else np.empty(batch.P.shape)
    for k in range(n1):
        state, out = est.update(state, truth.y[:, k])
        xhat[:, k] = out.xhat
        assert "innovation" in out.diagnostics or out.P is None  # Kalman-type filters report their innovation
        if P is not None:
            P[:, k] = out.P
        if k < n1 - 1:
            state = est.predict(state, truth.u[:, k])
    np.testing.assert_allclose(xhat, batch.xhat, rtol=1e-12, atol=1e-15 * np.abs(batch.xhat).max())
    if P is not None:  # the covariance the step reports is the batch's too
        np.testing.assert_allclose(P, batch.P, rtol=1e-12, atol=1e-15 * np.abs(batch.P).max())


def test_converges_without_noise_on_a_stable_problem(case):
    if case.paper == "sun2011":
        # with maneuver the closed loop is stable; without noise every filter's error must vanish
        sc = Scenario(duration_s=1500.0, rms_window_s=(1400.0, 1500.0))
        est = build_estimator(sc, case.name)
        res = hn.simulate(sc, est, runs=1, seed=0, noise=ZeroNoise(), maneuver=True)
        final = np.abs(res.error[0, -1])
        if case.name in ("model_stkf", "model_mckf"):
            # measured properties of the algorithms (issue 33), each against its Kalman limit: without noise
            # Huang 2017's E[ξ] → (ω+n)/ω > 1 shrinks the prior (the filter turns overconfident) and the error
            # stalls (0.08 → 0.056 in 1500 s); Chen 2017's weights whiten the innovation by R alone, so with
            # σ = 2 the readings fall to the weight floor and the filter loses the track (85 m). Their limits
            # ω → ∞, σ → ∞ converge as the Kalman filter does (below 1 mm)
            assert 1e-2 < final.max() and (final.max() < 0.08 if case.name == "model_stkf" else final.max() > 1.0)
            limit = {"dof_process": 1e6} if case.name == "model_stkf" else {"sigma": 100.0}
            res = hn.simulate(sc, build_estimator(sc, case.name, **limit), runs=1, seed=0, noise=ZeroNoise(),
                              maneuver=True)
            final = np.abs(res.error[0, -1])
        # limit 0 (no noise); 1 mm and 1 mm/s leave room for the slowest transient (the unaware EKF's)
        assert np.all(final < 1e-3), (case.name, final)
    elif case.paper == "yang2020":
        # the loop closed on the true state by the linear ADRC is stable; without noise each group's error is
        # 100x below its prior error after 300 s (below 1e-9 where that is 0). Exception, a property of
        # Algorithm 2 (Fig 6): the accelerometers see r only through K r / m_tm = 1e-6 r, so its displacement
        # error does not converge in 300 s; it must stay within 10x its prior error
        lt = case.scenario
        res = hn.simulate(lt, case.estimator, runs=1, seed=0, noise=ZeroNoise(), n_steps=3000)
        model = lt.truth_model()
        prior, final = np.abs(model.x0 - lt.xhat0), np.abs(res.error[0, -1])
        st = model.system.state
        for group in st.groups:
            e0, e = st.select(prior, group).max(), st.select(final, group).max()
            if case.name.startswith("yang2020_alg2") and group == "displacement":
                assert e < 10 * e0, (case.name, group, e, e0)
            elif e0 > 0:
                assert e <= 1e-2 * e0, (case.name, group, e, e0)
            else:
                assert e < 1e-9, (case.name, group, e)
    elif case.paper == "attitude2018":
        # limit 0: no measurement noise, a negligible torque (T0 = 1e-12 N m); initial errors ~1e-2 rad
        sc = AttitudeScenario(orbits=0.1, T0=1e-12)
        res = hn.simulate(sc, build_estimator(sc, case.name), runs=1, noise=ZeroNoise(), keep_covariance=False,
                          diagnostics=False)
        e = np.abs(res.error[0, -1])
        assert np.all(e[:3] < 1e-9) and np.all(e[3:6] < 1e-10) and np.all(e[6:] < 1e-11), (case.name, e)
    else:
        pytest.skip(f"{case.paper}: convergence without noise is tested in that paper's filter tests")


@pytest.mark.parametrize(
    "change, word",
    [
        (lambda y, u, x0: (y[:, :, :2], u, x0), "y"),
        (lambda y, u, x0: (y[0], u, x0), "y"),
        (lambda y, u, x0: (np.where(np.arange(y.shape[1])[None, :, None] == 3, np.nan, y), u, x0), "y"),
        (lambda y, u, x0: (y, u[:, :-1], x0), "u"),
        (lambda y, u, x0: (y, u, x0[:5]), "xhat0"),
        (lambda y, u, x0: (y, u, np.full(x0.size, np.inf)), "xhat0"),
    ],
    ids=["y-channels", "y-2d", "y-nan", "u-length", "xhat0-size", "xhat0-inf"],
)
def test_bad_input_names_the_parameter(case, change, word):
    y, u, x0 = change(case.truth.y, case.truth.u, np.asarray(case.scenario.xhat0, dtype=float))
    with pytest.raises(hn.InputError, match=rf"\b{word}\b"):
        case.estimator.estimate(y, u, x0)


def test_saturation_flags_in_the_diagnostics():
    lt = YANG.linear_truth("dragfree")
    tr = simulate_truth(lt.truth_model(disturbance=-12.8e-3, feedback=False, n_steps=50), runs=1, seed=0)
    hist = build_estimator(lt, "yang2020_alg2").estimate(tr.y, tr.u, lt.xhat0, diagnostics=True)
    np.testing.assert_array_equal(hist.diagnostics["saturated"], tr.y <= -6e-6)


def test_unknown_name_lists_the_registered_ones():
    with pytest.raises(hn.InputError, match="published"):
        build_estimator(SCENARIO, "kalmann")
