"""Shi & Wang (2018)'s rebuilt scenario: model, maneuver, noise, calibration and Kalman limit (issue 9, item 3).

Sources of the expected values are given per test: the closed-form CW
solution, identities between two computations, the mixture's moments, and
the calibration target (the paper's EKF accuracy, §3.1).
"""

import numpy as np
import pytest
from scipy.stats import norm

import hinfnav as hn
from hinfnav.core import InputError
from hinfnav.papers.shi2018 import (
    CALIBRATED_SENSOR_ERRORS,
    EKF,
    ContaminatedNoise,
    Scenario,
    calibrate_sensor_errors,
    riccati_accuracy,
)
from hinfnav.papers.shi2018.constants import MU_EARTH, R_EARTH_M

SC = Scenario()


def test_orbit_and_closed_relative_orbit():
    # Closed form: n = sqrt(mu/a^3) for a 500 km circular orbit (period 5677 s), and the
    # drift-free CW solution x = A cos nt, y = y_c - 2A sin nt, z = B sin nt.
    n = np.sqrt(MU_EARTH / (R_EARTH_M + 500e3) ** 3)
    assert SC.n == pytest.approx(n, rel=1e-12)
    assert 2 * np.pi / SC.n == pytest.approx(5677.0, abs=1.0)
    t = SC.time
    x = SC.nominal_trajectory()
    A, yc, B = 500.0, 3000.0, 300.0
    np.testing.assert_allclose(x[:, 0], A * np.cos(n * t), atol=1e-6)
    np.testing.assert_allclose(x[:, 1], yc - 2 * A * np.sin(n * t), atol=1e-6)
    np.testing.assert_allclose(x[:, 2], B * np.sin(n * t), atol=1e-6)
    assert SC.n_steps == 2500 and SC.dt == 0.4  # T = 0.4 s (paper, §3), 1000 s


def test_maneuver_is_away_along_x_and_only_adds_its_response():
    # Identity: the maneuver truth is the no-maneuver truth (same seed, same draws) plus
    # Phi^(k - k_m) dv; readings before the maneuver are identical.
    sc = Scenario(duration_s=40.0, maneuver_time_s=20.0, rms_window_s=(10.0, 40.0))
    dv = sc.maneuver_dv()
    assert dv[3] == pytest.approx(0.1) and np.count_nonzero(dv) == 1  # x(20 s) > 0: away = +x
    a = sc.simulate_truth(runs=3, seed=5)
    b = sc.simulate_truth(runs=3, seed=5, maneuver=True)
    np.testing.assert_allclose(b.x - a.x, np.broadcast_to(sc.maneuver_response(), a.x.shape), atol=1e-12)
    km = sc.maneuver_step
    assert sc.time[km] == pytest.approx(20.0)
    np.testing.assert_array_equal(b.y[:, :km], a.y[:, :km])
    assert np.all(b.y[:, km + 10:, 0] != a.y[:, km + 10:, 0])
    assert b.settings["maneuver"] is True and a.settings["maneuver"] is False
    # the generic truth model refuses the maneuver rather than dropping it
    with pytest.raises(InputError, match="maneuver"):
        sc.truth_model(maneuver=True)


def test_generic_simulate_runs_the_scenario():
    sc = Scenario(duration_s=40.0, maneuver_time_s=20.0, rms_window_s=(10.0, 40.0))
    res = hn.simulate(sc, "ekf_converted", runs=2, seed=1)
    direct = sc.simulate_truth(runs=2, seed=1)
    np.testing.assert_array_equal(res.x, direct.x)  # same seed convention as simulate_truth
    assert res.xhat.shape == (2, 101, 6)


@pytest.mark.parametrize("ratio, variance", [(2.0, 0.4 + 0.6 * 4), (np.sqrt(2.0), 0.4 + 0.6 * 2)])
def test_contaminated_noise_moments(ratio, variance):
    # Closed form: (1-eps) N(0,1) + eps N(0, r^2) has variance (1-eps) + eps r^2
    # (2.8 reading N(0, sigma) with sigma a standard deviation, 1.6 reading it as a variance).
    noise = ContaminatedNoise(eps=0.6, ratio=ratio)
    assert noise.variance == pytest.approx(variance)
    v = noise.sample(np.random.default_rng(0), (400_000,))
    se = np.sqrt((np.mean(v**4) - variance**2) / v.size)
    assert abs(np.var(v) - variance) < 4 * se
    # the narrow component is the sensor's sigma: |v| <= 0.1 is N(0,1)'s share times 0.4 plus N(0, r^2)'s times 0.6
    p = 0.4 * (2 * norm.cdf(0.1) - 1) + 0.6 * (2 * norm.cdf(0.1 / ratio) - 1)
    assert abs(np.mean(np.abs(v) <= 0.1) - p) < 4 * np.sqrt(p * (1 - p) / v.size)


def test_calibration_reproduces_the_stored_sensor_errors():
    # Source: the calibration target, the paper's EKF accuracy 3.59 m / 0.11 m/s (§3.1),
    # read as the Riccati accuracy of the EKF over the window, RMS over axes.
    cal = calibrate_sensor_errors()
    assert cal["achieved"]["pos_m"] == pytest.approx(3.59, rel=1e-6)
    assert cal["achieved"]["vel_mps"] == pytest.approx(0.11, rel=1e-6)
    for key in ("sigma_range_m", "sigma_angle_rad", "sigma_accel_mps2"):
        assert CALIBRATED_SENSOR_ERRORS[key] == pytest.approx(cal[key], rel=1e-4), key
    assert cal["sigma_range_m"] == pytest.approx(np.linalg.norm(SC.x0[:3]) * cal["sigma_angle_rad"], rel=1e-12)
    lim = riccati_accuracy(SC)
    assert lim.pos_m == pytest.approx(3.59, rel=1e-4) and lim.vel_mps == pytest.approx(0.11, rel=1e-4)
    with pytest.raises(InputError, match="target"):
        calibrate_sensor_errors(target={"pos_m": -1.0, "vel_mps": 0.1})


def test_ekf_error_sits_on_the_kalman_limit(assert_rms_matches):
    # Independent computation: the time-varying Riccati recursion along the noise-free
    # trajectory predicts the EKF's per-axis RMS error (Gaussian case) within 4 standard errors
    # of the Monte Carlo mean over 24 runs.
    truth = SC.simulate_truth(runs=24, seed=2)
    hist = EKF(SC).estimate(truth.y, truth.u, SC.xhat0, keep_covariance=False)
    lim = riccati_accuracy(SC)
    assert_rms_matches(truth.x - hist.xhat, SC.time, SC.rms_window_s, lim.axes)


def test_bad_settings_name_the_parameter():
    with pytest.raises(InputError, match="sigma_range"):
        Scenario(sigma_range=0.0)
    with pytest.raises(InputError, match="maneuver_time_s"):
        Scenario(maneuver_time_s=2000.0)
    with pytest.raises(InputError, match="window_s"):
        Scenario(rms_window_s=(500.0, 100.0))
    with pytest.raises(InputError, match="P0"):
        Scenario(P0=-np.eye(6))
    with pytest.raises(InputError, match="x0"):
        Scenario(x0=np.zeros(6))
