"""Synthesis corner cases (issue 8, item 8): badly scaled noise, loose certificates, the observer form's γ,
the small-gain limit of the printed uncertainty factors, and SCS."""

import warnings

import control
import numpy as np
import pytest
import scipy.optimize

from hinfnav.analysis import hinf_norm, hinf_norm_bisection, schur_gamma, worst_case_norm
from hinfnav.analysis.error_system import error_system_matrices
from hinfnav.core.exceptions import (
    CertificationError,
    InfeasibleLMIError,
    LooseBoundWarning,
    SolverAccuracyWarning,
)
from hinfnav.design import SolverOptions, synthesize
from hinfnav.lmi import lmi20_matrix, prepare, prepare_uncertainty
from hinfnav.lmi.conditioning import NORMALIZE_THRESHOLD, block_scales
from hinfnav.papers.sun2011 import design_for_scenario
from hinfnav.papers.sun2011.designs import small_gain_bounds, small_gain_crossing
from hinfnav.systems import UncertainSystem

# ------------------------------------------------------------------ badly scaled noise channels


def test_noise_scaled_system_designs_and_certifies(random_uncertain):
    # B × 1000, D ÷ 1000: the γ-free part of LMI (20) holds neither B nor D, so a filter exists. Before issue 8
    # such systems gave a false InfeasibleLMIError (measured with k = 1024 on seeds 0–9: 10 of 10; Clarabel
    # "solver error", CVXOPT "infeasible" on the minimization)
    A, B, C, D, L, H, E = random_uncertain(np.random.default_rng(0), size=0.05)
    Bs, Ds = B * 1000, D / 1000
    # without the normalisation the solvers fail on the data as given; the fallback order of
    # hinfnav.design.certify_loop (issue 31) then minimises on the rescaled (normalised) data, which certifies
    raw = synthesize(UncertainSystem(A, Bs, C, Ds, L, H, E), options=SolverOptions(normalize_above=float("inf")))
    assert any("normalised" in a and "certified γ" in a for a in raw.attempts)
    res = synthesize(UncertainSystem(A, Bs, C, Ds, L, H, E))
    system = UncertainSystem(A, Bs, C, Ds, L, H, E)
    # the certificate is that of the ORIGINAL data: LMI (20) with B × 1000, D ÷ 1000 at the returned variables
    # (original units), tested here after our own power-of-two equilibration of rows and columns (exact), and
    # the smallest γ making it negative definite is the returned one (1e-6: Schur complement, two roundings)
    v = res.witness
    M0 = lmi20_matrix(A, Bs, C, Ds, L, v["H"], v["E"], v["R"], v["S"], v["Abar_F"], v["Bbar_F"], v["Cbar_F"], v["lam"], 0.0)
    n, p, q = 3, 2, 2
    k = 2.0 ** np.round(np.log2(np.sqrt(np.abs(np.diag(M0)) + 1e-300)))  # powers of two: exact congruence
    k[4 * n:4 * n + p + q] = 2.0 ** np.round(np.log2(res.gamma))
    gamma_eq, _ = schur_gamma(M0 / k[:, None] / k[None, :], np.arange(4 * n, 4 * n + p + q))
    assert gamma_eq * 2.0 ** np.round(np.log2(res.gamma)) == pytest.approx(res.gamma, rel=1e-6)
    # Theorem 1's guarantee on F it never saw (independent norm algorithm), and a tight bound (sampled ≥ 95 %)
    rng = np.random.default_rng(5)
    fresh = [F / np.linalg.norm(F, 2) for F in rng.standard_normal((8, 2, 2))]
    wc = worst_case_norm(system, res.A_F, res.B_F, res.C_F, fresh)
    assert wc.stable and wc.norm <= res.gamma
    assert res.verified_norm <= res.gamma < 1.05 * res.verified_norm
    assert hinf_norm_bisection(res.error_system(system)) == pytest.approx(hinf_norm(res.error_system(system)), rel=1e-8)


def test_paper_model_is_not_normalised(scenario):
    # the paper's designs keep their numbers: its block scales (noise 0.1, output 16 after the state scaling) are
    # below the threshold (tests/test_sun2011_reproduce.py checks the numbers themselves to 1e-9)
    scales = block_scales(prepare(scenario.design_model(0.05), "diagonal", "balance"))
    assert scales == pytest.approx({"inputs": 0.1, "output": 16.0})
    assert max(scales.values()) < NORMALIZE_THRESHOLD / 2


def test_infeasible_is_confirmed_on_the_gamma_free_part():
    # a truly infeasible problem (0.5 + f, |f| ≤ 1, reaches 1.5) is still reported, with the confirmation named
    with pytest.raises(InfeasibleLMIError, match="γ-free part"):
        synthesize(UncertainSystem([[0.5]], [[1000.0]], [[1.0]], [[1e-3]], [[1.0]], [[1.0]], [[1.0]]), uncertainty_samples=[[[0.0]]])


# ------------------------------------------------------------------ loose certificates


@pytest.fixture(scope="module")
def lightly_damped(random_uncertain):
    """Random 3-state plants with spectral radius 0.9999 and an uncertainty of size 1e-7 (small gain ≈ 5e-4)."""
    return lambda seed: random_uncertain(np.random.default_rng(seed), rho=0.9999, size=1e-7)


def test_loose_certificate_is_tightened(lightly_damped):
    # seed 0, Clarabel first: its first certified point (γ-free start) is 470338, 5700 × the sampled norm 82.4
    # (measured); trying harder (CVXOPT's full method) finds a filter certified within 1e-4 of its own sampled
    # norm (3.2806). The default chain (CVXOPT first, issue 21) reaches the same filter without trying harder; since
    # issue 31 so does the Clarabel-first chain (the fallback order minimises with every solver before bisecting)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LooseBoundWarning)
        res = synthesize(UncertainSystem(*lightly_damped(0)), options=SolverOptions(solvers=("CLARABEL", "CVXOPT")))
        default = synthesize(UncertainSystem(*lightly_damped(0)))
    assert any(a.startswith("CVXOPT") and "certified γ" in a for a in res.attempts)
    assert res.verified_norm <= res.gamma < 1.001 * res.verified_norm
    assert res.gamma == pytest.approx(3.2806, rel=1e-3)  # measured (November 2026)
    assert default.gamma == pytest.approx(res.gamma, rel=1e-9)  # same CVXOPT bisection (measured, issue 21)


def test_uncertified_optimum_is_tightened_by_feasibility_just_above(lightly_damped):
    # seed 1: no solver certifies its own minimiser (3.2601, LMI (20) not negative definite there). Before issue 31
    # the best certified γ stayed thousands of times the sampled norm (a LooseBoundWarning); the fallback order of
    # hinfnav.design.certify_loop now asks for an interior point just above the solvers' level (step 3), which
    # certifies within 1e-4 of the sampled norm (measured 3.260381 against 3.260363, November 2026)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LooseBoundWarning)
        res = synthesize(UncertainSystem(*lightly_damped(1)))
    assert any("feasibility at γ" in a and "certified γ" in a for a in res.attempts)
    assert res.verified_norm <= res.gamma < 1.0001 * res.verified_norm


# ------------------------------------------------------------------ observer form: a full Lyapunov matrix


def _robust_level(Ab, Bb, Cb, Hb, Eb):
    """min over λ of the least γ with ‖[C̄; √λ Ē](zI − Ā)⁻¹[B̄/γ, H̄/√λ]‖∞ < 1: no LMI solver.

    The robust bounded real LMI with one multiplier λ (Lemmas 1–3) is, by the Schur complement, the bounded real
    lemma of this augmented system, and γ²(λ) is convex in λ (the LMI is jointly linear in P, λ, γ²), so a
    bounded scalar search over log λ finds the minimum; each γ(λ) is a root of a SLICOT norm minus 1.
    """
    def norm(g, lam):
        B = np.hstack([Bb / g, Hb / np.sqrt(lam)])
        C = np.vstack([Cb, np.sqrt(lam) * Eb])
        return hinf_norm(control.ss(Ab, B, C, np.zeros((C.shape[0], B.shape[1])), True))

    def gamma_of(loglam):
        lam = 10.0**loglam
        if norm(1e12, lam) >= 1.0:
            return 1e6  # even γ → ∞ fails at this λ
        root = scipy.optimize.brentq(lambda lg: norm(np.exp(lg), lam) - 1.0, np.log(1e-3), np.log(1e3), xtol=1e-13)
        return float(np.exp(root))

    return scipy.optimize.minimize_scalar(gamma_of, bounds=(-8, 8), method="bounded", options={"xatol": 1e-7}).fun


def test_observer_gamma_is_the_full_lyapunov_level(scenario):
    # issue 8 measured 0.358644 at δ̄ = 0.05 in independent code; LMI (20)'s restricted Lyapunov matrix gives
    # 0.358738 (kept as witness["lmi20_gamma"]; lmi_gamma is the solver's). Here: the returned γ equals the level
    # of the independent computation above to 1e-6 relative (measured agreement 2e-9)
    res = design_for_scenario(scenario, 0.05, form="observer")
    s = scenario.design_model(0.05)
    Ab, Bb, Cb = error_system_matrices(s.A, s.B, s.C, s.D, s.L, res.A_F, res.B_F, res.C_F)
    H, E, _ = prepare_uncertainty(s.H, s.E, "diagonal")  # the balanced factors the design is certified for
    level = _robust_level(Ab, Bb, Cb, np.vstack([H, 0 * H]), np.hstack([E, 0 * E]))
    assert res.gamma == pytest.approx(level, rel=1e-6)
    assert res.gamma == pytest.approx(0.358644, rel=1e-5)
    assert res.witness["lmi20_gamma"] == pytest.approx(0.358738, rel=1e-5)
    assert res.verified_norm <= res.gamma < res.witness["lmi20_gamma"]


# ------------------------------------------------------------------ the printed factors: small gain


def test_printed_factors_small_gain_crosses_one_between_1_5_and_2(scenario):
    # LMI (20) with the printed H, E and one λ needs ‖E(zI − A)⁻¹H‖∞ < 1 (small gain); it reaches 1 at
    # δ̄ ≈ 1.806, where structure="full" turns infeasible, while the channel-balanced number stays below 0.05
    sg = small_gain_bounds(scenario, [1.5, 2.0])
    assert sg["printed"][0] < 1.0 < sg["printed"][1]
    assert np.all(sg["balanced"] < 0.05)
    np.testing.assert_allclose(sg["printed"], [0.764073, 1.164278], rtol=1e-5)  # measured (SLICOT)
    assert 1.5 < small_gain_crossing(scenario) < 2.0
    # the same number by an independent algorithm (Hamiltonian bisection, hinfnav.analysis)
    m = scenario.design_model(2.0)
    sys2 = control.ss(m.A, m.H, m.E, np.zeros((6, 6)), scenario.dt)
    assert hinf_norm_bisection(sys2) == pytest.approx(sg["printed"][1], rel=1e-7)


# ------------------------------------------------------------------ SCS


def test_scs_warns_with_its_looseness():
    # the warning carries the looseness measured on the paper's model (issue 8: γ = 6.55 against 0.3586); one
    # minimization of a scalar problem keeps the test short (SCS's point does not certify here: the warning is
    # the point of the test)
    with pytest.warns(SolverAccuracyWarning, match=r"SCS.*6\.55.*0\.3586"):
        with pytest.raises(CertificationError):
            synthesize(UncertainSystem([[0.5]], [[1.0]], [[1.0]], [[1.0]], [[1.0]]), options=SolverOptions.only("SCS", method="minimize"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", SolverAccuracyWarning)  # and the default solvers do not warn
        synthesize(UncertainSystem([[0.5]], [[1.0]], [[1.0]], [[1.0]], [[1.0]]), options=SolverOptions(method="minimize"))
