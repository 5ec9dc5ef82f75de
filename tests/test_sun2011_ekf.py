"""Tests of the EKF baseline (hinfnav.papers.sun2011.ekf on hinfnav.estimators.ExtendedKalmanFilter), issue 4 item 1."""

import numpy as np
import pytest
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEKF

from hinfnav.core import InputError
from hinfnav.estimators import ExtendedKalmanFilter
from hinfnav.metrics import rms_error
from hinfnav.papers.sun2011 import (
    EKF,
    Scenario,
    build_ekf,
    kalman_limit,
    make_estimator,
    pos_vel,
    range_angle_measurements,
)
from hinfnav.papers.sun2011.constants import DEFAULT_P0_STD
from hinfnav.sim import simulate, simulate_truth
from hinfnav.systems import position_from_range_angles, range_angles, range_angles_jacobian


def _rot(a, b, c):
    """A rotation matrix from three angles (for C_bl)."""
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    Rz = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])
    Ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    Rx = np.array([[1, 0, 0], [0, cc, -sc], [0, sc, cc]])
    return Rz @ Ry @ Rx


def filterpy_reference(ekf, y, u, xhat0):
    """The same EKF run through filterpy's ``ExtendedKalmanFilter``, one run at a time.

    Returns the estimates and covariances the EKF reports, (runs, n_samples, 6) and
    (runs, n_samples, 6, 6): x̂(k|k), P(k|k) for ``output="filtered"``, the priors otherwise.
    """
    runs, n1, _ = y.shape
    which = 1 if ekf.output == "filtered" else 0
    xs = np.empty((runs, n1, 6))
    Ps = np.empty((runs, n1, 6, 6))
    meas = ekf.measurement
    for r in range(runs):
        f = FilterpyEKF(dim_x=6, dim_z=3, dim_u=3)
        f.x = np.array(xhat0, dtype=float)
        f.P = ekf.P0.copy()
        f.F, f.Q, f.R = ekf.F, ekf.Q, ekf.R
        f.B = ekf.Gamma if ekf.uses_input else 0
        for k in range(n1):
            if k:
                f.predict(u=u[r, k - 1] if ekf.uses_input else 0)
            if not which:
                xs[r, k], Ps[r, k] = f.x, f.P
            f.update(y[r, k], meas.jacobian, meas.function, residual=meas.residual)
            if which:
                xs[r, k], Ps[r, k] = f.x, f.P
    return xs, Ps


# --- convergence to the Riccati steady state ------------------------------


@pytest.mark.parametrize("output, field", [("filtered", "P_filtered"), ("predicted", "P_predicted")])
def test_covariance_converges_to_dare(output, field, scenario):
    # expected value: the DARE solution of kalman_limit (scipy solve_discrete_are)
    ekf = EKF(scenario, output=output)
    truth = simulate_truth(scenario.truth_model(maneuver=False), runs=1, seed=0)
    P_end = ekf.estimate(truth.y, truth.u, scenario.xhat0).P[0, -1]
    P_dare = getattr(kalman_limit(scenario, maneuver=False), field)
    np.testing.assert_allclose(P_end, P_dare, rtol=1e-8, atol=1e-12)


def test_monte_carlo_rms_matches_riccati_without_maneuver(scenario, assert_rms_matches):
    # expected value: sqrt(diag) of the filtered DARE solution, 0.0626 m and 0.0224 m/s
    # per axis (kalman_limit); tolerance: 4 standard errors of the 50-run mean
    # (measured ~0.15 % for position, ~2.5 % for velocity: the velocity error is slow)
    res = simulate(scenario, EKF(scenario), maneuver=False, runs=50, seed=11)
    lim = kalman_limit(scenario, maneuver=False)
    sigma = np.r_[lim.pos_m, lim.vel_mps]
    rms, _ = assert_rms_matches(res.error, res.t, scenario.rms_window_s, sigma)
    assert np.all(np.abs(rms[:3] / sigma[:3] - 1) < 0.01)
    assert np.all(np.abs(rms[3:] / sigma[3:] - 1) < 0.12)


# --- with maneuver: the paper's failure, and the known-input variant ------


@pytest.fixture(scope="module")
def maneuver_results(scenario):
    truth = simulate_truth(scenario.truth_model(maneuver=True), runs=50, seed=3)
    out = {}
    for known in (False, True):
        hist = build_ekf(scenario, known_input=known).estimate(truth.y, truth.u, scenario.xhat0, keep_covariance=False)
        out[known] = truth.x - hist.xhat
    return truth.t, out, truth.state


def test_unknown_input_ekf_fails_during_thrust(maneuver_results):
    # measured (50 runs, seed 3; 10 and 20 runs gave the same to 2 digits: the error
    # is driven by the deterministic part of the thrust, not by the noise):
    # 100-500 s per-axis RMS ≈ (0.51, 0.43, 0.67) m and (3.2, 2.7, 4.3) m/s,
    # i.e. 7-11x the position limit 0.0626 m and >100x the velocity limit 0.0224 m/s
    # (paper, Fig 4: the EKF "cannot converge in the first 500 s")
    t, err, state = maneuver_results
    pos, vel = pos_vel(rms_error(err[False], t, (100.0, 500.0)), state)
    assert np.all(pos > 0.3) and np.all(pos < 1.0)
    assert np.all(vel > 2.0) and np.all(vel < 6.0)
    # and recovers once the thrust has died away; measured 700-1000 s:
    # (0.063, 0.063, 0.063) m (the limit) and (0.045, 0.039, 0.040) m/s (2x the limit:
    # the residual thrust of a few N still pushes the velocity)
    pos, vel = pos_vel(rms_error(err[False], t, (700.0, 1000.0)), state)
    assert np.all(pos < 0.07) and np.all(vel < 0.07)


def test_known_input_ekf_does_not_fail(maneuver_results, scenario, assert_rms_matches):
    # expected value: told the applied thrust, the EKF's error obeys the open-loop
    # model whatever u is, so it sits at the maneuver=False Riccati limit (kalman_limit):
    # 0.0626 m, 0.0224 m/s per axis; tolerance 4 standard errors of the 50-run mean
    t, err, _ = maneuver_results
    lim = kalman_limit(scenario, maneuver=False)
    assert_rms_matches(err[True], t, (100.0, 500.0), np.r_[lim.pos_m, lim.vel_mps])


def test_known_input_error_does_not_depend_on_the_maneuver(short_scenario):
    # the known-input EKF's error recursion contains neither x nor u, so with the
    # same noise (same seed) its error histories with and without maneuver agree
    # up to rounding on states of ~1000 m
    errs = []
    for maneuver in (False, True):
        res = simulate(short_scenario, build_ekf(short_scenario, known_input=True), maneuver=maneuver, runs=2, seed=6)
        errs.append(res.error)
    np.testing.assert_allclose(errs[0], errs[1], rtol=0, atol=1e-8)


def test_control_law_ekf_reaches_closed_loop_limit(scenario, assert_rms_matches):
    # expected value: the closed-loop Riccati limit, velocity 0.0135-0.0139 m/s (kalman_limit)
    res = simulate(scenario, EKF(scenario, dynamics="control_law"), maneuver=True, runs=50, seed=5)
    lim = kalman_limit(scenario, maneuver=True)
    assert_rms_matches(res.error, res.t, scenario.rms_window_s, np.r_[lim.pos_m, lim.vel_mps])


# --- batched gains == filterpy run by run ---------------------------------


@pytest.mark.parametrize("dynamics", ["unforced", "applied_thrust", "control_law"])
@pytest.mark.parametrize("output", ["filtered", "predicted"])
def test_batched_equals_filterpy_run_by_run(dynamics, output, short_scenario):
    # the batched filter (one shared covariance recursion for all runs) against filterpy's
    # ExtendedKalmanFilter run by run on the same model, Q, R and P0
    sc = short_scenario
    truth = simulate_truth(sc.truth_model(maneuver=True), runs=3, seed=2)
    fast = EKF(sc, dynamics=dynamics, output=output)
    assert isinstance(fast, ExtendedKalmanFilter) and fast.vectorized and fast.shares_covariance
    a = fast.estimate(truth.y, truth.u, sc.xhat0)
    xs, Ps = filterpy_reference(fast, truth.y, truth.u, sc.xhat0)
    np.testing.assert_allclose(a.xhat, xs, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.P, Ps, rtol=0, atol=1e-12)


def test_range_angle_ekf_equals_filterpy_run_by_run(short_scenario):
    # with the nonlinear measurement each run carries its own covariance; the batched update
    # (Jacobian at each run's prior, wrapped angle residual) equals filterpy run by run
    sc = short_scenario
    truth = simulate_truth(sc.truth_model(maneuver=True), runs=2, seed=7)
    C_bl = _rot(0.2, 0.1, -0.4)
    y = range_angle_measurements(truth.x, np.random.default_rng(1), C_bl=C_bl)
    ekf = build_ekf(sc, known_input=True, measurement="range_angles", C_bl=C_bl)
    assert not ekf.shares_covariance
    a = ekf.estimate(y, truth.u, sc.xhat0)
    xs, Ps = filterpy_reference(ekf, y, truth.u, sc.xhat0)
    np.testing.assert_allclose(a.xhat, xs, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.P, Ps, rtol=1e-9, atol=1e-12)


def test_timing_convention(short_scenario):
    sc = short_scenario
    truth = simulate_truth(sc.truth_model(maneuver=False), runs=1, seed=0)
    pred = EKF(sc, output="predicted").estimate(truth.y, truth.u, sc.xhat0)
    filt = EKF(sc, output="filtered").estimate(truth.y, truth.u, sc.xhat0)
    # predicted estimate at t_0 is the prior; P(0|−1) = P0
    np.testing.assert_array_equal(pred.xhat[0, 0], sc.xhat0)
    np.testing.assert_allclose(pred.P[0, 0], np.diag(DEFAULT_P0_STD**2))
    # the filtered one has used y(0): its position is within a few σ_v of y(0)
    assert np.all(np.abs(filt.xhat[0, 0, :3] - truth.y[0, 0]) < 0.5)
    # x̂(k+1|k) = Φ x̂(k|k) for the unforced model
    Phi, _ = sc.truth_matrices(0.0, "exact")
    np.testing.assert_allclose(pred.xhat[0, 1:], filt.xhat[0, :-1] @ Phi.T, atol=1e-9)


def test_keep_covariance_and_diagnostics(short_scenario):
    # estimate(keep_covariance=False) drops P (it replaces the old constructor argument);
    # diagnostics=True returns the innovation history y(k) − C x̂(k|k−1)
    sc = short_scenario
    truth = simulate_truth(sc.truth_model(maneuver=False), runs=2, seed=0)
    ekf = EKF(sc, output="predicted")
    # diagnostics=True runs the NumPy path (all diagnostics): compare with the same path, bitwise
    bare = ekf.estimate(truth.y, truth.u, sc.xhat0, keep_covariance=False, backend="numpy")
    assert bare.P is None
    full = ekf.estimate(truth.y, truth.u, sc.xhat0, diagnostics=True)
    np.testing.assert_array_equal(bare.xhat, full.xhat)
    np.testing.assert_allclose(full.diagnostics["innovation"], truth.y - full.xhat[..., :3], rtol=0, atol=1e-12)


def test_registry_and_simulate(short_scenario):
    sc = short_scenario
    ekf = make_estimator(sc, "ekf")
    known = make_estimator(sc, "ekf_known_input")
    assert (ekf.name, ekf.uses_input, ekf.vectorized) == ("ekf", False, True)
    assert (known.name, known.uses_input, known.vectorized) == ("ekf_known_input", True, True)
    res = simulate(sc, ekf, maneuver=False, runs=2, seed=0)
    assert res.xhat.shape == (2, sc.n_steps + 1, 6)
    assert res.P.shape == (2, sc.n_steps + 1, 6, 6)
    again = simulate(sc, make_estimator(sc, "ekf"), maneuver=False, runs=2, seed=0)
    np.testing.assert_array_equal(res.xhat, again.xhat)


# --- range / azimuth / elevation -------------------------------------------


def test_range_angles_closed_form():
    # expected values: (7) evaluated by hand
    cases = {
        (2.0, 0.0, 0.0): (2.0, 0.0, 0.0),
        (0.0, 3.0, 0.0): (3.0, np.pi / 2, 0.0),
        (0.0, 0.0, 4.0): (4.0, 0.0, -np.pi / 2),  # z down is β = +π/2 (−ρ sin β)
        (-1.0, -1.0, 0.0): (np.sqrt(2), -3 * np.pi / 4, 0.0),
        (1.0, 1.0, -np.sqrt(2)): (2.0, np.pi / 4, np.pi / 4),
    }
    for p, expected in cases.items():
        got = range_angles(np.r_[p, 0.1, 0.2, 0.3])
        np.testing.assert_allclose(got, expected, atol=1e-14)


def test_range_angles_round_trip_and_jacobian():
    rng = np.random.default_rng(0)
    C_bl = _rot(0.3, -0.7, 1.1)
    x = rng.normal(0, 500, (20, 6))
    m = range_angles(x, C_bl)
    np.testing.assert_allclose(position_from_range_angles(m, C_bl), x[:, :3], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(m[:, 0], np.linalg.norm(x[:, :3], axis=1), rtol=1e-14)
    for xi in x[:5]:
        J = range_angles_jacobian(xi, C_bl)
        h = 1e-4
        num = np.column_stack([(range_angles(xi + h * e, C_bl) - range_angles(xi - h * e, C_bl)) / (2 * h) for e in np.eye(6)])
        np.testing.assert_allclose(J, num, rtol=1e-6, atol=1e-12)
    # batched: one call on (k, 6) states gives the (k, 3, 6) stack of the single Jacobians
    Jb = range_angles_jacobian(x[:5], C_bl)
    assert Jb.shape == (5, 3, 6)
    for i in range(5):
        np.testing.assert_allclose(Jb[i], range_angles_jacobian(x[i], C_bl), rtol=1e-13, atol=1e-18)


def test_range_angle_measurement_noise():
    x = np.tile([600.0, 550.0, 1040.0, 0, 0, 0], (200_000, 1))
    m = range_angle_measurements(x, np.random.default_rng(1), sigma_range=0.1, sigma_angle=1e-4)
    d = m - range_angles(x)
    np.testing.assert_allclose(d.std(axis=0), [0.1, 1e-4, 1e-4], rtol=0.01)
    assert np.all(np.abs(d.mean(axis=0)) < np.array([0.1, 1e-4, 1e-4]) * 0.01)
    again = range_angle_measurements(x, np.random.default_rng(1), sigma_range=0.1, sigma_angle=1e-4)
    np.testing.assert_array_equal(m, again)
    exact = range_angle_measurements(x[:3], np.random.default_rng(1), sigma_range=0.0, sigma_angle=0.0)
    np.testing.assert_array_equal(exact, range_angles(x[:3]))
    # azimuth stays wrapped near ±π
    xb = np.tile([-1000.0, 1e-6, 0, 0, 0, 0], (1000, 1))
    mb = range_angle_measurements(xb, np.random.default_rng(2), sigma_angle=1e-3)
    assert np.all(np.abs(mb[:, 1]) <= np.pi)


def test_range_angle_ekf_tracks():
    # no maneuver, 200 s, one run; the position error must be consistent with the
    # filter's own covariance (normalized error squared ≈ 1) and near the
    # indirect-measurement limit 0.0626 m (the default sigmas make the two
    # measurements about equally informative at ~1.3 km range)
    sc = Scenario(duration_s=200.0, rms_window_s=(50.0, 200.0))
    truth = simulate_truth(sc.truth_model(maneuver=False), runs=1, seed=4)
    C_bl = _rot(0.2, 0.1, -0.4)
    y = range_angle_measurements(truth.x, np.random.default_rng(9), C_bl=C_bl)
    ekf = build_ekf(sc, measurement="range_angles", C_bl=C_bl)
    assert not ekf.shares_covariance and ekf.name == "ekf_range_angles"
    hist = ekf.estimate(y, truth.u, sc.xhat0)
    err = truth.x - hist.xhat
    mask = truth.t >= 50.0
    nees = np.einsum("ki,kij,kj->k", err[0, mask], np.linalg.inv(hist.P[0, mask]), err[0, mask]) / 6
    assert 0.7 < nees.mean() < 1.3
    pos, vel = pos_vel(rms_error(err, truth.t, (50.0, 200.0)), truth.state)
    assert np.all(pos < 0.12) and np.all(vel < 0.04)


# --- bad input ------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"measurement": "lidar"}, "measurement model"),
        ({"dynamics": "magic"}, "dynamics model"),
        ({"discretization": "tustin"}, "discretization"),
        ({"output": "smoothed"}, "output"),
        ({"Q": np.eye(5)}, "Q must have shape 6x6"),
        ({"Q": -np.eye(6)}, "Q must be positive semidefinite"),
        ({"Q": np.triu(np.ones((6, 6)))}, "Q must be symmetric"),
        ({"R": np.zeros((3, 3))}, "R must be positive definite"),
        ({"R": np.eye(2)}, "R must have shape 3x3"),
        ({"P0": np.diag([1, 1, 1, 1, 1, -1.0])}, "P0 must be positive definite"),
        ({"sigma_range": 0.1}, "sigma_range applies only"),
        ({"measurement": "range_angles", "sigma_range": 0.0}, "sigma_range must be > 0"),
        ({"measurement": "range_angles", "sigma_angle": -1e-4}, "sigma_angle must be > 0"),
        ({"measurement": "range_angles", "C_bl": 2 * np.eye(3)}, "C_bl must be a rotation"),
        ({"scenario": "paper"}, "scenario"),
    ],
)
def test_bad_options(kwargs, match, short_scenario):
    kwargs = dict(kwargs)
    scenario = kwargs.pop("scenario", short_scenario)
    with pytest.raises(InputError, match=match):
        EKF(scenario, **kwargs)


def test_removed_options_are_rejected(short_scenario):
    # vectorized= and keep_covariance= are no longer options of EKF: every estimator is
    # batched (shares_covariance says whether the gains depend on the data) and the covariance
    # history is asked of estimate(keep_covariance=...)
    for option in ({"vectorized": True}, {"keep_covariance": False}):
        with pytest.raises(TypeError, match=next(iter(option))):
            EKF(short_scenario, **option)


def test_build_ekf_bad_options(short_scenario):
    sc = short_scenario
    with pytest.raises(InputError, match="known_input"):
        build_ekf(sc, known_input="yes")
    with pytest.raises(InputError, match="contradicts known_input"):
        build_ekf(sc, known_input=True, dynamics="unforced")
    with pytest.raises(InputError, match="contradicts known_input"):
        build_ekf(sc, known_input=False, dynamics="applied_thrust")
    assert build_ekf(sc, dynamics="control_law").name == "ekf_control_law"


def test_bad_estimate_arguments(short_scenario):
    sc = short_scenario
    ekf = EKF(sc)
    n1 = sc.n_steps + 1
    y, u = np.zeros((1, n1, 3)), np.zeros((1, n1, 3))
    with pytest.raises(InputError, match="y must have 3 measurement channels"):
        ekf.estimate(np.zeros((1, n1, 2)), u, sc.xhat0)
    with pytest.raises(InputError, match="u must have shape"):
        ekf.estimate(y, np.zeros((1, n1 - 1, 3)), sc.xhat0)
    # the thrust channels are checked where the thrust is used
    with pytest.raises(InputError, match="u must have 3 input channels"):
        build_ekf(sc, known_input=True).estimate(y, np.zeros((1, n1, 2)), sc.xhat0)
    with pytest.raises(InputError, match="xhat0 must have 6 entries"):
        ekf.estimate(y, u, np.zeros(5))
    with pytest.raises(InputError, match="y must have shape"):
        ekf.estimate(np.zeros((n1, 3)), u, sc.xhat0)
    known = build_ekf(sc, known_input=True)
    with pytest.raises(InputError, match="predict at step 0 needs u"):
        known.predict(known.update(known.start(sc.xhat0), y[:, 0])[0])


def test_bad_range_angle_arguments():
    x = np.ones((4, 6))
    with pytest.raises(InputError, match="rng"):
        range_angle_measurements(x, 0)
    with pytest.raises(InputError, match="sigma_range must be >= 0"):
        range_angle_measurements(x, np.random.default_rng(0), sigma_range=-1)
    # any state whose first three components are the position is accepted; fewer are not
    with pytest.raises(InputError, match="x must have shape"):
        range_angles(np.ones((4, 2)))
    with pytest.raises(InputError, match="zero relative position"):
        range_angles(np.zeros(6))
    with pytest.raises(InputError, match="sensor z axis"):
        range_angles_jacobian(np.array([0, 0, 5.0, 0, 0, 0]))
    with pytest.raises(InputError, match="m must have shape"):
        position_from_range_angles(np.ones((3, 2)))
