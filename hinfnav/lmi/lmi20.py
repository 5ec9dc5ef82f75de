"""LMI (20) of Sun et al. (2011), built once as an :class:`~hinfnav.lmi.solve.LMIProblem`, and its solve.

:func:`lmi20_problem` poses the norm-bounded robust H∞ filtering LMI (20) (general or observer form), on the
whole plant or, for a plant that decouples into blocks (:func:`hinfnav.analysis.structure.decoupled_blocks`),
block by block with shared λ and γ²; :func:`solve_lmi` solves it through the one solver path of
:mod:`hinfnav.lmi.solve`.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

import cvxpy as cp
import numpy as np

from .blocks import gamma_index, lmi20_matrix, observer_lmi_matrix
from .conditioning import solver_data
from .solve import LMIProblem, Solution

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..analysis.structure import Block
    from .conditioning import Prepared

__all__ = ["lmi20_problem", "solve_lmi", "BLOCK_RETRY"]

#: Looser tolerances a solver is asked at, in turn, when it raises on a decoupled plant's LMI (20): measured on 2
#: stacked Sun et al. (2011) chasers (unit-free scaling), CVXOPT stops with a singular KKT matrix at 1e-8 and 1e-6
#: (gap 1e-6 reached) and returns "optimal" at 1e-5 in 0.56 s CPU; the certificate is independent of the tolerance.
BLOCK_RETRY = (100.0, 1000.0)


def lmi20_problem(P: Prepared, margin: float = 1e-8, accuracy: float = 1e-8, bound: float = 1e8,
                  blocks: Sequence[Block] | None = None) -> LMIProblem:
    """LMI (20) (or its observer form) on prepared data, built once (:class:`LMIProblem`).

    When ``P`` is normalised (:func:`hinfnav.lmi.conditioning.normalize`),
    the solver sees the normalised data, and the levels asked for and the
    solutions returned by :func:`solve_lmi` are in the units of the original
    data.

    With ``P.form == "observer"`` the equality constraints
    ``Ā_F = S A + B̄_F C`` and ``C̄_F = −L`` (in the scaled coordinates of
    ``P``) are eliminated by substitution, and the LMI is posed in its
    congruent form :func:`observer_lmi_matrix` (variables X = R − S, S,
    B̄_F, λ), on which the solvers converge (on (20) with the substitution
    they stop with numerical errors near the optimum). The γ-free part is
    (20) without the rows and columns of −γ²I: feasible iff (20) is for some
    finite γ. ``R ≤ bound·I`` bounds every variable when (20) holds
    (S < R, ‖Ā_F‖² ≤ ‖R‖‖S‖, λ‖E‖² < ‖R‖, ...).

    **Decoupled plants** (``blocks``: two or more
    :class:`~hinfnav.analysis.structure.Block` of
    :func:`~hinfnav.analysis.structure.decoupled_blocks` on ``P``'s data).
    Write ``T_c`` for the signature matrix that flips the sign of every
    signal of block c (its states, w, v, y, z, and uncertainty channels r,
    s). Each data matrix is invariant, ``T A T = A``, ``T B T_w = B``, …,
    ``T H T_r = H``, ``T_s E T = E``, because it has no entry between two
    blocks. Hence LMI (20) at the variables ``T R T, T S T, T Ā_F T,
    T B̄_F T_y, T_z C̄_F T`` (λ, γ unchanged) is ``𝒯 M 𝒯`` for a signature
    matrix 𝒯: negative definite with the same margin. M is affine in the
    variables, so the average over the 2^k sign patterns, which is the
    block-diagonal part of each variable (``R_c = R[c, c]``, ``B̄_F[c_x,
    c_y]``, …), is feasible too, at the same λ and γ. So restricting R, S,
    Ā_F, B̄_F, C̄_F to be block-diagonal loses nothing: the restricted problem
    has the same optimum as the full one, for any decoupled plant (blocks
    need not be equal). With block-diagonal variables every block of (20)
    is block-diagonal (``R A + B̄_F C``, ``R B``, ``B̄_F D``, ``Lᵀ``,
    ``λEᵀE``, ``R H``, …), so M is, up to a permutation, ``diag(M_1, …,
    M_k, −γ²I, −I, −λI)``: the k LMIs (20) of the blocks, with a *common*
    λ (the one S-procedure multiplier of the single full block F, which
    couples all blocks) and a common γ², plus the rows of signals that touch
    no state. The solver sees k small matrix inequalities instead of one of
    size 4n + p + q + l + r. Any feasible point is a feasible point of the
    full LMI (block-diagonal variables are a special case), so the
    certificate, evaluated on the full (20) at the assembled variables,
    bounds the error for every contraction F, including the ones coupling
    the blocks. A solver that raises is asked again at the looser
    tolerances of :data:`BLOCK_RETRY`. Signals outside every block get zero filter gains (B̄_F
    columns, C̄_F rows), which the averaging argument shows is optimal.
    """
    P = solver_data(P)  # rounded to 32 bits on the unit-free, noise-normalised path (see there)
    n, p = P.B.shape
    q = P.D.shape[1]
    observer = P.form == "observer"
    if blocks is not None and len(blocks) > 1:
        return LMIProblem(_block_builder(P, bound, blocks), margin, accuracy, retry=BLOCK_RETRY)

    def build(t, free):
        # variables created in the same order as before the observer option: identical general-form problems
        X = cp.Variable((n, n), symmetric=True)  # R in the general form, R − S in the observer form
        S = cp.Variable((n, n), symmetric=True)
        AbF = None if observer else cp.Variable((n, n))
        BbF = cp.Variable((n, P.C.shape[0]))
        CbF = None if observer else cp.Variable((P.L.shape[0], n))
        lam = cp.Variable() if P.H is not None else 0.0
        g = 0.0 if free else cp.Variable()
        if observer:
            R = X + S
            M = observer_lmi_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, X, S, BbF, lam, g, bmat=cp.bmat)
        else:
            R = X
            M = lmi20_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, R, S, AbF, BbF, CbF, lam, g, bmat=cp.bmat)
        if free:
            keep = np.setdiff1d(np.arange(M.shape[0]), gamma_index(n, p, q))
            M = M[keep, :][:, keep]
        Msym = 0.5 * (M + M.T)
        cons = [Msym << -t * np.eye(M.shape[0]), R << bound * np.eye(n)]

        def readout():
            if X.value is None or S.value is None:
                return {}
            sym = lambda Y: 0.5 * (Y + Y.T)
            S_val = sym(S.value)
            if observer:
                R_val, Abar, Cbar = S_val + sym(X.value), S_val @ P.A + BbF.value @ P.C, -P.L.copy()
            else:
                R_val, Abar, Cbar = sym(X.value), AbF.value.copy(), CbF.value.copy()
            return {"R": R_val, "S": S_val, "Abar_F": Abar, "Bbar_F": BbF.value.copy(), "Cbar_F": Cbar,
                    "lam": float(lam.value) if P.H is not None else 0.0}

        return cons, (None if free else g), readout

    return LMIProblem(build, margin, accuracy)


def _block_builder(P: Prepared, bound: float, blocks: Sequence[Block]) -> Any:
    """The ``build`` of :class:`LMIProblem` for LMI (20) with block-diagonal variables (see :func:`lmi20_problem`)."""
    n, m, l = P.A.shape[0], P.C.shape[0], P.L.shape[0]
    observer = P.form == "observer"
    ix = np.ix_
    data = []
    for b in blocks:
        x = b.states
        H = E = None
        if P.H is not None and (b.r.size or b.s.size):
            # a block with rows of E but no column of H (or the reverse) keeps its λEᵀE term (or λ border) with a
            # zero column of H (row of E): the border adds −λ to the spectrum, as the full LMI's −λI does
            H = P.H[ix(x, b.r)] if b.r.size else np.zeros((x.size, 1))
            E = P.E[ix(b.s, x)] if b.s.size else np.zeros((1, x.size))
        data.append((P.A[ix(x, x)], P.B[ix(x, b.w)], P.C[ix(b.y, x)], P.D[ix(b.y, b.v)], P.L[ix(b.z, x)], H, E))

    def var(shape, **kw):
        return cp.Variable(shape, **kw) if min(shape) > 0 else np.zeros(shape)

    def build(t, free):
        lam = cp.Variable() if P.H is not None else 0.0
        g = 0.0 if free else cp.Variable()
        cons, parts = [], []
        for b, (A, B, C, D, L, H, E) in zip(blocks, data):
            k = b.states.size
            # a block without noise keeps one zero noise column (its −γ²I row), so that cvxpy never sees an empty block
            B = B if B.shape[1] else np.zeros((k, 1))
            D = D if D.shape[1] else np.zeros((D.shape[0], 1))
            X, S = cp.Variable((k, k), symmetric=True), cp.Variable((k, k), symmetric=True)
            BbF = var((k, C.shape[0]))
            lam_b = lam if H is not None else 0.0
            if observer:
                R, AbF, CbF = X + S, None, None
                M = observer_lmi_matrix(A, B, C, D, L, H, E, X, S, BbF, lam_b, g, bmat=_bmat)
            else:
                R, AbF, CbF = X, cp.Variable((k, k)), var((L.shape[0], k))
                M = lmi20_matrix(A, B, C, D, L, H, E, R, S, AbF, BbF, CbF, lam_b, g, bmat=_bmat)
            if free:
                keep = np.setdiff1d(np.arange(M.shape[0]), gamma_index(k, B.shape[1], D.shape[1]))
                M = M[keep, :][:, keep]
            cons += [0.5 * (M + M.T) << -t * np.eye(M.shape[0]), R << bound * np.eye(k)]
            parts.append((b, X, S, AbF, BbF, CbF))

        def readout():
            if any(X.value is None or S.value is None for _, X, S, *_ in parts):
                return {}
            sym = lambda Y: 0.5 * (Y + Y.T)
            out = {key: np.zeros(shape) for key, shape in
                   (("R", (n, n)), ("S", (n, n)), ("Abar_F", (n, n)), ("Bbar_F", (n, m)), ("Cbar_F", (l, n)))}
            value = lambda V: V if isinstance(V, np.ndarray) else V.value
            for b, X, S, AbF, BbF, CbF in parts:
                x = b.states
                S_val = sym(S.value)
                out["S"][ix(x, x)] = S_val
                out["R"][ix(x, x)] = S_val + sym(X.value) if observer else sym(X.value)
                out["Bbar_F"][ix(x, b.y)] = value(BbF)
                if not observer:
                    out["Abar_F"][ix(x, x)] = AbF.value
                    out["Cbar_F"][ix(b.z, x)] = value(CbF)
            if observer:
                out["Abar_F"], out["Cbar_F"] = out["S"] @ P.A + out["Bbar_F"] @ P.C, -P.L.copy()
            out["lam"] = float(lam.value) if P.H is not None else 0.0
            return out

        return cons, (None if free else g), readout

    return build


def _bmat(rows: list) -> Any:
    """``cvxpy.bmat`` that skips block rows and columns of zero size (a block without measurements or outputs)."""
    keep_r = [i for i, row in enumerate(rows) if _rows(row) > 0]
    keep_c = [j for j in range(len(rows[0])) if _cols(rows, j) > 0]
    return cp.bmat([[rows[i][j] for j in keep_c] for i in keep_r])


def _shape(blk):
    shape = tuple(getattr(blk, "shape", np.shape(blk)))
    return shape if len(shape) == 2 else (1, 1)


def _rows(row):
    return min(_shape(blk)[0] for blk in row)


def _cols(rows, j):
    return min(_shape(row[j])[1] for row in rows)


def solve_lmi(P: Prepared, problem: LMIProblem, solver: str, gamma2: float | str | None = None) -> Solution:
    """One solve of LMI (20) built by :func:`lmi20_problem` on ``P``, in the units of the original data.

    ``gamma2=None``: minimise γ² (Corollary 1); a number: feasibility at that
    level with the largest margin; ``"free"``: the γ-free part (``gamma2`` of
    the solution NaN, the certificate finds γ). With ``P`` normalised,
    ``γ'² = γ²/(νρ)²`` is solved for, and ``R, S, Ā_F, B̄_F, λ`` come back
    multiplied by ν², ``C̄_F`` by ν and γ² by (νρ)² (exact, powers of two);
    the margin is the normalised problem's (its sign is what matters).
    """
    if not P.normalized:
        return problem.solve(solver, gamma2)
    g = P.nu * P.rho
    level = gamma2 if gamma2 is None or isinstance(gamma2, str) else float(gamma2) / g**2
    sol = problem.solve(solver, level)
    k = P.nu**2
    values = {key: val * (P.nu if key == "Cbar_F" else k) for key, val in sol.values.items()}
    return dataclasses.replace(sol, gamma2=sol.gamma2 * g**2, values=values)
