"""The one Monte Carlo engine (hinfnav.sim.engine): batch sizes, sinks, memory.

The paper scenarios themselves (hinfnav.simulate on sun2011, shi2018, attitude2018, yang2020, truths against a
hand-written loop) are tested in tests/test_sim.py; the statistics sink against hinfnav.metrics on one batch size
in tests/test_metrics.py.
"""

import tracemalloc

import numpy as np
import pytest

from hinfnav.metrics import StatisticsSink, convergence_time, rms_error, rms_per_run
from hinfnav.papers import attitude2018, sun2011
from hinfnav.sim import HistorySink, run_monte_carlo

SUN = sun2011.Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))  # 201 samples of 0.1 s
ATT = attitude2018.Scenario().short(0.02)  # the nonlinear (quaternion) truth, short


def _histories(sc, estimators, runs, batch_size, **kw):
    return run_monte_carlo(sc, estimators, sink=HistorySink(sc.xhat0, runs), runs=runs, seed=17,
                           batch_size=batch_size, **kw)


def _assert_same(a, b):
    # run r draws from the r-th child generator whatever the batch, so the numbers are the same to round-off: a
    # matrix product over 1, 7 or 15 rows may take another BLAS kernel and summation order (seen: relative 5e-15
    # on the truth, 1e-9 on estimates near a zero crossing, absolute 1e-11 of values up to 1e3)
    for name in ("x", "y", "u", "xhat"):
        ref = getattr(b, name)
        np.testing.assert_allclose(getattr(a, name), ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max(), err_msg=name)


@pytest.mark.parametrize("case", ["linear", "nonlinear", "closed_loop"])
def test_batch_sizes_one_seven_and_all_give_the_same_numbers(case):
    runs = 15
    if case == "linear":  # Sun 2011's chaser, two estimators on one truth
        sc, ests, kw = SUN, ["published", "ekf"], {"maneuver": True}
    elif case == "nonlinear":  # gyroless attitude, the additive EKF
        sc, ests, kw = ATT, ["aekf"], {}
    else:  # Sun 2011's maneuver with u = K x̂ (the truth model's own law acting on the estimate)
        sc, ests, kw = SUN, ["ekf_known_input"], {"maneuver": True, "closed_loop": True}
    if case == "nonlinear":
        runs = 8  # the quaternion truth steps in Python per sample; 8 runs still split into batches of 1 and 7
    ref = _histories(sc, ests, runs, runs, keep_covariance=False, **kw)
    for batch in (1, 7):
        out = _histories(sc, ests, runs, batch, keep_covariance=False, **kw)
        assert out.keys() == ref.keys()
        for name in ests:
            _assert_same(out[name], ref[name])
            assert out[name].settings["runs"] == runs
    if len(ests) > 1:  # common random numbers: every estimator sees the same truth
        np.testing.assert_array_equal(ref[ests[0]].x, ref[ests[1]].x)
    # and a different seed gives different readings (the test could fail)
    other = run_monte_carlo(sc, ests[0], sink=HistorySink(sc.xhat0, 2), runs=2, seed=18, keep_covariance=False, **kw)
    assert not np.allclose(other[ests[0]].y, ref[ests[0]].y[:2])


def test_statistics_sink_equals_statistics_of_the_histories():
    # StatisticsSink (streaming, batches of 7) against hinfnav.metrics on the full histories (batch = all runs):
    # pooled RMS, per-run RMS, largest error and convergence times of the same 15 runs, round-off only
    runs, win, tol = 15, {"early": (0.0, 5.0), "late": (5.0, 20.0)}, 40.0
    kw = dict(runs=runs, seed=17, maneuver=True)
    acc = run_monte_carlo(SUN, ["published", "ekf"], sink=StatisticsSink(win, runs, SUN.xhat0, tol=tol),
                          batch_size=7, **kw)
    hist = run_monte_carlo(SUN, ["published", "ekf"], sink=HistorySink(SUN.xhat0, runs), batch_size=runs, **kw)
    for name in ("published", "ekf"):
        stats, h = acc[name].window_statistics(), hist[name]
        for key, w in win.items():
            np.testing.assert_allclose(stats[key].pooled, rms_error(h.error, h.t, w), rtol=1e-12)
            np.testing.assert_allclose(stats[key].per_run, rms_per_run(h.error, h.t, w), rtol=1e-12)
            mask = (h.t >= w[0]) & (h.t <= w[1])
            np.testing.assert_allclose(stats[key].max_abs, np.abs(h.error[:, mask]).max(axis=(0, 1)), rtol=1e-12)
        np.testing.assert_array_equal(acc[name].convergence_s, convergence_time(h.error, h.t, tol))


def _peak_bytes(runs, sink=None):
    sink = StatisticsSink({"all": (0.0, 20.0)}, runs, SUN.xhat0) if sink is None else sink
    tracemalloc.start()
    try:
        run_monte_carlo(SUN, "ekf", sink=sink, runs=runs, seed=1, batch_size=20, keep_covariance=False, maneuver=True)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_memory_does_not_grow_with_runs_without_histories():
    # with the statistics sink one batch of histories is alive at a time: 400 runs in batches of 20 must peak like
    # 20 runs (measured: 1.31 MB against 1.38 MB). What grows is only the per-run RMS (runs x 6 floats, 19 kB for
    # 400 runs) against a batch of ~1 MB, hence the factor 1.1. The control: keeping the histories of 200 runs
    # takes ten times one batch (measured 11.6 MB), so the test can fail.
    _peak_bytes(20)  # first calls (imports, caches) out of the way
    small, large = _peak_bytes(20), _peak_bytes(400)
    assert large < 1.1 * small, (small, large)
    kept = _peak_bytes(200, HistorySink(SUN.xhat0, 200))
    assert kept > 5 * small, (small, kept)


class _Failing:
    """An estimator (duck-typed, as a campaign may wrap one) that raises on its second batch."""

    def __init__(self, inner):
        self.inner, self.measurement, self.name, self.calls = inner, inner.measurement, "failing", 0

    def estimate(self, *args, **kwargs):
        self.calls += 1
        if self.calls == 2:
            raise FloatingPointError("blown up on purpose")
        return self.inner.estimate(*args, **kwargs)


class _Recording(HistorySink):
    def __init__(self, xhat0, runs):
        super().__init__(xhat0, runs)
        self.errors, self.seconds = {}, {}

    def fail(self, name, exc):
        self.errors[name] = exc

    def timed(self, name, wall_s, cpu_s):
        self.seconds.setdefault(name, []).append((wall_s, cpu_s))


def test_a_failing_estimator_stops_alone_when_the_sink_records_it():
    failing = _Failing(sun2011.make_estimator(SUN, "ekf"))
    sink = _Recording(SUN.xhat0, 6)
    out = run_monte_carlo(SUN, {"failing": failing, "published": "published"}, sink=sink, runs=6, seed=2,
                          batch_size=2, keep_covariance=False, maneuver=True)
    # batches of 2 runs: the failing one ran its first batch, raised on the second and got no third
    assert failing.calls == 2 and isinstance(sink.errors["failing"], FloatingPointError)
    assert out["published"].x.shape[0] == 6 and out["failing"].x.shape[0] == 2
    assert len(sink.seconds[None]) == 4 and len(sink.seconds["published"]) == 3 and len(sink.seconds["failing"]) == 2
    assert all(w >= 0 and c >= 0 for w, c in sink.seconds["published"])
    # the default sink re-raises
    with pytest.raises(FloatingPointError, match="on purpose"):
        failing.calls = 1
        run_monte_carlo(SUN, failing, sink=HistorySink(SUN.xhat0, 2), runs=2, seed=2, maneuver=True)
