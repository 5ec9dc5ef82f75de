"""Observer-form filters for polytopes whose uncertainty reads part of the state: marginally stable plants.

A navigation plant has integrators (attitude, position), and the uncertainty
almost never sits on them: an appendage mode with an uncertain frequency, a
stiffness, a damping. The error of an observer-form filter built on the
polytope's centre ``(A₀, C₀, L₀)`` then contains ``ΔA x``, ``ΔC x``,
``ΔL x``, and stays bounded exactly when the part of x these read is (the
condition, its derivation and the augmented error system
``ζ = [x_s; e]`` are in :mod:`hinfnav.analysis.marginal`). This module
designs the gain on ζ (:mod:`hinfnav.lmi.augmented_observer`) and certifies
it as :func:`~hinfnav.design.synthesize_polytopic` does:

1. (E1) re-evaluated in float64 at every vertex on ζ at the returned filter
   and the solver's ``Pᵢ`` and G (:func:`certify_augmented`, from the saved
   witness alone: ``P``, ``G``, ``T`` and the filter's ``C₀``);
2. the H∞ norm of ζ's system on a dense grid of the simplex; every sample
   Schur stable with a norm ≤ γ.

What the certificate covers: ζ is exact for any α(k), so with one common
Lyapunov matrix the bound holds for arbitrarily time-varying α(k); with
parameter-dependent ones for every α constant in time. The transfer function
from ``[w; v]`` to ``z − z_f`` of the plant and filter (``ξ = [x; x_f]``,
marginally stable: the integrator modes are unobservable from the error) is
the one of ζ, which is what an independent check can compute.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import control
import numpy as np

from ..analysis.certificates import schur_gamma
from ..analysis.marginal import augmented_error_coordinates, check_read_part, read_part
from ..analysis.norms import hinf_norm
from ..core.exceptions import InputError
from ..core.linalg import spectral_radius
from ..lmi.augmented_observer import solve_augmented_observer
from ..lmi.polytopic import extended_hinf_positive, hinf_gamma_index
from ..lmi.solve import Solution
from ..systems.polytopic import simplex_grid
from .certify_loop import Check, Loop, loop_outcome, solve_and_certify

__all__ = ["needs_augmented", "certify_augmented", "augmented_norms", "design_augmented_observer", "cell_weights",
           "cell_alphas"]


#: Accept a certified minimisation within 2 % of the solver's level; bisect to 2 %.
TIGHT = 2e-2
#: Levels tried above the solver's γ when its point does not certify: ×1.01, then doubling (12 levels).
DOUBLING = tuple(1.01 * 2.0**k - 1.0 for k in range(12))


def _tuples(system):
    return [(v.A, v.B, v.C, v.D, v.L) for v in system.vertices]


def needs_augmented(system) -> bool:
    """Whether A, C or L differ between the vertices (the observer form's error then reads the plant state)."""
    return any(k in ("A", "C", "L") for k in system.varying())


def _cells(system, witness):
    """Each cell's weights (the whole polytope when the witness has none)."""
    if "cells" in witness:
        return [np.asarray(W, dtype=float) for W in witness["cells"]]
    return [np.eye(system.n_vertices)]


def certify_augmented(system, A_F, B_F, C_F, witness: Mapping[str, Any]) -> tuple[float, list[float]]:
    """Smallest γ for which (E1) holds in float64 on ζ at every vertex of every cell with the witness (no solver).

    ``witness`` holds ``cells`` (weights of each cell's vertices, optional),
    ``P`` (one per cell vertex, cell by cell), ``G`` (one per cell), ``T``
    (read state) and ``C0`` (the filter's measurement model).
    """
    T, C0 = np.atleast_2d(np.asarray(witness["T"], dtype=float)), np.asarray(witness["C0"], dtype=float)
    cells = _cells(system, witness)
    Gs = np.asarray(witness["G"], dtype=float)
    Gs = Gs[None] if Gs.ndim == 2 else Gs
    P_list = list(witness["P"])
    if len(Gs) != len(cells) or len(P_list) != sum(len(W) for W in cells):
        raise InputError(f"the witness has {len(Gs)} slack matrices and {len(P_list)} Lyapunov matrices for "
                         f"{len(cells)} cells of {[len(W) for W in cells]} vertices")
    per, k = [], 0
    for W, G in zip(cells, Gs):
        for a in W:
            s = system.at(a)
            Ab, Bb, Cb = augmented_error_coordinates((s.A, s.B, s.C, s.D, s.L), A_F, B_F, C_F, T, C0)
            P = np.asarray(P_list[k], dtype=float)
            k += 1
            if P.shape != Ab.shape or G.shape != Ab.shape:
                raise InputError(f"the witness has P of shape {P.shape} and G of shape {G.shape}; the augmented "
                                 f"error system has {Ab.shape[0]} states")
            per.append(e1_gamma(P, G, Ab, Bb, Cb))
    return max(per), per


def e1_gamma(P, G, Ab, Bb, Cb) -> float:
    """Smallest γ making (E1) positive definite in float64, as given or in unit-diagonal coordinates (internal).

    The second test is the same inequality as ``D N D``, ``D = diag(d, d, I, I)``, ``d_i`` the power of two
    nearest ``1/√P_ii`` (exact in floating point: the coordinates in which P has a unit diagonal, as a plant in
    other state units needs, issue 36), with noise far from unit scale (``‖D⁻¹B̄‖`` outside [1e-2, 1e2]) taken at
    the nearest power of two. Both are certificates; the smaller is returned.
    """
    idx = hinf_gamma_index(Ab.shape[0], Bb.shape[1])
    g = schur_gamma(-extended_hinf_positive(P, G @ Ab, G @ Bb, Cb, G, 0.0), idx)[0]
    dP = np.diag(P)
    if np.all(dP > 0) and np.all(np.isfinite(dP)):
        d = 2.0 ** np.round(np.log2(1.0 / np.sqrt(dP)))
        s2 = float(np.linalg.norm(Bb / d[:, None], 2))
        r2 = 2.0 ** round(np.log2(s2)) if s2 > 0 and np.isfinite(s2) and not 1e-2 <= s2 <= 1e2 else 1.0
        N2 = extended_hinf_positive(P, G @ Ab, G @ (Bb / r2), Cb, G, 0.0)
        dd = np.concatenate([d, d, np.ones(N2.shape[0] - 2 * d.size)])
        g = min(g, schur_gamma(-(dd[:, None] * N2 * dd[None, :]), idx)[0] * r2)
    return g


def augmented_norms(system, A_F, B_F, C_F, witness, alphas):
    """H∞ norms and spectral radii of ζ's system at the convex weights ``alphas``."""
    T, C0 = np.atleast_2d(np.asarray(witness["T"], dtype=float)), np.asarray(witness["C0"], dtype=float)
    norms, radii = [], []
    for a in alphas:
        s = system.at(a)
        Ab, Bb, Cb = augmented_error_coordinates((s.A, s.B, s.C, s.D, s.L), A_F, B_F, C_F, T, C0)
        radii.append(spectral_radius(Ab))
        norms.append(hinf_norm(control.ss(Ab, Bb, Cb, np.zeros((Cb.shape[0], Bb.shape[1])), system.dt))
                     if radii[-1] < 1.0 else float("inf"))
    return np.array(norms), np.array(radii)


def cell_weights(system) -> list[np.ndarray]:
    """The system's cells as weight matrices (row r: the convex weights of the cell's r-th vertex)."""
    if not system.cells:
        return [np.eye(system.n_vertices)]
    eye = np.eye(system.n_vertices)
    return [eye[list(c)] for c in system.cells]


def cell_alphas(system, points: int | None = None, n_random: int = 0, seed=0) -> np.ndarray:
    """Convex weights sampling every cell densely (the simplex grid of each cell mapped to the polytope)."""
    out = []
    for W in cell_weights(system):
        Nc = W.shape[0]
        pts = points if points is not None else (41 if Nc <= 2 else (200 if len(cell_weights(system)) == 1 else 35))
        out.append(simplex_grid(Nc, points=pts, n_random=n_random if Nc > 2 else 0, seed=seed) @ W)
    return np.unique(np.round(np.vstack(out), 15), axis=0)


def design_augmented_observer(system, lyapunov: str, solvers: Sequence[str], alphas=None,
                              names: Sequence[str] | None = None, steps: tuple = DOUBLING) -> dict[str, Any]:
    """Design and certify an observer-form filter on ζ (internal; wrapped by ``synthesize_polytopic``).

    With ``system.cells`` each cell has its own slack and Lyapunov matrices
    (:mod:`hinfnav.lmi.augmented_observer`) and the certificate covers the
    union of the cells; ``alphas`` (default :func:`cell_alphas`) should
    sample the cells.

    Returns
    -------
    dict
        ``ok`` and, when a filter certified, ``A_F, B_F, C_F, gamma, lmi_gamma,
        witness, norms, radii, solver``; always ``log``, ``statuses``,
        ``seconds``, ``calls`` (solver invocations), ``part`` (:class:`~hinfnav.analysis.marginal.ReadPart`),
        ``alphas``.

    Raises
    ------
    UnstablePlantError
        The part of the state the uncertainty reads is not Schur stable at some
        vertex (no filter has a bounded error; the message names the states).
    """
    c = system.center()
    nominal = (c.A, c.C, c.L)
    part = read_part(_tuples(system), nominal)
    check_read_part(part, system.labels, names)
    alphas = cell_alphas(system) if alphas is None else np.asarray(alphas)
    cells = cell_weights(system)
    verts = [[(lambda s: (s.A, s.B, s.C, s.D, s.L))(system.at(a)) for a in W] for W in cells]

    def solve(slv, gamma2=None):
        return Solution.from_dict(solve_augmented_observer(verts, part.T, nominal, lyapunov, slv, gamma2=gamma2), slv)

    def certify(_, sol):
        c = (_certify(system, sol.as_dict(), nominal, part.T, cells, alphas) if "B_F" in sol.values
             else {"gamma": float("inf"), "ok": False})
        return Check(c["ok"], c["gamma"], "certified" if c["ok"] else "not certified", c)

    run = Loop()
    for slv in solvers:
        solve_and_certify([(f"augmented observer, {len(cells)} cells", solve)], [slv], certify, rtol=TIGHT,
                          max_bisection=5, steps=steps, loop=run)
        best = run.best()
        if best is not None and best.check.gamma <= best.level * (1 + TIGHT):
            break  # within 2 % of the solver's own optimum: the next solver would not do much better
    return loop_outcome(run, part=part, alphas=alphas)


def _certify(system, sol, nominal, T, cells, alphas):
    A0, C0, L0 = nominal
    B_F = sol["B_F"]
    A_F, C_F = A0 + B_F @ C0, -np.asarray(L0, dtype=float).copy()
    witness = {"cells": np.array(cells), "P": [np.array(P) for cell in sol["P"] for P in cell],
               "G": np.array(sol["G"]), "T": np.array(T), "C0": np.array(C0, dtype=float)}
    gamma, _ = certify_augmented(system, A_F, B_F, C_F, witness)
    out = {"gamma": gamma, "ok": False}
    if not np.isfinite(gamma):
        return out
    norms, radii = augmented_norms(system, A_F, B_F, C_F, witness, alphas)
    ok = bool(np.all(radii < 1.0) and np.max(norms) <= gamma * (1 + 1e-9))
    out.update(A_F=A_F, B_F=B_F, C_F=C_F, witness=witness, norms=norms, radii=radii, ok=ok)
    return out
