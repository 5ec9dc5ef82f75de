"""A polytopic plant whose parameter drifts, with a fixed linear filter: the error and its energy bound.

For a filter certified at level γ (H∞, zero initial state), the error
``e = z − z_f`` obeys the energy inequality::

    Σₖ₌₀ᴷ |e(k)|²  ≤  γ² Σₖ₌₀ᴷ (|w(k)|² + |v(k)|²)        for every K

when the parameter α is constant (a parameter-dependent Lyapunov certificate)
and also when it varies arbitrarily in time (a common one). A slowly drifting
α lies between the two: :func:`simulate_drift` reports both energies so the
inequality can be checked along the run, and how close the run came
(the ratio of the two square roots, ≤ γ when the promise holds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError

__all__ = ["DriftRun", "simulate_drift", "cell_sweep_weights"]


@dataclass(frozen=True, eq=False)
class DriftRun:
    """One run of :func:`simulate_drift`.

    Attributes
    ----------
    e : ndarray, shape (K, l)
        The error ``z − z_f``.
    error_energy, input_energy : ndarray, shape (K,)
        Running sums ``Σ |e|²`` and ``Σ (|w|² + |v|²)``.
    gain : float
        ``sqrt(error_energy[-1] / input_energy[-1])``, the run's energy gain.
    """

    e: np.ndarray
    error_energy: np.ndarray
    input_energy: np.ndarray

    @property
    def gain(self) -> float:
        return float(np.sqrt(self.error_energy[-1] / self.input_energy[-1]))

    def running_gain(self) -> np.ndarray:
        """``sqrt(Σ|e|² / Σ|τ|²)`` after each step (nan before the first nonzero input)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.sqrt(self.error_energy / self.input_energy)


def simulate_drift(system, A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike, alphas: ArrayLike, w: ArrayLike,
                   v: ArrayLike) -> DriftRun:
    """Run the plant at the convex weights ``alphas[k]`` (step k) and the filter, from zero initial states.

    Parameters
    ----------
    system : PolytopicSystem
    A_F, B_F, C_F : array_like
        The filter ``x_f⁺ = A_F x_f + B_F y``, ``z_f = C_F x_f``.
    alphas : array_like, shape (K, N)
    w, v : array_like, shapes (K, p), (K, q)
        Process and measurement noise inputs.

    Returns
    -------
    DriftRun
    """
    alphas, w, v = (np.asarray(a, dtype=float) for a in (alphas, w, v))
    A_F, B_F, C_F = (np.asarray(a, dtype=float) for a in (A_F, B_F, C_F))
    K = alphas.shape[0]
    if alphas.shape != (K, system.n_vertices) or w.shape[0] != K or v.shape[0] != K:
        raise InputError(f"alphas must have shape (K, {system.n_vertices}) and w, v K rows; got {alphas.shape}, "
                         f"{w.shape}, {v.shape}")
    stack = {k: np.stack([getattr(s, k) for s in system.vertices]) for k in ("A", "B", "C", "D", "L")}
    x = np.zeros(system.n)
    xf = np.zeros(A_F.shape[0])
    e = np.empty((K, C_F.shape[0]))
    for k in range(K):
        M = {name: np.tensordot(alphas[k], S, axes=1) for name, S in stack.items()}
        y = M["C"] @ x + M["D"] @ v[k]
        e[k] = M["L"] @ x - C_F @ xf
        x = M["A"] @ x + M["B"] @ w[k]
        xf = A_F @ xf + B_F @ y
    return DriftRun(e, np.cumsum(np.sum(e * e, axis=1)), np.cumsum(np.sum(w * w, axis=1) + np.sum(v * v, axis=1)))


def cell_sweep_weights(system, u: ArrayLike, r: float = 0.5) -> np.ndarray:
    """Convex weights sweeping the cells of a two-parameter box split along its first parameter.

    For a polytope from :func:`hinfnav.systems.polytope_from_parameters` with
    two parameters and ``splits`` on the first, cell j has the vertices
    ``(p₁ⱼ, p₂lo), (p₁ⱼ, p₂hi), (p₁ⱼ₊₁, p₂lo), (p₁ⱼ₊₁, p₂hi)``. ``u ∈ [0, n_cells]``
    moves the first parameter through the cells (``s = u − j`` inside cell j,
    linearly in the vertices), ``r ∈ [0, 1]`` is the fraction of the second.
    """
    cells = system.cells or (tuple(range(system.n_vertices)),)
    if any(len(c) != 4 for c in cells):
        raise InputError("cell_sweep_weights needs cells of 4 vertices (a two-parameter box)")
    u = np.clip(np.atleast_1d(np.asarray(u, dtype=float)), 0.0, len(cells))
    out = np.zeros((len(u), system.n_vertices))
    for k, uk in enumerate(u):
        j = min(int(uk), len(cells) - 1)
        s = uk - j
        for idx, wgt in zip(cells[j], ((1 - s) * (1 - r), (1 - s) * r, s * (1 - r), s * r)):
            out[k, idx] += wgt
    return out
