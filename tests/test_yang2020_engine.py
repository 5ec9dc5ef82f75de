"""The package's one stepped closed loop (hinfnav.sim.stepped.run_stepped) and yang2020's loop as a use of it.

Expected values: the closed form of a scalar loop (x_k = (a − g)^k x_0), the order of the hooks stated in
the driver's docstring, and yang2020's loop replayed step by step outside the driver from its own
recorded histories and a fresh draw of each run's noise: the plant (4), the Algorithm 3 filter on the
readings (5), (11), (14) and the ADRC law (44)-(46) must give back what the loop recorded.
"""

from dataclasses import replace

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.papers.yang2020 import Scenario, loop as yloop, run_closed_loop, run_closed_loops
from hinfnav.papers.yang2020.constants import ACCELEROMETER_RANGE, M_SC
from hinfnav.papers.yang2020.filters import build_fused
from hinfnav.papers.yang2020.model import MEASURED_INDICES
from hinfnav.sim import engine, stepped
from hinfnav.sim.truth import child_rngs

A, G = 0.9, 0.4  # scalar plant x' = A x + u, law u = -G z


class _Plant(stepped.SteppedPlant):
    def __init__(self, log, n1=8, block=3):
        self.rows, self.n1, self.n_input, self.log, self.block = 2, n1, 1, log, block

    def start(self):
        return np.array([[1.0], [-2.0]])

    def draw(self, k):
        self.log.append(("draw", k))
        return min(k + self.block, self.n1)

    def measure(self, k, x, u_read):
        self.log.append(("measure", k, float(u_read[0, 0])))
        return x.copy()

    def record(self, k, x, u):
        self.log.append(("record", k))

    def step(self, k, x, u):
        self.log.append(("step", k))
        return A * x + u


class _Stage:
    n_state = 1

    def __init__(self, log):
        self.log = log

    def start(self, rows):
        self.xp = np.array([[1.0], [-2.0]])  # the prior estimate: exact (the model is the plant's)

    def update(self, k, y, u_read):
        self.log.append(("update", k))
        return y

    def prior(self):
        return self.xp

    def predict(self, k, u):
        self.log.append(("predict", k))
        self.xp = A * self.xp + u


class _Law:  # stateful: counts its steps
    def start(self, rows):
        return 0

    def step(self, k, z, count):
        assert count == k
        return -G * z, count + 1


class _Observer:
    def __init__(self, log):
        self.log = log

    def observe(self, k, y, u_read, u):
        self.log.append(("observe", k, float(u_read[0, 0]), float(u[0, 0])))


@pytest.mark.parametrize("prior", [False, True])
@pytest.mark.parametrize("law", ["callable", "stateful"])
def test_driver_order_and_closed_form(prior, law):
    log = []
    controller = (lambda z: -G * z) if law == "callable" else _Law()
    h = stepped.run_stepped(_Plant(log), _Stage(log), controller, observers=[_Observer(log)], prior=prior)
    # closed form: x_k = (A − G)^k x_0 (the estimate is exact, so both timings give it), rtol: round-off of 7 steps
    expected = np.array([1.0, -2.0])[:, None] * (A - G) ** np.arange(8)[None, :]
    np.testing.assert_allclose(h.x[..., 0], expected, rtol=1e-13)
    np.testing.assert_allclose(h.xhat[..., 0], expected, rtol=1e-13)
    np.testing.assert_allclose(h.u[..., 0], -G * expected, rtol=1e-13)
    # the order of the module docstring; noise drawn where the last block ends; no predict/step after the last sample
    assert [e for e in log if e[0] == "draw"] == [("draw", 0), ("draw", 3), ("draw", 6)]
    steps = [e[:2] for e in log if e[0] != "draw"]
    per = ["measure", "update", "record", "observe", "predict", "step"]
    assert steps == [(name, k) for k in range(8) for name in per if not (k == 7 and name in ("predict", "step"))]
    # the reading contains u_{k-1} (zeros at k = 0) with posterior timing, u_k with prior timing
    u0 = h.u[0, :, 0]
    reads = [e[2] for e in log if e[0] == "measure"]
    np.testing.assert_array_equal(reads, u0 if prior else np.r_[0.0, u0[:-1]])
    np.testing.assert_array_equal([e[3] for e in log if e[0] == "observe"], u0)


def test_driver_refuses_a_bad_controller():
    with pytest.raises(InputError, match="controller"):
        stepped.run_stepped(_Plant([]), _Stage([]), object())
    with pytest.raises(InputError, match=r"shape \(2, 1\)"):
        stepped.run_stepped(_Plant([]), _Stage([]), lambda z: np.zeros(1))


def _spy(monkeypatch, module):
    calls = []
    real = stepped.run_stepped

    def spy(plant, estimator, controller, **kw):
        calls.append((plant, estimator, controller, kw))
        return real(plant, estimator, controller, **kw)

    monkeypatch.setattr(module, "run_stepped", spy)
    return calls


def test_yang_loop_and_engine_closed_loop_go_through_the_driver(monkeypatch):
    sc = Scenario(n_steps=60, step_on=20, step_off=40, settle_s=1.0)
    variants = [(sc, "adrc"), (replace(sc, noise="two_sided"), "pid")]
    plain = run_closed_loops(variants, runs=2, seed=4, passive=(True, False))
    calls = _spy(monkeypatch, yloop)
    spied = run_closed_loops(variants, runs=2, seed=4, passive=(True, False))
    assert len(calls) == 1 and isinstance(calls[0][0], stepped.SteppedPlant) and calls[0][0].rows == 4
    assert len(calls[0][3]["observers"]) == 1  # the standalone estimators ride along as a passive observer
    for a, b in zip(plain, spied):  # the spy changes nothing
        np.testing.assert_array_equal(a.xhat, b.xhat)
    np.testing.assert_array_equal(plain[0].passive["L1"], spied[0].passive["L1"])

    from hinfnav.papers.sun2011 import Scenario as SunScenario
    from hinfnav.sim import simulate_closed_loop
    calls = _spy(monkeypatch, engine)
    res = simulate_closed_loop(SunScenario(duration_s=30.0, rms_window_s=(5.0, 30.0)), "published", runs=3, seed=2,
                               batch_size=2)
    assert len(calls) == 2 and all(isinstance(c[0], stepped.ModelPlant) for c in calls)  # one per batch
    assert res.x.shape[0] == 3


def _noise(sc, seed, runs):
    """Each run's draws as the loop's docstring states them: blocks of BLOCK steps, w (9), d (9), d_a (3)."""
    n1 = sc.n_steps + 1
    out = []
    for rng in child_rngs(seed, runs):
        parts = [[], [], []]
        for k in range(0, n1, yloop.BLOCK):
            nb = min(yloop.BLOCK, n1 - k)
            for i, p in enumerate((9, 9, 3)):
                parts[i].append(rng.standard_normal((nb, p)))
        out.append([np.concatenate(p) for p in parts])
    return [np.stack([o[i] for o in out]) * sd for i, sd in enumerate((sc.input_std, sc.sensor_std, sc.accel_std))]


@pytest.mark.parametrize("timing", ["posterior", "prior"])
def test_yang_loop_replayed_outside_the_driver(monkeypatch, timing):
    monkeypatch.setattr(yloop, "BLOCK", 70)  # several noise blocks in a short loop
    sc = Scenario(n_steps=200, step_on=50, step_off=150, settle_s=1.0, timing=timing)
    res = run_closed_loop(sc, controller="adrc", runs=2, seed=9, passive=False)
    W, D, Da = _noise(sc, 9, 2)
    scale = np.abs(res.u).max() + np.abs(W).max() + np.abs(res.f).max()
    # w = drive − u − f is the run's own input noise: float round-off of one sum and two differences
    np.testing.assert_allclose(res.w, W, rtol=0, atol=4 * np.finfo(float).eps * scale)
    # the plant (4): x_{k+1} = Φ x_k + Γ (u_k + w_k + f_k) exactly (the same products)
    m = sc.model
    np.testing.assert_allclose(res.x[:, 1:], res.x[:, :-1] @ m.Phi.T + res.drive[:, :-1] @ m.Gamma.T,
                               rtol=1e-12, atol=1e-12 * np.abs(res.x).max())
    # Algorithm 3 and the ADRC law replayed step by step on the recorded readings: they give back x̂ and u
    # (tolerance: round-off of the replay's own products, per component relative to its largest |value|)
    xscale, uscale = (np.maximum(np.abs(h).max(axis=(0, 1)), 1e-300) for h in (res.xhat, res.u))
    fused = build_fused(sc, steady_tol=sc.steady_tol)
    law = sc.controller("adrc")
    st, cs = fused.start(sc.xhat0, None, 2), law.start(2)
    u_prev = np.zeros((2, 9))
    acc_c = np.clip(res.acc, *ACCELEROMETER_RANGE)
    ref = sc.attitude_reference(sc.n_steps + 1)
    for k in range(sc.n_steps + 1):
        if timing == "prior":
            u, _, cs = law(st.x, ref[k], cs)
            u_read = u
        else:
            u_read = u_prev
        Y = res.x[:, k][:, MEASURED_INDICES] + D[:, k]
        st = fused.feed_input(st, u_read)
        st, out = fused.update(st, np.concatenate([Y, acc_c[:, k]], axis=1))
        assert np.all(np.abs(out.xhat - res.xhat[:, k]) <= 1e-9 * xscale), k
        if timing == "posterior":
            u, _, cs = law(out.xhat, ref[k], cs)
        assert np.all(np.abs(u - res.u[:, k]) <= 1e-9 * uscale), k
        st = fused.predict(st, u)
        u_prev = u
    # the accelerometers (11) with the run's own d_a: the reading of t_k contains u_{k-1} + w_{k-1} (posterior)
    # or u_k + w_k (prior) and F_Dsc(t_k); tolerance: round-off relative to the largest reading
    uw = res.u + W
    if timing == "posterior":
        uw = np.concatenate([np.zeros((2, 1, 9)), uw[:, :-1]], axis=1)
    a = res.x @ m.accel_C.T + (uw[..., 3:6] + res.f[None, :, 3:6]) * (1.0 / M_SC) + Da
    np.testing.assert_allclose(res.acc, a, rtol=0, atol=1e-12 * np.abs(res.acc).max())
