"""Error metrics on hand-made error histories (expected values by hand)."""

import numpy as np
import pytest

from hinfnav import InputError, monte_carlo_summary, rms_error
from hinfnav.metrics import by_group, convergence_time, group_rms, max_error, rms_per_run
from hinfnav.systems import chaser_state_spec

STATE = chaser_state_spec()


def test_rms_of_constant_and_sine():
    t = np.arange(0, 10.0001, 0.01)
    e = np.zeros((1, t.size, 6))
    e[0, :, 0] = 2.0  # RMS 2
    e[0, :, 4] = np.sin(2 * np.pi * t)  # RMS 1/√2 over whole periods
    rms = rms_error(e, t, (0.0, 10.0))
    assert rms.shape == (6,)
    pos, vel = STATE.select(rms, "position"), STATE.select(rms, "velocity")
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
    pos = STATE.select(rms_error(e, t, (5, 10)), "position")
    assert pos[1] == pytest.approx(np.sqrt((9 + 16) / 2))


def test_monte_carlo_summary_interval():
    # per-run RMS values 1 and 3: mean 2, s = √2, CI half-width t·√2/√2 = t with the Student t quantile
    # t_{0.975, 1} = 12.7062 (t table, 1 degree of freedom; issue 22: not the normal 1.96)
    t = np.arange(3.0)
    e = np.zeros((2, 3, 6))
    e[0, :, 0] = 1.0
    e[1, :, 0] = 3.0
    s = monte_carlo_summary(e, t, (0, 2))
    assert s.mean[0] == pytest.approx(2.0)
    np.testing.assert_allclose(s.ci95[:, 0], [2 - 12.7062, 2 + 12.7062], atol=1e-4)
    assert s.pooled[0] == pytest.approx(np.sqrt(5.0))


def test_convergence_time():
    t = np.arange(10.0)
    e = np.zeros((2, 10, 6))
    e[0, :4, 0] = 5.0  # outside until t = 3, settled from t = 4
    e[1, -1, 3] = 9.0  # leaves at the end: never settles
    np.testing.assert_array_equal(convergence_time(e, t, tol=np.ones(6)), [4.0, np.nan])
    np.testing.assert_array_equal(convergence_time(e, t, tol=1.0), [4.0, np.nan])
    # a per-component tolerance: 5.0 on x is inside a tolerance of 5 (settled from the start)
    np.testing.assert_array_equal(convergence_time(e, t, tol=[5.0, 1, 1, 1, 1, 1]), [0.0, np.nan])
    # streaming statistics of runs that may diverge: a NaN counts as outside (run 1: NaN at t = 6, its 9.0 at the
    # end inside a tolerance of 10: settled from t = 7, counted by hand)
    e[1, 6, 2] = np.nan
    with pytest.raises(InputError, match="finite"):
        convergence_time(e, t, tol=1.0)
    np.testing.assert_array_equal(convergence_time(e, t, tol=[5.0, 1, 1, 10, 1, 1], nonfinite="outside"), [0.0, 7.0])
    e[1, :] = 0.0
    e[1, 2, 2] = np.nan  # NaN at t = 2 only: settled from t = 3 (counted by hand)
    np.testing.assert_array_equal(convergence_time(e, t, tol=1.0, nonfinite="outside"), [4.0, 3.0])


def test_statistics_sink_is_the_accumulator_of_the_engine():
    # the engine's streaming sink against the histories of the same runs (hinfnav.metrics.rms_error, a
    # separate computation from full histories): pooled RMS to round-off, per-run convergence times equal
    from hinfnav.metrics import StatisticsSink
    from hinfnav.papers.sun2011 import Scenario
    from hinfnav.sim import HistorySink, run_monte_carlo
    sc = Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))
    win = {"w": (5.0, 20.0)}
    kw = dict(runs=3, seed=2, batch_size=2, maneuver=True)
    acc = run_monte_carlo(sc, "ekf", sink=StatisticsSink(win, 3, sc.xhat0, tol=50.0), **kw)["ekf"]
    hist = run_monte_carlo(sc, "ekf", sink=HistorySink(sc.xhat0, 3), **kw)["ekf"]
    np.testing.assert_allclose(acc.window_statistics()["w"].pooled, rms_error(hist.error, hist.t, win["w"]), rtol=1e-12)
    np.testing.assert_array_equal(acc.convergence_s, convergence_time(hist.error, hist.t, 50.0))


def test_bad_input():
    t = np.arange(5.0)
    # any state dimension is accepted, and (n_samples, n) is one run; a 1-D or 4-D error is not
    with pytest.raises(InputError, match="error must have shape"):
        rms_error(np.zeros(5), t, (0, 4))
    with pytest.raises(InputError, match="error must have shape"):
        rms_error(np.zeros((1, 5, 6, 1)), t, (0, 4))
    np.testing.assert_array_equal(rms_error(np.ones((5, 4)), t, (0, 4)), np.ones(4))
    with pytest.raises(InputError, match="t must have shape"):
        rms_error(np.zeros((1, 5, 6)), np.arange(4.0), (0, 4))
    with pytest.raises(InputError, match="holds no sample"):
        rms_error(np.zeros((1, 5, 6)), t, (10, 20))
    with pytest.raises(InputError, match="start < end"):
        rms_error(np.zeros((1, 5, 6)), t, (3, 1))
    with pytest.raises(InputError, match="tol must be finite and > 0"):
        convergence_time(np.zeros((1, 5, 6)), t, tol=0)
    with pytest.raises(InputError, match="tol must be finite and > 0"):
        convergence_time(np.zeros((1, 5, 6)), t, tol=[1, 1, 1, 1, 1, -1])


def test_groups_split_by_the_state_spec():
    # group_rms: sqrt(mean(v²)) over a group's components, by hand: sqrt((1 + 4 + 4)/3) = sqrt(3)
    v = np.array([1.0, 2.0, 2.0, 0.1, 0.2, 0.3])
    groups = by_group(v, STATE)
    np.testing.assert_array_equal(groups["position"], [1.0, 2.0, 2.0])
    np.testing.assert_array_equal(groups["velocity"], [0.1, 0.2, 0.3])
    assert group_rms(v, STATE, "position") == pytest.approx(np.sqrt(3.0), rel=1e-15)
    with pytest.raises(InputError, match="unknown state group 'attitude'"):
        STATE.select(v, "attitude")
