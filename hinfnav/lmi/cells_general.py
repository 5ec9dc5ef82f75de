"""Extended H∞ LMI (E1) for a general full-order filter on a polytope cut into cells; one cvxpy solve.

The general-form parametrization of :mod:`hinfnav.lmi.polytopic`
(``G = [[X, V], [Z, V]]``, ``Â = V A_F``, ``B̂ = V B_F``, ``C_F``) with, per
cell, its own ``X``, ``Z`` and ``Pᵢ``, and ``V, Â, B̂, C_F`` — the filter
``A_F = V⁻¹Â``, ``B_F = V⁻¹B̂`` — common to all cells. (E1) at every vertex of
every cell certifies the bound for every α constant in time in each cell
(the union of the cells' hulls). With a single cell it is the LMI of
:func:`hinfnav.lmi.polytopic.solve_polytopic_hinf`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import cvxpy as cp
import numpy as np
from numpy.typing import ArrayLike

from .polytopic import extended_hinf_positive, filter_slack_products
from .solve import solve_once

__all__ = ["solve_cells_general", "read_cell_witness"]


def solve_cells_general(cells: Sequence[Sequence[Sequence[ArrayLike]]], lyapunov: str = "parameter-dependent",
                        solver: str = "CLARABEL", margin: float = 1e-8, accuracy: float = 1e-8, bound: float = 1e6,
                        gamma2: float | None = None) -> dict[str, Any]:
    """Minimize γ² (or maximize the margin at ``gamma2``) subject to (E1) at every vertex ``(A, B, C, D, L)`` of every cell.

    Returns
    -------
    dict
        ``status``, ``gamma2``, ``seconds`` (:func:`hinfnav.lmi.solve.solve_once`) and, when solved, ``P`` (list of
        lists), ``G`` (list, one per cell), ``A_F``, ``B_F``, ``C_F``, ``margin``.
    """
    A0, B0, C0, D0, L0 = (np.asarray(M, dtype=float) for M in cells[0][0])
    n, m, l = A0.shape[0], C0.shape[0], L0.shape[0]
    V, Ahat, Bhat, CF = cp.Variable((n, n)), cp.Variable((n, n)), cp.Variable((n, m)), cp.Variable((l, n))
    g = cp.Variable() if gamma2 is None else float(gamma2)
    t = margin if gamma2 is None else cp.Variable()
    common = cp.Variable((2 * n, 2 * n), symmetric=True) if lyapunov == "common" else None
    cons, Gs, Ps = [], [], []
    for vertices in cells:
        X, Z = cp.Variable((n, n)), cp.Variable((n, n))
        G = cp.bmat([[X, V], [Z, V]])
        Gs.append(G)
        cell_P = [common if common is not None else cp.Variable((2 * n, 2 * n), symmetric=True) for _ in vertices]
        Ps.append(cell_P)
        for P, vert in zip(cell_P, vertices):
            vert = tuple(np.asarray(M, dtype=float) for M in vert)
            GA, GB, Cbar = filter_slack_products(vert, X, Z, V, Ahat, Bhat, CF, bmat=cp.bmat)
            M = extended_hinf_positive(P, GA, GB, Cbar, G, g, bmat=cp.bmat)
            cons.append(0.5 * (M + M.T) >> t * np.eye(M.shape[0]))
            if common is None:
                cons.append(P << bound * np.eye(2 * n))
    if common is not None:
        cons.append(common << bound * np.eye(2 * n))
    out = solve_once(cons, g, solver, accuracy, t=t, gamma2=gamma2)
    if read_cell_witness(out, V, Ps, Gs, t) and np.linalg.cond(V.value) < 1e14:
        out["A_F"], out["B_F"] = np.linalg.solve(V.value, Ahat.value), np.linalg.solve(V.value, Bhat.value)
        out["C_F"] = np.array(CF.value)
    return out


def read_cell_witness(out: dict[str, Any], key: cp.Variable, Ps: Sequence[Sequence[cp.Variable]],
                      Gs: Sequence[Any], t: Any) -> bool:
    """Add a solved cells problem's witness to ``out``: ``P`` (per cell, per vertex, symmetrised), ``G``, ``margin``.

    ``key`` is the variable the filter is recovered from (its slack block);
    ``t`` the margin, a number (minimisation) or the maximised cvxpy
    variable. False (``out`` unchanged) when ``key`` or some ``Pᵢ`` has no value.
    """
    if key.value is None or any(P.value is None for cell in Ps for P in cell):
        return False
    out["P"] = [[0.5 * (P.value + P.value.T) for P in cell] for cell in Ps]
    out["G"] = [np.array(G.value) for G in Gs]
    out["margin"] = float(t.value) if isinstance(t, cp.Variable) else t
    return True
