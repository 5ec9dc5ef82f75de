"""Decoupled blocks of a plant: the connected components of its coupling graph (issue 31).

A plant ``x⁺ = (A + H F E) x + B w``, ``y = C x + D v``, ``z = L x`` is
*block-diagonal up to a permutation* when its states, noise inputs w and v,
measurements y, estimated outputs z and uncertainty channels (the columns of
H, the rows of E) fall into groups such that every nonzero entry of A, B, C,
D, L, H, E couples two members of one group. The groups are the connected
components of the undirected graph whose nodes are all those signals and
whose edges are the nonzero entries of the seven matrices (A: state–state,
B: state–w, C: y–state, D: y–v, L: z–state, H: state–r, E: s–state).

The same function splits a filtering error system ``(Ā, B̄, C̄)`` into
independent subsystems (``C = D = 0`` rows, ``L = C̄``): its transfer
matrix is then block-diagonal up to a permutation of inputs and outputs, so
``‖Ψ‖∞ = max_c ‖Ψ_c‖∞`` and the spectral radius of Ā is the largest of the
blocks' (Ā is block-diagonal after the same permutation of its states).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse
from numpy.typing import ArrayLike, NDArray
from scipy.sparse.csgraph import connected_components

__all__ = ["Block", "decoupled_blocks"]


@dataclass(frozen=True, eq=False)
class Block:
    """Index sets of one decoupled block (every array sorted, into the plant's own ordering).

    Attributes
    ----------
    states, w, v, y, z, r, s : ndarray of int
        The block's states (rows of A), process-noise inputs (columns of
        B), measurement-noise inputs (columns of D), measurements (rows of
        C), estimated outputs (rows of L), and uncertainty channels (columns
        of H, rows of E).
    """

    states: NDArray[np.intp]
    w: NDArray[np.intp]
    v: NDArray[np.intp]
    y: NDArray[np.intp]
    z: NDArray[np.intp]
    r: NDArray[np.intp]
    s: NDArray[np.intp]


def decoupled_blocks(A: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike, L: ArrayLike,
                     H: ArrayLike | None = None, E: ArrayLike | None = None) -> list[Block]:
    """The decoupled blocks of a plant that contain states (see the module docstring).

    Signals that touch no state (a zero column of B, a measurement with a
    zero row of C and only noise, ...) belong to no returned block: they do
    not interact with any state, so a filter, an LMI or a norm may treat
    them on their own (see :func:`hinfnav.lmi.lmi20_problem`).

    Parameters
    ----------
    A, B, C, D, L : array_like
        Shapes (n, n), (n, p), (m, n), (m, q), (l, n).
    H, E : array_like or None
        Shapes (n, r1), (r2, n); ``None`` for no uncertainty.

    Returns
    -------
    list of Block
        Ordered by their smallest state; one block (every index) when the
        plant does not decouple.
    """
    mats = [np.asarray(M, dtype=float) for M in (A, B, C, D, L)]
    A, B, C, D, L = mats
    H = np.zeros((A.shape[0], 0)) if H is None else np.asarray(H, dtype=float)
    E = np.zeros((0, A.shape[0])) if E is None else np.asarray(E, dtype=float)
    n, p, m, q, l, r1, r2 = A.shape[0], B.shape[1], C.shape[0], D.shape[1], L.shape[0], H.shape[1], E.shape[0]
    sizes = (n, p, q, m, l, r1, r2)  # node groups: states, w, v, y, z, r, s
    off = np.concatenate([[0], np.cumsum(sizes)])
    X, W, V, Y, Z, R, S = range(7)
    rows, cols = [], []
    for M, gi, gj in ((A, X, X), (B, X, W), (C, Y, X), (D, Y, V), (L, Z, X), (H, X, R), (E, S, X)):
        i, j = np.nonzero(M)
        rows.append(i + off[gi])
        cols.append(j + off[gj])
    i, j = np.concatenate(rows), np.concatenate(cols)
    N = int(off[-1])
    graph = scipy.sparse.coo_matrix((np.ones(i.size), (i, j)), shape=(N, N))
    _, label = connected_components(graph, directed=False)
    blocks = []
    for c in dict.fromkeys(label[:n]):  # components with states, in the order of their first state
        members = np.flatnonzero(label == c)
        parts = [members[(members >= off[g]) & (members < off[g + 1])] - off[g] for g in range(7)]
        blocks.append(Block(*parts))
    return blocks
