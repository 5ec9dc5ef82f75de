"""The matrices of the mixed H2/H∞ filter synthesis: extended (dilated) LMIs with one slack G.

Written once for numbers (``bmat=np.block``: certification) and for cvxpy
expressions (``bmat=cvxpy.bmat``: the solver), like :mod:`.blocks` for LMI (20).

Why a slack variable
--------------------
In LMI (20) the filter is linearized through the Lyapunov matrix itself,
``P = [[R, S], [S, S]]`` and ``Ā_F = S A_F``, ``B̄_F = S B_F``. Imposing an H2
and an H∞ condition that way forces both to use the *same* P (the
"common Lyapunov" approach of Bernstein & Haddad 1989 and Khargonekar & Rotea
1991), because ``S A_F`` with two different S is not linear. The extended LMIs
of de Oliveira, Bernussou & Geromel (Systems & Control Letters 37, 1999;
de Oliveira, Geromel & Bernussou, Int. J. Control 75(9), 2002; used for
robust filtering by Geromel, Bernussou, Garcia & de Oliveira, SIAM J. Control
Optim. 38(5), 2000) move the filter into a slack matrix G that multiplies the
error system, so that each criterion keeps its own Lyapunov matrix (P₂, P∞):

    ∃ P > 0:  Āᵀ P Ā − P + C̄ᵀC̄ < 0
    ⇔ ∃ P > 0, G:  [[P − G − Gᵀ, GᵀĀ, 0], [ĀᵀG, −P, C̄ᵀ], [0, C̄, −I]] < 0

(⇐: ``P − G − Gᵀ ≥ −GᵀP⁻¹G`` and a congruence with ``diag(G⁻¹, I, I)``;
⇒: take ``G = P``). The filter enters only through
``Gᵀ = [[X, Z], [Y, Z]]`` (X, Y, Z any n×n matrices) and the products

    GᵀĀ = [[X A + B̄_F C, Ā_F], [Y A + B̄_F C, Ā_F]],
    GᵀB̄ = [[X B, B̄_F D], [Y B, B̄_F D]],       GᵀH̄ = [[X H], [Y H]],

with ``Ā_F = Z A_F``, ``B̄_F = Z B_F``, ``C̄_F = C_F`` (linear, as in (20)).
Restricting G to this form loses nothing: a change of the filter's state
coordinates ``x_f → T x_f`` maps G to ``diag(I, T)ᵀ G diag(I, T)``, and
``T = G₂₂⁻¹ G₂₁`` makes its two lower blocks equal. With ``X = R``,
``Y = Z = S`` (symmetric), ``Gᵀ = [[R, S], [S, S]]`` is (20)'s P: the
common-Lyapunov solutions are among the extended ones, so the extended
formulation is never more conservative.

The norm-bounded uncertainty ``Ā + H̄ F Ē`` (``H̄ = [H; 0]``, ``Ē = [E, 0]``)
enters as ``GᵀH̄ F Ē`` and is removed by Lemma 2 of Sun et al. (2011) with one
multiplier λ per inequality, exactly as in (20).
"""

import numpy as np

__all__ = [
    "slack_products",
    "robust_extended_hinf_negative",
    "extended_h2_matrix",
    "h2_trace_matrix",
    "h2_output_index",
]


def slack_products(A, B, C, D, L, H, E, X, Y, Z, Abar_F, Bbar_F, Cbar_F, bmat=np.block):
    """G, GᵀĀ, GᵀB̄, GᵀH̄, C̄ and Ē of the error system (13)–(14) in the slack variables.

    Parameters
    ----------
    A, B, C, D, L : ndarray
        The plant ψ_d (9), shapes (n, n), (n, p), (m, n), (m, q), (l, n).
    H, E : ndarray or None
        Uncertainty factors (``ΔA = H F E``), shapes (n, r1), (r2, n).
    X, Y, Z : ndarray or cvxpy expression, shape (n, n)
        The slack ``Gᵀ = [[X, Z], [Y, Z]]``.
    Abar_F, Bbar_F, Cbar_F : ndarray or cvxpy expression
        ``Z A_F``, ``Z B_F``, ``C_F``.
    bmat : callable

    Returns
    -------
    dict
        ``G`` (2n, 2n), ``GA`` = GᵀĀ, ``GB`` = GᵀB̄ (2n, p + q), ``GH`` =
        GᵀH̄ (2n, r1) or None, ``Cbar`` = [L, −C̄_F] (l, 2n), ``Ebar`` =
        [E, 0] (r2, 2n) or None.
    """
    n = A.shape[0]
    Gt = bmat([[X, Z], [Y, Z]])
    XA = X @ A + Bbar_F @ C
    YA = Y @ A + Bbar_F @ C
    BD = Bbar_F @ D
    out = {
        "G": Gt.T,
        "GA": bmat([[XA, Abar_F], [YA, Abar_F]]),
        "GB": bmat([[X @ B, BD], [Y @ B, BD]]),
        "Cbar": bmat([[L, -Cbar_F]]),
        "GH": None,
        "Ebar": None,
    }
    if H is not None:
        out["GH"] = bmat([[X @ H], [Y @ H]])
        out["Ebar"] = np.hstack([E, np.zeros((E.shape[0], n))])
    return out


def robust_extended_hinf_negative(P, G, GA, GB, Cbar, GH, Ebar, lam, gamma2, bmat=np.block):
    """Extended robust bounded real LMI (H∞ part), negative definite iff the bound holds.

    Block rows/columns ``[N, N, p + q, l, r]`` (N = 2n; the last only with
    uncertainty)::

        [ P − G − Gᵀ   GᵀĀ            GᵀB̄    0     GᵀH̄ ]
        [  *          −P + λĒᵀĒ       0      C̄ᵀ    0   ]
        [  *           *             −γ²I    0     0   ]  < 0
        [  *           *              *     −I     0   ]
        [  *           *              *      *    −λI  ]

    It implies ``‖C̄(zI − Ā − H̄FĒ)⁻¹B̄‖∞ < γ`` for every ``FᵀF ≤ I`` (Lemma 1
    with the slack, Lemma 2 for F). With ``G = P`` it is (17)/(26), and with
    ``P = Gᵀ = [[R, S], [S, S]]`` it is LMI (20) itself. The ``−γ²I`` rows
    are :func:`hinfnav.lmi.blocks.gamma_index` (n, p, q), as in (20).

    Parameters
    ----------
    P : ndarray or expression, shape (N, N)
        The H∞ Lyapunov matrix P∞.
    G, GA, GB, Cbar, GH, Ebar
        From :func:`slack_products` (or evaluated at a given filter).
    lam : float or expression
        Multiplier λ∞ of Lemma 2 (ignored without uncertainty).
    gamma2 : float or expression
        γ².

    Returns
    -------
    ndarray or expression, shape (2N + p + q + l [+ r1],) * 2
    """
    N = G.shape[0]
    k = GB.shape[1]
    l = Cbar.shape[0]
    Z = np.zeros
    I = np.eye
    rows = [
        [P - G - G.T, GA, GB, Z((N, l))],
        [GA.T, -P, Z((N, k)), Cbar.T],
        [GB.T, Z((k, N)), -gamma2 * I(k), Z((k, l))],
        [Z((l, N)), Cbar, Z((l, k)), -I(l)],
    ]
    if GH is not None:
        r = GH.shape[1]
        rows[1][1] = -P + lam * (Ebar.T @ Ebar)
        for row, blk in zip(rows, [GH, Z((N, r)), Z((k, r)), Z((l, r))]):
            row.append(blk)
        rows.append([GH.T, Z((r, N)), Z((r, k)), Z((r, l)), -lam * I(r)])
    return bmat(rows)


def extended_h2_matrix(P, G, GA, Cbar, GH, Ebar, lam, kappa, bmat=np.block):
    """Extended robust Lyapunov LMI (H2 part): ``Ā_Fᵀ(κP)Ā_F − κP + C̄ᵀC̄ < 0`` for every F.

    Block rows/columns ``[N, N, l, r]``::

        [ P − G − Gᵀ   GᵀĀ           0      GᵀH̄ ]
        [  *          −P + λĒᵀĒ      C̄ᵀ     0   ]  < 0
        [  *           *            −κI     0   ]
        [  *           *             *     −λI  ]

    The solver uses κ = 1; the certificate finds the smallest κ for which the
    matrix, evaluated at the returned filter, is negative definite
    (:func:`hinfnav.analysis.schur_gamma` on the rows :func:`h2_output_index`,
    which returns √κ). It implies (slack lemma, then Lemma 2) that
    ``Ā_Δᵀ(κP)Ā_Δ − κP + C̄ᵀC̄ < 0`` for ``Ā_Δ = Ā + H̄FĒ``, hence for a
    constant F the observability Gramian is below κP and
    ``‖Ψ_F‖₂² ≤ κ · trace(B̄ᵀ P B̄)`` (for a time-varying F the same number
    bounds the asymptotic mean square error under unit white noise).

    Parameters
    ----------
    P : ndarray or expression, shape (N, N)
        The H2 Lyapunov matrix P₂.
    G, GA, Cbar, GH, Ebar
        From :func:`slack_products`.
    lam : float or expression
        Multiplier λ₂ of Lemma 2.
    kappa : float or expression

    Returns
    -------
    ndarray or expression, shape (2N + l [+ r1],) * 2
    """
    N = G.shape[0]
    l = Cbar.shape[0]
    Z = np.zeros
    I = np.eye
    rows = [
        [P - G - G.T, GA, Z((N, l))],
        [GA.T, -P, Cbar.T],
        [Z((l, N)), Cbar, -kappa * I(l)],
    ]
    if GH is not None:
        r = GH.shape[1]
        rows[1][1] = -P + lam * (Ebar.T @ Ebar)
        for row, blk in zip(rows, [GH, Z((N, r)), Z((l, r))]):
            row.append(blk)
        rows.append([GH.T, Z((r, N)), Z((r, l)), -lam * I(r)])
    return bmat(rows)


def h2_trace_matrix(W, P, G, GB, bmat=np.block):
    """``[[W, B̄ᵀG], [GᵀB̄, G + Gᵀ − P]] > 0``, which gives ``W > B̄ᵀ P B̄``.

    (``G + Gᵀ − P ≤ GᵀP⁻¹G``, so by a Schur complement
    ``W > B̄ᵀG(G + Gᵀ − P)⁻¹GᵀB̄ ≥ B̄ᵀPB̄``.) With :func:`extended_h2_matrix`
    and ``trace W < ν²`` it bounds the worst-case H2 norm by ν.

    Parameters
    ----------
    W : ndarray or expression, shape (p + q, p + q)
    P : shape (N, N)
        P₂.
    G, GB
        From :func:`slack_products`.

    Returns
    -------
    ndarray or expression, shape (p + q + N,) * 2
    """
    return bmat([[W, GB.T], [GB, G + G.T - P]])


def h2_output_index(n, l):
    """Rows of :func:`extended_h2_matrix` that carry ``−κI`` (N = 2n)."""
    return np.arange(4 * n, 4 * n + l)
