"""Observer form of a full-order filter (12): is it ``x̂⁺ = A x̂ + G (y − C x̂)``?"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..core.validation import as_matrix

__all__ = ["observer_form"]


def observer_form(A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike, A: ArrayLike, C: ArrayLike) -> dict[str, Any]:
    """Express a filter with invertible ``C_F`` as an observer for ``x̂ = C_F x_f``.

    In the coordinates ``x̂ = C_F x_f`` the filter (12) reads
    ``x̂⁺ = Â x̂ + G y`` with ``Â = C_F A_F C_F⁻¹`` and ``G = C_F B_F``. It is
    a predictor observer ``x̂⁺ = A x̂ + G (y − C x̂)`` exactly when
    ``Â = A − G C``.

    Parameters
    ----------
    A_F, B_F, C_F : array_like
        The filter (``C_F`` square).
    A : array_like, shape (n, n)
        Plant matrix of the design model.
    C : array_like, shape (m, n)

    Returns
    -------
    dict
        ``G`` (n, m), ``A_hat`` (n, n), ``residual`` = ``max |Â − (A − G C)|``,
        ``observer_eigenvalues`` (eigenvalues of A_F).
    """
    A_F = as_matrix("A_F", A_F)
    C_F = as_matrix("C_F", C_F, A_F.shape)
    B_F = as_matrix("B_F", B_F, (A_F.shape[0], None))
    A = as_matrix("A", A, A_F.shape)
    C = as_matrix("C", C, (B_F.shape[1], A_F.shape[0]))
    cond = np.linalg.cond(C_F)
    if not cond < 1e12:
        raise InputError(f"C_F must be invertible (x̂ = C_F x_f); its condition number is {cond:.3g}")
    A_hat = C_F @ np.linalg.solve(C_F.T, A_F.T).T
    G = C_F @ B_F
    return {
        "G": G,
        "A_hat": A_hat,
        "residual": float(np.max(np.abs(A_hat - (A - G @ C)))),
        "observer_eigenvalues": np.linalg.eigvals(A_F),
    }
