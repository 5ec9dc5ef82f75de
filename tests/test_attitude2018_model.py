"""Paper 002's attitude model: quaternion algebra, orbit rate, torque, Jacobians, error definition.

Expected values: identities of the quaternion algebra; SciPy's independent
``Rotation`` (scalar-last quaternions, active matrices: our passive A(q) is its
transpose); the printed ω_e of paper 002 (0.06148839356680 °/s); the torque
periods of the reference guide (975.8, 1463.7, 731.8 s); central finite
differences for every Jacobian; ``scipy.linalg.expm`` for Φ.
"""

import numpy as np
import pytest
import scipy.linalg
from scipy.spatial.transform import Rotation

from hinfnav.core.exceptions import InputError
from hinfnav.papers.attitude2018 import (
    PAPER_OMEGA_E_DEG_S,
    Scenario,
    orbit_rate,
    torque_periods,
)
from hinfnav.systems.attitude import (
    AttitudeSystem,
    StarSensorVectors,
    attitude_matrix,
    attitude_state_spec,
    cross,
    cross_matrix,
    euler321_from_quat,
    omega_matrix,
    quat_conjugate,
    quat_from_euler321,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    rotvec_from_quat,
)

RNG = np.random.default_rng(20180101)
Q = quat_normalize(RNG.standard_normal((5, 4)))
P = quat_normalize(RNG.standard_normal((5, 4)))
J = np.diag([15.0, 12.0, 10.0])


def test_attitude_matrix_is_scipy_rotation_transposed():
    # SciPy: as_matrix() rotates vectors (active); A(q) maps reference components to body (passive) = its transpose
    np.testing.assert_allclose(attitude_matrix(Q), np.transpose(Rotation.from_quat(Q).as_matrix(), (0, 2, 1)),
                               atol=1e-14)


def test_product_composes_attitude_matrices_and_inverts():
    np.testing.assert_allclose(attitude_matrix(quat_multiply(P, Q)), attitude_matrix(P) @ attitude_matrix(Q), atol=1e-14)
    np.testing.assert_allclose(quat_multiply(Q, quat_conjugate(Q)), np.tile([0, 0, 0, 1.0], (5, 1)), atol=1e-15)
    R3 = quat_normalize(RNG.standard_normal((5, 4)))
    np.testing.assert_allclose(quat_multiply(quat_multiply(P, Q), R3), quat_multiply(P, quat_multiply(Q, R3)), atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(quat_multiply(P, Q), axis=-1), 1.0, atol=1e-15)


def test_cross_helpers_match_numpy():
    a, b = RNG.standard_normal((2, 7, 3))
    np.testing.assert_allclose(cross(a, b), np.cross(a, b), atol=1e-14)
    np.testing.assert_allclose(cross_matrix(a) @ b[..., None], np.cross(a, b)[..., None], atol=1e-14)


def test_rotation_vector_and_euler_round_trips():
    v = RNG.standard_normal((5, 3)) * np.array([[1.0], [1e-3], [1e-6], [0.5], [2.0]])
    np.testing.assert_allclose(quat_from_rotvec(v), Rotation.from_rotvec(v).as_quat(), atol=1e-15)
    np.testing.assert_allclose(rotvec_from_quat(quat_from_rotvec(v)), v, atol=1e-14)
    ang = np.array([[0.1, -0.2, 0.3], [1e-5, 2e-5, -3e-5], [-1.0, 0.5, 2.5]])
    np.testing.assert_allclose(euler321_from_quat(quat_from_euler321(ang)), ang, atol=1e-13)
    # A = R1(φ) R2(θ) R3(ψ), frame rotations written out by hand
    phi, th, psi = ang[0]
    R1 = np.array([[1, 0, 0], [0, np.cos(phi), np.sin(phi)], [0, -np.sin(phi), np.cos(phi)]])
    R2 = np.array([[np.cos(th), 0, -np.sin(th)], [0, 1, 0], [np.sin(th), 0, np.cos(th)]])
    R3 = np.array([[np.cos(psi), np.sin(psi), 0], [-np.sin(psi), np.cos(psi), 0], [0, 0, 1]])
    np.testing.assert_allclose(attitude_matrix(quat_from_euler321(ang[0])), R1 @ R2 @ R3, atol=1e-14)


def test_kinematics_omega_matrix_and_attitude_rate():
    w = np.array([0.01, -0.02, 0.005])
    q = Q[0]
    np.testing.assert_allclose(omega_matrix(w) @ q, quat_multiply(np.append(w, 0.0), q), atol=1e-16)
    sysm = AttitudeSystem(J, dt=1e-3)
    x = np.concatenate([q, w, np.zeros(3)])[None]
    x1 = sysm.step(x)
    # Ȧ = −[ω×] A (body rate in body axes), to O(h)
    Adot = (attitude_matrix(x1[0, :4]) - attitude_matrix(q)) / 1e-3
    np.testing.assert_allclose(Adot, -cross_matrix(w) @ attitude_matrix(q), atol=1e-4)


def test_orbit_rate_of_a_650_km_orbit_matches_the_paper():
    # paper 002: ω_e = 0.06148839356680 °/s at 650 km; R_E = 6371 km, μ = 3.986006e14 m³/s² give it to 1e-10
    assert np.degrees(orbit_rate()) == pytest.approx(PAPER_OMEGA_E_DEG_S, rel=1e-7)
    # with μ = 3.986004418e14 (WGS-84) the difference would be 2.0e-7 relative: the paper used 3.986006e14
    assert abs(np.degrees(orbit_rate(mu=3.986004418e14)) / PAPER_OMEGA_E_DEG_S - 1) > 1.5e-7


def test_torque_periods_and_values():
    # reference guide: 975.8 s, 1463.7 s, 731.8 s
    np.testing.assert_allclose(torque_periods(), [975.8, 1463.7, 731.8], atol=0.05)
    sc = Scenario()
    t = np.array([0.0, 0.25 * torque_periods()[0]])
    np.testing.assert_allclose(sc.torque(t)[1, 0], -1e-5, rtol=1e-12)  # −T₀ sin(π/2)
    h = 1e-3
    np.testing.assert_allclose(sc.torque_rate(np.array([100.0])), (sc.torque(np.array([100 + h])) -
                               sc.torque(np.array([100 - h]))) / (2 * h), rtol=1e-6)
    assert sc.duration_s >= 2 * sc.orbital_period


def test_measurement_jacobians_against_finite_differences():
    meas = StarSensorVectors([[1.0, 0, 0], [0, 0, 1.0], [0.6, 0.8, 0]], 1e-5)
    x = np.concatenate([Q[1], [1e-3, 2e-3, -1e-3], [1e-5, 0, 0]])
    eps = 1e-7
    fd = np.stack([(meas.function(x + eps * e) - meas.function(x - eps * e)) / (2 * eps) for e in np.eye(10)], axis=-1)
    np.testing.assert_allclose(meas.jacobian(x), fd, atol=1e-8)
    fd9 = np.stack([(meas.function(AttitudeSystem.inject(x[None], eps * e[None]))[0]
                     - meas.function(AttitudeSystem.inject(x[None], -eps * e[None]))[0]) / (2 * eps) for e in np.eye(9)],
                   axis=-1)
    np.testing.assert_allclose(meas.error_jacobian(x), fd9, atol=1e-8)


def test_error_dynamics_against_finite_differences_and_expm():
    sysm = AttitudeSystem(J, dt=1e-3, h=np.array([0.1, 0.0, -0.05]))
    xhat = np.concatenate([Q[2], [0.02, -0.01, 0.03], [1e-4, -2e-4, 5e-5]])[None]
    F = sysm.error_dynamics(xhat)[0]
    spec = attitude_state_spec()
    for k in range(9):
        d = np.zeros(9)
        d[k] = 1e-6
        x = sysm.inject(xhat, d[None])
        e1 = spec.error(sysm.step(x), sysm.step(xhat))[0]
        # (e(h) − e(0))/h = F δ + O(h) + O(δ): relative 1e-3 of the column (h = 1e-3 s)
        np.testing.assert_allclose((e1 - d) / sysm.dt, F @ d, atol=2e-3 * np.abs(F @ d).max() + 1e-12)
    big = AttitudeSystem(J, dt=1.0, h=np.array([0.1, 0.0, -0.05]))
    A = big.error_dynamics(xhat)[0] * big.dt
    exact = scipy.linalg.expm(A)
    a = np.linalg.norm(A, 2)
    # third-order Taylor remainder bound ‖A‖⁴/4! e^‖A‖ (here ω is 300× the scenario's rates)
    assert np.linalg.norm(big.transition(xhat)[0] - exact, 2) <= a**4 / 24 * np.exp(a)
    np.testing.assert_allclose(big.transition(xhat, order=8)[0], exact, atol=1e-13)


def test_filter_mean_prediction_is_close_to_the_rk4_truth():
    sc = Scenario()
    sysm = sc.system()
    x = np.concatenate([quat_from_euler321([0.01, -0.01, 0.01]), [1e-4, -1e-4, 5e-5], [1e-5, -1e-5, 1e-5]])[None]
    u = np.array([[2e-5, 0, -1e-5]])
    err = attitude_state_spec().error(sysm.step(x, u), sysm.predict_mean(x, u))
    # second-order scheme vs RK4 over 1 s: far below a micro-radian (documented in predict_mean)
    assert np.all(np.abs(err) < 1e-9)


def test_error_definition():
    spec = attitude_state_spec()
    x = np.concatenate([Q[3], [1, 2, 3], [4, 5, 6]])
    np.testing.assert_array_equal(spec.error(x, x), np.zeros(9))
    small = np.array([1e-5, -2e-5, 3e-5])
    xt = np.concatenate([quat_multiply(quat_from_euler321(small), Q[3]), [1, 2, 3], [4, 5, 6]])
    np.testing.assert_allclose(spec.error(xt, x)[:3], small, rtol=1e-9)
    assert spec.n == 9 and spec.n_stored == 10 and spec.group_unit("attitude") == "rad"


def test_bad_inputs_name_the_parameter():
    with pytest.raises(InputError, match="references"):
        StarSensorVectors([[1.0, 0, 0], [2.0, 0, 0]], 1e-5)
    with pytest.raises(InputError, match="J"):
        AttitudeSystem(-np.eye(3), 1.0)
    with pytest.raises(InputError, match="orbits"):
        Scenario(orbits=-1.0)


def test_model_functions_do_not_depend_on_the_batch():
    # identity (same computation): a run's mean prediction, measurement, Jacobians and correction are bitwise
    # the same alone and in a batch (a 2-D `a @ B` rounds differently for one row than for several)
    sc = Scenario()
    sysm, meas = sc.system(), sc.measurement
    rng = np.random.default_rng(5)
    x = np.concatenate([rng.normal(size=(7, 4)), 1e-4 * rng.normal(size=(7, 3)), 1e-5 * rng.normal(size=(7, 3))], axis=1)
    x[:, :4] /= np.linalg.norm(x[:, :4], axis=1, keepdims=True)
    u, dx = 1e-5 * rng.normal(size=(7, 3)), 1e-4 * rng.normal(size=(7, 9))
    maps = {"predict_mean": lambda s: sysm.predict_mean(x[s], u[s]), "step": lambda s: sysm.step(x[s], u[s]),
            "transition": lambda s: sysm.transition(x[s]), "inject": lambda s: sysm.inject(x[s], dx[s]),
            "function": lambda s: meas.function(x[s]), "error_jacobian": lambda s: meas.error_jacobian(x[s])}
    for name, f in maps.items():
        whole = f(slice(None))
        for r in (0, 6):
            np.testing.assert_array_equal(f(slice(r, r + 1))[0], whole[r], err_msg=name)
