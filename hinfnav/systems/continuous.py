"""A continuous-time plant family (``dt = 0`` in a system TOML file): nominal or a polytope of vertices.

``ẋ = A x + B w``, ``y = C x + D v``, ``z = L x`` with ``(A, B, C, D, L)``
a convex combination of the vertices (one vertex: the nominal plant). The
discrete-time objects (:class:`~hinfnav.systems.UncertainSystem`,
:class:`~hinfnav.systems.PolytopicSystem`) require ``dt > 0``; this one is
what the continuous-time design
(:func:`hinfnav.design.continuous.synthesize_continuous_observer`) takes
from a file. Norm-bounded uncertainty and cells are not carried in
continuous time (write the vertices ``A ± H E`` as a polytope).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError
from .polytopic import MATRIX_KEYS

__all__ = ["ContinuousPolytope"]


@dataclass(frozen=True)
class ContinuousPolytope:
    """Vertices ``(A, B, C, D, L)`` of a continuous-time plant (``dt = 0``).

    Parameters
    ----------
    vertices : tuple of tuple of ndarray
        Each ``(A, B, C, D, L)`` with A n×n, B n×p, C m×n, D m×q, L r×n.
    labels : tuple of str
    """

    vertices: tuple
    labels: tuple = ()

    def __post_init__(self):
        if not self.vertices:
            raise InputError("vertices: at least one (A, B, C, D, L) is needed")
        verts = []
        for i, v in enumerate(self.vertices):
            if len(v) != 5:
                raise InputError(f"vertices[{i}]: expected (A, B, C, D, L); got {len(v)} matrices")
            A, B, C, D, L = (np.atleast_2d(np.asarray(M, dtype=float)) for M in v)
            n = A.shape[0]
            for name, M, rows, cols in (("A", A, n, n), ("B", B, n, None), ("C", C, None, n), ("D", D, C.shape[0], None),
                                        ("L", L, None, n)):
                if (rows is not None and M.shape[0] != rows) or (cols is not None and M.shape[1] != cols):
                    raise InputError(f"vertices[{i}].{name}: shape {M.shape} does not fit A {A.shape}, C {C.shape}")
                if not np.all(np.isfinite(M)):
                    raise InputError(f"vertices[{i}].{name}: has non-finite entries")
            if verts and tuple(M.shape for M in (A, B, C, D, L)) != tuple(M.shape for M in verts[0]):
                raise InputError(f"vertices[{i}]: shapes differ from vertex 0")
            verts.append((A, B, C, D, L))
        object.__setattr__(self, "vertices", tuple(verts))
        labels = tuple(self.labels) or tuple(f"vertex {i}" for i in range(len(verts)))
        object.__setattr__(self, "labels", labels)

    dt = 0.0
    """Continuous time (the TOML key ``dt = 0``)."""

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @classmethod
    def from_matrices(cls, nominal: dict, vertices: list[dict] | None = None) -> ContinuousPolytope:
        """Nominal matrices (dict of A, B, C, D, L) and vertices giving any of them that differ (as in the TOML)."""
        if not vertices:
            return cls((tuple(nominal[k] for k in MATRIX_KEYS),), ("nominal",))
        return cls(tuple(tuple(nominal[k] if v.get(k) is None else v[k] for k in MATRIX_KEYS)
                         for v in vertices))
