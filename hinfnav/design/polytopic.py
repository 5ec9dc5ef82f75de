"""Certified robust H∞ filters on polytopes: common or parameter-dependent Lyapunov matrices.

:func:`synthesize_polytopic` minimizes γ² subject to the extended bounded real
LMI (E1) of :mod:`hinfnav.lmi.polytopic` at every vertex of a
:class:`~hinfnav.systems.PolytopicSystem`, and certifies the returned filter
independently of the solver's status:

1. (E1) is re-evaluated in float64 at the returned filter (``G Ā`` and
   ``G B̄`` recomputed from the filter matrices, not taken from the solver)
   and the solver's ``Pᵢ`` and ``G``; the smallest γ making it positive
   definite at every vertex is found by a Schur complement confirmed by an
   eigenvalue test (:func:`hinfnav.analysis.certificates.schur_gamma`). This
   is the result's ``gamma``; :func:`certify_polytopic` does it from a saved
   witness alone (no solver).
2. The H∞ norm of the error system is computed (SLICOT ab13dd) on a dense
   grid of the simplex plus its vertices (:func:`simplex_grid`); every
   sample must be Schur stable with a norm ≤ ``gamma``.

What the certificate covers is stated in ``covers``: with one common
Lyapunov matrix, every arbitrarily time-varying α(k) in the simplex
(quadratic stability); with parameter-dependent ones, every α constant in
time (a Lyapunov function ``ξᵀ(Σ αᵢ Pᵢ)ξ`` for each α).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Mapping
from typing import Any

import control
import numpy as np
from numpy.typing import ArrayLike

from ..analysis.certificates import certify_negative_definite, schur_gamma
from ..analysis.error_system import worst_case_norm
from ..analysis.norms import h2_norm, hinf_norm
from ..core.exceptions import CertificationError, InfeasibleLMIError, InputError, UnstablePlantError
from ..core.linalg import spectral_radius
from ..core.validation import as_choice, as_int_at_least
from ..lmi.polytopic import extended_h2_matrices, extended_hinf_positive, hinf_gamma_index, polytopic_problem
from ..lmi.conditioning import noise_scale, pow2, round_mantissa, unit_scaling
from ..lmi.solve import INFEASIBLE, SOLVERS
from ..systems.polytopic import PolytopicSystem, simplex_grid
from ..systems.uncertain import UncertainSystem
from .augmented import DOUBLING, augmented_norms, certify_augmented, design_augmented_observer, needs_augmented
from .cells import certify_cells_general, design_cells_general
from .explain import small_gain_number, unstable_plant_message
from .certify_loop import Check, solve_and_certify
from .result import COVERS_NOMINAL, DesignResult

__all__ = ["LYAPUNOV", "COVERS", "synthesize_polytopic", "certify_polytopic",
           "sampled_norms", "error_coordinates", "observer_nominal"]

#: Lyapunov structures :func:`synthesize_polytopic` accepts.
LYAPUNOV = ("common", "parameter-dependent")

#: What each certificate covers.
COVERS = {
    "common": "every arbitrarily time-varying α(k) in the simplex (one quadratic Lyapunov function)",
    "parameter-dependent": "every α constant in time in the simplex (uncertainty constant in time; "
                           "Lyapunov matrix Σ αᵢ Pᵢ)",
}


def _vertex_tuples(system):
    return [(v.A, v.B, v.C, v.D, v.L) for v in system.vertices]


def error_coordinates(vertex, A_F, B_F, C_F, form):
    """``(Ā, B̄, C̄)`` of the error system at one vertex ``(A, B, C, D, L)``.

    General form: ``ξ = [x; x_f]`` (13)–(14). Observer form: the error
    ``e = x + x_f`` alone, ``(A_F, [B, B_F D], L)`` (exact when A, C, L are
    the vertex's nominal ones; its transfer function equals the general one).
    """
    A, B, C, D, L = vertex
    n, p = B.shape
    q = D.shape[1]
    if form == "observer":
        return A_F, np.hstack([B, B_F @ D]), L
    nf = A_F.shape[0]
    Abar = np.block([[A, np.zeros((n, nf))], [B_F @ C, A_F]])
    Bbar = np.block([[B, np.zeros((n, q))], [np.zeros((nf, p)), B_F @ D]])
    return Abar, Bbar, np.hstack([L, -C_F])


def certify_polytopic(system: PolytopicSystem, A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike,
                      witness: Mapping[str, Any], form: str = "general") -> tuple[float, list[float]]:
    """Smallest γ for which (E1) holds in float64 at every vertex with the witness ``P``, ``G`` (no solver).

    Returns
    -------
    gamma : float
        The largest over the vertices (``inf`` if (E1) fails at some vertex
        for every γ).
    per_vertex : list of float
    """
    if "W" in witness:
        return _certify_h2(system, A_F, B_F, C_F, witness, form)
    if "T" in witness:  # observer form on the augmented error system [x_s; e] (issue 30)
        return certify_augmented(system, A_F, B_F, C_F, witness)
    if "cells" in witness:  # general form, one slack and Lyapunov matrices per cell (issue 30)
        return certify_cells_general(system, A_F, B_F, C_F, witness)
    P_list, G = witness["P"], np.asarray(witness["G"], dtype=float)
    if len(P_list) != system.n_vertices:
        raise InputError(f"the witness has {len(P_list)} Lyapunov matrices for {system.n_vertices} vertices")
    per = []
    for vert, P in zip(_vertex_tuples(system), P_list):
        Abar, Bbar, Cbar = error_coordinates(vert, A_F, B_F, C_F, form)
        P = np.asarray(P, dtype=float)
        if P.shape != (Abar.shape[0],) * 2 or G.shape != P.shape:
            raise InputError(f"the witness has P of shape {P.shape} and G of shape {G.shape}; the error system "
                             f"has {Abar.shape[0]} states")
        # noise far from unit scale: (E1) is tested as T N T, T = diag(I, I, I/r, I) with r a power of two (exact in
        # floating point), at level γ/r: the same inequality, with the eigenvalue tolerance at the unit scale
        s = float(np.linalg.norm(Bbar, 2))
        r = pow2(s) if s > 0 and np.isfinite(s) and not NOISE_WINDOW[0] <= s <= NOISE_WINDOW[1] else 1.0
        N0 = extended_hinf_positive(P, G @ Abar, G @ (Bbar / r), Cbar, G, 0.0)
        idx = hinf_gamma_index(Abar.shape[0], Bbar.shape[1])
        g, _ = schur_gamma(-N0, idx)
        g *= r
        # states far from unit scale (other state units, issue 36): the same inequality tested as D N D, D =
        # diag(d, d, I, I), d_i the power of two nearest 1/√P_ii (exact in floating point; the coordinates ξ = D ξ̂ in
        # which P has a unit diagonal, B̄ → D⁻¹B̄ for the noise scale); either value is a certificate
        dP = np.diag(P)
        if np.all(dP > 0) and np.all(np.isfinite(dP)):
            d = np.array([pow2(1.0 / np.sqrt(x)) for x in dP])
            if np.any(d != 1.0):
                s2 = float(np.linalg.norm(Bbar / d[:, None], 2))
                r2 = pow2(s2) if s2 > 0 and np.isfinite(s2) and not NOISE_WINDOW[0] <= s2 <= NOISE_WINDOW[1] else 1.0
                N2 = extended_hinf_positive(P, G @ Abar, G @ (Bbar / r2), Cbar, G, 0.0)
                dd = np.concatenate([d, d, np.ones(N2.shape[0] - 2 * d.size)])
                g = min(g, schur_gamma(-(dd[:, None] * N2 * dd[None, :]), idx)[0] * r2)
        per.append(g)
    return max(per), per


def _certify_h2(system, A_F, B_F, C_F, witness, form):
    """Certified H2 bound from (E2) in float64: both matrices positive definite at every vertex (internal)."""
    P_list, G, W = witness["P"], np.asarray(witness["G"], dtype=float), np.asarray(witness["W"], dtype=float)
    if len(P_list) != system.n_vertices:
        raise InputError(f"the witness has {len(P_list)} Lyapunov matrices for {system.n_vertices} vertices")
    scale = max(abs(np.trace(W)), np.finfo(float).tiny)
    for eps in (0.0, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4):
        Wc = W + eps * scale * np.eye(W.shape[0])
        ok = True
        for vert, P in zip(_vertex_tuples(system), P_list):
            Abar, Bbar, Cbar = error_coordinates(vert, A_F, B_F, C_F, form)
            P = np.asarray(P, dtype=float)
            if P.shape != (Abar.shape[0],) * 2 or G.shape != P.shape or Wc.shape != (Bbar.shape[1],) * 2:
                raise InputError("the witness's P, G or W does not fit the error system's dimensions")
            M1, M2 = extended_h2_matrices(P, G @ Abar, G @ Bbar, Cbar, G, Wc)
            if not (certify_negative_definite(-M1)[0] and certify_negative_definite(-M2)[0]):
                ok = False
                break
        if ok:
            g = float(np.sqrt(max(np.trace(Wc), 0.0)))
            return g, [g] * system.n_vertices
    return float("inf"), [float("inf")] * system.n_vertices


def sampled_norms(system, A_F, B_F, C_F, form="general", alphas=None, objective="hinf", witness=None):
    """H∞ norms of the error system at convex weights ``alphas`` (default: :func:`simplex_grid`).

    A ``witness`` with ``T`` (observer form whose uncertainty reads part of
    the state) selects the augmented error system of
    :mod:`hinfnav.analysis.marginal`. Returns ``(norms, spectral_radii, alphas)``.
    """
    if alphas is None:
        alphas = simplex_grid(system.n_vertices, points=41 if system.n_vertices <= 2 else 200,
                              n_random=0 if system.n_vertices <= 2 else 20)
    if witness is not None and "T" in witness:
        return (*augmented_norms(system, A_F, B_F, C_F, witness, alphas), np.asarray(alphas))
    norms, radii = [], []
    for a in alphas:
        s = system.at(a)
        if objective == "h2":
            Ab, Bb, Cb = error_coordinates((s.A, s.B, s.C, s.D, s.L), A_F, B_F, C_F, form)
            radii.append(spectral_radius(Ab))
            norms.append(h2_norm(control.ss(Ab, Bb, Cb, np.zeros((Cb.shape[0], Bb.shape[1])), True)))
        elif form == "observer":
            Ab, Bb, Cb = error_coordinates((s.A, s.B, s.C, s.D, s.L), A_F, B_F, C_F, form)
            radii.append(spectral_radius(Ab))
            norms.append(hinf_norm(control.ss(Ab, Bb, Cb, np.zeros((Cb.shape[0], Bb.shape[1])), True)))
        else:
            wc = worst_case_norm(s, A_F, B_F, C_F, dt=1.0)
            radii.append(float(wc.spectral_radii[0]))
            norms.append(wc.norm)
    return np.array(norms), np.array(radii), np.asarray(alphas)


def _check(system, form):
    if form == "observer":
        varying = [k for k in system.varying() if k in ("A", "C", "L")]
        if varying:
            raise InputError(
                f"form='observer' needs the uncertainty not to multiply the plant state, but {', '.join(varying)} "
                "differ between the vertices: the estimation error then contains ΔA x (or ΔC x, ΔL x), driven by the "
                "plant trajectory, so the error system carries the plant state. Use form='general' (needs the plant "
                "Schur stable at every vertex), or keep A, C and L common to all vertices.")
        return
    for i, v in enumerate(system.vertices):
        rho = spectral_radius(v.A)
        if not rho < 1.0:
            raise UnstablePlantError(unstable_plant_message(rho, f"vertex {i} ({system.labels[i]})"))


def synthesize_polytopic(system: PolytopicSystem, *, lyapunov: str = "parameter-dependent", form: str = "general",
                         solver: str | None = None, grid_points: int | None = None, seed: int | np.random.Generator = 0,
                         objective: str = "hinf", state_scaling: str | None = None,
                         _steps: tuple | None = None) -> DesignResult:
    """Certified H∞ filter for every system of a polytope (extended LMIs, de Oliveira et al. 2002).

    Parameters
    ----------
    system : PolytopicSystem
        The vertices (a single vertex: the nominal H∞ filter).
    lyapunov : {"parameter-dependent", "common"}, optional
        One Lyapunov matrix per vertex (certifies α constant in time), or one
        for all (certifies arbitrarily time-varying α(k)).
    form : {"general", "observer"}, optional
        Any full-order filter (needs the plant Schur stable at each vertex),
        or a predictor observer ``C_F = −L``, ``A_F = A + B_F C`` (needs only
        detectability; A, C, L must be common to all vertices).
    solver : str, optional
        cvxpy solver; default Clarabel, then CVXOPT if Clarabel's answer
        does not certify.
    grid_points : int, optional
        Lattice points of the simplex for the sampled norms (default 41 for
        two vertices, 200 plus 20 random points otherwise).
    seed : int, optional
        Seed of the random simplex points.
    objective : {"hinf", "h2"}, optional
        ``"h2"``: minimize the H2 bound ``tr W`` of the extended H2 LMIs (E2)
        instead (same filter parametrization; the result's norms are H2).
    state_scaling : {None, "units"}, optional
        ``"units"``: solve in the coordinates ``x = diag(σ) x̃`` of
        :func:`hinfnav.lmi.conditioning.unit_scaling` (σ moves with the state
        units, so the solver sees the same data whatever units the file is
        written in) and map the filter and witness back; the result is
        certified on the original data (issue 36). ``None``: as given.

    Returns
    -------
    DesignResult
        With ``uncertainty="polytope"``, ``lyapunov``, ``covers``, ``alphas``
        (the convex weights sampled) and ``witness`` (``P`` per vertex, ``G``;
        ``W`` for H2) that :func:`certify_polytopic` re-checks.

    Raises
    ------
    InputError, UnstablePlantError, InfeasibleLMIError, CertificationError
    """
    t0 = time.perf_counter()
    if not isinstance(system, PolytopicSystem):
        raise InputError(f"system must be a hinfnav PolytopicSystem; got {type(system).__name__}")
    lyapunov = as_choice("lyapunov", lyapunov, LYAPUNOV)
    form = as_choice("form", form, ("general", "observer"))
    objective = as_choice("objective", objective, ("hinf", "h2"))
    solvers = ("CLARABEL", "CVXOPT") if solver is None else (as_choice("solver", str(solver).upper(), SOLVERS),)
    if not np.any([np.any(v.L) for v in system.vertices]):
        raise InputError("L is zero at every vertex: the estimated signal z = L x is identically 0, so there is "
                         "nothing to estimate (the zero filter is exact); give a nonzero L")
    N = system.n_vertices
    if grid_points is None:
        alphas = simplex_grid(N, points=41 if N <= 2 else 200, n_random=0 if N <= 2 else 20, seed=seed)
    else:
        alphas = simplex_grid(N, points=as_int_at_least("grid_points", grid_points, 1), n_random=0, seed=seed)
    if state_scaling is not None and as_choice("state_scaling", state_scaling, ("units",)) == "units":
        return _in_unit_free_coordinates(system, lyapunov=lyapunov, form=form, solver=solver, grid_points=grid_points,
                                         seed=seed, objective=objective)
    if form == "observer" and objective == "hinf" and needs_augmented(system):
        return _augmented_result(system, lyapunov, solvers, alphas, t0, _steps)
    _check(system, form)
    if form == "general" and objective == "hinf" and system.cells:
        return _cells_result(system, lyapunov, solvers, t0, _steps)
    verts = _vertex_tuples(system)
    rho = _noise_normalisation(verts) if objective == "hinf" else 1.0
    if rho != 1.0:  # (E1) with B̄/ρ at level γ²/ρ² is a congruence of (E1): same witness, γ × ρ (issue 36)
        verts = [(A, B / rho, C, D / rho, L) for A, B, C, D, L in verts]
    problem = polytopic_problem(verts, form, lyapunov, objective=objective)  # built once, re-solved below

    def solve(slv, level):
        if rho == 1.0:
            return problem.solve(slv, level)
        sol = problem.solve(slv, level if level is None or isinstance(level, str) else level / rho**2)
        return dataclasses.replace(sol, gamma2=sol.gamma2 * rho**2)

    def certify(_, sol):
        out = _rebuild_and_certify(system, sol.as_dict(), form, alphas, objective)
        return Check(out[-1], out[0], "certified" if out[-1] else "not certified", out)

    # the one certify loop (hinfnav.design.certify_loop): each solver's minimisation, stopping when one certifies
    # within 1e-5 of its own level; then an interior point just above the lowest level (no bisection)
    run = solve_and_certify([("as given", solve)], list(solvers), certify, rtol=1e-5, max_bisection=0,
                            steps=(1e-5, 1e-4, 1e-3, 1e-2, 1e-1) if _steps is None else _steps)
    log, seconds = run.log, run.seconds
    statuses = [f"{slv} {st}" for slv, st in run.statuses]
    top = run.best()
    best = None if top is None else (top.check.data, None, top.solver, top.level)
    if best is None:
        if all(any(s.endswith(st) for st in INFEASIBLE) or "solver error" in s for s in statuses):
            hint = (" With one common Lyapunov matrix the filter must work for arbitrarily time-varying α(k); "
                    "lyapunov='parameter-dependent' only asks for α constant in time and is less conservative."
                    if lyapunov == "common" and N > 1 else
                    " Reduce the uncertainty (a smaller polytope) or check that the plant is detectable from y.")
            if N == 2 and set(system.varying()) <= {"A"}:
                nb = system.norm_bounded_cover()
                hint += (f" The small-gain number of the polytope written as A₀ + H F E (‖E(zI − A₀)⁻¹H‖∞, H of rank "
                         f"{nb.H.shape[1]}) is {small_gain_number(nb.A, nb.H, nb.E):.4g}: at or above 1 no single "
                         "quadratic Lyapunov function exists for time-varying F.")
            raise InfeasibleLMIError("no solver found a solution of the extended LMIs ((E1) for H∞, (E2) for H2) at the vertices: "
                                     "infeasible, or too ill-conditioned to solve (solver status: "
                                     + "; ".join(statuses) + ")." + hint)
        raise CertificationError("no solution of the extended LMIs passed certification: " + " | ".join(log))
    (gamma_c, A_F, B_F, C_F, witness, norms, radii, ok), _, slv, g_s = best
    k = int(np.argmax(norms))
    return DesignResult(
        A_F=A_F, B_F=B_F, C_F=C_F, gamma=float(gamma_c), lmi_gamma=g_s, uncertainty="polytope", verified_norm=float(norms[k]),
        sample_norms=norms, alphas=alphas, worst_sample=k, spectral_radius=float(np.max(radii)),
        lyapunov=lyapunov, form=form, covers=COVERS[lyapunov], witness=witness, solver=slv,
        solve_time_s=seconds, total_time_s=time.perf_counter() - t0, dt=system.dt, attempts=tuple(log),
        system=system, objective=objective, solver_calls=run.calls,
    )


#: Noise scales (max ‖B‖₂, ‖D‖₂ over the vertices) outside this window are normalised to 1 before solving.
NOISE_WINDOW = (1e-2, 1e2)


def _noise_normalisation(verts):
    """ρ dividing B and D of every vertex before the solve (internal; issue 36: γ scales with the noise).

    1 (nothing done, so existing designs are unchanged to the bit) when the
    noise scale ``s = max_i max(‖Bᵢ‖₂, ‖Dᵢ‖₂)`` is inside
    :data:`NOISE_WINDOW`; otherwise ``s``: the solvers fail on (E1) with
    noise of 1e-7 (double integrator, B, D × 1e-6: "optimal_inaccurate",
    nothing certified) or 1e5 ("infeasible"). (E1) of ``(B/ρ, D/ρ)`` at
    ``γ²/ρ²`` is ``T N T`` with ``T = diag(I, I, I/ρ, I)``: the same
    witness certifies γ for the original data.
    """
    s = max(max(np.linalg.norm(B, 2), np.linalg.norm(D, 2)) for _, B, _, D, _ in verts)
    if not (s > 0 and np.isfinite(s)) or NOISE_WINDOW[0] <= s <= NOISE_WINDOW[1]:
        return 1.0
    return float(s)


def _augmented_result(system, lyapunov, solvers, alphas, t0, steps=None):
    """Observer form when A, C or L vary: the augmented error system [x_s; e] (:mod:`.augmented`; internal)."""
    out = design_augmented_observer(system, lyapunov, solvers, alphas if not system.cells else None,
                                    steps=steps + DOUBLING if steps is not None else DOUBLING)
    alphas = out["alphas"]
    if not out["ok"]:
        if all(any(s.endswith(st) for st in INFEASIBLE) for s in out["statuses"]):
            raise InfeasibleLMIError(
                "no solver found a solution of the extended LMI (E1) on the augmented error system [x_s; e] (observer "
                "form, the uncertainty reading the states " + ", ".join(f"x[{j}]" for j in out["part"].states)
                + "); solver status: " + "; ".join(out["statuses"]) + ". With lyapunov='common' try "
                "'parameter-dependent' (α constant in time); otherwise reduce the uncertainty.")
        raise CertificationError("no solution of the augmented observer LMI passed certification: "
                                 + " | ".join(out["log"] or out["statuses"]))
    norms, k = out["norms"], int(np.argmax(out["norms"]))
    states = ", ".join(f"x[{j}]" for j in out["part"].states)
    return DesignResult(
        A_F=out["A_F"], B_F=out["B_F"], C_F=out["C_F"], gamma=float(out["gamma"]), lmi_gamma=out["lmi_gamma"],
        uncertainty="polytope", solver_calls=out["calls"],
        verified_norm=float(norms[k]), sample_norms=norms, alphas=alphas, worst_sample=k,
        spectral_radius=float(np.max(out["radii"])), lyapunov=lyapunov, form="observer",
        covers=COVERS[lyapunov].replace("in the simplex", "in the simplex of each cell (the union of the cells' hulls)"
                                        if system.cells else "in the simplex")
        + f"; the error system is augmented with the states the uncertainty reads ({states})",
        witness=out["witness"], solver=out["solver"], solve_time_s=out["seconds"],
        total_time_s=time.perf_counter() - t0, dt=system.dt, attempts=tuple(out["log"]), system=system,
        objective="hinf")


def _cells_result(system, lyapunov, solvers, t0, steps=None):
    """General form on a polytope with cells: :mod:`.cells` (internal)."""
    out = design_cells_general(system, lyapunov, solvers,
                               *(() if steps is None else (steps + (0.2, 1.0),)))
    if not out["ok"]:
        raise CertificationError("no general-form solution of (E1) on the cells passed certification (solver status: "
                                 + "; ".join(out["statuses"]) + "): " + " | ".join(out["log"]))
    norms, k = out["norms"], int(np.argmax(out["norms"]))
    return DesignResult(
        A_F=out["A_F"], B_F=out["B_F"], C_F=out["C_F"], gamma=float(out["gamma"]), lmi_gamma=out["lmi_gamma"],
        uncertainty="polytope", solver_calls=out["calls"],
        verified_norm=float(norms[k]), sample_norms=norms, alphas=out["alphas"], worst_sample=k,
        spectral_radius=float(np.max(out["radii"])), lyapunov=lyapunov, form="general",
        covers=COVERS[lyapunov].replace("in the simplex", "in the simplex of each cell (the union of the cells' hulls)"),
        witness=out["witness"], solver=out["solver"], solve_time_s=out["seconds"],
        total_time_s=time.perf_counter() - t0, dt=system.dt, attempts=tuple(out["log"]), system=system,
        objective="hinf")


def _rebuild_and_certify(system, sol, form, alphas, objective="hinf"):
    """Filter from the solver's variables, (E1) in float64, sampled norms; a tuple ending in ok (internal)."""
    fail = (float("inf"), None, None, None, None, None, None, False)
    if form == "observer":
        A, C, L = system.vertices[0].A, system.vertices[0].C, system.vertices[0].L
        G = sol["G"]
        if not np.linalg.cond(G) < 1e14:
            return fail
        B_F = np.linalg.solve(G, sol["Ghat"])
        A_F, C_F = A + B_F @ C, -L.copy()
    else:
        V = sol["V"]
        if not np.linalg.cond(V) < 1e14:
            return fail
        A_F, B_F, C_F = np.linalg.solve(V, sol["Ahat"]), np.linalg.solve(V, sol["Bhat"]), sol["C_F"].copy()
    witness = {"P": [np.array(P) for P in sol["P"]], "G": np.array(sol["G"])}
    if objective == "h2":
        witness["W"] = 0.5 * (sol["W"] + sol["W"].T)
    gamma_c, _ = certify_polytopic(system, A_F, B_F, C_F, witness, form)
    if not np.isfinite(gamma_c):
        return fail
    norms, radii, _ = sampled_norms(system, A_F, B_F, C_F, form, alphas, objective)
    ok = bool(np.all(radii < 1.0) and np.max(norms) <= gamma_c * (1 + 1e-9))
    return gamma_c, A_F, B_F, C_F, witness, norms, radii, ok


def observer_nominal(system, dt, solvers, t_start, state_scaling=None):
    """Nominal observer-form filter of a plant that need not be stable, as a norm-bounded :class:`DesignResult`.

    The estimation error ``e⁺ = (A + B_F C) e + B w + B_F D v`` does not
    contain the plant state, so only (A, C) detectable is needed; designed by
    :func:`synthesize_polytopic` on the single vertex (internal, used by
    :func:`hinfnav.design.synthesize` with ``form="observer"`` and no
    uncertainty). The certificate is (E1) in error coordinates and the norm of
    the error-coordinate system; the witness is in ``variables``.
    """
    system = UncertainSystem(system.A, system.B, system.C, system.D, system.L, dt=1.0 if dt is True else dt)
    poly = PolytopicSystem((system,), system.dt)
    res = synthesize_polytopic(poly, lyapunov="common", form="observer", solver=solvers[0] if len(solvers) == 1 else None,
                               state_scaling=state_scaling)
    return dataclasses.replace(
        res, worst_sample=0, total_time_s=time.perf_counter() - t_start, method="minimize", dt=dt,
        witness={"P": res.witness["P"], "G": res.witness["G"], "lyapunov": "common",
                 "coordinates": "estimation error e = x + x_f (observer form)"},
        attempts=res.attempts + ("nominal observer form in error coordinates: the plant need not be stable",),
        samples=(None,), system=system, uncertainty="norm-bounded", alphas=None, covers=COVERS_NOMINAL,
    )


def _in_unit_free_coordinates(system, **kw):
    """:func:`synthesize_polytopic` in the unit-free state coordinates, certified on the original data (internal).

    With ``x = T x̃``, ``T = diag(σ)`` from :func:`~hinfnav.lmi.conditioning.unit_scaling` (on ``Σ|Aᵢ|`` and
    the row norms of the ``Bᵢ`` against the column norms of the ``[Cᵢ; Lᵢ]``), each vertex is ``(T⁻¹AᵢT, T⁻¹Bᵢ, CᵢT, Dᵢ,
    LᵢT)``, rounded to :data:`~hinfnav.lmi.conditioning.SOLVER_DATA_BITS` bits so that the same plant in other
    units gives the solver bitwise the same data. The error system's transfer function, hence γ, is unchanged:

    * general form: the filter's input/output map does not depend on the plant's coordinates, so
      ``(A_F, B_F, C_F)`` is kept; ``ξ = S ξ̃`` with ``S = diag(T, I)``;
    * observer form (``A_F = A + B_F C``, ``C_F = −L``): ``B_F = T B̃_F``, ``A_F = T Ã_F T⁻¹``; ``e = T ẽ``,
      ``S = T``.

    (E1)/(E2) map by the congruence ``diag(S⁻ᵀ, S⁻ᵀ, I, I)``: ``P = S⁻ᵀ P̃ S⁻¹``, ``G = S⁻ᵀ G̃ S⁻¹``, ``W``
    unchanged. The mapped filter and witness are certified again by :func:`certify_polytopic` and the sampled
    norms on the ORIGINAL vertices; if that fails in float64 (conditioning), the design is redone as given and
    the result's ``attempts`` say so. The augmented observer (``ζ = [x_s; e]``, :mod:`.augmented`) maps with
    ``S = blkdiag(T diag(σ) T̃ᵀ, diag(σ))``, ``T`` the orthonormal rows spanning ``T̃ diag(σ)⁻¹`` (the read part in
    the original coordinates); cells map as the general form, G per cell. The scaled solve takes interior points
    from 1e-7 above the solver's level (its minimiser may sit on the LMI's boundary).
    """
    t0 = time.perf_counter()
    form, objective = kw["form"], kw["objective"]
    augmented = form == "observer" and objective == "hinf" and needs_augmented(system)
    verts = system.vertices
    # the coupling K = Σ|Aᵢ| + u vᵀ (u_i: norm of row i of every Bᵢ, v_j: norm of column j of every [Cᵢ; Lᵢ]) moves
    # with the units as A does (K_ij ∝ t_j / t_i) and closes the chains of a double integrator, which |A| alone
    # leaves open (Osborne's iteration then cannot remove a position/velocity unit ratio)
    # (u from B/ρ₀, ρ₀ = noise_scale: unit-free and ∝ the noise, so σ does not move with B, D × k either)
    u = np.linalg.norm(np.hstack([v.B for v in verts]), axis=1) / max(noise_scale(v) for v in verts)
    w = np.linalg.norm(np.vstack([np.vstack([v.C, v.L]) for v in verts]), axis=0)
    # (2000 sweeps: the flexible attitude polytope needs ~1000 to converge to 1e-13; the iteration stops when converged)
    sig = unit_scaling(sum(np.abs(v.A) for v in verts), u[:, None], w[None, :], sweeps=2000)
    if not (np.all(np.isfinite(sig)) and np.all(sig > 0)):
        sig = np.ones(verts[0].A.shape[0])
    scaled = PolytopicSystem(tuple(dataclasses.replace(
        v, A=round_mantissa(v.A * sig[None, :] / sig[:, None]), B=round_mantissa(v.B / sig[:, None]),
        C=round_mantissa(v.C * sig[None, :]), L=round_mantissa(v.L * sig[None, :])) for v in verts),
        system.dt, system.labels, system.cells)
    try:  # interior points from 1e-7 above the solver's level: the minimiser may sit on the LMI's boundary
        res = synthesize_polytopic(scaled, **kw, _steps=(1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
                                   if not augmented else (1e-7, 1e-6, 1e-5, 1e-4, 1e-3))
    except (InfeasibleLMIError, CertificationError) as exc:
        res, why = None, f"{type(exc).__name__}: {exc}"
    if res is not None:
        if augmented:
            # read part in the original coordinates: the row space of T̃ diag(σ)⁻¹, orthonormal rows (as read_part's)
            c, Tt = system.center(), np.atleast_2d(np.asarray(res.witness["T"], dtype=float))
            T = np.linalg.qr((Tt / sig[None, :]).T)[0].T
            M = T @ (sig[:, None] * Tt.T)
            B_F = sig[:, None] * res.B_F
            A_F, C_F = c.A + B_F @ c.C, -c.L.copy()
            S = None
        elif form == "observer":
            v0 = verts[0]
            B_F = sig[:, None] * res.B_F
            A_F, C_F = v0.A + B_F @ v0.C, -v0.L.copy()
            S = sig
        else:
            A_F, B_F, C_F = res.A_F, res.B_F, res.C_F
            S = np.concatenate([sig, np.ones(res.A_F.shape[0])])
        if S is None:
            Si = np.linalg.inv(np.block([[M, np.zeros((M.shape[0], sig.size))],
                                         [np.zeros((sig.size, M.shape[1])), np.diag(sig)]]))
            witness = dict(res.witness, P=[Si.T @ np.asarray(P) @ Si for P in res.witness["P"]],
                           G=np.einsum("ji,...jk,kl->...il", Si, np.asarray(res.witness["G"]), Si), T=T, C0=c.C.copy())
        else:
            cong = np.outer(1.0 / S, 1.0 / S)
            witness = dict(res.witness, P=[cong * np.asarray(P) for P in res.witness["P"]], G=cong * res.witness["G"])
        gamma_c, _ = certify_polytopic(system, A_F, B_F, C_F, witness, form)
        norms, radii, _ = sampled_norms(system, A_F, B_F, C_F, form, res.alphas, objective,
                                        witness=witness if augmented else None)
        if np.isfinite(gamma_c) and np.all(radii < 1.0) and np.max(norms) <= gamma_c * (1 + 1e-9):
            k = int(np.argmax(norms))
            return dataclasses.replace(
                res, A_F=A_F, B_F=B_F, C_F=C_F, gamma=float(gamma_c), verified_norm=float(norms[k]),
                sample_norms=norms, worst_sample=k, spectral_radius=float(np.max(radii)), witness=witness,
                system=system, total_time_s=time.perf_counter() - t0,
                attempts=res.attempts + ("solved in unit-free state coordinates x = diag(σ) x̃ (state_scaling="
                                         "'units'); filter and witness mapped back and certified on the original "
                                         "data",))
        why = (f"the design in unit-free coordinates (γ {res.gamma:.10g}) did not certify on the original data in "
               f"float64 (γ {gamma_c:.10g}, sampled worst {np.max(norms):.10g})")
    res = synthesize_polytopic(system, **kw)
    return dataclasses.replace(res, total_time_s=time.perf_counter() - t0,
                               attempts=res.attempts + (f"state_scaling='units' not used: {why}; designed in the "
                                                        "given state coordinates",))
