"""Extended H∞ LMI (E1) for an observer-form filter on the augmented error system ``ζ = [x_s; e]``; one cvxpy solve.

The augmented error system of :mod:`hinfnav.analysis.marginal` at vertex i::

    Āᵢ = [[Ãᵢ, 0], [ΔAᵢTᵀ + B_F ΔCᵢTᵀ, A₀ + B_F C₀]],   B̄ᵢ = [[T Bᵢ, 0], [Bᵢ, B_F Dᵢ]],
    C̄ᵢ = [ΔLᵢTᵀ, L₀]

is bilinear in the gain B_F and a slack G. With G block lower triangular,
``G = [[G₁₁, 0], [G₂₁, G₂₂]]``, and the change of variable ``Ĝ = G₂₂ B_F``::

    G Āᵢ = [[G₁₁Ãᵢ, 0], [G₂₁Ãᵢ + G₂₂ΔAᵢTᵀ + Ĝ ΔCᵢTᵀ, G₂₂A₀ + Ĝ C₀]]
    G B̄ᵢ = [[G₁₁T Bᵢ, 0], [G₂₁T Bᵢ + G₂₂Bᵢ, Ĝ Dᵢ]]

are linear, and (E1) of :mod:`hinfnav.lmi.polytopic` at every vertex is an
LMI in ``(Pᵢ, G₁₁, G₂₁, G₂₂, Ĝ, γ²)``. (E1) implies ``G + Gᵀ > Pᵢ > 0``,
so G₂₂ is invertible and ``B_F = G₂₂⁻¹ Ĝ``. The triangular structure of G
(no ``G₁₂``) is a restriction (sufficient, not necessary); it keeps the
problem an SDP, and the float64 certificate checks the (E1) the returned
filter and witness satisfy with the full G.

**Cells.** A polytope of lightly damped modes whose frequency varies widely
is beyond one common slack G: already the mode's own stability (E1) with
``Pᵢ`` per vertex and one G is infeasible for a 1 Hz mode with damping
0.002 at ±20 % in frequency (feasible at ±5 %). The polytope is then cut into
cells (sub-polytopes whose vertices are convex combinations of the original
ones, their union the whole polytope); each cell has its own ``G₁₁, G₂₁``
and ``Pᵢ``, while ``G₂₂`` and ``Ĝ`` — the filter ``B_F = G₂₂⁻¹Ĝ`` — are
common. (E1) on every cell's vertices certifies the bound for every α
constant in time in the cell, hence in the polytope.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import cvxpy as cp
import numpy as np
from numpy.typing import ArrayLike

from .cells_general import read_cell_witness
from .polytopic import extended_hinf_positive
from .solve import solve_once

__all__ = ["solve_augmented_observer"]


def solve_augmented_observer(cells: Sequence[Sequence[Sequence[ArrayLike]]], T: ArrayLike,
                             nominal: Sequence[ArrayLike], lyapunov: str = "parameter-dependent",
                             solver: str = "CLARABEL", margin: float = 1e-8, accuracy: float = 1e-8,
                             bound: float = 1e6, gamma2: float | None = None) -> dict[str, Any]:
    """Minimize γ² subject to (E1) on the augmented error system at every vertex of every cell.

    Parameters
    ----------
    cells : sequence of sequences of ``(A, B, C, D, L)``
        The polytope, or sub-polytopes whose union covers it (each cell
        with its own ``G₁₁, G₂₁`` and, parameter-dependent, its own ``Pᵢ``;
        ``G₂₂`` and ``Ĝ``, hence the filter, are common to all cells).
    T : ndarray, shape (n_s, n), n_s ≥ 1
        The read state ``x_s = T x`` (:func:`hinfnav.analysis.marginal.read_part`).
    nominal : ``(A₀, C₀, L₀)``
    lyapunov : {"parameter-dependent", "common"}
        ``"common"``: one P for every vertex of every cell.
    solver : str
    margin, accuracy, bound : float
        (E1) ≥ margin·I, solver tolerances, ``Pᵢ ≤ bound·I``.
    gamma2 : float, optional
        Feasibility at this level maximizing the margin, instead of minimizing.

    Returns
    -------
    dict
        ``status``, ``gamma2``, ``seconds`` and, when solved, ``P`` (list of
        lists, cell by cell), ``G`` (list, one full triangular G per cell),
        ``B_F``, ``margin``.
    """
    T = np.asarray(T, dtype=float)
    A0, C0, L0 = (np.asarray(M, dtype=float) for M in nominal)
    ns, n = T.shape
    m = C0.shape[0]
    N = ns + n
    G22, Ghat = cp.Variable((n, n)), cp.Variable((n, m))
    g = cp.Variable() if gamma2 is None else float(gamma2)
    t = margin if gamma2 is None else cp.Variable()
    common = cp.Variable((N, N), symmetric=True) if lyapunov == "common" else None
    cons, Gs, Ps = [], [], []
    for vertices in cells:
        G11, G21 = cp.Variable((ns, ns)), cp.Variable((n, ns))
        G = cp.bmat([[G11, np.zeros((ns, n))], [G21, G22]])
        Gs.append(G)
        cell_P = [common if common is not None else cp.Variable((N, N), symmetric=True) for _ in vertices]
        Ps.append(cell_P)
        for P, (A, B, C, D, L) in zip(cell_P, vertices):
            A, B, C, D, L = (np.asarray(M, dtype=float) for M in (A, B, C, D, L))
            As, dA, dC = T @ A @ T.T, (A - A0) @ T.T, (C - C0) @ T.T
            q = D.shape[1]
            GA = cp.bmat([[G11 @ As, np.zeros((ns, n))], [G21 @ As + G22 @ dA + Ghat @ dC, G22 @ A0 + Ghat @ C0]])
            GB = cp.bmat([[G11 @ (T @ B), np.zeros((ns, q))], [G21 @ (T @ B) + G22 @ B, Ghat @ D]])
            Cbar = np.hstack([(L - L0) @ T.T, L0])
            M = extended_hinf_positive(P, GA, GB, Cbar, G, g, bmat=cp.bmat)
            cons.append(0.5 * (M + M.T) >> t * np.eye(M.shape[0]))
            if common is None:
                cons.append(P << bound * np.eye(N))
    if common is not None:
        cons.append(common << bound * np.eye(N))
    out = solve_once(cons, g, solver, accuracy, t=t, gamma2=gamma2)
    if read_cell_witness(out, G22, Ps, Gs, t) and np.linalg.cond(G22.value) < 1e14:
        out["B_F"] = np.linalg.solve(G22.value, Ghat.value)
    return out
