"""Discrete linear dynamics ``x(k+1) = Φ x(k) + Γ u(k) + B w(k)``.

The object every generic estimator, simulation and analysis reads its
dimensions, labels and sampling time from. Unit-variance white noise w
enters through B, so the process-noise covariance per step is ``Q = B Bᵀ``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_matrix, as_positive
from .compiled import CompiledDynamics, package_functions
from .state import StateSpec

__all__ = ["LinearSystem"]


@dataclass(frozen=True, eq=False)
class LinearSystem:
    """Discrete linear system with input and process noise.

    Attributes
    ----------
    Phi : ndarray, shape (n, n)
        State transition over one sampling interval.
    Gamma : ndarray, shape (n, m_u)
        Input matrix (input held over the interval).
    B : ndarray, shape (n, p)
        Process-noise matrix; w is white with unit variance, Q = B Bᵀ.
    dt : float
        Sampling time, s.
    state : StateSpec
        Labels, units, groups and error definition of the state.
    input_labels, input_units : tuple of str
        Names and units of the input channels.
    name : str
    """

    Phi: np.ndarray
    Gamma: np.ndarray
    B: np.ndarray
    dt: float
    state: StateSpec
    input_labels: tuple = ()
    input_units: tuple = ()
    name: str = "linear system"
    info: dict = field(default_factory=dict)

    #: The dynamics-model protocol (:mod:`hinfnav.systems.dynamics`): f is linear, its Jacobian is Φ.
    linear = True

    def __post_init__(self):
        Phi = as_matrix("Phi", self.Phi)
        n = Phi.shape[0]
        if Phi.shape != (n, n):
            raise InputError(f"Phi must be square; got shape {Phi.shape}")
        if not isinstance(self.state, StateSpec):
            raise InputError(f"state must be a StateSpec; got {type(self.state).__name__}")
        if self.state.n != n:
            raise InputError(f"state has {self.state.n} components but Phi is {n}x{n}")
        Gamma = as_matrix("Gamma", self.Gamma, (n, None))
        B = as_matrix("B", self.B, (n, None))
        for key, value in (("Phi", Phi), ("Gamma", Gamma), ("B", B)):
            value.setflags(write=False)
            object.__setattr__(self, key, value)
        object.__setattr__(self, "dt", as_positive("dt", self.dt))
        m = Gamma.shape[1]
        labels = tuple(self.input_labels) or tuple(f"u{i}" for i in range(m))
        units = tuple(self.input_units) or ("",) * m
        if len(labels) != m or len(units) != m:
            raise InputError(f"input_labels and input_units must have {m} entries (columns of Gamma)")
        object.__setattr__(self, "input_labels", labels)
        object.__setattr__(self, "input_units", units)

    @property
    def n(self) -> int:
        """State dimension."""
        return self.Phi.shape[0]

    @property
    def n_input(self) -> int:
        """Number of input channels."""
        return self.Gamma.shape[1]

    @property
    def n_noise(self) -> int:
        """Number of process-noise channels (columns of B)."""
        return self.B.shape[1]

    @property
    def Q(self) -> NDArray[np.float64]:
        """Process-noise covariance per step, ``B Bᵀ``."""
        return self.B @ self.B.T

    def transition_matrix(self, K: ArrayLike | None = None) -> NDArray[np.float64]:
        """``Φ`` or, with a state-feedback gain K (u = K x), the closed loop ``Φ + Γ K``."""
        if K is None:
            return self.Phi
        K = as_matrix("K", K, (self.n_input, self.n))
        return self.Phi + self.Gamma @ K

    def f(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """The dynamics-model protocol: ``x Φᵀ (+ u Γᵀ)`` for a batch (rows are runs); t is not used."""
        return self.propagate(x, u)

    def jacobian(self, x: ArrayLike | None = None, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """The dynamics-model protocol: ``∂f/∂x = Φ``, shape (n, n), whatever x."""
        return self.Phi

    def compiled_functions(self) -> CompiledDynamics:
        """``Φ x + Γ u`` and Φ for one state, numba-compiled (:mod:`hinfnav.systems.compiled`), for a filter whose
        measurement is not linear."""
        fns = package_functions()
        params = np.concatenate([[self.n, self.n_input], self.Phi.ravel(), self.Gamma.ravel()])
        return CompiledDynamics(fns.linear_f, fns.linear_jacobian, params)

    def propagate(self, x: ArrayLike, u: ArrayLike | None = None, w: ArrayLike | None = None) -> NDArray[np.float64]:
        """One step for a batch: ``x Φᵀ + u Γᵀ + w Bᵀ`` (rows are runs)."""
        out = np.asarray(x) @ self.Phi.T
        if u is not None:
            out = out + np.asarray(u) @ self.Gamma.T
        if w is not None:
            out = out + np.asarray(w) @ self.B.T
        return out
