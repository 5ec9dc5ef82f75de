"""The EKF and the sigma-point filter compiled on a model's own numba functions (hinfnav.systems.compiled).

Every compiled run is compared with the NumPy path (``backend="numpy"``, the
reference: the filters' own step loops) on the same data: estimates,
covariances and the NIS inputs (innovation, S) to 1e-10 relative (each state
channel over its largest |x̂|, the covariance over the outer product of its
largest standard deviations). Models: the README's constant-turn target with a
range/bearing sensor, Sun's chaser (a LinearSystem, Hill) with a
range/azimuth/elevation sensor, a linear model with missing readings, and a
pendulum written here with ``numba.njit`` functions, as a user would.
"""

import numba
import numpy as np
import pytest

import hinfnav as hn
from hinfnav.estimators import ExtendedKalmanFilter, SigmaPointFilter, StrongTrackingEKF
from hinfnav.estimators.base import check_estimator_inputs
from hinfnav.estimators.compiled import run_compiled, why_numpy
from hinfnav.systems import ConstantTurn, DiscreteDynamics, DynamicsModel, MeasurementModel, RangeAzimuthElevation, \
    RangeBearing, StateSpec
from hinfnav.systems.compiled import CompiledDynamics, CompiledMeasurement

NIS = ("innovation", "innovation_covariance")


def _assert_same(ref, got, what, innovation_atol=0.0):
    """got equals ref (the NumPy path) to 1e-10 relative: estimates per channel, P by its scale, NIS inputs (or
    the innovation within ``innovation_atol``)."""
    scale = np.abs(ref.xhat).max(axis=(0, 1))
    err = float(np.max(np.abs(got.xhat - ref.xhat) / scale))
    assert err <= 1e-10, f"{what}: estimates differ by {err:.1e}"
    if ref.P is not None:
        d = np.sqrt(np.abs(np.diagonal(ref.P, axis1=-2, axis2=-1)).max(axis=(0, 1)))
        err = float(np.max(np.abs(got.P - ref.P) / np.outer(d, d)))
        assert err <= 1e-10, f"{what}: covariances differ by {err:.1e}"
    for key in ref.diagnostics:
        r, g = ref.diagnostics[key], got.diagnostics[key]
        assert g.shape == r.shape, (what, key)
        np.testing.assert_array_equal(np.isnan(g), np.isnan(r), err_msg=f"{what} {key}")
        ok = ~np.isnan(r)
        if key == "innovation" and innovation_atol:
            assert float(np.max(np.abs(g[ok] - r[ok]))) <= innovation_atol, what
            continue
        err = float(np.max(np.abs(g[ok] - r[ok])) / np.abs(r[ok]).max())
        assert err <= 1e-10, f"{what} {key}: differs by {err:.1e}"


def _both(est, y, u, x0, **kw):
    """(NumPy reference, default backend) of one estimator; the default must be the compiled path, and the kernel
    must run to its end (a kernel that fails hands the batch back to the NumPy path silently)."""
    assert why_numpy(est, set(kw.get("diagnostics", ()))) is None, why_numpy(est)
    yc, uc, xc = check_estimator_inputs(y, u, x0, est.n_state, est.measurement.n_meas,
                                        est.n_input if est.uses_input else None, est.missing)
    assert run_compiled(est, yc, uc, xc, None, False)[0] is not None, f"{est.name}: the kernel did not finish"
    return est.estimate(y, u, x0, backend="numpy", **kw), est.estimate(y, u, x0, **kw)


@pytest.fixture(scope="module")
def turn():
    """The README's own-model example: constant turn (5 states), range/bearing (2 channels), 3 runs × 150 steps."""
    model = ConstantTurn(dt=1.0, sigma_accel=0.05, sigma_turn_rate=1e-3)
    sensor = RangeBearing(model.n, sigma_range=5.0, sigma_bearing=0.01, origin=(100.0, -50.0))
    x0, P0 = np.array([-1500.0, 400.0, 0.0, -15.0, 0.03]), np.diag([50, 50, 5, 5, 0.02]) ** 2.0
    rng = np.random.default_rng(7)
    x = [np.broadcast_to(x0, (3, 5))]
    for _ in range(149):
        x.append(model.step(x[-1], w=rng.standard_normal((3, 5))))
    y = sensor.measure(np.stack(x, 1), rng.standard_normal((3, 150, 2)))
    return model, sensor, x0, P0, y, np.zeros((3, 150, 0))


def test_constant_turn_ekf_and_sigma_point_compiled_equal_numpy(turn):
    model, sensor, x0, P0, y, u = turn
    ekf = ExtendedKalmanFilter(model, sensor, P0=P0)
    for est in (ekf, SigmaPointFilter.from_ekf(ekf), SigmaPointFilter.from_ekf(ekf, rule="cubature"),
                SigmaPointFilter.from_ekf(ekf, alpha=0.5, kappa=1.0),
                ExtendedKalmanFilter(model, sensor, P0=P0, output="predicted"),
                SigmaPointFilter(model, sensor, P0=P0, output="predicted")):
        ref, got = _both(est, y, u, x0, diagnostics=NIS)
        _assert_same(ref, got, f"{est.name} {getattr(est, 'rule', '')}")
        for keep in (False, "diagonal"):
            ref, got = _both(est, y[:1, :40], u[:1, :40], x0, keep_covariance=keep)
            assert (got.P is None) == (keep is False)
            _assert_same(ref, got, f"{est.name} keep={keep}")


def test_missing_readings_skipped_on_the_compiled_path(turn):
    model, sensor, x0, P0, y, u = turn
    y = y.copy()
    y[0, 5:9, 1] = np.nan  # a channel missing in one run only
    y[1, 20, :] = np.nan  # a whole reading missing
    y[:, 30, 0] = np.nan  # a channel missing in every run
    ekf = ExtendedKalmanFilter(model, sensor, P0=P0, missing="skip")
    for est in (ekf, SigmaPointFilter(model, sensor, P0=P0, missing="skip")):
        ref, got = _both(est, y, u, x0, diagnostics=NIS)
        _assert_same(ref, got, f"{est.name} missing")
    # a linear model (the chaser's kernels need missing='refuse'): missing readings on the model kernels
    A = np.array([[1.0, 1.0], [0.0, 1.0]])
    lin = hn.LinearSystem(A, np.zeros((2, 0)), [[0.05], [0.1]], 1.0, StateSpec(("x", "v"), ("m", "m/s")))
    meas = hn.LinearMeasurement([[1.0, 0.0]], [[0.5]])
    rng = np.random.default_rng(3)
    yl = rng.standard_normal((4, 60, 1))
    yl[1, 10:13] = np.nan
    est = ExtendedKalmanFilter(lin, meas, P0=np.eye(2), missing="skip")
    _assert_same(*_both(est, yl, np.zeros((4, 60, 0)), np.zeros(2), diagnostics=NIS), "linear missing")


def test_range_azimuth_elevation_on_the_chaser_is_compiled():
    # Sun's chaser (Hill's relative motion, a LinearSystem with thrust input) seen by a range/azimuth/elevation
    # sensor (7): the linear kernels do not apply (h is not linear), the model kernels do
    import hinfnav.papers  # noqa: F401 - registers the papers' estimators
    from hinfnav.estimators import build_estimator
    from hinfnav.papers.sun2011 import Scenario

    base = build_estimator(Scenario(duration_s=10.0, rms_window_s=(0.0, 10.0)), "ekf_known_input")
    sensor = RangeAzimuthElevation(6, sigma_range=1.0, sigma_angle=1e-3)
    rng = np.random.default_rng(11)
    steps, runs = 100, 2
    x = np.empty((runs, steps, 6))
    x[:, 0] = [-2000.0, 300.0, 150.0, 1.0, -0.5, 0.2]
    u = 0.01 * rng.standard_normal((runs, steps, base.system.n_input))
    for k in range(steps - 1):
        x[:, k + 1] = base.system.propagate(x[:, k], u[:, k])
    y = sensor.measure(x, rng.standard_normal((runs, steps, 3)))
    ekf = ExtendedKalmanFilter(base.system, sensor, P0=base.P0, Q=base.Q, uses_input=True)
    for est in (ekf, SigmaPointFilter.from_ekf(ekf)):
        _assert_same(*_both(est, y, u, x[0, 0], diagnostics=NIS), f"{est.name} range/az/el")


# -- a model of one's own: a pendulum, θ̈ = −(g/ℓ) sin θ (explicit Euler over Δt), its bob's position measured ---

@numba.njit(cache=True)
def pendulum_f(x, u, t, p):  # p = (Δt, g/ℓ)
    out = np.empty(2)
    out[0] = x[0] + p[0] * x[1]
    out[1] = x[1] - p[0] * p[1] * np.sin(x[0])
    return out


@numba.njit(cache=True)
def pendulum_jacobian(x, u, t, p):
    J = np.empty((2, 2))
    J[0, 0], J[0, 1] = 1.0, p[0]
    J[1, 0], J[1, 1] = -p[0] * p[1] * np.cos(x[0]), 1.0
    return J


@numba.njit(cache=True)
def bob_h(x, p):  # p = (ℓ,)
    out = np.empty(2)
    out[0], out[1] = p[0] * np.sin(x[0]), -p[0] * np.cos(x[0])
    return out


@numba.njit(cache=True)
def bob_jacobian(x, p):
    H = np.zeros((2, 2))
    H[0, 0], H[1, 0] = p[0] * np.cos(x[0]), p[0] * np.sin(x[0])
    return H


class Pendulum(DynamicsModel):
    """θ, ω (rad, rad/s); one explicit Euler step of Δt."""

    def __init__(self, dt, g_over_l, q):
        super().__init__(StateSpec(("theta", "omega"), ("rad", "rad/s")), dt, np.diag([0.0, q]))
        self.g_over_l = g_over_l

    def f(self, x, u=None, t=0.0):
        x = np.asarray(x, dtype=float)
        return np.stack([x[:, 0] + self.dt * x[:, 1], x[:, 1] - self.dt * self.g_over_l * np.sin(x[:, 0])], axis=-1)

    def jacobian(self, x, u=None, t=0.0):
        x = np.asarray(x, dtype=float)
        J = np.zeros((x.shape[0], 2, 2))
        J[:, 0, 0], J[:, 0, 1], J[:, 1, 1] = 1.0, self.dt, 1.0
        J[:, 1, 0] = -self.dt * self.g_over_l * np.cos(x[:, 0])
        return J

    def compiled_functions(self):
        return CompiledDynamics(pendulum_f, pendulum_jacobian, [self.dt, self.g_over_l])


class Bob(MeasurementModel):
    """The bob's position (ℓ sin θ, −ℓ cos θ), m."""

    def __init__(self, length, sigma):
        super().__init__(2, sigma * np.eye(2), ("x", "z"), ("m", "m"))
        self.length = length

    def function(self, x):
        x = np.asarray(x, dtype=float)
        return np.stack([self.length * np.sin(x[..., 0]), -self.length * np.cos(x[..., 0])], axis=-1)

    def jacobian(self, x):
        x = np.asarray(x, dtype=float)
        H = np.zeros(x.shape[:-1] + (2, 2))
        H[..., 0, 0], H[..., 1, 0] = self.length * np.cos(x[..., 0]), self.length * np.sin(x[..., 0])
        return H

    def compiled_functions(self):
        return CompiledMeasurement(bob_h, bob_jacobian, None, [self.length])


@pytest.fixture(scope="module")
def swing():
    model, sensor = Pendulum(0.01, 9.81 / 2.0, 1e-6), Bob(2.0, 0.02)
    rng = np.random.default_rng(5)
    x = [np.array([[1.0, 0.0], [0.5, 0.3]])]
    for _ in range(299):
        x.append(model.step(x[-1], w=rng.standard_normal((2, 2))))
    y = sensor.measure(np.stack(x, 1), rng.standard_normal((2, 300, 2)))
    return model, sensor, y, np.zeros((2, 300, 0))


def test_a_users_numba_model_gets_the_compiled_path(swing):
    model, sensor, y, u = swing
    ekf = ExtendedKalmanFilter(model, sensor, P0=np.diag([0.1, 0.1]))
    for est in (ekf, SigmaPointFilter.from_ekf(ekf)):
        ref, got = _both(est, y, u, np.array([0.9, 0.0]), diagnostics=NIS)
        _assert_same(ref, got, f"pendulum {est.name}")
        est.estimate(y, u, np.array([0.9, 0.0]), backend="numba")  # no InputError: the kernel fits


def test_a_plain_python_model_runs_numpy_and_says_why(swing):
    model, sensor, y, u = swing
    plain = DiscreteDynamics(lambda x, u, t: model.f(x), model.state, model.dt, model.Q,
                             jacobian=lambda x, u, t: model.jacobian(x))
    est = ExtendedKalmanFilter(plain, sensor, P0=np.diag([0.1, 0.1]))
    assert "declares no compiled functions" in why_numpy(est)
    with pytest.raises(hn.InputError, match="backend='numba' is not available"):
        est.estimate(y, u, np.array([0.9, 0.0]), backend="numba")
    np.testing.assert_array_equal(est.estimate(y, u, np.array([0.9, 0.0])).xhat,
                                  est.estimate(y, u, np.array([0.9, 0.0]), backend="numpy").xhat)

    class Faster(Pendulum):  # changes f, inherits compiled_functions: not trusted
        def f(self, x, u=None, t=0.0):
            return 2.0 * super().f(x, u, t)

    est = ExtendedKalmanFilter(Faster(0.01, 4.9, 1e-6), sensor, P0=np.eye(2))
    assert "overrides f" in why_numpy(est)
    # strong tracking on a nonlinear model: no compiled route (the reason is given)
    est = StrongTrackingEKF(model, sensor, P0=np.eye(2))
    assert "linear model only" in why_numpy(est)


def test_compiled_functions_that_disagree_with_numpy_are_refused(swing):
    model, sensor, y, u = swing

    class Wrong(Pendulum):
        def compiled_functions(self):
            return CompiledDynamics(pendulum_f, pendulum_jacobian, [self.dt, 1.01 * self.g_over_l])

    est = ExtendedKalmanFilter(Wrong(0.01, 4.9, 1e-6), sensor, P0=np.eye(2))
    with pytest.raises(hn.InputError, match="compiled f of Wrong differs from its NumPy function"):
        est.estimate(y, u, np.array([0.9, 0.1]))
    with pytest.raises(hn.InputError, match="numba.njit"):
        CompiledDynamics(lambda x, u, t, p: x, pendulum_jacobian)


def test_a_singular_point_raises_the_numpy_paths_error(turn):
    model, sensor, x0, P0, y, u = turn
    est = ExtendedKalmanFilter(model, sensor, P0=P0)
    at_sensor = np.array([100.0, -50.0, 1.0, 1.0, 0.01])  # zero range: the bearing has no derivative
    with pytest.raises(hn.HinfnavError, match="singular point") as numpy_error:
        est.estimate(y[:1, :5], u[:1, :5], at_sensor, backend="numpy")
    with pytest.raises(hn.HinfnavError, match="singular point") as default_error:
        est.estimate(y[:1, :5], u[:1, :5], at_sensor)
    assert str(default_error.value) == str(numpy_error.value)


def test_grace_two_body_j2_ekf_compiled_equals_numpy():
    # the GRACE chapter's EKF whose mean goes through the two-body (+ J2) pair model (one RK4 step of both
    # spacecraft from GRACE-B's tabulated state), its covariance through Hill's Φ: its PairPrediction model declares
    # numba functions; 150 epochs of the real data with gaps (missing='skip'), against the NumPy path
    from hinfnav.papers.grace2010 import filters as grace
    from hinfnav.papers.grace2010.dataset import load
    from hinfnav.papers.grace2010.measurements import make_measurements
    from hinfnav.systems.hill import hill_system

    data = load()
    ms = make_measurements(data, "gnss", seed=0)
    Q = 1e-4 * np.eye(6)
    sys_hill = hill_system(data.orbital_rate, 1.0, grace.DT_S, np.linalg.cholesky(Q))
    n = 150
    y = np.where(ms.available[:n, None], ms.y[:n], np.nan)[None]
    # the prediction subtracts inertial positions of |r| = 6.8e6 m to form Hill offsets of ~1e5 m: the two paths'
    # orders of sums differ by an ulp of |r| (9.3e-10 m; measured: estimates 9e-10 m, innovations 1.4e-9 m apart, 4 m
    # at most): the estimates meet 1e-10 relative, the innovations are compared to 4 ulps of |r| (3.7e-9 m)
    ulp = float(np.spacing(np.linalg.norm(data.rB[0])))
    for model in ("two_body_j2", "two_body"):
        est = grace.CompiledNonlinearPredictionEKF(sys_hill, ms.model, chief=(data.rB, data.vB), model=model,
                                                   P0=np.diag(grace.P0_STD**2), Q=Q, missing="skip")
        _assert_same(*_both(est, y, np.zeros((1, n, est.n_input)), data.truth[0], diagnostics=NIS), model,
                     innovation_atol=4 * ulp)
