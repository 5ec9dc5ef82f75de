"""Irregular time (:mod:`hinfnav.systems.timed`, :mod:`hinfnav.estimators.timed`): a time-stamped record with
jittered steps, 30 s gaps and two sensors at their own rates, filtered and smoothed through the public API.

Expected values: the closed-form discretisation of the constant-velocity model (Φ = [[1, Δt], [0, 1]],
Q_d = q [[Δt³/3, Δt²/2], [Δt²/2, Δt]] per axis; Bar-Shalom, Li & Kirubarajan 2001, §6.2.2) in a Kalman filter and
an RTS smoother written out in this file.
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import ExtendedKalmanFilter, SigmaPointFilter
from hinfnav.estimators.sqrt import square_root
from hinfnav.estimators.timed import estimate_timed, smooth_timed
from hinfnav.systems import LinearMeasurement
from hinfnav.systems.state import StateSpec
from hinfnav.systems.timed import TimedReadings, TimedSystem, merge_readings, read_timed_csv, van_loan

Q_C = 0.05  # m²/s³, the acceleration noise density per axis
A = np.kron(np.eye(2), [[0.0, 1.0], [0.0, 0.0]])
STATE = StateSpec(("x", "vx", "y", "vy"), ("m", "m/s", "m", "m/s"))
QC = np.kron(np.eye(2), [[0.0, 0.0], [0.0, Q_C]])


def cv(dt):
    """Closed-form Φ and Q_d of the constant-velocity model for one step."""
    Phi = np.kron(np.eye(2), [[1.0, dt], [0.0, 1.0]])
    Qd = Q_C * np.kron(np.eye(2), [[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    return Phi, Qd


def record(runs=2, seed=0):
    """Jittered GNSS positions (~1 s, two 30 s gaps) and a velocity sensor every 5 s, with their truth."""
    rng = np.random.default_rng(seed)
    t_gnss = np.cumsum(rng.uniform(0.7, 1.3, 120))
    t_gnss = t_gnss[(t_gnss < 40) | (t_gnss > 70)]  # a 30 s gap
    t_gnss = np.concatenate([t_gnss, t_gnss[-1] + 30 + np.cumsum(rng.uniform(0.7, 1.3, 20))])  # and another
    t_vel = np.arange(2.5, t_gnss[-1], 5.0)
    for a, b in zip(t_gnss[:-1][np.diff(t_gnss) > 20], t_gnss[1:][np.diff(t_gnss) > 20]):
        t_vel = t_vel[(t_vel < a) | (t_vel > b)]  # the whole log drops out in the gaps
    t = np.unique(np.concatenate([t_gnss, t_vel]))
    x = np.empty((runs, t.size, 4))
    x[:, 0] = [0.0, 3.0, 10.0, -1.0]
    for k in range(1, t.size):
        Phi, Qd = cv(t[k] - t[k - 1])
        x[:, k] = x[:, k - 1] @ Phi.T + rng.standard_normal((runs, 4)) @ np.linalg.cholesky(Qd).T
    ig, iv = np.searchsorted(t, t_gnss), np.searchsorted(t, t_vel)
    gnss = TimedReadings(t_gnss, x[:, ig][..., [0, 2]] + 2.0 * rng.standard_normal((runs, ig.size, 2)), ("x", "y"))
    vel = TimedReadings(t_vel, x[:, iv][..., [1, 3]] + 0.1 * rng.standard_normal((runs, iv.size, 2)), ("vx", "vy"))
    return t, x, gnss, vel


MEAS = LinearMeasurement(np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]]),
                         np.diag([2.0, 2.0, 0.1, 0.1]))
P0 = np.diag([25.0, 4.0, 25.0, 4.0])
XHAT0 = np.array([0.0, 3.0, 10.0, -1.0])


def written_out_kf_rts(t, y):
    """Kalman filter and RTS smoother with the closed-form CV matrices, one run, NaN channels skipped."""
    H, R = MEAS.H, MEAS.R
    x, P = XHAT0.copy(), P0.copy()
    xf, Pf, xp, Pp, F = [], [], [], [], []
    for k in range(t.size):
        ok = ~np.isnan(y[k])
        if ok.any():
            Hk, Rk = H[ok], R[np.ix_(ok, ok)]
            K = P @ Hk.T @ np.linalg.inv(Hk @ P @ Hk.T + Rk)
            x = x + K @ (y[k, ok] - Hk @ x)
            P = (np.eye(4) - K @ Hk) @ P
        xf.append(x), Pf.append(P)
        if k < t.size - 1:
            Phi, Qd = cv(t[k + 1] - t[k])
            x, P = Phi @ x, Phi @ P @ Phi.T + Qd
            xp.append(x), Pp.append(P), F.append(Phi)
    xs, Ps = list(xf), list(Pf)
    for k in range(t.size - 2, -1, -1):
        G = Pf[k] @ F[k].T @ np.linalg.inv(Pp[k])
        xs[k] = xf[k] + G @ (xs[k + 1] - xp[k])
        Ps[k] = Pf[k] + G @ (Ps[k + 1] - Pp[k]) @ G.T
    return np.array(xf), np.array(Pf), np.array(xs), np.array(Ps)


def test_van_loan_equals_the_closed_form_cv_discretisation():
    for dt in (0.3, 1.0, 30.0):
        Phi, Qd = van_loan(A, QC, dt)
        Phi_ref, Qd_ref = cv(dt)
        np.testing.assert_allclose(Phi, Phi_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(Qd, Qd_ref, rtol=1e-10, atol=1e-14 * max(1.0, dt**3))


def test_jittered_record_with_gaps_and_two_rates_filters_and_smooths(tmp_path):
    t, x, gnss, vel = record()
    readings = merge_readings(gnss, vel)
    np.testing.assert_array_equal(readings.t, t)
    assert readings.dt.max() > 29.0 and readings.labels == ("x", "y", "vx", "vy")
    # the same record through a CSV file of time-stamped readings (empty cells: not read)
    path = tmp_path / "log.csv"
    with path.open("w") as fh:
        fh.write("t,x,y,vx,vy\n")
        for k in range(t.size):
            fh.write(f"{float(t[k])!r}," + ",".join("" if np.isnan(v) else repr(float(v)) for v in readings.y[0, k]) + "\n")
    loaded = read_timed_csv(path, time="t")
    np.testing.assert_array_equal(loaded.t, readings.t)
    np.testing.assert_array_equal(loaded.y[0], readings.y[0])

    timed = TimedSystem.from_continuous(A, QC, STATE)
    kf = ExtendedKalmanFilter(timed.at(readings.nominal_dt), MEAS, P0=P0, missing="skip")
    hist = estimate_timed(kf, timed, readings, XHAT0)
    sm = smooth_timed(kf, timed, readings, XHAT0)
    for r in range(readings.runs):
        xf, Pf, xs, Ps = written_out_kf_rts(t, readings.y[r])
        # independent: closed-form matrices, a written-out loop; agreement to 1e-10 of the scale
        np.testing.assert_allclose(hist.xhat[r], xf, rtol=0, atol=1e-10 * np.abs(xf).max())
        np.testing.assert_allclose(hist.P[r], Pf, rtol=0, atol=1e-10 * np.abs(Pf).max())
        np.testing.assert_allclose(sm.xhat[r], xs, rtol=0, atol=1e-10 * np.abs(xs).max())
        np.testing.assert_allclose(sm.P[r], Ps, rtol=0, atol=1e-10 * np.abs(Ps).max())
    # the sigma-point filter and the square-root forms take the same path
    ukf = SigmaPointFilter(timed.at(1.0), MEAS, P0=P0, rule="cubature", missing="skip")
    for est in (ukf, square_root(kf), square_root(ukf)):
        h = estimate_timed(est, timed, readings, XHAT0)
        np.testing.assert_allclose(h.xhat, hist.xhat, rtol=0, atol=1e-9 * np.abs(hist.xhat).max())
    # prediction-only stamps in the gaps (no step over 5 s) leave the estimates at the reading stamps unchanged
    fine = readings.with_max_step(5.0)
    assert fine.dt.max() <= 5.0 + 1e-9
    h_fine = smooth_timed(kf, timed, fine, XHAT0)
    at = np.searchsorted(fine.t, readings.t)
    np.testing.assert_allclose(h_fine.xhat[:, at], sm.xhat, rtol=0, atol=1e-9 * np.abs(sm.xhat).max())
    # in the middle of a 30 s gap the smoother's position variance is far below the filter's (predicted) one
    gap = np.argmax(readings.dt)
    mid = np.argmin(np.abs(fine.t - 0.5 * (readings.t[gap] + readings.t[gap + 1])))
    assert h_fine.P[0, mid, 0, 0] < 0.5 * h_fine.P_filt[0, mid, 0, 0]


def test_timed_inputs_are_checked(tmp_path):
    with pytest.raises(InputError, match="strictly increasing"):
        TimedReadings([0.0, 1.0, 1.0], np.zeros((3, 2)))
    path = tmp_path / "bad.csv"
    path.write_text("time,a\n0,1\n")
    with pytest.raises(InputError, match="no time column 't'"):
        read_timed_csv(path)
    iso = tmp_path / "iso.csv"
    iso.write_text("t,a\n2010-07-27T00:00:10,1\n2010-07-27T00:00:00,2\n")
    r = read_timed_csv(iso)
    np.testing.assert_array_equal(r.t, [0.0, 10.0])
    np.testing.assert_array_equal(r.y[0, :, 0], [2.0, 1.0])


def test_readme_irregular_time_example_runs_verbatim(capsys):
    # README.md, "Your own system", the second code block (the first is tests/test_readme.py's)
    import re
    from pathlib import Path
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    section = text.split("## Your own system", 1)[1].split("## Command line", 1)[0]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[1]
    namespace = {}
    exec(compile(code, "README.md", "exec"), namespace)
    # the square-root form gives the Joseph form's numbers (1e-10 of the scale)
    np.testing.assert_allclose(namespace["sqrt"].xhat, namespace["filt"].xhat, rtol=0, atol=1e-10 * 20)
    out = capsys.readouterr().out
    v_f, v_s = (float(v) for v in re.search(r"filter (\S+) smoother (\S+)", out).groups())
    assert abs(v_s - 0.5) < abs(v_f - 0.5)  # the smoother's velocity at t = 0 is nearer the true 0.5 m/s
