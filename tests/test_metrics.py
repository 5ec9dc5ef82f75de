"""Error metrics on hand-made error histories (expected values by hand)."""

import numpy as np
import pytest

from hinfnav import InputError, convergence_time, max_error, monte_carlo_summary, rms_error, rms_per_run


def test_rms_of_constant_and_sine():
    t = np.arange(0, 10.0001, 0.01)
    e = np.zeros((1, t.size, 6))
    e[0, :, 0] = 2.0  # RMS 2
    e[0, :, 4] = np.sin(2 * np.pi * t)  # RMS 1/√2 over whole periods
    pos, vel = rms_error(e, t, (0.0, 10.0))
    assert pos[0] == pytest.approx(2.0)
    assert vel[1] == pytest.approx(1 / np.sqrt(2), rel=1e-3)
    assert max_error(e, t, (0, 10))[0] == 2.0


def test_window_selects_samples():
    t = np.arange(11.0)
    e = np.zeros((2, 11, 6))
    e[:, 5:, 1] = 3.0
    e[1, :, 1] += 1.0
    per = rms_per_run(e, t, (5, 10))
    np.testing.assert_allclose(per[:, 1], [3.0, 4.0])
    pos, _ = rms_error(e, t, (5, 10))
    assert pos[1] == pytest.approx(np.sqrt((9 + 16) / 2))


def test_monte_carlo_summary_interval():
    # per-run RMS values 1 and 3: mean 2, s = √2, CI half-width 1.96·√2/√2 = 1.96
    t = np.arange(3.0)
    e = np.zeros((2, 3, 6))
    e[0, :, 0] = 1.0
    e[1, :, 0] = 3.0
    s = monte_carlo_summary(e, t, (0, 2))
    assert s.mean[0] == pytest.approx(2.0)
    np.testing.assert_allclose(s.ci95[:, 0], [2 - 1.96, 2 + 1.96])
    assert s.pooled[0] == pytest.approx(np.sqrt(5.0))


def test_convergence_time():
    t = np.arange(10.0)
    e = np.zeros((2, 10, 6))
    e[0, :4, 0] = 5.0  # outside until t = 3, settled from t = 4
    e[1, -1, 3] = 9.0  # leaves at the end: never settles
    np.testing.assert_array_equal(convergence_time(e, t, pos_tol=1.0, vel_tol=1.0), [4.0, np.nan])


def test_bad_input():
    t = np.arange(5.0)
    with pytest.raises(InputError, match="error must have shape"):
        rms_error(np.zeros((5, 4)), t, (0, 4))
    with pytest.raises(InputError, match="t must have shape"):
        rms_error(np.zeros((1, 5, 6)), np.arange(4.0), (0, 4))
    with pytest.raises(InputError, match="holds no sample"):
        rms_error(np.zeros((1, 5, 6)), t, (10, 20))
    with pytest.raises(InputError, match="start < end"):
        rms_error(np.zeros((1, 5, 6)), t, (3, 1))
    with pytest.raises(InputError, match="pos_tol must be > 0"):
        convergence_time(np.zeros((1, 5, 6)), t, pos_tol=0)
