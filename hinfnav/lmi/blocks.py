"""The matrices of LMI (20) (Theorem 1 of Sun et al. 2011) and of its observer-form variant; the error-system check.

Written once for both numbers (``bmat=np.block``: certification) and cvxpy
expressions (``bmat=cvxpy.bmat``: the solver), so the certificate evaluates
exactly the matrix the solver was given.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_matrix

if TYPE_CHECKING:
    import cvxpy as cp

__all__ = ["lmi20_matrix", "observer_lmi_matrix", "gamma_index", "error_system_matrices"]


def lmi20_matrix(A: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike, L: ArrayLike, H: ArrayLike | None,
                 E: ArrayLike | None, R: ArrayLike | cp.Expression, S: ArrayLike | cp.Expression, Abar_F: ArrayLike | cp.Expression, Bbar_F: ArrayLike | cp.Expression,
                 Cbar_F: ArrayLike | cp.Expression, lam: float | cp.Expression, gamma2: float | cp.Expression,
                 bmat: Callable[..., Any] = np.block) -> NDArray[np.float64] | cp.Expression:
    """The matrix of LMI (20) (Theorem 1), negative definite iff the bound holds.

    Block rows/columns: ``[n, n, n, n, p, q, l, r]`` (the last one only when
    ``H`` is given)::

        [ −R  −S  RA + B̄_F C   Ā_F   RB   B̄_F D    0     RH  ]
        [  *  −S  SA + B̄_F C   Ā_F   SB   B̄_F D    0     SH  ]
        [  *   *  −R + λEᵀE    −S     0    0       Lᵀ     0   ]
        [  *   *   *           −S     0    0     −C̄_Fᵀ    0   ]
        [  *   *   *            *   −γ²I   0       0      0   ]
        [  *   *   *            *     *  −γ²I      0      0   ]
        [  *   *   *            *     *    *      −I      0   ]
        [  *   *   *            *     *    *       *    −λI   ]

    Parameters
    ----------
    A, B, C, D, L : ndarray
        The plant ψ_d (9), shapes (n, n), (n, p), (m, n), (m, q), (l, n).
    H, E : ndarray or None
        Uncertainty factors, shapes (n, r1) and (r2, n) (``ΔA = H F E``);
        ``None`` for the nominal LMI (no λ block).
    R, S : ndarray or cvxpy expression, shape (n, n)
    Abar_F : shape (n, n)
    Bbar_F : shape (n, m)
    Cbar_F : shape (l, n)
    lam : float or cvxpy expression
        λ = 1/ε of Lemma 2.
    gamma2 : float or cvxpy expression
        γ².
    bmat : callable, optional
        ``np.block`` for a numeric matrix, ``cvxpy.bmat`` for an expression.

    Returns
    -------
    ndarray or cvxpy expression, shape (4n + p + q + l [+ r1],) * 2
    """
    n, p = B.shape
    q = D.shape[1]
    l = L.shape[0]
    Z = np.zeros
    I = np.eye
    RA = R @ A + Bbar_F @ C
    SA = S @ A + Bbar_F @ C
    BD = Bbar_F @ D
    rows = [
        [-R, -S, RA, Abar_F, R @ B, BD, Z((n, l))],
        [-S, -S, SA, Abar_F, S @ B, BD, Z((n, l))],
        [RA.T, SA.T, -R, -S, Z((n, p)), Z((n, q)), L.T],
        [Abar_F.T, Abar_F.T, -S, -S, Z((n, p)), Z((n, q)), -Cbar_F.T],
        [(R @ B).T, (S @ B).T, Z((p, n)), Z((p, n)), -gamma2 * I(p), Z((p, q)), Z((p, l))],
        [BD.T, BD.T, Z((q, n)), Z((q, n)), Z((q, p)), -gamma2 * I(q), Z((q, l))],
        [Z((l, n)), Z((l, n)), L, -Cbar_F, Z((l, p)), Z((l, q)), -I(l)],
    ]
    if H is not None:
        _border_uncertainty(rows, R, S, H, E, lam, (n, p, q, l))
    return bmat(rows)


def observer_lmi_matrix(A: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike, L: ArrayLike, H: ArrayLike | None,
                        E: ArrayLike | None, X: ArrayLike | cp.Expression, S: ArrayLike | cp.Expression, Bbar_F: ArrayLike | cp.Expression,
                        lam: float | cp.Expression, gamma2: float | cp.Expression, bmat: Callable[..., Any] = np.block) -> NDArray[np.float64] | cp.Expression:
    """LMI (20) for an observer-form filter, in error coordinates (congruent to (20)).

    With the observer constraints ``Ā_F = S A + B̄_F C`` and ``C̄_F = −L``
    substituted, ``R = S + X``, and the congruence ``Tᵀ M T`` with
    ``T = diag(T₀, T₀, I, I, I[, I])``, ``T₀ = [[I, 0], [−I, I]]`` (the change
    of coordinates ``(x, x_f) → (x, e = x + x_f)``), LMI (20) becomes::

        [ −X   0    XA         0         XB     0      0    XH  ]
        [  *  −S    0        SA + B̄_F C  SB   B̄_F D    0    SH  ]
        [  *   *   −X + λEᵀE   0          0     0      0    0   ]
        [  *   *    *         −S          0     0      Lᵀ   0   ]
        [  *   *    *          *        −γ²I    0      0    0   ]
        [  *   *    *          *          *   −γ²I     0    0   ]
        [  *   *    *          *          *     *     −I    0   ]
        [  *   *    *          *          *     *      *  −λI   ]

    It is negative definite iff (20) is (congruence with an invertible T),
    at ``R = S + X``, ``Ā_F = S A + B̄_F C``, ``C̄_F = −L``. In these
    coordinates the Lyapunov matrix ``[[R, S], [S, S]]`` of (20) is
    ``diag(X, S)``: X weighs the plant state, S the estimation error, and
    the two are coupled only through the uncertainty (H, E) and the common
    −γ²I row of w. At δ̄ = 0 the infimum has X → 0 (the plant state does
    not reach the error), a boundary of the feasible set. On the paper's
    model, (20) with the constraints merely substituted makes Clarabel and
    CVXOPT stop with numerical errors near the optimum (δ̄ = 0 … 5, γ off by
    up to 6e-3 after bisection); on this form CVXOPT converges to ~1e-7.

    Parameters
    ----------
    A, B, C, D, L, H, E
        As in :func:`lmi20_matrix` (any ``L``); ``H = None`` for the
        nominal LMI.
    X, S : ndarray or cvxpy expression, shape (n, n)
    Bbar_F : shape (n, m)
    lam, gamma2 : float or cvxpy expression
    bmat : callable, optional

    Returns
    -------
    ndarray or cvxpy expression, same shape as :func:`lmi20_matrix`'s
    """
    n, p = B.shape
    q = D.shape[1]
    l = L.shape[0]
    Z = np.zeros
    I = np.eye
    XA = X @ A
    SA = S @ A + Bbar_F @ C
    BD = Bbar_F @ D
    rows = [
        [-X, Z((n, n)), XA, Z((n, n)), X @ B, Z((n, q)), Z((n, l))],
        [Z((n, n)), -S, Z((n, n)), SA, S @ B, BD, Z((n, l))],
        [XA.T, Z((n, n)), -X, Z((n, n)), Z((n, p)), Z((n, q)), Z((n, l))],
        [Z((n, n)), SA.T, Z((n, n)), -S, Z((n, p)), Z((n, q)), L.T],
        [(X @ B).T, (S @ B).T, Z((p, n)), Z((p, n)), -gamma2 * I(p), Z((p, q)), Z((p, l))],
        [Z((q, n)), BD.T, Z((q, n)), Z((q, n)), Z((q, p)), -gamma2 * I(q), Z((q, l))],
        [Z((l, n)), Z((l, n)), Z((l, n)), L, Z((l, p)), Z((l, q)), -I(l)],
    ]
    if H is not None:
        _border_uncertainty(rows, X, S, H, E, lam, (n, p, q, l))
    return bmat(rows)


def _border_uncertainty(rows: list, P: Any, S: Any, H: ArrayLike, E: ArrayLike, lam: Any,
                        dims: tuple[int, int, int, int]) -> None:
    """Add the λ border of Lemma 2 (``ΔA = H F E``) to the 7×7 block rows of LMI (20) or its observer form, in place.

    ``P`` is the block at (1, 1) and (3, 3) (``R`` in (20), ``X`` in the observer
    form): the (3, 3) block gains ``λ EᵀE``, and a last block row/column
    ``[P H, S H, 0, 0, 0, 0, 0, −λI]`` is appended; ``dims = (n, p, q, l)``.
    """
    n, p, q, l = dims
    r = H.shape[1]
    Z = np.zeros
    rows[2][2] = -P + lam * (E.T @ E)
    extra = [P @ H, S @ H] + [Z((k, r)) for k in (n, n, p, q, l)]
    for row, blk in zip(rows, extra):
        row.append(blk)
    rows.append([(P @ H).T, (S @ H).T, Z((r, n)), Z((r, n)), Z((r, p)), Z((r, q)), Z((r, l)), -lam * np.eye(r)])


def gamma_index(n: int, p: int, q: int) -> NDArray[np.intp]:
    return np.arange(4 * n, 4 * n + p + q)




def error_system_matrices(Abar, Bbar, Cbar, Hbar=None, Ebar=None):
    """Check the uncertain error system (13) ``(Ā, B̄, C̄, H̄, Ē)`` of an LMI; return them as float matrices.

    Shapes: Ā (N, N), B̄ (N, ·), C̄ (·, N), H̄ (N, ·) and Ē (·, N), the last
    two given together or not at all; an :class:`InputError` names the one
    that is wrong.
    """
    Abar = as_matrix("Abar", Abar)
    N = Abar.shape[0]
    Bbar = as_matrix("Bbar", Bbar, (N, None))
    Cbar = as_matrix("Cbar", Cbar, (None, N))
    if (Hbar is None) != (Ebar is None):
        raise InputError("Hbar and Ebar must be given together")
    if Hbar is not None:
        Hbar = as_matrix("Hbar", Hbar, (N, None))
        Ebar = as_matrix("Ebar", Ebar, (None, N))
    return Abar, Bbar, Cbar, Hbar, Ebar
