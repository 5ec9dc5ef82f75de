"""Small dense linear algebra for the compiled kernels (numba; imported with :mod:`.compiled_kernels`).

The kernels' matrices are small (n ≤ ~10, m ≤ ~5): a BLAS/LAPACK call per
product would cost more than the product, so products, Cholesky factors,
triangular solves and inverses are plain loops. Functions named ``*_to``
write into a given array (no allocation in the kernels' step loops); the
others return a new array. ``chol``/``chol_to``/``inv_to``/``spd_inv`` report
a matrix that is not positive definite by a False flag (the kernels then hand
the batch back to the NumPy reference, which raises its own error).

numba's on-disk cache checks only the file of the function it compiles: after editing
this module, delete the kernels' cache (``__pycache__/compiled_*.nbi``/``.nbc`` or
``NUMBA_CACHE_DIR``) or touch :mod:`hinfnav.estimators.compiled_kernels`.
"""

import numpy as np
from numba import njit

__all__ = ["chol", "chol_solve", "chol_to", "eye_minus", "finite", "inv_to", "lin", "maxabs", "mm", "mm_to", "mmt",
           "mmt_sym_to", "mmt_to", "mv", "mv_to", "sym", "tri_inv"]

@njit(cache=True, error_model="numpy")
def mm(A, B):
    """A B."""
    n, k = A.shape
    p = B.shape[1]
    out = np.zeros((n, p))
    for i in range(n):
        for j in range(k):
            a = A[i, j]
            if a != 0.0:
                for c in range(p):
                    out[i, c] += a * B[j, c]
    return out


@njit(cache=True, error_model="numpy")
def mmt(A, B):
    """A Bᵀ."""
    n, k = A.shape
    p = B.shape[0]
    out = np.empty((n, p))
    for i in range(n):
        for c in range(p):
            s = 0.0
            for j in range(k):
                s += A[i, j] * B[c, j]
            out[i, c] = s
    return out


@njit(cache=True, error_model="numpy")
def mv(A, x):
    n, k = A.shape
    out = np.empty(n)
    for i in range(n):
        s = 0.0
        for j in range(k):
            s += A[i, j] * x[j]
        out[i] = s
    return out


@njit(cache=True, error_model="numpy")
def mm_to(A, B, out):
    """out = A B (no allocation; the zero entries of A skipped: Φ, I − K H and the augmented blocks are sparse)."""
    n, k = A.shape
    p = B.shape[1]
    for i in range(n):
        for c in range(p):
            out[i, c] = 0.0
        for j in range(k):
            a = A[i, j]
            if a != 0.0:
                for c in range(p):
                    out[i, c] += a * B[j, c]


@njit(cache=True, error_model="numpy")
def mmt_to(A, B, out):
    """out = A Bᵀ (no allocation; the zero entries of B skipped)."""
    n, k = A.shape
    p = B.shape[0]
    for i in range(n):
        for c in range(p):
            out[i, c] = 0.0
    for c in range(p):
        for j in range(k):
            b = B[c, j]
            if b != 0.0:
                for i in range(n):
                    out[i, c] += A[i, j] * b


@njit(cache=True, error_model="numpy")
def mmt_sym_to(A, B, out):
    """out = A Bᵀ for a product known to be symmetric (F P Fᵀ, (I − KH) P (I − KH)ᵀ): the upper triangle
    computed (the zero entries of B skipped), the lower one mirrored."""
    n, k = A.shape
    for i in range(n):
        for c in range(i, n):
            out[i, c] = 0.0
    for c in range(n):
        for j in range(k):
            b = B[c, j]
            if b != 0.0:
                for i in range(c + 1):
                    out[i, c] += A[i, j] * b
    for i in range(n):
        for c in range(i):
            out[i, c] = out[c, i]


@njit(cache=True, error_model="numpy")
def mv_to(A, x, out):
    """out = A x (no allocation)."""
    n, k = A.shape
    for i in range(n):
        s = 0.0
        for j in range(k):
            s += A[i, j] * x[j]
        out[i] = s


@njit(cache=True, error_model="numpy")
def chol_to(A, L):
    """L = the lower Cholesky factor of A (no allocation); False if A is not positive definite."""
    n = A.shape[0]
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            return False
        d = np.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            t = A[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
            L[j, i] = 0.0
    return True


@njit(cache=True, error_model="numpy")
def inv_to(A, L, out):
    """out = A⁻¹ of a symmetric positive definite A, by its Cholesky factor in L; False if not definite."""
    n = A.shape[0]
    if not chol_to(A, L):
        return False
    for c in range(n):
        for i in range(n):
            s = 1.0 if i == c else 0.0
            for k in range(i):
                s -= L[i, k] * out[k, c]
            out[i, c] = s / L[i, i]
        for i in range(n - 1, -1, -1):
            s = out[i, c]
            for k in range(i + 1, n):
                s -= L[k, i] * out[k, c]
            out[i, c] = s / L[i, i]
    sym(out)
    return True


@njit(cache=True, error_model="numpy")
def lin(a, X, b, Y):
    """a X + b Y (1-D or 2-D arrays of one shape), a new array."""
    out = np.empty_like(X)
    xf, yf, of = X.ravel(), Y.ravel(), out.ravel()
    for i in range(xf.size):
        of[i] = a * xf[i] + b * yf[i]
    return out


@njit(cache=True, error_model="numpy")
def eye_minus(B):
    """I − B."""
    out = -B
    for i in range(B.shape[0]):
        out[i, i] += 1.0
    return out


@njit(cache=True, error_model="numpy")
def maxabs(x):
    s = 0.0
    for v in x:
        s = max(s, abs(v))
    return s


@njit(cache=True, error_model="numpy")
def sym(A):
    n = A.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            v = 0.5 * (A[i, j] + A[j, i])
            A[i, j] = v
            A[j, i] = v


@njit(cache=True, error_model="numpy")
def chol(A):
    """Lower Cholesky factor of a symmetric matrix; ``(L, ok)`` (:func:`chol_to` into a new array)."""
    L = np.zeros(A.shape)
    ok = chol_to(A, L)
    return L, ok


@njit(cache=True, error_model="numpy")
def chol_solve(L, B):
    """(L Lᵀ)⁻¹ B for a lower factor L and B (n, p)."""
    n, p = B.shape
    X = B.copy()
    for c in range(p):
        for i in range(n):
            s = X[i, c]
            for k in range(i):
                s -= L[i, k] * X[k, c]
            X[i, c] = s / L[i, i]
        for i in range(n - 1, -1, -1):
            s = X[i, c]
            for k in range(i + 1, n):
                s -= L[k, i] * X[k, c]
            X[i, c] = s / L[i, i]
    return X


@njit(cache=True, error_model="numpy")
def tri_inv(L):
    """L⁻¹ of a lower-triangular L."""
    n = L.shape[0]
    X = np.zeros((n, n))
    for c in range(n):
        for i in range(c, n):
            s = 1.0 if i == c else 0.0
            for k in range(c, i):
                s -= L[i, k] * X[k, c]
            X[i, c] = s / L[i, i]
    return X


@njit(cache=True, error_model="numpy")
def spd_inv(A):
    """``(A⁻¹, True)`` of a symmetric positive definite A (:func:`inv_to` into new arrays), else ``(A, False)``."""
    X = np.empty(A.shape)
    if not inv_to(A, np.zeros(A.shape), X):
        return A, False
    return X, True


@njit(cache=True, error_model="numpy")
def finite(A):
    for v in A.ravel():
        if not np.isfinite(v):
            return False
    return True
