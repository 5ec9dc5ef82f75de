"""Issue 31 (and issue 36 item 3): one solve path, few solver calls, unit-free balancing, independent worst case.

The plant is Sun et al. (2011)'s chaser at δ̄ = 0.05 (norm-bounded, ``structure="full"``: the path of
``design --system``), stacked k times (block-diagonal, one uncertainty channel set per copy).
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from hinfnav.design import SolverOptions, design_from_system_file, synthesize
from hinfnav.papers.sun2011 import Scenario
from hinfnav.systems.uncertain import UncertainSystem


#: The unit-free state scaling (the one ``design --system`` uses).
UNITS = SolverOptions(state_scaling="units")


def _stacked(k, delta_bar=0.05):
    s = Scenario().design_model(delta_bar)
    bd = lambda M: scipy.linalg.block_diag(*([M] * k))
    return UncertainSystem(bd(s.A), bd(s.B), bd(s.C), bd(s.D), bd(s.L), bd(s.H), bd(s.E), dt=s.dt)


def _in_units(s, t):
    """The same plant with states x' = diag(t)⁻¹ x (each state in other units)."""
    T = np.asarray(t, dtype=float)
    return UncertainSystem(s.A * T[None, :] / T[:, None], s.B / T[:, None], s.C * T[None, :], s.D, s.L * T[None, :],
                           s.H / T[:, None], s.E * T[None, :], dt=s.dt)


@pytest.fixture(scope="module")
def chaser():
    s = _stacked(1)
    return s, synthesize(s, structure="full", options=UNITS)


def test_first_solve_succeeds_in_one_call(chaser):
    # issue 31: on main 0d4cc82 this design made 28 cvxpy solves (CVXOPT's minimisation failed, then bisection)
    # and certified γ = 0.3589227 (measured); the Done-when asks for at most 3 solver calls when the first succeeds
    s, res = chaser
    assert res.solver_calls <= 3
    assert res.method == "minimize"
    assert res.gamma <= 0.3589227144 * (1 + 1e-6)  # never above main's certified level (measured on 0d4cc82)


@pytest.mark.parametrize("factor", [1e-6, 1e-3, 1e3, 1e6])
def test_gamma_does_not_depend_on_state_units(chaser, factor):
    # issue 36 item 3: the plant in other state units (every state, and positions only) is the same H∞ problem, so
    # the certified γ must agree within 1e-6 relative (on main 0d4cc82: 0.437 instead of 0.288 at ×1e3 on a file)
    s, res = chaser
    for t in (np.full(6, factor), np.r_[np.full(3, factor), np.ones(3)]):
        assert synthesize(_in_units(s, t), structure="full", options=UNITS).gamma == pytest.approx(res.gamma, rel=1e-6)


@pytest.mark.parametrize("k", [1e-6, 1e-4, 1e-2, 1e2, 1e4, 1e6])
def test_gamma_scales_with_the_noise(chaser, k):
    # w and v both scaled by k: the error is k times larger for every filter, so γ is k times γ (exact, linearity);
    # issue 36 item 3 asks for 1e-6 relative. The unit-free path normalises B, D by a noise scale that is
    # proportional to them (conditioning.noise_scale), so the solver sees the same problem whatever k (before:
    # a power-of-two normalisation above 64 only, 3.8e-5 at k = 100, where CVXOPT failed and Clarabel certified)
    s, res = chaser
    scaled = UncertainSystem(s.A, s.B * k, s.C, s.D * k, s.L, s.H, s.E, dt=s.dt)
    out = synthesize(scaled, structure="full", options=UNITS)
    assert out.gamma == pytest.approx(k * res.gamma, rel=1e-6)
    # the filter does not depend on the noise scale (only C_F = −L, A_F and B_F of the same problem)
    np.testing.assert_allclose(out.B_F, res.B_F, rtol=1e-6, atol=1e-9 * np.abs(res.B_F).max())


@pytest.mark.parametrize("k", [1e-6, 1e6])
def test_gamma_scales_with_the_noise_on_the_polytopic_route(k):
    # the double integrator of examples/ (nominal, not Schur stable: designed in observer form by the extended LMI
    # (E1), the polytopic route); before: γ 10x loose at k = 1e-6 (certificate's tolerance at γ² ~ 1e-13) and
    # nothing certified at k = 1e6; now normalised before the solve and certified at the unit scale
    import dataclasses

    from hinfnav.systems.files import read_system_file

    s = read_system_file(Path(__file__).resolve().parents[1] / "examples" / "double_integrator.toml")
    g1 = synthesize(s, form="observer", options=UNITS).gamma
    scaled = dataclasses.replace(s, B=s.B * k, D=s.D * k)
    assert synthesize(scaled, form="observer", options=UNITS).gamma == pytest.approx(k * g1, rel=1e-6)


def _dense_worst_case(s, A_F, B_F, C_F, rng, n_f=60, n_w=2000):
    """Largest σ_max of the error transfer function over random contractions F and a dense frequency grid.

    Written here from (13)–(15) without hinfnav's design or norm code: a lower bound of the worst case.
    """
    n = s.A.shape[0]
    Fs = [np.zeros((s.H.shape[1], s.E.shape[0])), np.eye(s.H.shape[1]), -np.eye(s.H.shape[1])]
    for _ in range(n_f):
        F = rng.standard_normal((s.H.shape[1], s.E.shape[0]))
        Fs.append(F / np.linalg.norm(F, 2))
    w = np.concatenate([np.geomspace(1e-6, np.pi, n_w), [0.0]])
    worst = 0.0
    for F in Fs:
        Ap = s.A + s.H @ F @ s.E
        Ab = np.block([[Ap, np.zeros((n, n))], [B_F @ s.C, A_F]])
        Bb = np.block([[s.B, np.zeros((n, s.D.shape[1]))], [np.zeros((n, s.B.shape[1])), B_F @ s.D]])
        Cb = np.hstack([s.L, -C_F])
        lam, V = np.linalg.eig(Ab)
        Vi_B, C_V = np.linalg.solve(V, Bb), Cb @ V
        for z in np.exp(1j * w):
            G = (C_V / (z - lam)[None, :]) @ Vi_B
            worst = max(worst, np.linalg.norm(G, 2))
    return worst


def test_certified_gamma_bounds_an_independent_dense_worst_case(chaser):
    # the certified γ must be ≥ the worst case over F it never saw, by an independent algorithm (a dense
    # frequency grid through an eigendecomposition, not SLICOT ab13dd); and tight (≥ 99 % of γ here)
    s, res = chaser
    worst = _dense_worst_case(s, res.A_F, res.B_F, res.C_F, np.random.default_rng(7))
    assert worst <= res.gamma
    assert worst >= 0.99 * res.gamma


def test_two_mass_example_designs_in_one_call():
    # issue 30 item 3: examples/two_mass_spring_30pct.toml, parameter-dependent (the default for a polytope);
    # certified γ unchanged from main 0d4cc82 (2.641990187, measured), one solver call (Clarabel's minimisation
    # certifies at its own level), and no sampled norm above the certificate
    path = Path(__file__).resolve().parents[1] / "examples" / "two_mass_spring_30pct.toml"
    res, summary = design_from_system_file(path)
    assert res.solver_calls <= 3
    assert res.gamma <= 2.641990187 * (1 + 1e-6)
    assert res.verified_norm <= res.gamma


@pytest.fixture(scope="module")
def two_chasers():
    s = _stacked(2)
    return s, synthesize(s, structure="full", options=UNITS)


def test_decoupled_plant_is_posed_per_block_with_the_same_gamma(chaser, two_chasers):
    # issue 31: two stacked chasers (one full F couples both) decouple into two 6-state blocks; LMI (20) with
    # block-diagonal variables and a common λ, γ has the optimum of the full LMI (sign-symmetry argument in
    # hinfnav.lmi.lmi20_problem), and for two equal blocks that is the optimum of one chaser: expected value = the
    # single chaser's certified γ (computed here by the full route, n = 6, not decoupled), to 1e-6 relative; and
    # not above the full route at n = 12 (0.35872417, measured on i31 by the full route, 13.96 s CPU: too slow here)
    s1, res1 = chaser
    s2, res2 = two_chasers
    assert any(a.startswith("decoupled plant: 2 blocks") for a in res2.attempts)
    assert res2.gamma == pytest.approx(res1.gamma, rel=1e-6)
    assert res2.gamma <= 0.35872417 * (1 + 1e-6)
    assert res2.solver_calls <= 3


def test_block_certificate_holds_for_a_full_coupling_contraction(two_chasers):
    # the block route certifies the whole plant: F is one full contraction (8 × 8 after the zero channels, here
    # 12 × 12) coupling the two chasers, which the per-block LMIs never see; an independent dense frequency grid
    # (eigendecomposition, no design or SLICOT code) at 20 random full contractions, ±I and 0 stays below γ
    s, res = two_chasers
    worst = _dense_worst_case(s, res.A_F, res.B_F, res.C_F, np.random.default_rng(11), n_f=20, n_w=400)
    assert worst <= res.gamma
    assert worst >= 0.99 * res.gamma  # and tight: F = ±I (block-diagonal) reaches each chaser's worst case


def _random_block(rng, n, rho=0.9):
    A = rng.standard_normal((n, n))
    A *= rho / max(abs(np.linalg.eigvals(A)))
    return (A, rng.standard_normal((n, 2)) / 2, rng.standard_normal((1, n)), 0.1 * np.eye(1), np.eye(n),
            rng.standard_normal((n, 1)) * 0.2, rng.standard_normal((1, n)) * 0.2)


def test_unequal_blocks_give_the_full_routes_gamma():
    # two different random 3-state blocks (one uncertainty channel each, one full 2 × 2 F): the block route and
    # the full route (SolverOptions(blocks=False), one LMI of the whole plant) certify the same γ (the restriction
    # is exact for any decoupled plant, not only equal blocks); 1e-5 relative: two solver runs on different problems
    # (measured 8.6e-7 here, block route above; seeds 4 and 5: 8e-9 and 2e-14)
    rng = np.random.default_rng(3)
    parts = [_random_block(rng, 3), _random_block(rng, 3)]
    mats = [scipy.linalg.block_diag(*[p[i] for p in parts]) for i in range(7)]
    s = UncertainSystem(*mats, dt=1.0)
    block = synthesize(s, structure="full", options=UNITS)
    full = synthesize(s, structure="full", options=SolverOptions(state_scaling="units", blocks=False))
    assert any(a.startswith("decoupled plant: 2 blocks") for a in block.attempts)
    assert not any(a.startswith("decoupled plant") for a in full.attempts)
    assert block.gamma == pytest.approx(full.gamma, rel=1e-5)


def test_split_norms_equal_the_whole_error_systems(two_chasers):
    # worst_case_norm(split=True) takes the norm block by block where F does not couple the two chasers: the
    # transfer matrix is then block-diagonal, so the whole system's norm (SLICOT on all 24 error states, split=False)
    # is the expected value, to ab13dd's accuracy (1e-9 asked; 1e-7 here); a full F is evaluated whole either way
    from hinfnav.analysis.error_system import worst_case_norm
    from hinfnav.analysis.structure import decoupled_blocks

    s, res = two_chasers
    assert [b.states.tolist() for b in decoupled_blocks(s.A, s.B, s.C, s.D, s.L, s.H, s.E)] == [list(range(6)),
                                                                                              list(range(6, 12))]
    rng = np.random.default_rng(2)
    full = rng.standard_normal((12, 12))
    samples = [np.eye(12), -np.eye(12), np.diag(rng.choice([-1.0, 1.0], 12)), full / np.linalg.norm(full, 2)]
    split = worst_case_norm(s, res.A_F, res.B_F, res.C_F, samples, split=True)
    whole = worst_case_norm(s, res.A_F, res.B_F, res.C_F, samples)
    np.testing.assert_allclose(split.norms, whole.norms, rtol=1e-7)
    np.testing.assert_allclose(split.spectral_radii, whole.spectral_radii, rtol=1e-12)
