"""Mixed H2/H∞ robust synthesis (issue 12): known answers, independent certificates, the front.

Expected values come from closed forms (the Kalman predictor's DARE, the
Lyapunov inequality), from LMI (20) itself (the blocks reduce to it), from
independent re-evaluation (scipy Lyapunov solves, the BBBS H∞ iteration) or
from set inclusion (a looser constraint cannot give a larger optimum).
"""

import numpy as np
import pytest
import scipy.linalg

import hinfnav as hn
from hinfnav.papers import sun2011
from hinfnav.analysis import error_system, error_system_matrices, hinf_norm_bisection, schur_gamma
from hinfnav.core.exceptions import SynthesisError
from hinfnav.design.mixed import front_gammas, knee_index, synthesize_mixed
from hinfnav.lmi.blocks import gamma_index, lmi20_matrix
from hinfnav.lmi.mixed_blocks import extended_h2_matrix, robust_extended_hinf_negative, h2_output_index, slack_products
from hinfnav.papers.sun2011 import (
    delta_samples,
    design_for_scenario,
    mixed_design_for_scenario,
    mixed_front_for_scenario,
)

DELTA_BAR = 0.05


@pytest.fixture(scope="module")
def scenario():
    return sun2011.Scenario()


@pytest.fixture(scope="module")
def hinf_opt(scenario):
    return design_for_scenario(scenario, DELTA_BAR)


@pytest.fixture(scope="module")
def near_opt(scenario, hinf_opt):
    return mixed_design_for_scenario(scenario, DELTA_BAR, hinf_opt.gamma * (1 + 1e-3))


@pytest.fixture(scope="module")
def front(scenario, hinf_opt):
    return mixed_front_for_scenario(scenario, DELTA_BAR, points=3, hinf_result=hinf_opt)


def _spd(rng, n):
    M = rng.standard_normal((n, n))
    return M @ M.T + n * np.eye(n)


def test_extended_blocks_with_g_equal_p_are_lmi20(random_uncertain):
    # identity: with Gᵀ = P = [[R, S], [S, S]] the extended H∞ LMI is LMI (20) of Sun et al. (2011)
    rng = np.random.default_rng(3)
    A, B, C, D, L, H, E = random_uncertain(rng)
    n, m, l = A.shape[0], C.shape[0], L.shape[0]
    R, S = _spd(rng, n), _spd(rng, n)
    AbF, BbF, CbF = rng.standard_normal((n, n)), rng.standard_normal((n, m)), rng.standard_normal((l, n))
    sp = slack_products(A, B, C, D, L, H, E, R, S, S, AbF, BbF, CbF)
    P = np.block([[R, S], [S, S]])
    np.testing.assert_array_equal(sp["G"], P)
    M_ext = robust_extended_hinf_negative(P, sp["G"], sp["GA"], sp["GB"], sp["Cbar"], sp["GH"], sp["Ebar"], 0.7, 0.3)
    M_20 = lmi20_matrix(A, B, C, D, L, H, E, R, S, AbF, BbF, CbF, 0.7, 0.3)
    np.testing.assert_allclose(M_ext, M_20, rtol=0, atol=1e-12 * np.abs(M_20).max())


def test_extended_h2_level_matches_the_lyapunov_closed_form(random_stable):
    # With G = P the extended H2 LMI is negative definite iff ĀᵀPĀ − P + C̄ᵀC̄/κ < 0, i.e. iff
    # κ > λ_max(C̄ (P − ĀᵀPĀ)⁻¹ C̄ᵀ) (closed form). Any other slack G can only need a larger κ
    # (the slack lemma is sufficient only).
    rng = np.random.default_rng(5)
    sys = random_stable(rng, 4, 2, 3, 0.8)
    A, C = np.asarray(sys.A), np.asarray(sys.C)
    P = scipy.linalg.solve_discrete_lyapunov(A.T, 2.0 * C.T @ C + 0.1 * np.eye(4))  # P − ĀᵀPĀ = 2C̄ᵀC̄ + 0.1 I
    kappa_ref = np.linalg.eigvalsh(C @ np.linalg.solve(P - A.T @ P @ A, C.T)).max()
    M0 = extended_h2_matrix(P, P, P @ A, C, None, None, 0.0, 0.0)
    root, _ = schur_gamma(M0, np.arange(8, 11))
    assert root**2 == pytest.approx(kappa_ref, rel=1e-8)
    G = P + 0.05 * rng.standard_normal((4, 4))
    root_g, _ = schur_gamma(extended_h2_matrix(P, G, G.T @ A, C, None, None, 0.0, 0.0), np.arange(8, 11))
    assert root_g**2 >= kappa_ref * (1 - 1e-10)


def test_nominal_h2_bound_is_the_kalman_predictor(scenario):
    # Known answer: at δ̄ = 0 and an inactive γ, min ν is the H2 norm of the optimal one-step predictor,
    # sqrt(trace P), P the stationary predictor covariance (DARE with Q = BBᵀ, R = DDᵀ, scipy), L = I.
    s = scenario.design_model(0.0)
    P = scipy.linalg.solve_discrete_are(s.A.T, s.C.T, s.B @ s.B.T, s.D @ s.D.T)
    nu_kalman = np.sqrt(np.trace(P))
    # γ = 100 is ~250 times the H∞ norm of that predictor's error system (0.393): "very large"
    for gamma in (None, 100.0):
        res = mixed_design_for_scenario(scenario, 0.0, gamma)
        assert res.h2_bound == pytest.approx(nu_kalman, rel=1e-4)
        assert res.h2_bound >= nu_kalman * (1 - 1e-9)  # a certified bound cannot beat the optimum
        assert nu_kalman * (1 - 1e-9) <= res.h2_verified <= res.h2_bound


def test_near_gamma_star_the_filter_reaches_the_hinf_optimum(hinf_opt, near_opt):
    # γ* is the infimum of Corollary 1; the extended H∞ LMI has the same infimum (it contains (20) and
    # implies the bounded real lemma), so the certified γ of the mixed design at γ*(1 + 1e-3) lies in
    # [γ*(1 − 1e-4), γ*(1 + 1e-3)] (1e-4: the synthesis' own tolerance, SolverOptions.rtol).
    g_star = hinf_opt.gamma
    assert g_star * (1 - 1e-4) <= near_opt.gamma <= g_star * (1 + 1e-3)
    assert near_opt.verified_norm <= near_opt.gamma
    assert near_opt.gamma_bound == pytest.approx(g_star * (1 + 1e-3), rel=1e-12)


def test_certificates_hold_when_rechecked_independently(scenario, near_opt):
    res = near_opt
    s = scenario.design_model(DELTA_BAR)
    for F in delta_samples(DELTA_BAR).matrices:
        Ap = s.A + s.H @ F @ s.E
        sys = error_system(Ap, s.B, s.C, s.D, s.L, res.A_F, res.B_F, res.C_F)
        # H∞ by the BBBS iteration (not SLICOT), H2 by scipy's Lyapunov solver (not hinfnav's h2_norm)
        assert hinf_norm_bisection(sys) <= res.gamma * (1 + 1e-9)
        W = scipy.linalg.solve_discrete_lyapunov(np.asarray(sys.A), np.asarray(sys.B) @ np.asarray(sys.B).T)
        assert np.sqrt(np.trace(np.asarray(sys.C) @ W @ np.asarray(sys.C).T)) <= res.h2_bound * (1 + 1e-9)
    # the extended H∞ LMI at the returned filter and the returned variables (original coordinates),
    # with γ 1e-6 above the level they certify, is negative definite (issue 22: ``gamma`` may be the smaller
    # robust-BRL certificate of the filter alone; the synthesis level is then kept as ``gamma_synthesis``)
    v = res.witness
    gamma_lmi = v.get("gamma_synthesis", res.gamma)
    assert res.gamma <= gamma_lmi
    Abar, Bbar, Cbar = error_system_matrices(s.A, s.B, s.C, s.D, s.L, res.A_F, res.B_F, res.C_F)
    Gt = np.block([[v["X"], v["Z"]], [v["Y"], v["Z"]]])
    Hbar = np.vstack([v["H"], np.zeros_like(v["H"])])
    Ebar = np.hstack([v["E"], np.zeros_like(v["E"])])
    M = robust_extended_hinf_negative(v["Pinf"], Gt.T, Gt @ Abar, Gt @ Bbar, Cbar, Gt @ Hbar, Ebar, v["lam_inf"],
                             (gamma_lmi * (1 + 1e-6)) ** 2)
    assert np.linalg.eigvalsh(0.5 * (M + M.T)).max() < 0
    n = s.A.shape[0]
    assert gamma_index(n, 6, 3)[0] == 4 * n and h2_output_index(n, 6)[0] == 4 * n


def test_front_is_monotone_and_every_point_certified(front, hinf_opt):
    assert len(front.results) == 3 and front.gamma_star == hinf_opt.gamma
    np.testing.assert_allclose(front.gamma_bounds, front_gammas(hinf_opt.gamma, 3), rtol=1e-12)
    assert front.monotone()
    env, designs = front.pareto()
    assert np.all(np.diff(env) <= 0)
    for r in list(front.results) + [front.h2_result]:
        assert r.verified_norm <= r.gamma
        assert r.gamma_bound is None or r.gamma <= r.gamma_bound
        assert r.h2_verified <= r.h2_bound <= r.h2_synthesis_bound * (1 + 1e-12)
    for g, d in zip(front.gamma_bounds, designs):
        assert d.gamma <= g
    # set inclusion: dropping the H∞ constraint cannot raise the synthesis optimum (solver accuracy 1e-6)
    assert front.h2_result.h2_synthesis_bound <= front.synthesis_nus.min() * (1 + 1e-6)
    assert 0 <= front.knee < 3


def test_extended_is_no_more_conservative_than_common_lyapunov(scenario, front):
    # the common-Lyapunov solutions are extended ones (G = P₂ = P∞), so the extended optimum is ≤
    gamma = front.gamma_bounds[1]
    ext = front.results[1]
    com = mixed_design_for_scenario(scenario, DELTA_BAR, gamma, lyapunov="common")
    assert ext.h2_synthesis_bound <= com.h2_synthesis_bound * (1 + 1e-6)


def test_knee_of_a_known_curve():
    # ν = 1/γ, γ in [1, 100]: with x = ln γ / ln 100 and y = (1/γ − 0.01)/0.99, 1 − x − y is largest where
    # d/d(ln γ) = −1/ln 100 + 1/(0.99 γ) = 0, i.e. γ = ln(100)/0.99 ≈ 4.652 (closed form)
    g = np.logspace(0, 2, 2001)
    k = knee_index(g, 1 / g)
    assert g[k] == pytest.approx(np.log(100) / 0.99, rel=3e-3)
    assert knee_index([1, 2, 3], [1, 1, 1]) == 0


def test_bad_gamma(scenario, hinf_opt):
    s = scenario.design_model(DELTA_BAR)
    with pytest.raises(hn.InputError, match="gamma"):
        synthesize_mixed(s, gamma=-1.0, structure="diagonal")
    with pytest.raises(SynthesisError, match="infeasible"):
        mixed_design_for_scenario(scenario, DELTA_BAR, 0.5 * hinf_opt.gamma, solver="CVXOPT")
