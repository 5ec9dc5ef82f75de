"""The closed loop of Yang et al. (2020), Section 3 (hinfnav.papers.yang2020.loop), at reduced length.

Expected values are identities (same seed, run batching, the loop's own
sensor equations (11) under each timing), the noise level of the readings
(σ from the one-sided conversion), and limits (the accelerometers saturate only
while the disturbance is not yet compensated).
"""

from dataclasses import replace

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.papers.yang2020 import Scenario, residual_acceleration, run_closed_loop, run_closed_loops, saturation_summary
from hinfnav.papers.yang2020.constants import D_TRANS, K_TRANS, M_SC, M_TM

SC = Scenario(n_steps=800, step_on=300, step_off=600)


@pytest.fixture(scope="module")
def loop():
    return run_closed_loop(SC, runs=2, seed=11, passive=True)


def _same(a, b, tol=1e-9):
    """Equal up to round-off: per component, the largest difference relative to the largest |b|."""
    scale = np.maximum(np.abs(b).max(axis=0), 1e-300)
    return np.all(np.abs(a - b).max(axis=0) <= tol * scale)


def test_same_seed_same_numbers_and_run_batching(loop):
    again = run_closed_loop(SC, runs=2, seed=11, passive=True)
    np.testing.assert_array_equal(again.xhat, loop.xhat)
    one = run_closed_loop(SC, runs=1, seed=11, passive=True)
    # run 0 draws from the seed's first child whatever the number of runs; BLAS round-off only
    assert _same(one.x[0], loop.x[0]) and _same(one.xhat[0], loop.xhat[0])
    assert _same(one.passive["L1"][0], loop.passive["L1"][0])
    assert not np.allclose(loop.x[0], loop.x[1])


def test_accelerometer_reading_eq_11_posterior_timing(loop):
    # a_k = (K r_k + D v_k)/m_tm + (u_{k-1} + w_{k-1} + f(t_k))/m_sc + d_k: what is left is d (σ = 1e-12/√(2h))
    x, drive, f = loop.x, loop.drive, loop.f
    coupling = (x[..., 6:9] @ K_TRANS.T + x[..., 9:12] @ D_TRANS.T) / M_TM
    prev = np.concatenate([np.zeros((2, 1, 9)), drive[:, :-1] - f[None, :-1]], axis=1)  # u + w of the last hold
    d = loop.acc - coupling - (prev[..., 3:6] + f[None, :, 3:6]) / M_SC
    sigma = 1e-12 / np.sqrt(0.2)
    assert np.abs(d).max() < 6 * sigma and d.std() == pytest.approx(sigma, rel=0.05)


def test_accelerometer_reading_prior_timing():
    # (13) literally: the reading contains the command applied at t_k
    res = run_closed_loop(replace(SC, timing="prior", n_steps=300), seed=1, passive=False)
    coupling = (res.x[..., 6:9] @ K_TRANS.T + res.x[..., 9:12] @ D_TRANS.T) / M_TM
    d = res.acc - coupling - res.drive[..., 3:6] / M_SC
    assert np.abs(d).max() < 6e-12 / np.sqrt(0.2)


def test_residual_readings(loop):
    a_tm = residual_acceleration(loop, "test_mass")
    np.testing.assert_allclose(a_tm, -(loop.x[..., 6:9] @ K_TRANS.T + loop.x[..., 9:12] @ D_TRANS.T) / M_TM)
    rel = residual_acceleration(loop, "relative")
    np.testing.assert_allclose(rel, a_tm - loop.drive[..., 3:6] / M_SC)
    assert residual_acceleration(loop, "accelerometer") is loop.acc


def test_saturation_only_before_the_disturbance_is_compensated(loop):
    # F_Dsc/m_sc ≈ -1.2e-5 < -6e-6 at t = 0 (no compensation yet); the ADRC cancels it within a few steps
    s = saturation_summary(loop)
    assert s["saturated_steps"] >= 1 and s["last_saturated_step"] < 20
    # with the drag-free loop open the readings sit beyond the range most of the time (Fig 5's setting)
    open_ = run_closed_loop(replace(SC, n_steps=400), controller="dragfree_off", passive=False)
    assert saturation_summary(open_)["saturated_fraction"][0] > 0.5


def test_attitude_follows_the_command():
    # the step of Section 3 (0.01, 0.02, 0.03 rad), reached within 5 % in 250 s (torques clipped at 0.03 N m)
    res = run_closed_loop(replace(SC, n_steps=3000, step_on=100, step_off=3000), passive=False)
    np.testing.assert_allclose(res.x[0, -1, 0:3], [0.01, 0.02, 0.03], rtol=0.05)


def test_passive_filters_shapes(loop):
    assert set(loop.passive) == {"alg1", "L1", "L2", "L3"}
    assert all(v.shape == (2, SC.n_steps + 1, 9) for v in loop.passive.values())
    short = run_closed_loop(replace(SC, n_steps=200), passive=True, passive_steps=50)
    assert short.passive["L2"].shape == (1, 50, 9)


def test_batched_variants_equal_their_own_loops(loop):
    # run_closed_loops steps several loops as rows of one batch (controllers, integral readings, and noise/omega_d
    # readings, each with its own estimator); each variant must give the numbers of its own run_closed_loop (the
    # reference: the loop run alone), round-off aside, whatever the other rows do
    sc_i, sc_n, sc_w = replace(SC, integral="dt"), replace(SC, noise="two_sided"), replace(SC, omega_d="rad_s")
    others = ((SC, "pid"), (sc_n, "adrc"), (sc_i, "adrc"), (sc_w, "pid"))
    batched = run_closed_loops([(SC, "adrc"), *others], runs=2, seed=11, passive=(True, False, False, False, False))
    assert _same(batched[0].x, loop.x) and _same(batched[0].xhat, loop.xhat)
    assert _same(batched[0].passive["L1"], loop.passive["L1"]) and batched[1].passive == {}
    for res, (sc, kind) in zip(batched[1:], others):
        alone = run_closed_loop(sc, controller=kind, runs=2, seed=11, passive=False)
        assert _same(res.x, alone.x) and _same(res.u, alone.u) and _same(res.xhat, alone.xhat)
        np.testing.assert_array_equal(res.f, alone.f)
        assert res.settings == alone.settings
    with pytest.raises(InputError, match="differs"):
        run_closed_loops([(SC, "adrc"), (replace(SC, timing="prior"), "adrc")])
    with pytest.raises(InputError, match="first variant's readings"):
        run_closed_loops([(SC, "adrc"), (sc_n, "adrc")], passive=(False, True))


def test_a_loop_that_goes_non_finite_is_refused(monkeypatch):
    # the loop calls the filters' hooks (no per-step input checks): a NaN state must still end in an InputError,
    # checked once after the loop, not a silently NaN result
    from hinfnav.papers.yang2020 import loop

    step = loop._Plant.step

    def nan_step(self, k, x, u):
        out = step(self, k, x, u)
        if k == 50:
            out[:, 6] = np.nan
        return out

    monkeypatch.setattr(loop._Plant, "step", nan_step)
    with pytest.raises(InputError, match="non-finite"):
        run_closed_loop(replace(SC, n_steps=100), passive=True)
