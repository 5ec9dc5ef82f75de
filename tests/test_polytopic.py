"""Issue 19: marginally stable plants, polytopes with common and parameter-dependent Lyapunov matrices.

Every certified γ is compared with the error system's H∞ norm computed independently of the LMIs
(hinf_norm_bisection, Boyd–Balakrishnan, not SLICOT) on a dense grid of the simplex: a certified
bound can never be below it. Orderings γ(PDL) ≤ γ(quadratic) ≤ γ(norm-bounded) hold in exact
arithmetic (each LMI set contains the next one's solutions); the tolerance 1e-6 relative is the
solvers' accuracy (tolerances 1e-8 on γ², certificates within 1e-9).
"""

import control
import numpy as np
import pytest

import hinfnav as hn
from hinfnav.papers import sun2011
from hinfnav.analysis.norms import hinf_norm_bisection
from hinfnav.core.exceptions import InfeasibleLMIError, InputError, UnstablePlantError
from hinfnav.design.polytopic import error_coordinates
from hinfnav.systems import PolytopicSystem, simplex_grid, two_mass_spring
from hinfnav.systems.uncertain import UncertainSystem

T = 0.1
A_DI = np.block([[np.eye(2), T * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
B_DI = np.vstack([T * T / 2 * np.eye(2), T * np.eye(2)])
C_DI = np.hstack([np.eye(2), np.zeros((2, 2))])
D_DI = 0.1 * np.eye(2)
ORDER_RTOL = 1e-6


def _independent_worst(system, res, points=101):
    """Worst H∞ norm over a dense simplex grid, by the bisection algorithm (independent of SLICOT and the LMI)."""
    worst = 0.0
    for a in simplex_grid(system.n_vertices, points=points):
        s = system.at(a)
        Ab, Bb, Cb = error_coordinates((s.A, s.B, s.C, s.D, s.L), res.A_F, res.B_F, res.C_F, res.form)
        worst = max(worst, hinf_norm_bisection(control.ss(Ab, Bb, Cb, 0 * Cb @ Bb, True)))
    return worst


def _rank_one(poly):
    """The same two-vertex polytope as norm-bounded A0 + H F E, scalar F ∈ [−1, 1] (exact: rank-1 difference)."""
    v0, v1 = poly.vertices
    U, s, Vt = np.linalg.svd((v1.A - v0.A) / 2)
    assert s[1] < 1e-12 * s[0]
    return UncertainSystem((v0.A + v1.A) / 2, v0.B, v0.C, v0.D, v0.L, U[:, :1] * s[0], Vt[:1], dt=poly.dt)


def test_double_integrator_observer_form_designs_and_certifies():
    res = hn.synthesize(hn.UncertainSystem(A_DI, B_DI, C_DI, D_DI, np.eye(4), dt=T), form="observer")
    assert res.form == "observer" and np.isfinite(res.gamma)
    # the observer structure: A_F = A + B_F C, C_F = −L (to round-off)
    assert np.allclose(res.A_F, A_DI + res.B_F @ C_DI, atol=1e-12) and np.allclose(res.C_F, -np.eye(4))
    # independent norm of the error e⁺ = (A + B_F C) e + B w + B_F D v, z − z_f = e (bisection, not ab13dd)
    nrm = hinf_norm_bisection(control.ss(res.A_F, np.hstack([B_DI, res.B_F @ D_DI]), np.eye(4), 0, True))
    assert nrm <= res.gamma * (1 + 1e-9)
    assert res.gamma <= nrm * (1 + 1e-5)  # nominal extended BRL is exact: γ at the norm within solver accuracy


def test_marginally_stable_plant_general_form_says_why_and_what_helps():
    with pytest.raises(UnstablePlantError) as exc:
        hn.synthesize(hn.UncertainSystem(A_DI, B_DI, C_DI, D_DI, np.eye(4)))
    msg = str(exc.value)
    assert "ΔA x" in msg and "form='observer'" in msg and "Scenario" not in msg


def test_zero_output_is_a_clear_error():
    with pytest.raises(InputError, match=r"\bL\b.*nothing to estimate"):
        hn.synthesize(hn.UncertainSystem(A_DI * 0.5, B_DI, C_DI, D_DI, np.zeros((2, 4))))


def test_observer_form_with_uncertainty_that_multiplies_the_state_designs_on_the_augmented_error():
    # issue 30: the plant is stable at every vertex, so the states ΔA reads are bounded and the observer form designs
    # on [x_s; e]; the certified γ bounds the independent dense-grid worst case (bisection norms, no design code)
    poly = two_mass_spring(0.1, c=0.2)
    res = hn.synthesize_polytopic(poly, form="observer")
    assert res.form == "observer" and "augmented" in res.covers
    worst = 0.0
    for a in simplex_grid(2, points=41):
        s = poly.at(a)
        Ab = np.block([[s.A, np.zeros((4, 4))], [res.B_F @ s.C, res.A_F]])
        Bb = np.block([[s.B, np.zeros((4, 1))], [np.zeros((4, 2)), res.B_F @ s.D]])
        worst = max(worst, hinf_norm_bisection(control.ss(Ab, Bb, np.hstack([s.L, -res.C_F]), 0, True)))
    assert worst <= res.gamma * (1 + 1e-9)


def test_two_mass_spring_30pct_designs_only_with_parameter_dependent_lyapunov():
    poly = two_mass_spring(0.3, c=0.2)
    nb = _rank_one(poly)
    # small-gain number (independent: SLICOT norm of E(zI − A)⁻¹H); > 1 means no quadratic design can exist
    gain = hn.hinf_norm(control.ss(nb.A, nb.H, nb.E, 0, True))
    assert gain > 1.0
    with pytest.raises(InfeasibleLMIError, match="parameter-dependent"):
        hn.synthesize_polytopic(poly, lyapunov="common")
    res = hn.synthesize_polytopic(poly, lyapunov="parameter-dependent")
    assert "constant in time" in res.covers
    assert res.verified_norm <= res.gamma and _independent_worst(poly, res) <= res.gamma * (1 + 1e-9)


def test_ordering_pdl_quadratic_norm_bounded_at_10pct():
    poly = two_mass_spring(0.1, c=0.2)
    nb = _rank_one(poly)
    g_pdl = hn.synthesize_polytopic(poly, lyapunov="parameter-dependent")
    g_q = hn.synthesize_polytopic(poly, lyapunov="common")
    g_nb = hn.synthesize(hn.UncertainSystem(nb.A, nb.B, nb.C, nb.D, nb.L, nb.H, nb.E, dt=poly.dt))
    assert "time-varying" in g_q.covers
    assert g_pdl.gamma <= g_q.gamma * (1 + ORDER_RTOL) and g_q.gamma <= g_nb.gamma * (1 + ORDER_RTOL)
    for r in (g_pdl, g_q):
        assert _independent_worst(poly, r) <= r.gamma * (1 + 1e-9)


def test_sun2011_as_a_polytope_beside_corollary1():
    model = sun2011.Scenario().design_model(0.05)
    cor1 = sun2011.design_for_scenario(None, 0.05)
    # F = diag(q, 0, q, d, d, 0) with q, d ∈ [−1, 1] (uncertainty_F): two parameters, four vertices
    poly = PolytopicSystem.from_norm_bounded(model, groups=[[0, 2], [3, 4]])
    assert poly.n_vertices == 4
    g_q = hn.synthesize_polytopic(poly, lyapunov="common", grid_points=10)
    g_pdl = hn.synthesize_polytopic(poly, lyapunov="parameter-dependent", grid_points=10)
    assert g_pdl.gamma <= g_q.gamma * (1 + ORDER_RTOL) and g_q.gamma <= cor1.gamma * (1 + ORDER_RTOL)
    for r in (g_q, g_pdl):
        assert r.verified_norm <= r.gamma


def test_norm_bounded_infeasibility_gives_the_small_gain_number():
    nb = _rank_one(two_mass_spring(0.3, c=0.2))
    with pytest.raises(InfeasibleLMIError, match=r"‖E\(zI − A\)⁻¹H‖∞ = [0-9.]+ ≥ 1.*parameter-dependent"):
        hn.synthesize(hn.UncertainSystem(nb.A, nb.B, nb.C, nb.D, nb.L, nb.H, nb.E), solver="CLARABEL")


def test_h2_double_integrator_matches_the_kalman_predictor():
    import scipy.linalg

    poly = PolytopicSystem((UncertainSystem(A_DI, B_DI, C_DI, D_DI, np.eye(4), dt=T),), T)
    res = hn.synthesize_polytopic(poly, lyapunov="common", form="observer", objective="h2")
    # independent: the optimal H2 observer is the steady Kalman predictor (Q = B Bᵀ, R = D Dᵀ); its error's
    # H2 norm squared is trace(P), P the a-priori DARE solution (scipy)
    P = scipy.linalg.solve_discrete_are(A_DI.T, C_DI.T, B_DI @ B_DI.T, D_DI @ D_DI.T)
    h2_opt = float(np.sqrt(np.trace(P)))
    assert res.verified_norm <= res.gamma * (1 + 1e-9)
    assert h2_opt * (1 - 1e-9) <= res.verified_norm <= h2_opt * (1 + 1e-4)  # solver accuracy
    assert res.gamma <= h2_opt * (1 + 1e-4)


def test_h2_polytope_pdl_not_above_common():
    poly = two_mass_spring(0.1, c=0.2)
    g_q = hn.synthesize_polytopic(poly, lyapunov="common", objective="h2")
    g_pdl = hn.synthesize_polytopic(poly, lyapunov="parameter-dependent", objective="h2")
    assert g_pdl.gamma <= g_q.gamma * (1 + ORDER_RTOL)
    for r in (g_q, g_pdl):
        assert r.objective == "h2" and r.verified_norm <= r.gamma
