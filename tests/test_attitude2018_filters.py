"""Paper 002's three filters and the generic augmented/strong-tracking/adaptive EKF.

Expected values: identities (strong tracking with every λ = 1 is the AEKF bit
for bit; a parameter sweep batched as runs equals the runs one by one; one
run equals its row of a batch; the step loop equals ``estimate``), the
fading-factor formulas (S1)–(S4) of Zhou, Xi & Zhang (1991) evaluated by
hand, the limit of zero error without noise, and the chaser result of item 5
against the paper's failing EKF (Sun 2011 Fig 4: ~1 m over 0–500 s).
"""

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.core.exceptions import InputError
from hinfnav.estimators import registered_estimators
from hinfnav.estimators.adaptive import (
    fade,
    fading_factors,
    innovation_moment,
    input_rate,
    rate_adapted_density,
)
from hinfnav.papers.attitude2018 import (
    ATTITUDE_FILTERS,
    CHASER_FILTERS,
    Scenario,
    build_aaekf,
    build_aekf,
    build_astekf,
    build_augmented_thrust,
)
from hinfnav.papers.sun2011 import Scenario as ChaserScenario
from hinfnav.sim import simulate_truth

SC = Scenario(orbits=0.05)  # 293 steps of 1 s
BUILDERS = {"aekf": build_aekf, "astekf": build_astekf, "aaekf": build_aaekf}


@pytest.fixture(scope="module")
def truth():
    return simulate_truth(SC.truth_model(), runs=3, seed=11)


@pytest.fixture(scope="module", params=ATTITUDE_FILTERS)
def est(request):
    return BUILDERS[request.param](SC)


def test_fading_factors_by_hand():
    rng = np.random.default_rng(1)
    n, m = 4, 2
    H = rng.standard_normal((m, n))
    A = rng.standard_normal((n, n))
    PhiPPhiT = A @ A.T
    Qd = np.diag([0.0, 0.0, 0.1, 0.2])
    R = 0.01 * np.eye(m)
    g1, g2 = rng.standard_normal((2, m)) * 3
    a = np.array([1.0, 1.0, 2.0, 3.0])
    V0 = innovation_moment(innovation_moment(None, g1[None], 0.9), g2[None], 0.9)
    Vh = (0.9 * np.outer(g1, g1) + np.outer(g2, g2)) / 1.9  # (S1)
    np.testing.assert_allclose(V0[0], Vh, rtol=1e-14)
    lam, c = fading_factors(V0, H, PhiPPhiT, Qd, R, beta=1.2, a=a)
    N = Vh - 1.2 * R - H @ Qd @ H.T  # (S2)
    M = PhiPPhiT @ H.T @ H
    ch = np.trace(N) / sum(a[i] * M[i, i] for i in range(n))  # (S3)
    np.testing.assert_allclose(c[0], ch, rtol=1e-12)
    np.testing.assert_allclose(lam[0], np.maximum(1.0, a * ch), rtol=1e-12)
    F = fade(PhiPPhiT[None], lam)[0]  # (S4): same diagonal as Λ Φ P Φᵀ, symmetric
    np.testing.assert_allclose(np.diag(F), lam[0] * np.diag(PhiPPhiT), rtol=1e-14)
    np.testing.assert_allclose(F, F.T, atol=0)


def test_rate_window_and_adapted_density():
    history = np.zeros((4, 1, 2))
    for k in range(6):  # a ramp of slope (2, −1) per step, ring buffer of m + 1 = 4
        history[k % 4, 0] = [2.0 * k, -1.0 * k]
    np.testing.assert_allclose(input_rate(history, 6, 3, 0.5), [[4.0, -2.0]])  # (β̂_k − β̂_{k−m})/(mΔt)
    np.testing.assert_allclose(input_rate(history, 2, 3, 0.5), [[4.0, -2.0]])  # fewer than m steps: the span available
    q = rate_adapted_density(np.array([1e-16, 1e-16]), np.array([[1e-9, 1e-7]]), 1e8, 1.0)
    np.testing.assert_allclose(q, [[1e-16, 1e-14]])  # max(1, (εκ)²) Q0


def test_strong_tracking_with_unit_factors_is_the_aekf(truth):
    # β so large that N < 0 and every λ = 1: (S4) is then Φ P Φᵀ + Q_d exactly
    a = build_aekf(SC, Q=1e-15).estimate(truth.y, truth.u, SC.xhat0, keep_covariance=False)
    s = build_astekf(SC, Q=1e-15, beta=1e12).estimate(truth.y, truth.u, SC.xhat0, keep_covariance=False,
                                                       diagnostics=("fading",))
    np.testing.assert_array_equal(s.diagnostics["fading"], 1.0)
    np.testing.assert_array_equal(a.xhat, s.xhat)


def test_parameter_sweep_batched_as_runs_equals_runs_one_by_one(truth):
    y, u = np.concatenate([truth.y[:1]] * 3), np.concatenate([truth.u[:1]] * 3)
    batch = build_astekf(SC, Q=[1e-16, 1e-14, 1e-12], beta=[1.0, 1.5, 2.0]).estimate(y, u, SC.xhat0).xhat
    for i, (q, b) in enumerate(((1e-16, 1.0), (1e-14, 1.5), (1e-12, 2.0))):
        one = build_astekf(SC, Q=q, beta=b).estimate(truth.y[:1], truth.u[:1], SC.xhat0).xhat[0]
        np.testing.assert_allclose(one, batch[i], rtol=1e-12, atol=1e-15)
    with pytest.raises(InputError, match="runs"):
        build_aekf(SC, Q=[1e-16, 1e-14]).estimate(truth.y, truth.u, SC.xhat0)


# -- attitude-specific checks; the contract itself (seed, batch, run by run, step loop, convergence without noise,
# bad input) runs over these filters in tests/test_contract.py ------------------------------------------------


def test_shapes_labels_and_diagnostics(est, truth):
    hist = est.estimate(truth.y, truth.u, SC.xhat0, diagnostics=True)
    assert hist.xhat.shape == truth.x.shape
    assert hist.labels == ("phi", "theta", "psi", "wx", "wy", "wz", "Tx", "Ty", "Tz")
    assert hist.P.shape == truth.x.shape[:2] + (9, 9)
    assert {"innovation", "input_estimate"} <= set(hist.diagnostics)
    extra = {"astekf": "fading", "aaekf": "q_adapted"}.get(est.name)
    if extra:
        assert hist.diagnostics[extra].shape[:2] == truth.x.shape[:2]
    np.testing.assert_allclose(np.linalg.norm(hist.xhat[..., :4], axis=-1), 1.0, atol=1e-12)


def test_registry_fits():
    assert set(ATTITUDE_FILTERS) <= set(registered_estimators(SC))
    assert not set(CHASER_FILTERS) & set(registered_estimators(SC))
    chaser = registered_estimators(ChaserScenario(duration_s=30.0, rms_window_s=(5.0, 30.0)))
    assert set(CHASER_FILTERS) <= set(chaser) and not set(ATTITUDE_FILTERS) & set(chaser)


def test_thrust_augmentation_fixes_the_first_500_s_of_the_maneuver():
    # Sun 2011 Fig 4 / README: the unaware EKF has ~1.0 m RMS over 0-500 s; item 5 measured 0.07-0.08 m
    sc = ChaserScenario()
    truth = hn.simulate_truth(sc.truth_model(maneuver=True), runs=2, seed=0)
    err = {}
    for name in ("ekf",) + CHASER_FILTERS:
        est = hn.build_estimator(sc, name) if name == "ekf" else build_augmented_thrust(sc, name.split("thrust")[1][1:] or "plain")
        res = hn.sim.run_estimator(est, truth, sc.xhat0)
        err[name] = float(np.sqrt(np.mean(hn.rms_error(res.error, res.t, (0.0, 500.0))[:3] ** 2)))
    assert err["ekf"] > 0.8
    for name in CHASER_FILTERS:
        assert err[name] < 0.15, err
