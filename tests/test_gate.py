"""The χ² innovation gate of the Kalman core: it rejects a spike, reports what it rejected, and cannot lock out.

A 2-D constant-velocity track read at 1 Hz with 1 m noise (σ per axis). Expected values come from the set-up:
a 25 m spike is 25 σ (far beyond χ²'s 0.999 quantile, 3.7 σ per channel); the degradation test puts an unmodelled
velocity change (0.3, −0.2) m/s under 5 minutes of 30 m readings, so a filter that rejects them drifts ~100 m off
and, with a small Q, never admits a reading again (lock-out, asserted for ``recovery=None``).
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators.correntropy import CorrentropyFilter
from hinfnav.estimators.gate import ChiSquareGate, gate_report, gated
from hinfnav.estimators.huber_filter import HuberFilter
from hinfnav.estimators.kalman import ExtendedKalmanFilter
from hinfnav.estimators.sigma_point import SigmaPointFilter
from hinfnav.estimators.variational import NoiseAdaptiveFilter, StudentTFilter
from hinfnav.systems.linear import LinearSystem
from hinfnav.systems.measurements import LinearMeasurement
from hinfnav.systems.state import StateSpec

T, q = 1.0, 1e-4  # s, m²/s³ (a quiet target: the filter's P grows slowly while it rejects)
F = np.block([[np.eye(2), T * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
Q = q * np.block([[T**3 / 3 * np.eye(2), T**2 / 2 * np.eye(2)], [T**2 / 2 * np.eye(2), T * np.eye(2)]])
STATE = StateSpec(labels=("x", "y", "vx", "vy"), units=("m", "m", "m/s", "m/s"),
                  groups={"position": (0, 1), "velocity": (2, 3)})
SYSTEM = LinearSystem(Phi=F, Gamma=np.zeros((4, 1)), B=np.linalg.cholesky(Q), dt=T, state=STATE)
MEAS = LinearMeasurement(np.hstack([np.eye(2), np.zeros((2, 2))]), np.eye(2))
P0 = np.diag([1.0, 1.0, 0.01, 0.01])
X0 = np.array([0.0, 0.0, 5.0, 2.0])


def _track(runs=4, n=800, seed=2, jump_at=None):
    rng = np.random.default_rng(seed)
    L = np.linalg.cholesky(Q)
    x = np.empty((runs, n, 4))
    x[:, 0] = X0
    for k in range(1, n):
        x[:, k] = x[:, k - 1] @ F.T + rng.standard_normal((runs, 4)) @ L.T
        if k == jump_at:
            x[:, k, 2:] += [0.3, -0.2]
    return x, x[..., :2] + rng.standard_normal((runs, n, 2))


def _error(hist, x):
    return np.linalg.norm(hist.xhat[..., :2] - x[..., :2], axis=-1)


@pytest.mark.parametrize("per", ["reading", "channel"])
def test_rejects_a_25_m_spike_and_reports_it(per):
    x, y = _track(runs=3, n=200)
    y = y.copy()
    y[:, 100, 0] += 25.0  # a 25 m spike on channel 0 (25 σ)
    u = np.zeros((3, 200, 1))
    kf = ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0)
    plain = kf.estimate(y, u, X0)
    hist = gated(kf, per=per).estimate(y, u, X0, diagnostics=True)
    rej = hist.diagnostics["gate_rejected"]
    assert rej[:, 100, 0].all()  # the spike, in every run
    # per reading the whole reading goes; per channel only the spiked channel
    assert rej[:, 100, 1].all() == (per == "reading")
    # the ungated filter is pulled off by the spike (measured 2.8-3.8 m); the gated one keeps its prior
    assert _error(plain, x)[:, 100].min() > 2.0
    assert _error(hist, x)[:, 100].max() < 1.5  # measured 0.4-1.0 m
    rep = gate_report(hist.diagnostics, dt=T)
    # the count is what the diagnostics hold (identity), the spike among the steps reported, and false alarms rare:
    # 600 readings at probability 0.999 give 0.6 expected (a bound of 5 fails with probability < 1e-3)
    assert rep["rejected_readings"] == int(rej.any(axis=2).sum()) and 100 in rep["steps"]
    assert 3 <= rep["rejected_readings"] <= 3 + 5
    assert rep["per_channel"][0] >= 3 and 100.0 in rep["times"]


@pytest.mark.parametrize("recovery", ["inflate", "reacquire"])
@pytest.mark.parametrize("cls", [ExtendedKalmanFilter, SigmaPointFilter])
def test_survives_a_5_minute_degradation(recovery, cls):
    x, y = _track(jump_at=200)
    y = y.copy()
    rng = np.random.default_rng(3)
    y[:, 200:500] += 29.0 * rng.standard_normal((4, 300, 2))  # 5 minutes of 30 m readings (1 + 29² = 30² m²)
    u = np.zeros((4, 800, 1))
    kf = cls(SYSTEM, MEAS, P0=P0)
    locked = gated(kf, recovery=None).estimate(y, u, X0, diagnostics=True)
    hist = gated(kf, recovery=recovery).estimate(y, u, X0, diagnostics=True)
    # without recovery the filter locks out (measured in 3 of 4 runs): it rejects every one of the last 100 readings
    # and ends > 50 m off (measured 170-230 m)
    lost = locked.diagnostics["gate_rejected"][:, 700:].all(axis=(1, 2))
    assert lost.sum() >= 2 and np.all(_error(locked, x)[lost, -1] > 50.0)
    # with recovery: every run accepts its last 100 readings and ends within 3 m (1 m readings; measured < 0.7 m)
    assert not hist.diagnostics["gate_rejected"][:, 700:].any()
    assert np.all(_error(hist, x)[:, -1] < 3.0)
    rep = gate_report(hist.diagnostics)
    assert rep["recoveries"] > 0 and rep["rejected_readings"] > 100  # it did reject most degraded readings
    assert rep["longest_run"] < 50  # a run of rejections is broken by the recovery


def test_every_kalman_core_filter_takes_a_gate():
    x, y = _track(runs=2, n=150)
    y = y.copy()
    y[:, 60, 1] -= 25.0
    u = np.zeros((2, 150, 1))
    for cls in (ExtendedKalmanFilter, HuberFilter, StudentTFilter, NoiseAdaptiveFilter, CorrentropyFilter,
                SigmaPointFilter):
        est = cls(SYSTEM, MEAS, P0=P0)
        est.gate = ChiSquareGate()
        hist = est.estimate(y, u, X0, diagnostics=True)
        assert hist.diagnostics["gate_rejected"][:, 60].all(), cls.__name__
        # the step loop gives the batch's numbers (identity)
        state = est.start(X0, None, 2)
        for k in range(150):
            state, out = est.update(state, y[:, k])
            np.testing.assert_allclose(out.xhat, hist.xhat[:, k], rtol=1e-12, atol=1e-12)
            if k < 149:
                state = est.predict(state, u[:, k])


def test_bad_gate_options_are_named():
    for bad in ({"probability": 1.0}, {"per": "run"}, {"after": 0}, {"inflation": 1.0}, {"recovery": "retry"}):
        with pytest.raises(InputError, match=list(bad)[0]):
            ChiSquareGate(**bad)
    with pytest.raises(InputError, match="gate"):
        ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0).gate = 3.0
    with pytest.raises(InputError, match="numpy"):
        gated(ExtendedKalmanFilter(SYSTEM, MEAS, P0=P0)).estimate(np.zeros((1, 5, 2)), np.zeros((1, 5, 1)), X0,
                                                                   backend="numba")


def test_campaign_table_shows_rejections_per_cell():
    import hinfnav.papers  # noqa: F401 - registers Sun 2011's scenario and estimators
    from hinfnav.campaign import Campaign, run_campaign
    from hinfnav.papers.sun2011 import Scenario

    # Sun 2011's chaser under the mixture noise (outliers), no maneuver: a gated Kalman cell (gate options are
    # JSON) beside an ungated one; 4 runs x 20 s
    grid = {"scenario": "sun2011", "estimator": ["model_ekf", "ekf"], "maneuver": [False], "noise": ["mixture"],
            "duration_s": [20.0], "rms_window_s": [[0.0, 20.0]]}
    spec = Campaign(grid=grid, runs=4, batch_size=2, windows={"all": [0.0, 20.0]}, seed=3,
                    estimator_options={"model_ekf": {"gate": {"probability": 0.99, "per": "channel"}}})
    table = run_campaign(spec, client="serial", progress=False)
    rows = table[table.statistic.str.startswith("gate_")]
    assert set(rows.estimator) == {"model_ekf"}  # the ungated cell has no gate rows
    got = dict(zip(rows.statistic, rows.value))
    assert got["gate_rejected_readings"] >= 1 and got["gate_rejected_channels"] >= got["gate_rejected_readings"]
    sc = Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))
    readings = 4 * (round(20.0 / sc.dt) + 1)  # runs x samples (t = 0 … 20 s)
    np.testing.assert_allclose(got["gate_rejected_fraction"], got["gate_rejected_readings"] / readings)
    assert got["gate_rejected_fraction"] < 0.2  # outliers are a minority of the mixture's readings


def test_a_gate_on_yang2020_algorithm_1_is_not_ignored():
    # Algorithm 1 (ExtendedStateKalmanFilter) has its own fast update; a gate sends it through the core's
    from hinfnav.estimators import build_estimator
    from hinfnav.papers.yang2020 import Scenario as YangScenario
    from hinfnav.sim import simulate_truth

    lt = YangScenario(n_steps=200).linear_truth("position")
    tr = simulate_truth(lt.truth_model(), runs=2, seed=1)
    y = tr.y.copy()
    y[:, 120] += 50.0 * np.sqrt(np.diag(lt.truth_model().measurement.R))  # a 50 σ spike
    est = build_estimator(lt, "yang2020_alg1", gate={"probability": 0.999})
    hist = est.estimate(y, tr.u, lt.xhat0, diagnostics=True)
    assert hist.diagnostics["gate_rejected"][:, 120].all()
    # without rejections the gated path is the filter's own (identity up to rounding)
    plain = build_estimator(lt, "yang2020_alg1").estimate(tr.y, tr.u, lt.xhat0).xhat
    quiet = build_estimator(lt, "yang2020_alg1", gate={"probability": 1 - 1e-12}).estimate(tr.y, tr.u, lt.xhat0)
    np.testing.assert_allclose(quiet.xhat, plain, rtol=1e-9, atol=1e-9 * np.abs(plain).max())
