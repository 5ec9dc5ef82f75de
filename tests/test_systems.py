"""Model identities of Sections 1 and 4 of the paper (hinfnav.systems, hinfnav.core.linalg)."""

import numpy as np
import pytest
import scipy.linalg

from hinfnav.core import InputError, discretize, spectral_radius
from hinfnav.systems import (
    UncertainSystem,
    delta_A1,
    hill_matrices,
    hill_system,
    measurement_matrix,
    position_measurement,
    uncertainty_F,
    uncertainty_structure,
)

W0 = 7.2722e-5


def test_hill_matrix_entries():
    # expected values: equation (1)-(2) of the paper, written out by hand
    A0, G0 = hill_matrices(W0, 1000.0)
    assert A0[3, 0] == pytest.approx(3 * W0**2, rel=1e-15)
    assert A0[3, 4] == pytest.approx(2 * W0, rel=1e-15)
    assert A0[4, 3] == pytest.approx(-2 * W0, rel=1e-15)
    assert A0[5, 2] == pytest.approx(-(W0**2), rel=1e-15)
    np.testing.assert_array_equal(A0[:3, 3:], np.eye(3))
    np.testing.assert_allclose(G0[3:], np.eye(3) / 1000.0, rtol=0, atol=0)
    # only these entries are non-zero: 3 (kinematics) + 4 (Hill terms)
    assert np.count_nonzero(A0) == 7


def test_hill_continuous_eigenvalues_closed_form():
    # closed form: the Hill (CW) model has eigenvalues 0, 0, ±iω, ±iω
    A0, _ = hill_matrices(W0, 1000.0)
    ev = np.sort_complex(np.linalg.eigvals(A0))
    np.testing.assert_allclose(np.sort(np.abs(ev.imag)), [0, 0, W0, W0, W0, W0], atol=1e-9)
    np.testing.assert_allclose(ev.real, 0, atol=1e-9)


@pytest.mark.parametrize("delta_bar", [0.01, 0.05, 0.5, 1.0, 5.0])
def test_norm_bounded_structure_holds_on_a_delta_grid(delta_bar):
    # identity (10)-(11) of Section 4: ΔA₁(δ) = H_a F(δ) E_a and ‖F‖ ≤ 1 for |δ| ≤ δ̄;
    # ΔA₁ itself is checked against A₀(ω₀(1+δ)) − A₀(ω₀) (definition (4)-(5))
    H, E = uncertainty_structure(W0, delta_bar)
    A1, _ = hill_matrices(W0, 1000.0)
    for delta in np.linspace(-delta_bar, delta_bar, 41):
        F = uncertainty_F(delta, delta_bar)
        dA = delta_A1(W0, delta)
        Aw, _ = hill_matrices(W0 * (1 + delta), 1000.0)
        np.testing.assert_allclose(dA, Aw - A1, rtol=1e-12, atol=1e-22)
        np.testing.assert_allclose(H @ F @ E, dA, rtol=1e-13, atol=1e-22)
        assert np.linalg.norm(F, 2) <= 1 + 1e-12
    # the bound is reached at the vertex δ = δ̄ (so the structure is not conservative there)
    assert np.linalg.norm(uncertainty_F(delta_bar, delta_bar), 2) == pytest.approx(1.0, abs=1e-14)


def test_uncertainty_F_rejects_delta_outside_bound():
    with pytest.raises(InputError, match="delta must satisfy"):
        uncertainty_F(0.2, 0.1)
    with pytest.raises(InputError, match="delta_bar must be > 0"):
        uncertainty_F(0.0, 0.0)
    with pytest.raises(InputError, match="delta_bar must be >= 0"):
        uncertainty_structure(W0, -0.1)


def test_euler_versus_exact_discretization(scenario):
    # Taylor series: e^{AT} = I + AT + A²T²/2 + O(T³), ∫e^{As}ds G = TG + AGT²/2 + O(T³)
    s = scenario
    A0, G0 = hill_matrices(W0, 1000.0)
    Ac = A0 + G0 @ s.K
    for T in (0.1, 0.01):
        Pe, Ge = discretize(A0, G0, T, "euler")
        Px, Gx = discretize(A0, G0, T, "exact")
        np.testing.assert_allclose(Pe, np.eye(6) + T * A0, rtol=0, atol=0)
        np.testing.assert_allclose(Px - Pe, A0 @ A0 * T**2 / 2, rtol=0, atol=T**3)
        np.testing.assert_allclose(Gx - Ge, A0 @ G0 * T**2 / 2, rtol=0, atol=T**3 * 1e-3)
    # closed loop with the paper's gain: the one-step Euler error is T²/2·A_cl² to within
    # 1 % (Taylor), largest entry T²/2·|K₃₆/m| = 0.005 × 0.02428 = 1.21e-4 (z axis)
    Pe, _ = discretize(Ac, np.zeros((6, 1)), 0.1, "euler")
    Px, _ = discretize(Ac, np.zeros((6, 1)), 0.1, "exact")
    np.testing.assert_allclose(Px, scipy.linalg.expm(Ac * 0.1), rtol=1e-13, atol=1e-15)
    second = Ac @ Ac * 0.1**2 / 2
    assert np.max(np.abs(Px - Pe - second)) < 0.01 * np.max(np.abs(second))
    assert np.max(np.abs(Px - Pe)) == pytest.approx(0.005 * 24.2818e-3, rel=0.01)


def test_euler_discretization_matches_design_model(scenario):
    # (6): A = I + T(A₁ + G₀K), computed two ways
    s = scenario
    A0, G0 = hill_matrices(s.omega0, s.mass)
    Pe, Ge = discretize(A0, G0, s.dt, "euler")
    np.testing.assert_allclose(s.design_model().A, Pe + Ge @ s.K, rtol=1e-15, atol=1e-17)


def test_discretize_bad_input():
    with pytest.raises(InputError, match="Ac must be square"):
        discretize(np.ones((2, 3)), np.ones((2, 1)), 0.1)
    with pytest.raises(InputError, match="Gc must have shape 2xany"):
        discretize(np.eye(2), np.ones((3, 1)), 0.1)
    with pytest.raises(InputError, match="dt must be > 0"):
        discretize(np.eye(2), np.ones((2, 1)), 0.0)
    with pytest.raises(InputError, match="unknown discretization method 'rk4'"):
        discretize(np.eye(2), np.ones((2, 1)), 0.1, "rk4")
    with pytest.raises(InputError, match="NaN or inf"):
        discretize(np.array([[np.nan]]), np.ones((1, 1)), 0.1)


def test_uncertain_system_validation(scenario):
    s = scenario.design_model()
    with pytest.raises(InputError, match="B must have shape 6xany"):
        UncertainSystem(s.A, np.ones((5, 2)), s.C, s.D, s.L)
    with pytest.raises(InputError, match="H and E must be given together"):
        UncertainSystem(s.A, s.B, s.C, s.D, s.L, H=s.H)
    with pytest.raises(InputError, match="A must contain only finite"):
        UncertainSystem(np.full((6, 6), np.inf), s.B, s.C, s.D, s.L)
    with pytest.raises(InputError, match="E must have shape 6x6"):
        UncertainSystem(s.A, s.B, s.C, s.D, s.L, H=s.H, E=np.ones((2, 6)))


def test_closed_loop_is_schur_stable_and_open_loop_is_not(scenario):
    # closed loop ρ(I + T(A₁+G₀K)) = 0.99904 (< 1); open loop ρ(I + T A₁) = |1 + iωT| > 1
    s = scenario
    assert spectral_radius(s.design_model().A) == pytest.approx(0.999039, abs=1e-6)
    A1, _ = hill_matrices(s.omega0, s.mass)
    assert spectral_radius(np.eye(6) + s.dt * A1) == pytest.approx(abs(1 + 1j * s.omega0 * s.dt), rel=1e-12)
    assert spectral_radius(np.eye(6) + s.dt * A1) > 1.0


def test_hill_system_is_the_discretized_hill_model(scenario):
    # hill_system = discretize(hill_matrices) (the same zero-order hold), with B, dt and the chaser's labels;
    # with K it is the closed loop Φ + ΓK without input
    s = scenario
    A0, G0 = hill_matrices(s.omega0, s.mass)
    for method in ("exact", "euler"):
        Phi, Gam = discretize(A0, G0, s.dt, method)
        sysm = hill_system(s.omega0, s.mass, s.dt, s.B, discretization=method)
        np.testing.assert_array_equal(sysm.Phi, Phi)
        np.testing.assert_array_equal(sysm.Gamma, Gam)
        np.testing.assert_array_equal(sysm.Q, s.B @ s.B.T)
        assert sysm.dt == s.dt and sysm.n == 6 and sysm.n_input == 3
        loop = hill_system(s.omega0, s.mass, s.dt, s.B, K=s.K, discretization=method)
        np.testing.assert_allclose(loop.Phi, Phi + Gam @ s.K, rtol=0, atol=0)
        assert loop.n_input == 0
    assert sysm.state.labels == ("x", "y", "z", "vx", "vy", "vz")
    assert sysm.state.indices("position") == (0, 1, 2) and sysm.state.indices("velocity") == (3, 4, 5)
    # (8): y = [I 0] x + D v
    meas = position_measurement(s.D)
    np.testing.assert_array_equal(meas.C, measurement_matrix())
    np.testing.assert_array_equal(meas.R, s.D @ s.D.T)
