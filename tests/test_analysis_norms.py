"""Tests of hinfnav.analysis (H∞ norms, the error system (13)–(15), certificates) and the robust
bounded real LMI of hinfnav.lmi."""

import control
import numpy as np
import pytest

from hinfnav.analysis import (
    brl_matrix,
    certify_negative_definite,
    channel_norms,
    error_system,
    error_system_matrices,
    frequency_response_sigma,
    h2_norm,
    hinf_norm,
    hinf_norm_bisection,
    hinf_norm_grid,
    schur_gamma,
    worst_case_norm,
)
from hinfnav.core import InputError, spectral_radius
from hinfnav.lmi import robust_bounded_real_lmi
from hinfnav.papers.sun2011 import published_filter
from hinfnav.systems import UncertainSystem


# --------------------------------------------------------------------------- known answers


@pytest.mark.parametrize("a", [0.5, 0.9, -0.7, 0.999, 0.0])
@pytest.mark.parametrize("method", [hinf_norm, hinf_norm_bisection, hinf_norm_grid])
def test_first_order_known_answer(a, method):
    # G(z) = c b / (z − a): |G(e^{jθ})| peaks at θ = 0 (a > 0) or π (a < 0), so
    # ‖G‖∞ = |c b| / (1 − |a|) (closed form)
    b, c = 2.0, -1.5
    sys = control.ss([[a]], [[b]], [[c]], [[0.0]], 0.1)
    expected = abs(c * b) / (1.0 - abs(a))
    assert method(sys) == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("method", [hinf_norm, hinf_norm_bisection, hinf_norm_grid])
def test_second_order_known_answer(method):
    # G(z) = 1/((z − a)(z − b)) with 0 < a, b < 1: every factor is largest at z = 1,
    # so ‖G‖∞ = 1/((1 − a)(1 − b)) (closed form)
    a, b = 0.8, 0.3
    A = np.array([[a, 1.0], [0.0, b]])
    sys = control.ss(A, [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]], True)
    assert method(sys) == pytest.approx(1.0 / ((1 - a) * (1 - b)), rel=1e-9)


def test_peak_frequency_of_first_order_system_in_rad_per_s():
    # a < 0 peaks at the Nyquist frequency π/T (closed form), T = 0.1 s → 31.4159 rad/s
    sys = control.ss([[-0.6]], [[1.0]], [[1.0]], [[0.0]], 0.1)
    for fn in (hinf_norm, hinf_norm_bisection):
        _, peak = fn(sys, return_peak=True)
        assert peak == pytest.approx(np.pi / 0.1, rel=1e-9)


def test_unstable_system_has_infinite_norm():
    # spectral radius ≥ 1 ⇒ H∞ norm infinite (definition)
    sys = control.ss([[1.01]], [[1.0]], [[1.0]], [[0.0]], True)
    assert hinf_norm(sys) == np.inf
    assert hinf_norm_bisection(sys) == np.inf
    assert hinf_norm_grid(sys) == np.inf


@pytest.mark.parametrize("seed", range(6))
def test_slycot_and_bisection_agree_on_random_systems(seed, random_stable):
    # two independent algorithms (SLICOT ab13dd; BBBS on the symplectic pencil here)
    # agree to 1e-8; the grid is a lower bound within 1e-3
    rng = np.random.default_rng(seed)
    sys = random_stable(rng, n=5, m=2, p=3, rho=rng.uniform(0.5, 0.99))
    g1 = hinf_norm(sys)
    g2 = hinf_norm_bisection(sys)
    g3 = hinf_norm_grid(sys)
    assert g2 == pytest.approx(g1, rel=1e-8)
    assert g3 <= g1 * (1 + 1e-9)
    assert g3 >= g1 * (1 - 1e-3)


def test_with_feedthrough(random_stable):
    # static gain D only: ‖D‖₂ (closed form); plus a dynamic part: agree between methods
    rng = np.random.default_rng(7)
    D = rng.standard_normal((2, 3))
    static = control.ss(np.zeros((1, 1)), np.zeros((1, 3)), np.zeros((2, 1)), D, True)
    assert hinf_norm(static) == pytest.approx(np.linalg.norm(D, 2), rel=1e-9)
    assert hinf_norm_bisection(static) == pytest.approx(np.linalg.norm(D, 2), rel=1e-9)
    sys = random_stable(rng, 4, 3, 2, 0.9)
    sys = control.ss(sys.A, sys.B, sys.C, D, True)
    assert hinf_norm_bisection(sys) == pytest.approx(hinf_norm(sys), rel=1e-8)


def test_frequency_response_matches_transfer_function():
    # σ_max from the state space equals |G(e^{jωT})| of the closed-form scalar G = cb/(z − a)
    a, b, c, T = 0.7, 1.0, 2.0, 0.5
    sys = control.ss([[a]], [[b]], [[c]], [[0.0]], T)
    w = np.array([0.1, 1.0, 3.0])
    expected = np.abs(c * b / (np.exp(1j * w * T) - a))
    np.testing.assert_allclose(frequency_response_sigma(sys, w), expected, rtol=1e-12)


def test_h2_norm_first_order_known_answer():
    # G(z) = c b/(z − a): impulse response c b a^(k−1), k ≥ 1, so ‖G‖₂² = c² b²/(1 − a²) (closed form);
    # infinite for an unstable system
    a, b, c = 0.6, 2.0, -1.5
    sys = control.ss([[a]], [[b]], [[c]], [[0.0]], 0.1)
    assert h2_norm(sys) == pytest.approx(abs(c * b) / np.sqrt(1 - a * a), rel=1e-12)
    assert h2_norm(control.ss([[1.01]], [[1.0]], [[1.0]], [[0.0]], True)) == np.inf


# --------------------------------------------------------------------------- error system (13)–(15)


def test_error_system_structure_and_transfer_function():
    rng = np.random.default_rng(3)
    n, p, m, q, l, nf = 3, 2, 2, 2, 3, 3
    A = rng.standard_normal((n, n))
    A *= 0.8 / spectral_radius(A)
    B, C, D, L = (rng.standard_normal(s) for s in [(n, p), (m, n), (m, q), (l, n)])
    A_F = rng.standard_normal((nf, nf))
    A_F *= 0.5 / spectral_radius(A_F)
    B_F, C_F = rng.standard_normal((nf, m)), rng.standard_normal((l, nf))
    Abar, Bbar, Cbar = error_system_matrices(A, B, C, D, L, A_F, B_F, C_F)
    # (14a)–(14c) block by block
    np.testing.assert_array_equal(Abar[:n, :n], A)
    np.testing.assert_array_equal(Abar[:n, n:], 0)
    np.testing.assert_array_equal(Abar[n:, :n], B_F @ C)
    np.testing.assert_array_equal(Bbar[n:, p:], B_F @ D)
    np.testing.assert_array_equal(Cbar, np.hstack([L, -C_F]))
    # (15) against an independent formula: e = L x − C_F x_f, x = G_x w, x_f = F(z)(C x + D v)
    sys = error_system(A, B, C, D, L, A_F, B_F, C_F, dt=0.2)
    z = np.exp(1j * 0.37)
    Gx = np.linalg.solve(z * np.eye(n) - A, B)
    Ff = C_F @ np.linalg.solve(z * np.eye(nf) - A_F, B_F)
    expected = np.hstack([L @ Gx - Ff @ C @ Gx, -Ff @ D])
    got = Cbar @ np.linalg.solve(z * np.eye(n + nf) - Abar, Bbar)
    np.testing.assert_allclose(got, expected, rtol=1e-10, atol=1e-12)
    assert sys.dt == 0.2


def test_published_filter_norm_cross_checked(scenario):
    # the published filter (Section 4) on the paper's error system at δ = 0: slycot and the
    # independent BBBS iteration agree to 1e-9; the dense grid to 1e-6
    sc = scenario
    s = sc.design_model(0.05)
    pub = published_filter()
    sys = error_system(s.A, s.B, s.C, s.D, s.L, pub.A_F, pub.B_F, pub.C_F, sc.dt)
    g = hinf_norm(sys)
    assert hinf_norm_bisection(sys) == pytest.approx(g, rel=1e-9)
    assert hinf_norm_grid(sys) == pytest.approx(g, rel=1e-6)
    assert 0.94 < g < 0.95


def test_channel_norms_of_diagonal_system():
    # a block-diagonal system: each channel's norm is its own |cb|/(1 − a) (closed form)
    A = np.diag([0.5, 0.8])
    sys = control.ss(A, np.diag([1.0, 2.0]), np.diag([3.0, 1.0]), np.zeros((2, 2)), 1.0)
    out = channel_norms(sys, {"u1": [0], "u2": [1]}, {"y1": [0], "y2": [1]})
    assert out[("u1", "y1")][0] == pytest.approx(3.0 / 0.5, rel=1e-9)
    assert out[("u2", "y2")][0] == pytest.approx(2.0 / 0.2, rel=1e-9)
    assert out[("u1", "y2")][0] == pytest.approx(0.0, abs=1e-12)


def test_worst_case_norm_over_samples():
    # scalar plant x⁺ = (a + h f e) x + w, z = x, with the filter z_f = 0 (C_F = 0):
    # ‖Ψ‖ = 1/(1 − a − h f e) for a + hfe > 0 (closed form), worst at f = +1
    a, h, e = 0.5, 0.2, 1.0
    s = UncertainSystem([[a]], [[1.0]], [[1.0]], [[1.0]], [[1.0]], [[h]], [[e]])
    wc = worst_case_norm(s, [[0.0]], [[0.0]], [[0.0]], [[[-1.0]], [[0.0]], [[1.0]]])
    np.testing.assert_allclose(wc.norms, [1 / (1 - a + h * e), 1 / (1 - a), 1 / (1 - a - h * e)], rtol=1e-9)
    assert wc.index == 2 and wc.stable
    assert wc.norm == pytest.approx(1 / (1 - a - h * e), rel=1e-9)


# --------------------------------------------------------------------------- certificates


def test_schur_gamma_known_answer():
    # M(γ) = [[−X, Y], [Yᵀ, −γ² I]] < 0 iff γ² > λmax(Yᵀ X⁻¹ Y) (Lemma 3, closed form)
    rng = np.random.default_rng(11)
    G = rng.standard_normal((4, 4))
    X = G @ G.T + np.eye(4)
    Y = rng.standard_normal((4, 2))
    M0 = np.block([[-X, Y], [Y.T, np.zeros((2, 2))]])
    gamma, info = schur_gamma(M0, [4, 5])
    exact = np.sqrt(np.max(np.linalg.eigvalsh(Y.T @ np.linalg.solve(X, Y))))
    assert gamma == pytest.approx(exact, rel=1e-6)
    assert gamma >= exact
    assert info["gamma_schur"] == pytest.approx(exact, rel=1e-12)


def test_schur_gamma_infinite_when_rest_not_negative_definite():
    # the γ-free part has a positive eigenvalue: no γ helps
    M0 = np.array([[1.0, 0.5], [0.5, 0.0]])
    gamma, info = schur_gamma(M0, [1])
    assert gamma == np.inf
    assert info["max_eig_OO"] == pytest.approx(1.0)


def test_certify_negative_definite():
    assert certify_negative_definite(-np.eye(3))[0]
    assert not certify_negative_definite(np.diag([-1.0, 0.0]))[0]
    # −1e-16 beside −1 is within rounding: not certified
    assert not certify_negative_definite(np.diag([-1.0, -1e-16]))[0]


def test_bounded_real_lemma_matches_norm(random_stable):
    # Lemma 1: the smallest γ for which (17) is feasible is the H∞ norm; solver + certificate
    # reproduce the slycot norm to 1e-6
    rng = np.random.default_rng(5)
    sys = random_stable(rng, 3, 2, 2, 0.8)
    cert = robust_bounded_real_lmi(sys.A, sys.B, sys.C)
    g = hinf_norm(sys)
    assert cert.gamma >= g * (1 - 1e-9)
    assert cert.gamma == pytest.approx(g, rel=1e-6)
    # and brl_matrix at that P is negative definite just above γ, not below the norm
    assert certify_negative_definite(brl_matrix(sys.A, sys.B, sys.C, cert.P, (cert.gamma * 1.001) ** 2))[0]
    assert not certify_negative_definite(brl_matrix(sys.A, sys.B, sys.C, cert.P, (g * 0.999) ** 2))[0]


def test_robust_bounded_real_lemma_scalar_known_answer():
    # x⁺ = (a + h f e) x + b w, z = x, |f| ≤ 1 (possibly time-varying), a, h, e > 0: the worst case
    # is f ≡ 1 (positive system) so the robust norm is b/(1 − a − h e) (closed form); Lemmas 1–2 are
    # lossless for one state and one scalar uncertainty
    a, b, h, e = 0.5, 1.0, 0.2, 1.0
    cert = robust_bounded_real_lmi([[a]], [[b]], [[1.0]], [[h]], [[e]])
    assert cert.gamma == pytest.approx(b / (1 - a - h * e), rel=1e-6)
    assert cert.lam > 0


# --------------------------------------------------------------------------- bad input


def test_error_system_rejects_bad_shapes():
    A, B, C, D, L = np.eye(2) * 0.5, np.ones((2, 1)), np.ones((1, 2)), np.ones((1, 1)), np.eye(2)
    with pytest.raises(InputError, match="B_F"):
        error_system_matrices(A, B, C, D, L, np.eye(2), np.ones((3, 1)), np.eye(2))
    with pytest.raises(InputError, match="C_F"):
        error_system_matrices(A, B, C, D, L, np.eye(2), np.ones((2, 1)), np.eye(3))
    with pytest.raises(InputError, match="A must be square"):
        error_system_matrices(np.ones((2, 3)), B, C, D, L, np.eye(2), np.ones((2, 1)), np.eye(2))
    with pytest.raises(InputError, match="A_F.*finite"):
        error_system_matrices(A, B, C, D, L, np.array([[np.nan, 0], [0, 0]]), np.ones((2, 1)), np.eye(2))


def test_norm_rejects_continuous_system():
    with pytest.raises(InputError, match="discrete"):
        hinf_norm(control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]))
    with pytest.raises(InputError, match="StateSpace"):
        hinf_norm(np.eye(2))
