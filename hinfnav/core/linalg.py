"""Small linear-algebra helpers shared by every layer.

Nothing here knows about a paper, a system or an estimator: spectral radius,
symmetric part, covariance checks, zero-order-hold discretization, the
inverse of a batch of small symmetric positive definite matrices (the
innovation covariances of filters run with a leading runs dimension), and the
package's one Joseph-form covariance update (the Kalman filters' and the
posterior Cramér–Rao bound's).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from .exceptions import InputError
from .validation import as_choice, as_matrix, as_positive

__all__ = ["spectral_radius", "sym", "as_covariance", "discretize", "inv_spd", "matmul_shared", "congruence",
           "joseph_covariance", "SERIAL_PRODUCT_SIZE", "inv_spd_cholesky"]


def spectral_radius(A):
    """Largest eigenvalue modulus of a square matrix (Schur stable iff < 1)."""
    A = np.asarray(A, dtype=float)
    if A.size == 0:
        return 0.0
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def sym(M):
    """Symmetric part ``(M + Mᵀ)/2``."""
    M = np.asarray(M, dtype=float)
    return 0.5 * (M + M.T)


def as_covariance(name, value, n, definite):
    """Return ``value`` as a symmetric ``n × n`` covariance, checking its sign.

    Parameters
    ----------
    name : str
        Parameter name used in error messages.
    value : array_like, shape (n, n)
    n : int
    definite : bool
        Require positive definiteness (True) or only semidefiniteness.

    Raises
    ------
    InputError
        Wrong shape, not symmetric, or an eigenvalue of the wrong sign.
    """
    M = as_matrix(name, value, (n, n))
    scale = max(float(np.max(np.abs(M))), np.finfo(float).tiny)
    if not np.allclose(M, M.T, rtol=0, atol=1e-10 * scale):
        raise InputError(f"{name} must be symmetric (a covariance matrix)")
    M = 0.5 * M + 0.5 * M.T  # halves first: no overflow near the largest double
    low = float(np.min(np.linalg.eigvalsh(M)))
    if definite and low <= 0:
        raise InputError(f"{name} must be positive definite; its smallest eigenvalue is {low:.3g}")
    if not definite and low < -1e-12 * scale:
        raise InputError(f"{name} must be positive semidefinite; its smallest eigenvalue is {low:.3g}")
    return M


def discretize(Ac: ArrayLike, Gc: ArrayLike, dt: float,
               method: str = "exact") -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Discretize ``ẋ = Ac x + Gc u`` with a zero-order hold on ``u``.

    Parameters
    ----------
    Ac : array_like, shape (n, n)
    Gc : array_like, shape (n, m)
    dt : float
        Sampling time T, s.
    method : {"exact", "euler"}
        ``"euler"``: ``(I + T Ac, T Gc)``.
        ``"exact"``: ``(e^{Ac T}, ∫₀ᵀ e^{Ac s} ds Gc)``.

    Returns
    -------
    Ad : ndarray, shape (n, n)
    Gd : ndarray, shape (n, m)

    Notes
    -----
    The two agree to first order in T; the Euler error is
    ``T² Ac²/2 + O(T³)`` (tested in ``tests/test_systems.py``).
    """
    Ac = as_matrix("Ac", Ac)
    n = Ac.shape[0]
    if Ac.shape != (n, n):
        raise InputError(f"Ac must be square; got shape {Ac.shape}")
    Gc = as_matrix("Gc", Gc, (n, None))
    dt = as_positive("dt", dt)
    as_choice("discretization method", method, ("exact", "euler"))
    if method == "euler":
        return np.eye(n) + dt * Ac, dt * Gc
    m = Gc.shape[1]
    M = np.zeros((n + m, n + m))
    M[:n, :n] = Ac * dt
    M[:n, n:] = Gc * dt
    E = scipy.linalg.expm(M)
    return E[:n, :n], E[:n, n:]


#: Largest size m solved by :func:`inv_spd`'s elementwise Cholesky loops (larger: LAPACK per matrix).
ELEMENTWISE_SIZE = 6
#: Largest batch that :func:`inv_spd` inverts one matrix at a time in Python floats (the same operations).
SCALAR_BATCH = 8


def _chol_inv_one(S):
    """``S⁻¹`` of one small symmetric matrix (nested lists of Python floats) by :func:`_chol_inv_elementwise`'s
    operations in Python's double arithmetic (the same roundings); None when a pivot is not positive."""
    m = len(S)
    L = [[0.0] * m for _ in range(m)]
    for j in range(m):
        Lj = L[j]
        s = S[j][j]
        for k in range(j):
            s -= Lj[k] * Lj[k]
        if not s > 0.0 or s == math.inf:
            return None
        d = math.sqrt(s)
        Lj[j] = d
        for i in range(j + 1, m):
            Li = L[i]
            t = S[i][j]
            for k in range(j):
                t -= Li[k] * Lj[k]
            Li[j] = t / d
    out = [[0.0] * m for _ in range(m)]
    for c in range(m):
        col = [0.0] * m
        for i in range(m):
            Li = L[i]
            s = 1.0 if i == c else 0.0
            for k in range(i):
                s -= Li[k] * col[k]
            col[i] = s / Li[i]
        for i in range(m - 1, -1, -1):
            s = col[i]
            for k in range(i + 1, m):
                s -= L[k][i] * col[k]
            col[i] = s / L[i][i]
        for i in range(m):
            out[i][c] = col[i]
    for i in range(m):
        for j in range(i + 1, m):
            v = 0.5 * (out[i][j] + out[j][i])
            out[i][j] = out[j][i] = v
    return out


def _chol_inv_elementwise(S):
    """``(S⁻¹, ok)`` of a batch of small symmetric matrices by their Cholesky factor, elementwise over the batch.

    The operations, in their order, of the compiled kernels' ``inv_to``
    (:mod:`hinfnav.estimators.compiled_linalg`): the lower factor
    ``L_jj = √(S_jj − Σ_{k<j} L_jk²)``, ``L_ij = (S_ij − Σ_{k<j} L_ik L_jk)/L_jj``
    (the lower triangle of S is read), then each column of S⁻¹ by a forward
    and a back substitution, then the symmetric part. ``ok`` (shape of the
    batch) is False where a pivot is not positive (not positive definite).
    """
    m = S.shape[-1]
    L = [[None] * m for _ in range(m)]
    ok = np.ones(S.shape[:-2], dtype=bool)
    with np.errstate(all="ignore"):
        for j in range(m):
            s = S[..., j, j].copy()
            for k in range(j):
                s -= L[j][k] * L[j][k]
            ok &= s > 0.0
            d = np.sqrt(s)
            L[j][j] = d
            for i in range(j + 1, m):
                t = S[..., i, j].copy()
                for k in range(j):
                    t -= L[i][k] * L[j][k]
                L[i][j] = t / d
        out = np.empty(S.shape)
        for c in range(m):
            col = [None] * m
            for i in range(m):
                s = np.full(S.shape[:-2], 1.0 if i == c else 0.0)
                for k in range(i):
                    s -= L[i][k] * col[k]
                col[i] = s / L[i][i]
            for i in range(m - 1, -1, -1):
                s = col[i]
                for k in range(i + 1, m):
                    s = s - L[k][i] * col[k]
                col[i] = s / L[i][i]
            for i in range(m):
                out[..., i, c] = col[i]
    out = 0.5 * (out + np.swapaxes(out, -1, -2))
    return out, ok & np.isfinite(out).all(axis=(-1, -2))


def inv_spd_cholesky(S):
    """Inverse of a batch of small symmetric positive definite matrices, by their Cholesky factors.

    Parameters
    ----------
    S : ndarray, shape (..., m, m)
        Symmetric positive definite (its lower triangle is read).

    Returns
    -------
    ndarray, shape (..., m, m)
        ``S⁻¹``, exactly symmetric.

    Notes
    -----
    ``S = L Lᵀ`` (Cholesky), then ``S⁻¹`` column by column by forward and
    back substitution, symmetrised: for m ≤ :data:`ELEMENTWISE_SIZE` as
    elementwise operations over the batch, in the order of the compiled
    kernels (so both backends compute the same numbers), larger m by
    LAPACK's Cholesky per matrix. Cholesky's backward error is of the order
    of the unit round-off u for any positive definite S, and it is
    invariant under a diagonal scaling of S (van der Sluis): the relative
    error of S⁻¹ is bounded by ``κ(D S D) u`` for the best diagonal D, not
    ``κ(S) u``, so channels in very different units (a condition of 1e12 of
    S, but not of its correlation matrix) lose nothing. An adjugate over a
    determinant (this function's former method for m ≤ 3) errs by up to
    ``κ(S)²``-like cancellations (about 2·10⁵ κ u measured on such S).
    The fallback: a matrix that is not positive definite (a pivot not
    positive) or whose inverse overflows is handed to ``numpy.linalg.inv``
    (LU), which raises ``LinAlgError`` if it is singular.
    """
    S = np.asarray(S, dtype=float)
    m = S.shape[-1]
    batch = S.size // max(1, m * m)
    if m == 1:  # the same operations: d = √s, (1/d)/d (the forward and the back substitution)
        s = S[..., 0, 0]
        if (s > 0).all() and (s < np.inf).all():
            d = np.sqrt(s)
            return ((1.0 / d) / d)[..., None, None]
    if m <= ELEMENTWISE_SIZE and batch <= SCALAR_BATCH:  # a few matrices: Python floats cost less than arrays
        rows = S.reshape(batch, m, m).tolist()
        inv = [_chol_inv_one(Sb) for Sb in rows]
        ok = np.array([v is not None for v in inv], dtype=bool).reshape(S.shape[:-2])
        out = np.array([np.full((m, m), np.nan) if v is None else v for v in inv], dtype=float).reshape(S.shape)
        ok &= np.isfinite(out).all(axis=(-1, -2))
    elif m <= ELEMENTWISE_SIZE:
        out, ok = _chol_inv_elementwise(S)
    else:
        out = np.empty(S.shape)
        ok = np.zeros(S.shape[:-2], dtype=bool)
        try:
            L = np.linalg.cholesky(S)
            Li = np.linalg.solve(L, np.broadcast_to(np.eye(m), S.shape))
            out = np.swapaxes(Li, -1, -2) @ Li
            out = 0.5 * (out + np.swapaxes(out, -1, -2))
            ok = np.isfinite(out).all(axis=(-1, -2))
        except np.linalg.LinAlgError:
            pass
    if ok.all():  # the usual case
        return out
    bad = ~ok
    if out.ndim == 2:
        return np.linalg.inv(S)
    out[bad] = np.linalg.inv(S[bad])
    return out


#: The NumPy reference path keeps :func:`inv_spd` (the adjugate for m ≤ 3) so that the papers' numbers stay as
#: published by this workbook: the Cholesky form :func:`inv_spd_cholesky` (the compiled kernels' operations, more
#: accurate on ill-conditioned innovation covariances) moves rounding-sensitive results (attitude2018's strong
#: tracking at β = 3, 4; several yang2020 fields) by up to 9 % when it replaces it (issue 32, measured; open).
def _inv_sym3(S):
    """Adjugate inverse of a batch of symmetric 3 × 3 matrices; ``(adjugate, determinant)``."""
    a, b, c = S[..., 0, 0], S[..., 0, 1], S[..., 0, 2]
    d, e, f = S[..., 1, 1], S[..., 1, 2], S[..., 2, 2]
    adj = np.empty(S.shape)
    adj[..., 0, 0] = d * f - e * e
    adj[..., 0, 1] = adj[..., 1, 0] = c * e - b * f
    adj[..., 0, 2] = adj[..., 2, 0] = b * e - c * d
    adj[..., 1, 1] = a * f - c * c
    adj[..., 1, 2] = adj[..., 2, 1] = b * c - a * e
    adj[..., 2, 2] = a * d - b * b
    det = a * adj[..., 0, 0] + b * adj[..., 0, 1] + c * adj[..., 0, 2]
    return adj, det


def inv_spd(S):
    """Inverse of a batch of small symmetric positive definite matrices.

    Parameters
    ----------
    S : ndarray, shape (..., m, m)
        Symmetric positive definite (only the upper triangle is read when
        m ≤ 3).

    Returns
    -------
    ndarray, shape (..., m, m)
        ``S⁻¹``, exactly symmetric for m ≤ 3.

    Notes
    -----
    For m ≤ 3 the inverse is the adjugate over the determinant, evaluated
    elementwise over the batch: about six times faster than
    ``numpy.linalg.inv`` on 1000 stacked 3 × 3 matrices, whose LAPACK call
    per matrix dominates a filter step run on many runs at once. Its
    relative error is of the order of the condition number times the unit
    round-off, as for LU; a matrix whose determinant is not positive and
    finite (not positive definite, or overflowing) is handed to
    ``numpy.linalg.inv`` instead, which raises ``LinAlgError`` if it is
    singular. Larger m: ``numpy.linalg.inv``.
    """
    S = np.asarray(S, dtype=float)
    m = S.shape[-1]
    if m == 1:
        det = S[..., 0, 0]
        if (det > 0).all() and np.isfinite(det).all():  # the usual case, as below with adj = 1
            return 1.0 / det[..., None, None]
        adj = np.ones_like(S)
    elif m == 2:
        det = S[..., 0, 0] * S[..., 1, 1] - S[..., 0, 1] * S[..., 0, 1]
        adj = np.stack([S[..., 1, 1], -S[..., 0, 1], -S[..., 0, 1], S[..., 0, 0]], axis=-1).reshape(S.shape)
    elif m == 3:
        adj, det = _inv_sym3(S)
    else:
        return np.linalg.inv(S)
    if (det > 0).all() and np.isfinite(det).all():  # the usual case: no quotient is invalid
        return adj / det[..., None, None]
    with np.errstate(all="ignore"):
        out = adj / det[..., None, None]
    bad = ~(np.isfinite(det) & (det > 0))
    out[bad] = np.linalg.inv(S[bad])
    return out


#: Largest m·n·k of one matrix product in :func:`matmul_shared`: OpenBLAS runs a product on several
#: threads from m·n·k = 4 × 65536 on; for these thin products the threads cost more than they save
#: (the strong-tracking filter of ``benchmarks/bench_campaign.py``: 27.9 s wall and 55 s CPU on 2
#: threads, 23 s on one), so longer stacks are multiplied in blocks of rows below that size.
SERIAL_PRODUCT_SIZE = 4 * 65536 - 1


def matmul_shared(A, B):
    """``A @ B`` for a batch ``A`` (..., i, j) and one matrix ``B`` (j, k), as a few matrix products.

    NumPy multiplies a stack by a broadcast matrix one pair at a time; the
    stack reshaped to ((...)·i, j) makes it one BLAS call (about twice as
    fast on 1000 stacked 9 × 9 matrices), in blocks of rows that keep each
    call single-threaded (:data:`SERIAL_PRODUCT_SIZE`). Every row is the
    same dot products as in ``A @ B``; the numbers do not depend on the
    batch size. Any other shapes: ``A @ B``.
    """
    if A.ndim < 3 or B.ndim != 2:
        return A @ B
    A2 = np.ascontiguousarray(A).reshape(-1, A.shape[-1])
    rows = max(1, SERIAL_PRODUCT_SIZE // max(1, B.shape[0] * B.shape[1]))
    if A2.shape[0] <= rows:
        out = A2 @ B
    else:
        out = np.empty((A2.shape[0], B.shape[1]), dtype=np.result_type(A2, B))
        for s in range(0, A2.shape[0], rows):
            np.matmul(A2[s:s + rows], B, out=out[s:s + rows])
    return out.reshape(A.shape[:-1] + (B.shape[-1],))


def congruence(F, P):
    """``F P Fᵀ`` for one matrix ``F`` (k, n) and a symmetric ``P`` (n, n) or batch (..., n, n).

    With a batch, ``F P Fᵀ = (P Fᵀ)ᵀ Fᵀ`` (P symmetric) by
    :func:`matmul_shared` twice. Equal to ``F @ P @ Fᵀ`` up to the order of
    the floating-point sums (neither is exactly symmetric).
    """
    if P.ndim < 3 or F.ndim != 2:
        return F @ P @ np.swapaxes(F, -1, -2)
    FT = F.T
    return matmul_shared(np.swapaxes(matmul_shared(P, FT), -1, -2), FT)


def joseph_covariance(P: NDArray[np.float64], K: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64], *,
                      symmetrize: bool = True) -> NDArray[np.float64]:
    """The Joseph-form posterior ``(I − K H) P (I − K H)ᵀ + K R Kᵀ`` for a given gain K, batched.

    Eq. (J2) of :mod:`hinfnav.estimators.correction` (P, R in the squared
    units of the state and the reading). Valid for any gain: the optimal one
    of (J1), one with some columns set to 0 for readings that are not used
    (Algorithm 2 on a skipped clipped reading), or an information update with
    R = I (the posterior Cramér–Rao bound's). The package's one Joseph form.
    Shapes broadcast: P (..., n, n), K (..., n, m), H (..., m, n), R (..., m, m).
    """
    I_KH = _identity(P.shape[-1]) - matmul_shared(K, H)
    P_post = I_KH @ P @ I_KH.swapaxes(-1, -2) + matmul_shared(K, R) @ K.swapaxes(-1, -2)
    if symmetrize:
        P_post = 0.5 * (P_post + P_post.swapaxes(-1, -2))
    return P_post


@functools.lru_cache(maxsize=64)
def _identity(n):
    """``np.eye(n)``, made once per size (read-only)."""
    eye = np.eye(n)
    eye.setflags(write=False)
    return eye
