"""General-form filters for a polytope cut into cells (the union of the cells' hulls).

A polytope with ``cells`` (:class:`~hinfnav.systems.PolytopicSystem`) is the
union of the hulls of groups of vertices, e.g. frequency sub-ranges of a
lightly damped mode (:func:`~hinfnav.systems.polytope_from_parameters` with
``splits``). :func:`design_cells_general` solves
:func:`hinfnav.lmi.cells_general.solve_cells_general` (per cell its own slack
rows and Lyapunov matrices, the filter common) and certifies the result as
:func:`~hinfnav.design.synthesize_polytopic` does: (E1) in float64 at every
vertex of every cell with the witness (:func:`certify_cells_general`), and the
H∞ norms of the error system (13)–(14) sampled densely in every cell. The
certificate covers every α constant in time in each cell (parameter-dependent
Lyapunov matrices) or every time-varying α(k) in the union (common).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..analysis.error_system import worst_case_norm
from ..core.exceptions import InputError
from ..lmi.cells_general import solve_cells_general
from ..lmi.solve import Solution
from .augmented import cell_alphas, cell_weights, e1_gamma
from .certify_loop import Check, Loop, loop_outcome, solve_and_certify

__all__ = ["certify_cells_general", "design_cells_general"]


def _error(s, A_F, B_F, C_F):
    n, nf = s.A.shape[0], A_F.shape[0]
    Abar = np.block([[s.A, np.zeros((n, nf))], [B_F @ s.C, A_F]])
    Bbar = np.block([[s.B, np.zeros((n, s.D.shape[1]))], [np.zeros((nf, s.B.shape[1])), B_F @ s.D]])
    return Abar, Bbar, np.hstack([s.L, -C_F])


def certify_cells_general(system, A_F, B_F, C_F, witness: Mapping[str, Any]) -> tuple[float, list[float]]:
    """Smallest γ for which (E1) holds in float64 at every vertex of every cell (general form; no solver)."""
    cells = [np.asarray(W, dtype=float) for W in witness["cells"]]
    Gs = np.asarray(witness["G"], dtype=float)
    P_list = list(witness["P"])
    if len(Gs) != len(cells) or len(P_list) != sum(len(W) for W in cells):
        raise InputError(f"the witness has {len(Gs)} slack and {len(P_list)} Lyapunov matrices for {len(cells)} cells")
    A_F, B_F, C_F = (np.asarray(M, dtype=float) for M in (A_F, B_F, C_F))
    per, k = [], 0
    for W, G in zip(cells, Gs):
        for a in W:
            Ab, Bb, Cb = _error(system.at(a), A_F, B_F, C_F)
            P = np.asarray(P_list[k], dtype=float)
            k += 1
            if P.shape != Ab.shape or G.shape != Ab.shape:
                raise InputError(f"the witness's P {P.shape} or G {G.shape} does not fit the error system {Ab.shape}")
            per.append(e1_gamma(P, G, Ab, Bb, Cb))
    return max(per), per


def _certify(system, sol, cells, alphas):
    if "A_F" not in sol:
        return {"gamma": float("inf"), "ok": False}
    witness = {"cells": np.array(cells), "P": [np.array(P) for cell in sol["P"] for P in cell], "G": np.array(sol["G"])}
    gamma, _ = certify_cells_general(system, sol["A_F"], sol["B_F"], sol["C_F"], witness)
    if not np.isfinite(gamma):
        return {"gamma": gamma, "ok": False}
    norms, radii = [], []
    for a in alphas:
        wc = worst_case_norm(system.at(a), sol["A_F"], sol["B_F"], sol["C_F"], dt=system.dt)
        norms.append(wc.norm)
        radii.append(float(wc.spectral_radii[0]))
    norms, radii = np.array(norms), np.array(radii)
    ok = bool(np.all(radii < 1.0) and norms.max() <= gamma * (1 + 1e-9))
    return {"gamma": gamma, "ok": ok, "A_F": sol["A_F"], "B_F": sol["B_F"], "C_F": sol["C_F"], "witness": witness,
            "norms": norms, "radii": radii}


def design_cells_general(system, lyapunov: str, solvers: Sequence[str], steps: tuple = (1e-3, 1e-2, 5e-2, 0.2, 1.0)
                         ) -> dict[str, Any]:
    """Design and certify a general-form filter on the cells (internal; wrapped by ``synthesize_polytopic``).

    Through the one certify loop (:func:`~hinfnav.design.certify_loop.solve_and_certify`), one solver at a time
    until one certifies: minimise γ; when the solver's point does not certify, maximise the margin at levels above
    the solver's γ (×1.001 … ×2) and keep the first that certifies.
    """
    cells = cell_weights(system)
    alphas = cell_alphas(system)
    verts = [[(lambda s: (s.A, s.B, s.C, s.D, s.L))(system.at(a)) for a in W] for W in cells]

    def solve(slv, gamma2=None):
        return Solution.from_dict(solve_cells_general(verts, lyapunov, slv, gamma2=gamma2), slv)

    def certify(_, sol):
        c = _certify(system, sol.as_dict(), cells, alphas)
        return Check(c["ok"], c["gamma"], "certified" if c["ok"] else "not certified", c)

    run = Loop()
    for slv in solvers:  # any certified point is accepted (rtol = inf): no bisection
        solve_and_certify([(f"general, {len(cells)} cells", solve)], [slv], certify, rtol=math.inf,
                          max_bisection=0, steps=steps, loop=run)
        if run.candidates:
            break
    return loop_outcome(run, alphas=alphas)
