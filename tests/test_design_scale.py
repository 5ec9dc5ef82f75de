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
