"""Strong tracking on the EKF core: a linear system or any dynamics model (issue 17, item 1).

The mixin :class:`~hinfnav.estimators.StrongTracking` is written once on the
hook ``complete_prior`` that both Kalman cores call. Expected values:

* on the constant-turn target, an independent step-by-step computation: the
  fading factor of Zhou, Xi & Zhang (1991) as documented in
  ``hinfnav/estimators/adaptive.py`` (S1)-(S4) with a = 1 (one common λ),
  written here with plain numpy from its formulas, and filterpy's
  ``ExtendedKalmanFilter.update`` for the Joseph update (tolerance 1e-10
  relative: two implementations of the same arithmetic);
* on a linear system, the augmented core's strong tracking
  (:class:`~hinfnav.estimators.AugmentedInputSTKF`) on the same model
  written as an EKF of the augmented system [x; u] (same Φ, Q, H, R, P₀):
  the same filter, so equal to 1e-9 relative (rounding: the augmented core
  symmetrises P⁺, the EKF does not).
"""

import numpy as np
import pytest
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEKF
from test_missing_readings import C, D, P0, SYSTEM, X0, measurement, small_data

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import AugmentedInputSTKF, HuberCorrection, StrongTrackingEKF
from hinfnav.systems import ConstantTurn, LinearMeasurement, LinearSystem, StateSpec

STEPS = 40


def _turn_data(seed=5):
    model = ConstantTurn(1.0, sigma_accel=0.1, sigma_turn_rate=1e-3)
    meas = LinearMeasurement(np.eye(2, 5), 3.0 * np.eye(2))
    rng = np.random.default_rng(seed)
    x = np.array([[0.0, 0.0, 10.0, 0.0, 0.05]])
    ys = []
    for k in range(STEPS):
        ys.append(x[0, :2] + 3.0 * rng.standard_normal(2))
        x = model.f(x)
        if k == 15:  # a manoeuvre the model does not know: the turn rate jumps
            x[0, 4] = -0.15
    return model, meas, np.array(ys)[None]


X0_CT = np.array([1.0, -1.0, 9.0, 0.5, 0.03])
P0_CT = np.diag([25.0, 25.0, 4.0, 4.0, 1e-3])


def test_strong_tracking_ekf_on_a_constant_turn_equals_a_hand_computation():
    model, meas, y = _turn_data()
    rho, beta = 0.9, 1.5
    hist = StrongTrackingEKF(model, meas, P0=P0_CT, rho=rho, beta=beta).estimate(
        y, np.zeros((1, STEPS, 0)), X0_CT, diagnostics=True)

    H, R, Q = meas.H, meas.R, model.Q
    f = FilterpyEKF(dim_x=5, dim_z=2)
    f.x, f.P, f.R = X0_CT.copy(), P0_CT.copy(), R
    ref, lams, V0 = [], [1.0], None
    for k in range(STEPS):
        if k > 0:
            F = model.jacobian(f.x[None])[0]  # at x̂(k−1|k−1)
            FPF = F @ f.P @ F.T
            x_pred = model.f(f.x[None])[0]
            g = y[0, k] - H @ x_pred
            V0 = np.outer(g, g) if V0 is None else (rho * V0 + np.outer(g, g)) / (1 + rho)  # (S1)
            N = V0 - beta * R - H @ Q @ H.T  # (S2)
            M = FPF @ H.T @ H
            lam = max(1.0, np.trace(N) / np.trace(M))  # (S3), a = 1
            lams.append(lam)
            f.x, f.P = x_pred, lam * FPF + Q  # (S4): with one λ, Λ^½ FPFᵀ Λ^½ = λ FPFᵀ
        f.update(y[0, k], lambda s: H, lambda s: H @ s)
        ref.append(f.x.copy())
    np.testing.assert_allclose(hist.xhat[0], np.array(ref), rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(hist.diagnostics["fading"][0], np.repeat(np.array(lams)[:, None], 5, axis=1),
                               rtol=1e-10)
    assert max(lams) > 2.0  # the manoeuvre is seen: the fading is active, not a plain EKF


def test_strong_tracking_ekf_equals_the_augmented_core_on_a_linear_system():
    y, u = small_data()
    Q_input = 0.01 * np.eye(2)
    aug = AugmentedInputSTKF(SYSTEM, measurement([0, 1, 2]), Q_input=Q_input, P0=P0, P0_input=np.eye(2), rho=0.9,
                             beta=1.2)
    ref = aug.estimate(y, u, X0, diagnostics=True)
    # the same filter as an EKF of the augmented system [x; u]: Φ_a = [[Φ, Γ], [0, I]], Q_a = diag(Q, Δt Q_u)
    n, m = 4, 2
    Phi_a = np.block([[SYSTEM.Phi, SYSTEM.Gamma], [np.zeros((m, n)), np.eye(m)]])
    Q_a = np.block([[SYSTEM.Q, np.zeros((n, m))], [np.zeros((m, n)), SYSTEM.dt * Q_input]])
    spec = StateSpec(labels=["x", "y", "vx", "vy", "ux", "uy"], units=["m", "m", "m/s", "m/s", "m/s2", "m/s2"])
    sys_a = LinearSystem(Phi_a, np.zeros((n + m, m)), np.zeros((n + m, 1)), SYSTEM.dt, spec)
    meas_a = LinearMeasurement(np.hstack([C, np.zeros((3, m))]), D)
    P0_a = np.block([[P0, np.zeros((n, m))], [np.zeros((m, n)), np.eye(m)]])
    ekf = StrongTrackingEKF(sys_a, meas_a, P0=P0_a, Q=Q_a, rho=0.9, beta=1.2)
    got = ekf.estimate(y, u, np.concatenate([X0, np.zeros(m)]), diagnostics=True)
    np.testing.assert_allclose(got.xhat[..., :n], ref.xhat, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(got.xhat[..., n:], ref.diagnostics["input_estimate"], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(got.diagnostics["fading"], ref.diagnostics["fading"], rtol=1e-9)
    assert ref.diagnostics["fading"].max() > 1.0


def test_huber_times_strong_tracking_on_the_ekf_core_and_a_missing_reading():
    model, meas, y = _turn_data()
    u = np.zeros((1, STEPS, 0))

    class HuberSTEKF(HuberCorrection, StrongTrackingEKF):
        pass

    st = StrongTrackingEKF(model, meas, P0=P0_CT, rho=0.9).estimate(y, u, X0_CT, diagnostics=True)
    # γ no whitened residual reaches: Huber's minimiser is the least-squares (Kalman) one (Karlgaard & Schaub
    # 2007, ψ = 1), so the combination equals strong tracking; 1e-8: (MᵀM)⁻¹ against the Joseph form
    hst = HuberSTEKF(model, meas, P0=P0_CT, rho=0.9, gamma=1e9).estimate(y, u, X0_CT, diagnostics=True)
    np.testing.assert_allclose(hst.xhat, st.xhat, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(hst.diagnostics["fading"], st.diagnostics["fading"], rtol=1e-8)
    # a fully missing reading (missing="skip"): no update, λ = 1 there (a prediction only), finite after
    y_gap = y.copy()
    y_gap[0, 20] = np.nan
    gap = StrongTrackingEKF(model, meas, P0=P0_CT, rho=0.9, missing="skip").estimate(y_gap, u, X0_CT,
                                                                                     diagnostics=True)
    assert np.all(np.isfinite(gap.xhat))
    np.testing.assert_array_equal(gap.diagnostics["fading"][0, 20], 1.0)
    np.testing.assert_allclose(gap.xhat[0, :20], st.xhat[0, :20], rtol=1e-12, atol=1e-12)


def test_strong_tracking_ekf_refuses_bad_parameters():
    model, meas, _ = _turn_data()
    with pytest.raises(InputError, match="rho"):
        StrongTrackingEKF(model, meas, P0=P0_CT, rho=1.5)
    with pytest.raises(InputError, match="prior weights"):
        StrongTrackingEKF(model, meas, P0=P0_CT, a=[1.0, 1.0])
    ekf = StrongTrackingEKF(model, meas, P0=P0_CT, rho=[0.9, 0.95])
    with pytest.raises(InputError, match="rho"):
        ekf.start(X0_CT, runs=3)
