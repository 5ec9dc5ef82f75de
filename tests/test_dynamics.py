"""Dynamics models (hinfnav.systems.dynamics) and the planar range/bearing models (hinfnav.systems.planar).

Expected values: closed forms (the straight line at ω = 0, the exact
constant-turn map against RK4's fourth order, the covariance of the converted
reading on an axis), the finite-difference default against analytic
Jacobians, and identities (a LinearSystem through the protocol).
"""

from math import factorial

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import ExtendedKalmanFilter
from hinfnav.systems import (
    ConstantTurn,
    ContinuousDynamics,
    ConvertedRangeBearing,
    DiscreteDynamics,
    LinearMeasurement,
    LinearSystem,
    RangeBearing,
    StateSpec,
)
from hinfnav.systems.dynamics import _turn_coefficients, finite_difference_jacobian

CT = ConstantTurn(2.0, sigma_accel=0.1, sigma_turn_rate=1e-3)
OMEGAS = [0.0, 1e-12, -1e-7, 3e-3, -4e-3, 0.05, -0.3, 1.2]


def states(omegas=OMEGAS, seed=4):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.normal(0, 500, (len(omegas), 2)), rng.normal(0, 20, (len(omegas), 2)), omegas])


def turn_rate(x, u, t):
    """ẋ of the constant turn: (vx, vy, −ω vy, ω vx, 0)."""
    return np.column_stack([x[:, 2], x[:, 3], -x[:, 4] * x[:, 3], x[:, 4] * x[:, 2], np.zeros(len(x))])


def test_constant_turn_jacobian_equals_finite_differences():
    x = states()
    J = CT.jacobian(x)
    # central differences: truncation + rounding about 1e-9 relative at these scales (|x| ≤ 2e3)
    np.testing.assert_allclose(J, finite_difference_jacobian(CT.f, x), rtol=0, atol=1e-7)
    assert J.shape == (len(OMEGAS), 5, 5)


def test_constant_turn_at_zero_turn_rate_is_a_straight_line():
    x = states([0.0, 0.0])
    x1 = CT.f(x)
    T = CT.dt
    # closed form at ω = 0: p + T v, v unchanged
    np.testing.assert_array_equal(x1[:, :2], x[:, :2] + T * x[:, 2:4])
    np.testing.assert_array_equal(x1[:, 2:], x[:, 2:])
    # ∂p⁺/∂ω at ω = 0: (−T² vy/2, T² vx/2) (limit of (CT1)'s derivatives)
    J = CT.jacobian(x)
    np.testing.assert_allclose(J[:, 0, 4], -T * T * x[:, 3] / 2, rtol=1e-15)
    np.testing.assert_allclose(J[:, 1, 4], T * T * x[:, 2] / 2, rtol=1e-15)
    # continuity: ω = 1e-9 differs from the line by O(ω T² |v|) ≈ 1e-7 m
    xs = x.copy()
    xs[:, 4] = 1e-9
    assert np.abs(CT.f(xs) - x1).max() < 1e-6


def test_turn_rate_coefficients_against_their_full_series():
    # reference: the full Taylor series of sin(a)/a, (1 − cos a)/a and their derivatives (20 terms, exact in double
    # precision for |a| ≤ 1), on both sides of the switch between the truncated series and the closed form
    T = 2.0
    for a in (1e-8, 1e-4, 0.99e-2, 1.01e-2, 0.3, -0.7):
        s, c, ds, dc = _turn_coefficients(np.array([a / T]), T)
        ref_s = sum((-1) ** k * a ** (2 * k) / factorial(2 * k + 1) for k in range(20))
        ref_c = sum((-1) ** k * a ** (2 * k + 1) / factorial(2 * k + 2) for k in range(20))
        ref_ds = sum((-1) ** k * 2 * k * a ** (2 * k - 1) / factorial(2 * k + 1) for k in range(1, 20))
        ref_dc = sum((-1) ** k * (2 * k + 1) * a ** (2 * k) / factorial(2 * k + 2) for k in range(20))
        np.testing.assert_allclose([s[0], c[0]], [T * ref_s, T * ref_c], rtol=1e-14)
        # closed form just above the switch loses ~eps/a² to cancellation: 1e-10 relative
        np.testing.assert_allclose([ds[0], dc[0]], [T * T * ref_ds, T * T * ref_dc], rtol=1e-10)


def test_rk4_converges_to_the_exact_turn_at_fourth_order_and_its_jacobian_is_the_steps():
    x = states([0.0, 0.05, -0.3, 0.2])
    errs = []
    for sub in (4, 8):
        model = ContinuousDynamics(turn_rate, CT.state, CT.dt, CT.Q, substeps=sub)
        errs.append(np.abs(model.f(x) - CT.f(x)).max())
    # fourth order: halving the sub-step divides the error by about 2⁴ = 16
    assert 12 < errs[0] / errs[1] < 20
    analytic = ContinuousDynamics(turn_rate, CT.state, CT.dt, CT.Q, substeps=3, derivative_jacobian=lambda x, u, t:
                                  np.stack([np.broadcast_to(np.eye(5)[2], (len(x), 5)),
                                            np.broadcast_to(np.eye(5)[3], (len(x), 5)),
                                            np.column_stack([0 * x[:, 0], 0 * x[:, 0], 0 * x[:, 0], -x[:, 4], -x[:, 3]]),
                                            np.column_stack([0 * x[:, 0], 0 * x[:, 0], x[:, 4], 0 * x[:, 0], x[:, 2]]),
                                            np.zeros((len(x), 5))], axis=1))
    numeric = ContinuousDynamics(turn_rate, CT.state, CT.dt, CT.Q, substeps=3)
    # (D2) with the analytic ∂a/∂x is the exact derivative of the RK4 map: equal to its central differences
    np.testing.assert_allclose(analytic.jacobian(x), finite_difference_jacobian(analytic.f, x), atol=1e-8)
    np.testing.assert_allclose(analytic.jacobian(x), numeric.jacobian(x), atol=1e-8)
    np.testing.assert_allclose(analytic.jacobian(x), CT.jacobian(x), atol=1e-2)  # O(h⁴) from the exact map


def test_linear_system_follows_the_protocol():
    spec = StateSpec(("p", "v"), ("m", "m/s"))
    sys = LinearSystem(np.array([[1.0, 0.5], [0.0, 1.0]]), np.array([[0.1], [0.5]]), np.eye(2) * 0.1, 0.5, spec)
    x, u = np.array([[1.0, 2.0], [3.0, -1.0]]), np.array([[0.2], [-0.4]])
    assert sys.linear is True and sys.jacobian(x) is sys.Phi
    np.testing.assert_array_equal(sys.f(x, u, 1.0), x @ sys.Phi.T + u @ sys.Gamma.T)


def test_ekf_on_a_discrete_model_of_a_linear_system_equals_the_linear_ekf():
    # identity: the same map given as a function (with the finite-difference Jacobian) or as Φ
    spec = StateSpec(("p", "v"), ("m", "m/s"))
    sys = LinearSystem(np.array([[1.0, 0.5], [0.0, 1.0]]), np.zeros((2, 0)), np.eye(2) * 0.1, 0.5, spec)
    dyn = DiscreteDynamics(lambda x, u, t: x @ sys.Phi.T, spec, 0.5, sys.Q)
    meas = LinearMeasurement(np.array([[1.0, 0.0]]), np.array([[0.3]]))
    y = np.random.default_rng(1).standard_normal((2, 30, 1))
    u = np.zeros((2, 30, 0))
    a = ExtendedKalmanFilter(dyn, meas, P0=np.eye(2)).estimate(y, u, [0.0, 0.0])
    b = ExtendedKalmanFilter(sys, meas, P0=np.eye(2)).estimate(y, u, [0.0, 0.0])
    np.testing.assert_allclose(a.xhat, b.xhat, atol=1e-8)  # FD Jacobian of a linear map: exact to ~1e-10
    np.testing.assert_allclose(a.P, b.P, atol=1e-8)


def test_dynamics_refuse_bad_input():
    with pytest.raises(InputError, match=r"x must have shape \(runs, 5\)"):
        CT.f(np.zeros(5))
    with pytest.raises(InputError, match="x must contain only finite"):
        CT.jacobian(np.full((1, 5), np.nan))
    with pytest.raises(InputError, match="dt"):
        ConstantTurn(0.0, 0.1, 0.1)
    with pytest.raises(InputError, match="sigma_accel"):
        ConstantTurn(1.0, -0.1, 0.1)
    dyn = DiscreteDynamics(lambda x, u, t: x, CT.state, 1.0, CT.Q, n_input=2)
    with pytest.raises(InputError, match=r"u must have shape \(1, 2\)"):
        dyn.f(np.zeros((1, 5)), np.zeros((1, 3)))
    with pytest.raises(InputError, match="fun must be callable"):
        DiscreteDynamics(3.0, CT.state, 1.0, CT.Q)
    with pytest.raises(InputError, match="substeps"):
        ContinuousDynamics(turn_rate, CT.state, 1.0, CT.Q, substeps=0)


def test_range_bearing_model():
    sensor = RangeBearing(5, 2.0, 0.01, origin=(100.0, -50.0))
    x = states()
    np.testing.assert_allclose(sensor.jacobian(x), finite_difference_jacobian(lambda x, u, t: sensor.function(x), x),
                               atol=1e-9)
    np.testing.assert_allclose(sensor.inverse(sensor.function(x)), x[:, :2], atol=1e-9)  # (P3) inverts (P1)
    # bearing residual wrapped: π − 0.01 against −π + 0.01 is −0.02 rad, not 2π − 0.02
    np.testing.assert_allclose(sensor.residual([1.0, np.pi - 0.01], [1.0, -np.pi + 0.01]), [0.0, -0.02], atol=1e-12)
    # (P4) on the x axis (b = 0): J R Jᵀ = diag(σ_r², r² σ_b²), closed form
    np.testing.assert_allclose(sensor.position_covariance([1000.0, 0.0]), np.diag([4.0, 1000.0**2 * 1e-4]), rtol=1e-14)
    conv = ConvertedRangeBearing(sensor)
    np.testing.assert_array_equal(conv.function(x), x[:, :2])
    assert conv.linear and conv.noise_covariance(np.array([[1000.0, 0.0]])).shape == (1, 2, 2)
    with pytest.raises(InputError, match="position must be two"):
        RangeBearing(5, 1.0, 0.1, position=(0, 0))
    with pytest.raises(InputError, match="coincides with the sensor"):
        sensor.jacobian(np.array([[100.0, -50.0, 0, 0, 0]]))
    with pytest.raises(InputError, match="sensor must be a RangeBearing"):
        ConvertedRangeBearing(object())
