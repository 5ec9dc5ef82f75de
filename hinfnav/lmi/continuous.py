"""Continuous-time robust H∞ analysis of a polytope: common and parameter-dependent Lyapunov functions.

For ``ẋ = A(α) x + B(α) w``, ``e = C(α) x + D(α) w`` with the matrices
convex combinations of vertices, ``‖C(sI − A)⁻¹B + D‖∞ < γ`` for every α
when

* **common** (quadratic stability; also every time-varying α(t)): one
  ``P > 0`` with, at every vertex, the bounded real lemma::

      [ AᵢᵀP + PAᵢ   PBᵢ    Cᵢᵀ ]
      [  *          −γ²I    Dᵢᵀ ]  < 0;                                   (C1)
      [  *            *     −I  ]

* **parameter-dependent** (every α constant in time): ``Pᵢ > 0`` per vertex
  and common slacks F, G with::

      [ FAᵢ + AᵢᵀFᵀ   Pᵢ − F + AᵢᵀGᵀ   FBᵢ    Cᵢᵀ ]
      [  *            −G − Gᵀ          GBᵢ    0   ]  < 0.                 (C2)
      [  *              *             −γ²I    Dᵢᵀ ]
      [  *              *               *     −I  ]

(C2) is Finsler's lemma applied to ``V̇ + |e|² − γ²|w|² < 0`` on the
subspace ``ẋ = A x + B w`` (``V = xᵀP(α)x``) with the multiplier
``[F; G; 0]``: the quadratic form in ``[x; ẋ; w]`` is
``[[CᵀC, P, CᵀD], [P, 0, 0], [DᵀC, 0, DᵀD − γ²I]]`` and adding
``Y [A, −I, B] + (·)ᵀ`` then a Schur complement on the output gives (C2).
It is affine in the vertex data and in ``Pᵢ`` with F, G common, so it holds
at every α in the simplex with ``P(α) = Σ αᵢ Pᵢ``; ``F = P``, ``G = 0``
recovers (C1) (so (C2) is never more conservative). The float64 certificate
(:func:`certify_continuous`) finds the smallest γ for which the matrices of
the returned witness are negative definite.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import cvxpy as cp
import numpy as np
from numpy.typing import ArrayLike

from ..analysis.certificates import schur_gamma
from .solve import solve_once_gamma

__all__ = ["robust_hinf_continuous", "certify_continuous",
           "solve_continuous_observer"]


def continuous_brl_matrix(P, A, B, C, D, gamma2, bmat: Callable[..., Any] = np.block):
    """The matrix of (C1) at one vertex (negative definite iff the bound holds with P)."""
    m, p = B.shape[1], C.shape[0]
    return bmat([[A.T @ P + P @ A, P @ B, C.T], [B.T @ P, -gamma2 * np.eye(m), D.T], [C, D, -np.eye(p)]])


def continuous_pd_matrix(P, F, G, A, B, C, D, gamma2, bmat: Callable[..., Any] = np.block):
    """The matrix of (C2) at one vertex."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    Z = np.zeros
    return bmat([
        [F @ A + A.T @ F.T, P - F + A.T @ G.T, F @ B, C.T],
        [(P - F + A.T @ G.T).T, -G - G.T, G @ B, Z((n, p))],
        [(F @ B).T, (G @ B).T, -gamma2 * np.eye(m), D.T],
        [C, Z((p, n)), D, -np.eye(p)],
    ])


def _as(vertices):
    return [tuple(np.atleast_2d(np.asarray(M, dtype=float)) for M in v) for v in vertices]


def robust_hinf_continuous(vertices: Sequence[Sequence[ArrayLike]], lyapunov: str = "parameter-dependent",
                           solver: str = "CLARABEL", margin: float = 1e-9, accuracy: float = 1e-9) -> dict[str, Any]:
    """Minimize γ² subject to (C1) (``"common"``) or (C2) (``"parameter-dependent"``) at every vertex ``(A, B, C, D)``.

    Returns
    -------
    dict
        ``status``, ``gamma`` (solver's), ``seconds``, and when solved the
        witness ``P`` (list per vertex) and, parameter-dependent, ``F``, ``G``.
    """
    verts = _as(vertices)
    n = verts[0][0].shape[0]
    g = cp.Variable()
    cons = []
    if lyapunov == "common":
        P = cp.Variable((n, n), symmetric=True)
        Ps = [P] * len(verts)
        cons.append(P >> margin * np.eye(n))
        for A, B, C, D in verts:
            M = continuous_brl_matrix(P, A, B, C, D, g, bmat=cp.bmat)
            cons.append(0.5 * (M + M.T) << -margin * np.eye(M.shape[0]))
        F = G = None
    else:
        F, G = cp.Variable((n, n)), cp.Variable((n, n))
        Ps = [cp.Variable((n, n), symmetric=True) for _ in verts]
        for P, (A, B, C, D) in zip(Ps, verts):
            cons.append(P >> margin * np.eye(n))
            M = continuous_pd_matrix(P, F, G, A, B, C, D, g, bmat=cp.bmat)
            cons.append(0.5 * (M + M.T) << -margin * np.eye(M.shape[0]))
    out = solve_once_gamma(cons, g, solver, accuracy)
    if any(P.value is None for P in Ps):
        return out
    out["P"] = [0.5 * (P.value + P.value.T) for P in Ps]
    if F is not None:
        out["F"], out["G"] = np.array(F.value), np.array(G.value)
    return out


def certify_continuous(vertices: Sequence[Sequence[ArrayLike]], witness: dict[str, Any]) -> float:
    """Smallest γ for which (C1) or (C2) (``F``, ``G`` in the witness) holds in float64 at every vertex.

    ``inf`` when some ``Pᵢ`` is not positive definite or the γ-free part fails.
    """
    verts = _as(vertices)
    worst = 0.0
    for P, (A, B, C, D) in zip(witness["P"], verts):
        P = np.asarray(P, dtype=float)
        if not np.all(np.linalg.eigvalsh(0.5 * (P + P.T)) > 0):
            return float("inf")
        n, m = A.shape[0], B.shape[1]
        if "F" in witness:
            M0 = continuous_pd_matrix(P, np.asarray(witness["F"]), np.asarray(witness["G"]), A, B, C, D, 0.0)
            idx = np.arange(2 * n, 2 * n + m)
        else:
            M0 = continuous_brl_matrix(P, A, B, C, D, 0.0)
            idx = np.arange(n, n + m)
        worst = max(worst, schur_gamma(M0, idx)[0])
    return worst


def solve_continuous_observer(vertices: Sequence[Sequence[ArrayLike]], T: ArrayLike, nominal: Sequence[ArrayLike],
                              eps: float, solver: str = "CLARABEL", margin: float = 1e-9,
                              accuracy: float = 1e-9) -> dict[str, Any]:
    """Minimize γ² subject to (C2) on the augmented error ζ = [x_s; e] of an observer, G = ε F (see design.continuous).

    ``F = [[F₁₁, 0], [F₂₁, F₂₂]]``, ``F̂ = F₂₂ B_F``; returns ``P`` (per vertex), ``F``, ``G``, ``B_F``, ``gamma``.
    """
    T = np.atleast_2d(np.asarray(T, dtype=float))
    A0, C0, L0 = (np.atleast_2d(np.asarray(M, dtype=float)) for M in nominal)
    ns, n = T.shape
    m = C0.shape[0]
    N = ns + n
    F11, F21, F22 = cp.Variable((ns, ns)), cp.Variable((n, ns)), cp.Variable((n, n))
    Fh = cp.Variable((n, m))
    F = cp.bmat([[F11, np.zeros((ns, n))], [F21, F22]]) if ns else F22
    g = cp.Variable()
    cons, Ps = [], []
    for A, B, C, D, L in _as_five(vertices):
        As, dA, dC = T @ A @ T.T, (A - A0) @ T.T, (C - C0) @ T.T
        q = D.shape[1]
        if ns:
            FA = cp.bmat([[F11 @ As, np.zeros((ns, n))], [F21 @ As + F22 @ dA + Fh @ dC, F22 @ A0 + Fh @ C0]])
            FB = cp.bmat([[F11 @ (T @ B), np.zeros((ns, q))], [F21 @ (T @ B) + F22 @ B, Fh @ D]])
        else:
            FA, FB = F22 @ A0 + Fh @ C0, cp.hstack([F22 @ B, Fh @ D])
        Cb = np.hstack([(L - L0) @ T.T, L0])
        P = cp.Variable((N, N), symmetric=True)
        Ps.append(P)
        p, k = Cb.shape[0], FB.shape[1]
        Z = np.zeros
        M = cp.bmat([
            [FA + FA.T, P - F + eps * FA.T, FB, Cb.T],
            [P - F.T + eps * FA, -eps * (F + F.T), eps * FB, Z((N, p))],
            [FB.T, eps * FB.T, -g * np.eye(k), Z((k, p))],
            [Cb, Z((p, N)), Z((p, k)), -np.eye(p)],
        ])
        cons += [P >> margin * np.eye(N), 0.5 * (M + M.T) << -margin * np.eye(M.shape[0])]
    out = solve_once_gamma(cons, g, solver, accuracy)
    if F22.value is None or any(P.value is None for P in Ps) or not np.linalg.cond(F22.value) < 1e14:
        return out
    Fv = np.array(F.value)
    out.update(P=[0.5 * (P.value + P.value.T) for P in Ps], F=Fv, G=eps * Fv,
               B_F=np.linalg.solve(F22.value, Fh.value))
    return out


def _as_five(vertices):
    return [tuple(np.atleast_2d(np.asarray(M, dtype=float)) for M in v) for v in vertices]
