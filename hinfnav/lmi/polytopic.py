"""Extended (slack-variable) H∞ LMIs for filters on polytopes, and one cvxpy solve.

The discrete bounded real lemma in its extended (slack-variable) form, in the
manner of de Oliveira, Geromel & Bernussou (2002) and of the polytopic filters
of Xie, Lu, Zhang & Zhang (2004) and Duan et al. (2006); written here for the
primal Lyapunov inequality and derived below (the theorem numbering and the
exact block order of those papers were not checked against the originals,
which are not in the workbook: the float64 certificate of every returned
filter is what vouches for it): the system
``ξ⁺ = Ā ξ + B̄ τ``, ``e = C̄ ξ`` is Schur stable with ``‖C̄(zI − Ā)⁻¹B̄‖∞ < γ``
iff there are ``P = Pᵀ`` and a slack ``G`` (not symmetric) with::

    N(P, G, γ²) = [ G + Gᵀ − P   G Ā   G B̄    0  ]
                  [  *            P     0     C̄ᵀ ]  > 0        (E1)
                  [  *            *    γ²I    0  ]
                  [  *            *     *     I  ]

(``G = P`` gives the Schur complement of the bounded real lemma; conversely
``G P⁻¹ Gᵀ ≥ G + Gᵀ − P``.) Because P is decoupled from Ā, a polytope is
handled vertex by vertex with ``P(α) = Σ αᵢ Pᵢ`` and one G: (E1) at every
vertex implies (E1) at every constant α in the simplex (it is affine in α),
so ``‖·‖∞ < γ`` for every *time-invariant* α ("parameter-dependent").
With ``Pᵢ = P`` for all i (``"common"``) a single quadratic Lyapunov function
holds, and the bound holds for *arbitrarily time-varying* α(k).

Filter parametrization (full order, general form): with the filter state
coordinates chosen so that ``G = [[X, V], [Z, V]]`` (no loss of generality
when V is invertible, which (E1) implies), ``Â = V A_F``, ``B̂ = V B_F``:
``G Ā = [[X A + B̂ C, Â], [Z A + B̂ C, Â]]``,
``G B̄ = [[X B, B̂ D], [Z B, B̂ D]]``, ``C̄ = [L, −C_F]`` — linear.

Observer form (a predictor observer, ``C_F = −L``, ``A_F = A + B_F C``): in
error coordinates ``e = x + x_f`` the error system is
``e⁺ = (A + B_F C) e + B w + B_F D v``, output ``L e``; with ``Ĝ = G B_F``,
``G Ā = G A + Ĝ C`` and ``G B̄ = [G B, Ĝ D]`` are linear. This needs A, C
and L to be the same at every vertex (the uncertainty must not multiply the
plant state); only (A, C) detectable is needed, not a stable A.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import cvxpy as cp
import numpy as np
from numpy.typing import ArrayLike, NDArray

from .solve import LMIProblem

__all__ = ["extended_hinf_positive", "hinf_gamma_index", "solve_polytopic_hinf", "polytopic_problem", "filter_slack_products",
           "extended_h2_matrices"]


def extended_hinf_positive(P: ArrayLike | cp.Expression, GA: ArrayLike | cp.Expression, GB: ArrayLike | cp.Expression, Cbar: ArrayLike | cp.Expression,
                         G: ArrayLike | cp.Expression, gamma2: float | cp.Expression, bmat: Callable[..., Any] = np.block) -> NDArray[np.float64] | cp.Expression:
    """The matrix N of (E1) (positive definite iff the bound holds), from the products ``G Ā`` and ``G B̄``.

    Block rows/columns ``[N, N, k, l]`` (N states, k inputs, l outputs).
    """
    N, k = GB.shape
    l = Cbar.shape[0]
    Z, I = np.zeros, np.eye
    return bmat([
        [G + G.T - P, GA, GB, Z((N, l))],
        [GA.T, P, Z((N, k)), Cbar.T],
        [GB.T, Z((k, N)), gamma2 * I(k), Z((k, l))],
        [Z((l, N)), Cbar, Z((l, k)), I(l)],
    ])


def extended_h2_matrices(P: ArrayLike | cp.Expression, GA: ArrayLike | cp.Expression, GB: ArrayLike | cp.Expression, Cbar: ArrayLike | cp.Expression,
                         G: ArrayLike | cp.Expression, W: ArrayLike | cp.Expression, bmat: Callable[..., Any] = np.block) -> tuple[NDArray[np.float64] | cp.Expression, NDArray[np.float64] | cp.Expression]:
    """The two matrices of the extended H2 LMIs (E2), both positive definite iff ``‖·‖₂² < tr W`` holds with P.

    ``Āᵀ P Ā − P + C̄ᵀC̄ < 0`` and ``W > B̄ᵀ P B̄`` (P bounds the observability
    Gramian, ``‖C̄(zI − Ā)⁻¹B̄‖₂² = tr B̄ᵀ Q B̄``), in the extended form of de
    Oliveira, Geromel & Bernussou (2002) (``G P⁻¹ Gᵀ ≥ G + Gᵀ − P``)::

        [ G + Gᵀ − P   G Ā   0  ]                [ W      (G B̄)ᵀ     ]
        [  *           P     C̄ᵀ ]  > 0,          [ G B̄   G + Gᵀ − P ]  > 0
        [  *           *     I  ]
    """
    N, k = GB.shape
    l = Cbar.shape[0]
    Z, I = np.zeros, np.eye
    M1 = bmat([[G + G.T - P, GA, Z((N, l))], [GA.T, P, Cbar.T], [Z((l, N)), Cbar, I(l)]])
    M2 = bmat([[W, GB.T], [GB, G + G.T - P]])
    return M1, M2


def hinf_gamma_index(N, k):
    """Rows/columns of (E1) that carry γ² (the input block)."""
    return np.arange(2 * N, 2 * N + k)


def filter_slack_products(vertex, X, Z, V, Ahat, Bhat, CF, bmat=np.block):
    """``G Ā``, ``G B̄``, ``C̄`` of the general form at one vertex ``(A, B, C, D, L)`` (see the module docstring)."""
    A, B, C, D, L = vertex
    GA = bmat([[X @ A + Bhat @ C, Ahat], [Z @ A + Bhat @ C, Ahat]])
    GB = bmat([[X @ B, Bhat @ D], [Z @ B, Bhat @ D]])
    Cbar = bmat([[L, -CF]])
    return GA, GB, Cbar


def solve_polytopic_hinf(vertices: Sequence[Sequence[ArrayLike]], form: str = "general",
                         lyapunov: str = "parameter-dependent", solver: str = "CLARABEL", margin: float = 1e-8,
                         accuracy: float = 1e-8, bound: float = 1e6, gamma2: float | None = None,
                         objective: str = "hinf") -> dict[str, Any]:
    """Minimize γ² subject to (E1) at every vertex; one cvxpy solve.

    Parameters
    ----------
    vertices : sequence of tuple of ndarray
        ``(A, B, C, D, L)`` per vertex.
    form : {"general", "observer"}
    lyapunov : {"parameter-dependent", "common"}
    solver : str
    margin, accuracy : float
        (E1) ≥ margin·I; solver tolerances.
    bound : float
        ``Pᵢ ≤ bound·I`` keeps the problem bounded.
    gamma2 : float, optional
        Feasibility at this level, maximizing the margin, instead of the
        minimization.
    objective : {"hinf", "h2"}
        ``"h2"``: minimize ``tr W`` subject to (E2) instead (``gamma2`` is
        then the H2 bound squared; returned ``W``).

    Returns
    -------
    dict
        ``status``, ``gamma2`` (solver's), ``seconds``, and when solved
        ``P`` (list, one per vertex), ``G``, the filter ``A_F, B_F, C_F``
        and the raw variables (``X, Z, V, Ahat, Bhat`` or ``Ghat``).
    """
    return polytopic_problem(vertices, form, lyapunov, margin, accuracy, bound, objective).solve(solver, gamma2).as_dict()


def polytopic_problem(vertices: Sequence[Sequence[ArrayLike]], form: str = "general",
                      lyapunov: str = "parameter-dependent", margin: float = 1e-8, accuracy: float = 1e-8,
                      bound: float = 1e6, objective: str = "hinf") -> LMIProblem:
    """(E1) (or (E2) for H2) at every vertex as one :class:`~hinfnav.lmi.solve.LMIProblem`, built once.

    The level is γ² (``tr W`` for H2); ``Pᵢ ≤ bound·I`` keeps the problem
    bounded. The solution's values: ``P`` (list, one per vertex), ``G`` and
    the raw variables (``X, Z, V, Ahat, Bhat, C_F`` or ``Ghat``; ``W``).
    """
    A0, B0, C0, D0, L0 = vertices[0]
    n, p = B0.shape
    m, q = D0.shape
    l = L0.shape[0]
    nv = len(vertices)

    def build(t, free):
        g = cp.Variable()
        cons = []
        if form == "observer":
            N = n
            G = cp.Variable((n, n))
            Ghat = cp.Variable((n, m))
            prods = []
            for A, B, C, D, L in vertices:
                prods.append((G @ A + Ghat @ C, cp.hstack([G @ B, Ghat @ D]), L))
            raw = {"Ghat": Ghat}
        else:
            N = 2 * n
            X, Z, V = cp.Variable((n, n)), cp.Variable((n, n)), cp.Variable((n, n))
            Ahat, Bhat, CF = cp.Variable((n, n)), cp.Variable((n, m)), cp.Variable((l, n))
            G = cp.bmat([[X, V], [Z, V]])
            prods = [filter_slack_products(v, X, Z, V, Ahat, Bhat, CF, bmat=cp.bmat) for v in vertices]
            raw = {"X": X, "Z": Z, "V": V, "Ahat": Ahat, "Bhat": Bhat, "C_F": CF}
        if lyapunov == "common":
            Ps = [cp.Variable((N, N), symmetric=True)] * nv
        else:
            Ps = [cp.Variable((N, N), symmetric=True) for _ in range(nv)]
        if objective == "h2":
            k = prods[0][1].shape[1]
            W = cp.Variable((k, k), symmetric=True)
            raw["W"] = W
            g = cp.trace(W)
        for P, (GA, GB, Cbar) in zip(Ps, prods):
            if objective == "h2":
                mats = extended_h2_matrices(P, GA, GB, Cbar, G, W, bmat=cp.bmat)
            else:
                mats = (extended_hinf_positive(P, GA, GB, Cbar, G, g, bmat=cp.bmat),)
            for M in mats:
                cons.append(0.5 * (M + M.T) >> t * np.eye(M.shape[0]))
        for P in (Ps[:1] if lyapunov == "common" else Ps):
            cons.append(P << bound * np.eye(N))

        def readout():
            if G.value is None or any(P.value is None for P in Ps):
                return {}
            out = {"P": [0.5 * (P.value + P.value.T) for P in Ps], "G": np.array(G.value)}
            out.update({k: np.array(v.value) for k, v in raw.items()})
            return out

        return cons, g, readout

    return LMIProblem(build, margin, accuracy, retry=False)
