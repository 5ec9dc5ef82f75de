"""Issue 30, item 1: marginally stable plants whose uncertainty reads a bounded part of the state.

Expected values come from closed forms (the read state of a block-diagonal plant, an eigenvector as a dual
certificate) or from norms computed here without the design code (frequency response of the full plant + filter
error system ξ = [x; x_f], whose integrator modes cancel).
"""

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.analysis.marginal import read_part, simplex_cells
from hinfnav.core.exceptions import UnstablePlantError
from hinfnav.design.augmented import cell_alphas
from hinfnav.design.io import save_design
from hinfnav.systems.flexible import flexible_attitude, flexible_attitude_closed_loop, flexible_attitude_matrices
from hinfnav.systems.parametric import polytope_coverage, polytope_from_parameters


def _tuples(poly):
    return [(v.A, v.B, v.C, v.D, v.L) for v in poly.vertices]


def test_read_state_of_the_flexible_mode_is_the_mode():
    # closed form: A is block diagonal (rigid | mode) and only the mode's block varies, so x_s spans (η, η̇)
    poly = flexible_attitude()
    c = poly.center()
    part = read_part(_tuples(poly), (c.A, c.C, c.L))
    assert part.states == (2, 3) and part.T.shape == (2, 4)
    assert np.allclose(part.T[:, :2], 0.0, atol=1e-14) and part.stable
    # the mode's spectral radius at the least damped vertex: exp(−ζ Ω dt) (closed form of the ZOH), 1e-12
    i = poly.labels.index("f=0.8, z=0.002")
    assert abs(part.spectral_radii[i] - np.exp(-0.002 * 2 * np.pi * 0.8 * 0.1)) < 1e-12


def test_uncertainty_on_an_integrator_is_refused_naming_the_states():
    # a rate-gyro scale error written into A (θ⁺ = θ + dt (1 ± 0.1) ω) reads ω, an integrator: impossible
    dt = 0.1
    verts = []
    for s in (0.9, 1.1):
        A = np.array([[1.0, dt * s], [0.0, 1.0]])
        verts.append(hn.UncertainSystem(A, [[dt * dt / 2], [dt]], [[1.0, 0.0]], [[0.1]], [[1.0, 0.0]], dt=dt))
    poly = hn.PolytopicSystem(tuple(verts), dt)
    with pytest.raises(UnstablePlantError, match=r"reads the states x\[1\].*spectral radius 1\b.*carried by x\[1\]") as exc:
        hn.synthesize_polytopic(poly, form="observer")
    assert "What helps" in str(exc.value)
    # hand-built dual certificate that the read part has no Lyapunov function (so no filter has a finite γ):
    # with v the eigenvector of T A Tᵀ at |λ| = 1, vᴴ(Ãᵀ P Ã − P)v = (|λ|² − 1) vᴴ P v = 0 for EVERY P > 0, so
    # Ãᵀ P Ã − P < 0 is infeasible; checked on random P (closed form, round-off 1e-12)
    c = poly.center()
    part = read_part(_tuples(poly), (c.A, c.C, c.L))
    lam, V = np.linalg.eig(part.A_s[0])
    k = int(np.argmax(np.abs(lam)))
    assert abs(abs(lam[k]) - 1.0) < 1e-12
    rng = np.random.default_rng(0)
    for _ in range(5):
        M = rng.standard_normal(part.A_s[0].shape)
        P = M @ M.T + np.eye(len(M))
        v = V[:, k]
        assert abs(np.vdot(v, (part.A_s[0].T @ P @ part.A_s[0] - P) @ v)) < 1e-12 * np.linalg.norm(P)


def test_general_form_on_the_open_loop_plant_says_why():
    poly = flexible_attitude()
    with pytest.raises(UnstablePlantError, match="form='observer'"):
        hn.synthesize_polytopic(poly, form="general")
    # hand-built proof that no general-form filter exists: u with uᵀA = uᵀ (the attitude integrator) makes [u; 0] a
    # left eigenvector of Ā = [[A, 0], [B_F C, A_F]] at 1 for EVERY filter, so Ā is never Schur stable and (E1)
    # (which implies Āᵀ P Ā < P) has no solution; checked on random filters to round-off (closed form)
    A = poly.vertices[0].A
    u = np.array([0.0, 1.0, 0.0, 0.0])
    assert np.allclose(u @ A, u, atol=1e-15)
    rng = np.random.default_rng(4)
    for _ in range(3):
        A_F, B_F = rng.standard_normal((4, 4)), rng.standard_normal((4, 1))
        Abar = np.block([[A, np.zeros((4, 4))], [B_F @ poly.vertices[0].C, A_F]])
        assert np.allclose(np.concatenate([u, np.zeros(4)]) @ Abar, np.concatenate([u, np.zeros(4)]), atol=1e-14)


def test_cells_from_parameter_splits_cover_the_box():
    poly = flexible_attitude(splits=4)
    assert poly.n_vertices == 10 and len(poly.cells) == 4 and all(len(c) == 4 for c in poly.cells)
    # every cell's vertices are the 4 corners of a frequency sub-range (labels: closed form of the grid)
    f = [sorted({float(poly.labels[i].split(",")[0][2:]) for i in c}) for c in poly.cells]
    assert np.allclose(f, [[0.8, 0.9], [0.9, 1.0], [1.0, 1.1], [1.1, 1.2]], atol=1e-12)
    assert len(cell_alphas(poly)) > 4 * 20  # each cell sampled densely


def test_simplex_cells_bisect_the_longest_edge():
    stacks = np.array([[0.0, 1.0, 10.0]])  # 3 vertices on a line: the longest edge is (0, 2)
    cells = simplex_cells(stacks, 2)
    assert len(cells) == 2
    for W in cells:
        assert np.allclose(W.sum(axis=1), 1.0) and np.any(np.all(np.isclose(W, [0.5, 0, 0.5]), axis=1))


def test_coverage_is_round_off_for_an_affine_family_and_positive_for_the_zero_order_hold():
    # continuous-time matrices are affine in (Ω², ζΩ): written in those parameters the box's corners hold the family
    def affine(w2, zw):
        A = np.array([[0.0, 1.0], [-w2, -2 * zw]])
        return (A, [[0.0], [1.0]], [[1.0, 0.0]], [[0.1]], [[1.0, 0.0]])
    ranges = {"w2": (25.0, 60.0), "zw": (0.01, 0.08)}
    poly = polytope_from_parameters(affine, ranges)
    cov = polytope_coverage(poly, affine, ranges, n_samples=30)
    assert cov.max_distance < 1e-9  # NNLS on the simplex: round-off
    # the ZOH matrices are not affine in (f, ζ): the corners' hull misses part of the family, cells shrink the gap
    def zoh(f, z):
        return flexible_attitude_matrices(f, z, dt=0.1)
    r = {"f": (0.8, 1.2), "z": (0.002, 0.01)}
    one = polytope_coverage(polytope_from_parameters(zoh, r, 0.1), zoh, r, n_samples=20)
    eight = polytope_coverage(polytope_from_parameters(zoh, r, 0.1, {"f": 8}), zoh, r, n_samples=20)
    assert one.max_distance > 1e-3 and eight.max_distance < one.max_distance / 10


def _gains(Ab, Bb, Cb, w, dt):
    """σ̄(C̄ (e^{jωdt} I − Ā)⁻¹ B̄) at each ω (rad/s)."""
    eye = np.eye(Ab.shape[0])
    return np.array([np.linalg.norm(Cb @ np.linalg.solve(np.exp(1j * x * dt) * eye - Ab, Bb), 2) for x in w])


def _full_error_response_worst(system, alphas, A_F, B_F, C_F, dt, n_freq=4000):
    """Independent worst gain: σ̄ of the FULL error system ξ = [x; x_f] (13)–(14) on a frequency grid, no design code.

    The integrator modes of ξ are cancelled in the transfer function; the grid starts at 1e-3 rad/s and is
    refined around each sample's largest peak (a lower bound of the norm).
    """
    worst = 0.0
    for a in alphas:
        s = system.at(a)
        n, nf = s.A.shape[0], A_F.shape[0]
        Ab = np.block([[s.A, np.zeros((n, nf))], [B_F @ s.C, A_F]])
        Bb = np.block([[s.B, np.zeros((n, s.D.shape[1]))], [np.zeros((nf, s.B.shape[1])), B_F @ s.D]])
        Cb = np.hstack([s.L, -C_F])

        w = np.geomspace(1e-3, np.pi / dt, n_freq)
        g = _gains(Ab, Bb, Cb, w, dt)
        k = int(np.argmax(g))
        fine = np.linspace(w[max(k - 1, 0)], w[min(k + 1, n_freq - 1)], 400)
        worst = max(worst, g.max(), _gains(Ab, Bb, Cb, fine, dt).max())
    return worst


@pytest.fixture(scope="module")
def open_loop_design():
    poly = flexible_attitude(splits=8)
    return poly, hn.synthesize_polytopic(poly, form="observer", lyapunov="parameter-dependent", solver="CLARABEL")


@pytest.mark.slow
def test_flexible_attitude_open_loop_20pct_designs_and_certifies(open_loop_design, tmp_path):
    poly, res = open_loop_design
    assert res.form == "observer" and "constant in time" in res.covers and "x[2], x[3]" in res.covers
    # observer structure to round-off: A_F = A₀ + B_F C₀ (C₀ common), C_F = −L
    c = poly.center()
    assert np.allclose(res.A_F, c.A + res.B_F @ c.C, atol=1e-12) and np.array_equal(res.C_F, -c.L)
    # independent dense worst case (every cell's vertices and 4 interior points each, full error system)
    rng = np.random.default_rng(1)
    eye = np.eye(poly.n_vertices)
    alphas = [eye[i] for i in range(poly.n_vertices)]
    for cell in poly.cells:
        alphas += list(rng.dirichlet(np.ones(len(cell)), size=4) @ eye[list(cell)])
    worst = _full_error_response_worst(poly, alphas, res.A_F, res.B_F, res.C_F, poly.dt)
    assert worst <= res.gamma * (1 + 1e-9)
    assert worst >= 0.5 * res.verified_norm  # the grid resolves the peaks (a loose sanity bound)
    # saved with its witness and cells, and re-certified in float64 without a solver
    path = save_design(res, poly, tmp_path / "flex.json")
    rep = hn.recertify(path)
    assert rep["ok"], rep["reasons"]


@pytest.mark.slow
def test_flexible_attitude_closed_loop_20pct_designs_and_certifies():
    poly = flexible_attitude_closed_loop(splits=8)
    assert all(np.max(np.abs(np.linalg.eigvals(v.A))) < 1 for v in poly.vertices)
    res = hn.synthesize_polytopic(poly, form="observer", lyapunov="parameter-dependent", solver="CLARABEL")
    # in closed loop the uncertainty reads the whole state (through the control input): x_s = x
    assert "x[0], x[1], x[2], x[3]" in res.covers
    rng = np.random.default_rng(2)
    eye = np.eye(poly.n_vertices)
    alphas = [eye[i] for i in range(poly.n_vertices)]
    for cell in poly.cells:
        alphas += list(rng.dirichlet(np.ones(len(cell)), size=3) @ eye[list(cell)])
    assert _full_error_response_worst(poly, alphas, res.A_F, res.B_F, res.C_F, poly.dt) <= res.gamma * (1 + 1e-9)


def test_drift_simulation_matches_the_error_system_and_its_energy_bound():
    from hinfnav.sim.drift import cell_sweep_weights, simulate_drift

    poly = flexible_attitude()
    c = poly.center()
    B_F = np.array([[-0.5], [-1.0], [0.0], [0.0]])  # a stabilising rigid-body gain (|eig(A + B_F C)| < 1 checked)
    A_F, C_F = c.A + B_F @ c.C, -c.L
    assert np.max(np.abs(np.linalg.eigvals(A_F))) < 1
    rng = np.random.default_rng(3)
    K = 400
    w, v = rng.standard_normal((K, 1)), rng.standard_normal((K, 1))
    alphas = cell_sweep_weights(poly, np.full(K, 0.5), 0.5)  # constant: the barycentre
    assert np.allclose(alphas, 0.25)
    run = simulate_drift(poly, A_F, B_F, C_F, alphas, w, v)
    # independent: the same run by control.forced_response of the full error system (13)–(14), 1e-9
    import control
    n = 4
    Ab = np.block([[c.A, np.zeros((n, n))], [B_F @ c.C, A_F]])
    Bb = np.block([[c.B, np.zeros((n, 1))], [np.zeros((n, 1)), B_F @ c.D]])
    out = control.forced_response(control.ss(Ab, Bb, np.hstack([c.L, -C_F]), 0, 0.1), U=np.vstack([w.T, v.T]))
    assert np.allclose(run.e[:, 0], np.ravel(out.outputs), atol=1e-9 * max(1.0, np.abs(run.e).max()))
    assert np.allclose(run.error_energy[-1], np.sum(run.e ** 2)) and run.gain > 0


def test_toml_cells_are_read_and_checked(tmp_path):
    from pathlib import Path

    from hinfnav.core.exceptions import InputError
    from hinfnav.systems import read_system_file

    root = Path(__file__).resolve().parents[1]
    poly = read_system_file(root / "examples" / "flexible_attitude_20pct.toml")
    ref = flexible_attitude(splits=8)  # the file is generated from it (examples/make_flexible_attitude.py): exact
    assert poly.cells == ref.cells and all(np.array_equal(a.A, b.A) and np.array_equal(a.B, b.B)
                                           for a, b in zip(poly.vertices, ref.vertices))
    text = (root / "examples" / "two_mass_spring_30pct.toml").read_text(encoding="utf-8")
    for bad, match in (('cells = "all"', "cells"), ("cells = [[0, 5]]", "vertex indices"), ("cells = [[0]]", "every")):
        f = tmp_path / "c.toml"
        f.write_text(text.replace('kind = "polytope"', 'kind = "polytope"\n' + bad), encoding="utf-8")
        with pytest.raises(InputError, match=match):
            read_system_file(f)


@pytest.mark.slow
def test_flexible_attitude_from_the_cli_designs(capsys):
    import json
    from pathlib import Path

    from hinfnav.cli import main

    root = Path(__file__).resolve().parents[1]
    rc = main(["design", "--system", str(root / "examples" / "flexible_attitude_20pct.toml"), "--form", "observer",
               "--solver", "CLARABEL", "--json"])
    out = capsys.readouterr()
    assert rc == 0, out.err
    rep = json.loads(out.out)
    assert rep["form"] == "observer" and rep["verified_worst_norm"] <= rep["gamma"] and "cells" in rep["covers"]


@pytest.mark.slow
def test_flexible_attitude_closed_loop_20pct_general_form_on_cells(tmp_path):
    poly = flexible_attitude_closed_loop(splits=8)
    res = hn.synthesize_polytopic(poly, form="general", lyapunov="parameter-dependent", solver="CLARABEL")
    assert res.form == "general" and "each cell" in res.covers
    rng = np.random.default_rng(5)
    eye = np.eye(poly.n_vertices)
    alphas = [eye[i] for i in range(poly.n_vertices)]
    for cell in poly.cells:
        alphas += list(rng.dirichlet(np.ones(len(cell)), size=3) @ eye[list(cell)])
    assert _full_error_response_worst(poly, alphas, res.A_F, res.B_F, res.C_F, poly.dt) <= res.gamma * (1 + 1e-9)
    rep = hn.recertify(save_design(res, poly, tmp_path / "clgen.json"))
    assert rep["ok"], rep["reasons"]
