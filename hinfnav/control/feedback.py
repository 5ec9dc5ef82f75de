"""Feedback laws that act on the true or on the estimated state."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_matrix

__all__ = ["SOURCES", "LinearFeedback"]

#: What a feedback law reads: the true state (the idealized loop of Sun et al.
#: 2011, u = K x) or the estimate (u = K x̂, a real closed loop).
SOURCES = ("truth", "estimate")


class LinearFeedback:
    """State feedback ``u = K x`` (or ``u = K x̂``), vectorized over runs.

    Parameters
    ----------
    K : array_like, shape (m_u, n)
        Gain, input units per state unit.
    source : {"truth", "estimate"}
        Whether the law acts on the true state or on the estimate.
    name : str
    """

    def __init__(self, K: ArrayLike, *, source: str = "truth", name: str = "linear feedback") -> None:
        self.K = as_matrix("K", K)
        self.K.setflags(write=False)
        self.source = as_choice("feedback source", source, SOURCES)
        self.name = str(name)

    @property
    def n_input(self) -> int:
        return self.K.shape[0]

    @property
    def n_state(self) -> int:
        return self.K.shape[1]

    def __call__(self, x):
        """``u = x Kᵀ`` for a batch of states (rows are runs)."""
        x = np.asarray(x)
        if x.shape[-1] != self.n_state:
            raise InputError(f"the feedback law needs states with {self.n_state} components; got shape {x.shape}")
        return x @ self.K.T

    def acting_on(self, source: str) -> LinearFeedback:
        """The same gain acting on ``source`` ("truth" or "estimate")."""
        return LinearFeedback(self.K, source=source, name=self.name)

    def __repr__(self):
        return f"<LinearFeedback {self.name!r} on the {self.source}>"
