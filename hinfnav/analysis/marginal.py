"""Marginally stable plants with uncertainty: the part of the state the uncertainty reads, and the error system.

An observer-form filter built on nominal matrices ``(A₀, C₀, L₀)``,
``x_f⁺ = A_F x_f + B_F y``, ``z_f = C_F x_f`` with ``A_F = A₀ + B_F C₀``,
``C_F = −L₀`` (``x̂ = −x_f``), run on the vertex plant
``x⁺ = Aᵢ x + Bᵢ w``, ``y = Cᵢ x + Dᵢ v``, ``z = Lᵢ x`` has, in the error
``e = x + x_f = x − x̂``::

    e⁺ = A_F e + (ΔAᵢ + B_F ΔCᵢ) x + Bᵢ w + B_F Dᵢ v,
    z − z_f = L₀ e + ΔLᵢ x,                 ΔAᵢ = Aᵢ − A₀ (same for C, L).

Without uncertainty the plant state x drops out, and only (A₀, C₀)
detectable is needed (integrators are fine). With uncertainty the terms
``ΔAᵢ x``, ``ΔCᵢ x``, ``ΔLᵢ x`` read x, and the error stays bounded only if
the part of x they read stays bounded. **The condition.** Let
``M = [ΔA₁; ΔC₁; ΔL₁; …; ΔA_N; ΔC_N; ΔL_N]`` (all the uncertainty's rows)
and let ``𝒩`` be the largest subspace of ``ker M`` invariant under every
``Aᵢ`` (the unobservable subspace of the pairs ``(Aᵢ, M)``, common to all
vertices). Its orthogonal complement is spanned by the rows of ``M`` and
``M Aᵢ``, ``M Aᵢ Aⱼ``, … ; an orthonormal basis ``T`` (``n_s × n``) of it
gives the *read state* ``x_s = T x``, which obeys its own dynamics (``𝒩``
is invariant, so ``T Aᵢ = (T Aᵢ Tᵀ) T``)::

    x_s⁺ = Ãᵢ x_s + T Bᵢ w,   Ãᵢ = T Aᵢ Tᵀ,      ΔAᵢ x = (ΔAᵢ Tᵀ) x_s  (ker T = 𝒩 ⊂ ker M).

The error is therefore the output of the *augmented error system*
``ζ = [x_s; e]``::

    ζ⁺ = [[Ãᵢ, 0], [ΔAᵢTᵀ + B_F ΔCᵢTᵀ, A_F]] ζ + [[T Bᵢ, 0], [Bᵢ, B_F Dᵢ]] [w; v]
    z − z_f = [ΔLᵢ Tᵀ, L₀] ζ,

exactly (for constant *and* time-varying α: the filter does not use α).
It is stable iff ``A_F`` is Schur and the read part ``Ãᵢ`` is: a
Schur-stable subsystem that the integrators do not feed (a flexible mode
driven only by noise) qualifies; integrators the uncertainty reads, directly
or through the modes it reads, do not. When ``Ã(α)`` has an eigenvalue on or
outside the unit circle the term ``(ΔA + B_F ΔC) x_s`` grows with the free
response of ``x_s``, whatever the filter's gain, because the filter does not
know α: no filter of this (or the general) form has a finite γ for that
plant, which is what :func:`read_part` reports (the states carrying the
unstable mode, and what would help). With ``M = 0`` (no ΔA, ΔC, ΔL) the read
part is empty and ζ = e (the nominal observer form).

The general-form filter's error system ``ξ = [x; x_f]`` has the block
triangular ``[[A, 0], [B_F C, A_F]]``, whose eigenvalues include A's: it is
never Schur stable for a marginally stable plant (no certificate exists in
those coordinates). A filter with a bounded error must reproduce the
integrators exactly, which is the observer form.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import orth

from ..core.exceptions import InputError, UnstablePlantError
from ..core.linalg import spectral_radius

__all__ = ["ReadPart", "read_part", "check_read_part", "augmented_error_coordinates",
           "simplex_cells"]


@dataclass(frozen=True, eq=False)
class ReadPart:
    """The part of the state that the uncertainty reads (see the module docstring).

    Attributes
    ----------
    T : ndarray, shape (n_s, n)
        Orthonormal rows; ``x_s = T x``. ``n_s = 0`` without ΔA, ΔC, ΔL.
    A_s : list of ndarray
        ``T Aᵢ Tᵀ`` per vertex.
    spectral_radii : ndarray
        Spectral radius of each ``A_s``.
    states : tuple of int
        Plant states (indices) that ``x_s`` involves (a nonzero column of T).
    """

    T: np.ndarray
    A_s: list
    spectral_radii: np.ndarray
    states: tuple

    @property
    def stable(self) -> bool:
        """Schur stable at every vertex, with a margin of 1e-9 (an integrator read through round-off is not)."""
        return bool(np.all(self.spectral_radii < 1.0 - 1e-9))


def _differences(vertices, nominal):
    A0, C0, L0 = nominal
    rows = []
    for A, _B, C, _D, L in vertices:
        rows += [np.asarray(A) - A0, np.asarray(C) - C0, np.asarray(L) - L0]
    return np.vstack(rows)


def read_part(vertices: Sequence[Sequence[ArrayLike]], nominal: Sequence[ArrayLike],
              tol: float = 1e-12) -> ReadPart:
    """The read state ``x_s = T x`` of the uncertainty of a polytope, and its dynamics at each vertex.

    Parameters
    ----------
    vertices : sequence of ``(A, B, C, D, L)``
    nominal : ``(A₀, C₀, L₀)``
        The filter's model.
    tol : float
        Relative rank tolerance.

    Returns
    -------
    ReadPart
    """
    A_list = [np.asarray(v[0], dtype=float) for v in vertices]
    n = A_list[0].shape[0]
    M = _differences(vertices, nominal)
    scale = max(1.0, max(np.abs(A).max() for A in A_list))
    if not np.any(np.abs(M) > tol * scale):
        return ReadPart(np.zeros((0, n)), [np.zeros((0, 0)) for _ in A_list], np.zeros(len(A_list)), ())
    V = orth(M.T, rcond=tol)
    while True:
        W = orth(np.hstack([V] + [A.T @ V for A in A_list]), rcond=tol)
        if W.shape[1] == V.shape[1]:
            break
        V = W
    T = V.T
    A_s = [T @ A @ T.T for A in A_list]
    radii = np.array([spectral_radius(As) if As.size else 0.0 for As in A_s])
    states = tuple(int(j) for j in np.flatnonzero(np.abs(T).max(axis=0) > 1e-9))
    return ReadPart(T, A_s, radii, states)


def unstable_states(A: ArrayLike, T: ArrayLike | None = None, names: Sequence[str] | None = None,
                    threshold: float = 1.0) -> list[str]:
    """Plant states carrying the modes of A (or of ``T A Tᵀ``) with ``|λ| ≥ threshold``, largest share first.

    Each mode's eigenvector (mapped back to plant coordinates by ``Tᵀ``) is
    normalised; a state is listed when it carries at least 10 % of it.
    """
    A = np.asarray(A, dtype=float)
    lam, vec = np.linalg.eig(A)
    if T is not None:
        vec = np.asarray(T, dtype=float).T @ vec
    n = vec.shape[0]
    names = list(names) if names is not None else [f"x[{i}]" for i in range(n)]
    out = []
    for k in np.flatnonzero(np.abs(lam) >= threshold - 1e-12):
        w = np.abs(vec[:, k])
        w = w / max(w.max(), np.finfo(float).tiny)
        for j in np.argsort(-w):
            if w[j] >= 0.1 and names[j] not in out:
                out.append(names[j])
    return out


def check_read_part(part: ReadPart, labels: Sequence[str], names: Sequence[str] | None = None) -> None:
    """Raise :class:`UnstablePlantError` when the read part is not Schur stable at some vertex, saying why."""
    if part.stable:
        return
    i = int(np.argmax(part.spectral_radii))
    who = unstable_states(part.A_s[i], part.T, names)
    read = [names[j] if names else f"x[{j}]" for j in part.states]
    raise UnstablePlantError(
        f"no filter has a bounded error for this polytope: the uncertainty (ΔA, ΔC, ΔL between the vertices and the "
        f"filter's model) reads the states {', '.join(read)}, whose dynamics (the part of x the uncertainty sees, "
        f"with everything that feeds it) has spectral radius {part.spectral_radii[i]:.12g} >= 1 at vertex {i} "
        f"({labels[i]}); the mode that does not decay is carried by {', '.join(who) or 'several states'}. The error "
        "then contains (ΔA + B_F ΔC) x with x growing, whatever the filter's gain, since the filter does not know "
        "the parameter. What helps: model the uncertainty so that it reads only a stable part of the state that the "
        "integrators do not feed (a flexible mode driven by noise); measure the states that carry the unstable mode "
        "without uncertainty; or design on the stabilised plant (closed loop u = K x, every vertex Schur stable), "
        "where the general form applies too.")


def augmented_error_coordinates(vertex: Sequence[ArrayLike], A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike,
                                T: ArrayLike, C0: ArrayLike) -> tuple[NDArray, NDArray, NDArray]:
    """``(Ā, B̄, C̄)`` of the augmented error system ``ζ = [x_s; e]`` at one vertex (module docstring).

    The filter's model is recovered from the filter: ``L₀ = −C_F`` and
    ``A₀ = A_F − B_F C₀``.
    """
    A, B, C, D, L = (np.asarray(M, dtype=float) for M in vertex)
    A_F, B_F, C_F, T, C0 = (np.asarray(M, dtype=float) for M in (A_F, B_F, C_F, T, C0))
    if C0.shape != C.shape:
        raise InputError(f"C0 has shape {C0.shape}; the plant's C has shape {C.shape}")
    A0, L0 = A_F - B_F @ C0, -C_F
    ns, n = T.shape[0], A.shape[0]
    Abar = np.block([[T @ A @ T.T, np.zeros((ns, n))], [(A - A0 + B_F @ (C - C0)) @ T.T, A_F]])
    q = D.shape[1]
    Bbar = np.block([[T @ B, np.zeros((ns, q))], [B, B_F @ D]])
    Cbar = np.hstack([(L - L0) @ T.T, L0])
    return Abar, Bbar, Cbar


def simplex_cells(stacks: ArrayLike, n_cells: int) -> list[NDArray[np.float64]]:
    """Cut the simplex of N vertices into ``n_cells`` sub-simplices by bisecting the longest edge, repeatedly.

    Parameters
    ----------
    stacks : array_like, shape (K, N)
        Each vertex's matrices stacked into one column (the edge length is the
        Frobenius distance between the plants at its two ends).
    n_cells : int

    Returns
    -------
    list of ndarray, each shape (N, N)
        Row r of a cell: the convex weights of its r-th vertex. The cells
        cover the simplex (each bisection splits a simplex into two whose
        union it is).
    """
    V = np.asarray(stacks, dtype=float)
    N = V.shape[1]
    cells = [np.eye(N)]
    while len(cells) < n_cells:
        best = (-1.0, 0, 0, 0)
        for c, W in enumerate(cells):
            P = W @ V.T
            for i in range(N):
                for j in range(i):
                    d = float(np.linalg.norm(P[i] - P[j]))
                    if d > best[0]:
                        best = (d, c, i, j)
        d, c, i, j = best
        if d <= 0:
            break
        W = cells.pop(c)
        mid = 0.5 * (W[i] + W[j])
        W1, W2 = W.copy(), W.copy()
        W1[i], W2[j] = mid, mid
        cells[c:c] = [W1, W2]
    return cells
