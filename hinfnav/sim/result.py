"""The result of a Monte Carlo simulation: truth plus one estimator's histories."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["SimulationResult"]


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Truth plus one estimator's output.

    Attributes
    ----------
    t : ndarray, shape (n_samples,)
    x, xhat : ndarray, shape (runs, n_samples, n)
    u : ndarray, shape (runs, n_samples, m_u)
    y : ndarray, shape (runs, n_samples, m)
    P : ndarray, shape (runs, n_samples, n, n), or None
    settings : dict
        The truth's settings plus ``filter``.
    state : StateSpec
        Labels, units, groups and error definition of the state.
    diagnostics : dict
        The estimator's diagnostics histories, when asked for.
    xhat0 : ndarray, shape (n,) or None
        The estimator's initial estimate (for the consistency checks,
        :func:`hinfnav.metrics.consistency`).
    """

    t: np.ndarray
    x: np.ndarray
    xhat: np.ndarray
    u: np.ndarray
    y: np.ndarray
    P: np.ndarray = None
    settings: dict = field(default_factory=dict)
    state: object = None
    diagnostics: dict = field(default_factory=dict)
    xhat0: np.ndarray = None

    @property
    def error(self) -> NDArray[np.float64]:
        """Estimation error by the state's definition (``x − x̂`` for an additive state)."""
        if self.state is None:
            return self.x - self.xhat
        return self.state.error(self.x, self.xhat)

    @property
    def runs(self) -> int:
        """Number of Monte Carlo runs."""
        return self.x.shape[0]
