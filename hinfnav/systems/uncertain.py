"""The norm-bounded uncertain discrete system ψ_d of Sun et al. (2011), (9)–(11).

``x(k+1) = (A + H F E) x(k) + B w(k)``, ``y(k) = C x(k) + D v(k)``,
``z(k) = L x(k)``, with ``FᵀF ≤ I``: what the robust filter designs take.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_matrix, as_positive

__all__ = ["UncertainSystem"]


@dataclass(frozen=True, eq=False)
class UncertainSystem:
    """The uncertain discrete system ψ_d of (9)–(11).

    ``x(k+1) = (A + H F E) x(k) + B w(k)``, ``y(k) = C x(k) + D v(k)``,
    ``z(k) = L x(k)``, with ``FᵀF ≤ I``.

    Attributes
    ----------
    A : ndarray, shape (n, n)
    B : ndarray, shape (n, p)
    C : ndarray, shape (m, n)
    D : ndarray, shape (m, q)
    L : ndarray, shape (l, n)
    H : ndarray, shape (n, r) or None
    E : ndarray, shape (r, n) or None
    dt : float
        Sampling time, s.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray
    H: np.ndarray = None
    E: np.ndarray = None
    dt: float = 1.0

    def __post_init__(self):
        A = as_matrix("A", self.A)
        n = A.shape[0]
        if A.shape != (n, n):
            raise InputError(f"A must be square; got shape {A.shape}")
        checked = {
            "A": A,
            "B": as_matrix("B", self.B, (n, None)),
            "C": as_matrix("C", self.C, (None, n)),
            "L": as_matrix("L", self.L, (None, n)),
        }
        checked["D"] = as_matrix("D", self.D, (checked["C"].shape[0], None))
        if (self.H is None) != (self.E is None):
            raise InputError("H and E must be given together (or both left out for a nominal system)")
        if self.H is not None:
            H = as_matrix("H", self.H, (n, None))
            checked["H"] = H
            checked["E"] = as_matrix("E", self.E, (H.shape[1], n))
        for key, value in checked.items():
            value.setflags(write=False)
            object.__setattr__(self, key, value)
        object.__setattr__(self, "dt", as_positive("dt", self.dt))

    @property
    def n(self) -> int:
        """State dimension."""
        return self.A.shape[0]

    def perturbed_A(self, F: ArrayLike | None) -> NDArray[np.float64]:
        """``A + H F E`` for a given uncertainty matrix ``F`` (shape (r, r))."""
        if self.H is None:
            return self.A.copy()
        F = as_matrix("F", F, (self.H.shape[1], self.E.shape[0]))
        return self.A + self.H @ F @ self.E
