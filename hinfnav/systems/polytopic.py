"""Polytopic uncertain discrete systems: A, B, C, D, L convex combinations of vertices.

``x(k+1) = A(α) x(k) + B(α) w(k)``, ``y(k) = C(α) x(k) + D(α) v(k)``,
``z(k) = L(α) x(k)`` with ``(A, B, C, D, L)(α) = Σᵢ αᵢ (Aᵢ, Bᵢ, Cᵢ, Dᵢ, Lᵢ)``
and α in the unit simplex ``{αᵢ ≥ 0, Σ αᵢ = 1}``: the model of the
polytopic robust filtering literature (Geromel, de Oliveira & Bernussou 2002;
Xie, Lu, Zhang & Zhang 2004). :meth:`PolytopicSystem.from_norm_bounded`
writes a norm-bounded ``A + H F E`` with a diagonal (or scalar) F as the
polytope of its sign vertices; :func:`two_mass_spring` is an example plant.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from math import comb

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_matrix, as_positive
from .uncertain import UncertainSystem

__all__ = ["PolytopicSystem", "simplex_grid", "two_mass_spring", "MATRIX_KEYS"]

#: The matrices a vertex may change.
MATRIX_KEYS = ("A", "B", "C", "D", "L")


@dataclass(frozen=True, eq=False)
class PolytopicSystem:
    """A discrete system whose matrices lie in the convex hull of vertices.

    Attributes
    ----------
    vertices : tuple of UncertainSystem
        The vertex systems (nominal, no H/E), all of the same dimensions.
    dt : float
        Sampling time, s.
    labels : tuple of str
        One label per vertex.
    cells : tuple of tuple of int, optional
        When given, the family is the union of the hulls of these groups of
        vertices (e.g. sub-boxes of a parameter range,
        :func:`hinfnav.systems.polytope_from_parameters` with ``splits``), not
        the hull of all of them; a design may certify cell by cell (the
        observer form on a marginally stable plant does), or certify the
        whole hull, which contains the union.
    """

    vertices: tuple
    dt: float = 1.0
    labels: tuple = ()
    cells: tuple = ()

    def __post_init__(self):
        verts = tuple(self.vertices)
        if not verts:
            raise InputError("vertices must contain at least one system")
        for i, v in enumerate(verts):
            if not isinstance(v, UncertainSystem) or v.H is not None:
                raise InputError(f"vertices[{i}] must be a nominal hinfnav UncertainSystem (no H, E)")
            for k in MATRIX_KEYS:
                if getattr(v, k).shape != getattr(verts[0], k).shape:
                    raise InputError(f"vertices[{i}].{k} has shape {getattr(v, k).shape}, vertex 0 has "
                                     f"{getattr(verts[0], k).shape}: every vertex needs the same dimensions")
        labels = tuple(str(s) for s in self.labels) or tuple(f"vertex {i}" for i in range(len(verts)))
        if len(labels) != len(verts):
            raise InputError(f"labels must have one entry per vertex ({len(verts)}); got {len(labels)}")
        cells = tuple(tuple(int(i) for i in c) for c in self.cells)
        for c in cells:
            if not c or min(c) < 0 or max(c) >= len(verts):
                raise InputError(f"cells must hold vertex indices 0 … {len(verts) - 1}; got {c!r}")
        if cells and set().union(*cells) != set(range(len(verts))):
            raise InputError("cells must use every vertex")
        object.__setattr__(self, "vertices", verts)
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "dt", as_positive("dt", self.dt))

    @classmethod
    def from_matrices(cls, nominal: Mapping[str, ArrayLike], vertices: Sequence[Mapping[str, ArrayLike]],
                      dt: float = 1.0, labels: Sequence[str] = ()) -> PolytopicSystem:
        """Vertices given as dicts of the matrices that differ from ``nominal`` (a dict of A, B, C, D, L)."""
        if not isinstance(nominal, dict) or any(k not in nominal for k in MATRIX_KEYS):
            raise InputError(f"nominal must be a dict with the matrices {', '.join(MATRIX_KEYS)}")
        out = []
        for i, vert in enumerate(vertices):
            if not isinstance(vert, dict):
                raise InputError(f"vertices[{i}] must be a table (dict) of matrices; got {type(vert).__name__}")
            unknown = sorted(set(vert) - set(MATRIX_KEYS))
            if unknown:
                raise InputError(f"vertices[{i}] has unknown key(s) {unknown}; allowed: {', '.join(MATRIX_KEYS)}")
            mats = {k: as_matrix(f"vertices[{i}].{k}", vert[k]) if k in vert else nominal[k] for k in MATRIX_KEYS}
            out.append(UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], dt=dt))
        return cls(tuple(out), dt, labels)

    @classmethod
    def from_norm_bounded(cls, system: UncertainSystem,
                          groups: str | Sequence[Sequence[int]] | None = None) -> PolytopicSystem:
        """The polytope of ``A + H F E`` for a diagonal F with entries in [−1, 1] (sign vertices).

        Parameters
        ----------
        system : UncertainSystem
            With H (n, r) and E (r, n).
        groups : None, "scalar" or sequence of sequences of int, optional
            Which diagonal entries of F share one parameter: ``None`` (each
            channel its own), ``"scalar"`` (``F = f I``, two vertices) or a
            list of channel-index lists. Channels whose column of H or row of
            E is zero are dropped.

        Returns
        -------
        PolytopicSystem
            ``2^g`` vertices (g parameters); its convex hull is exactly the
            set ``{A + H F E}`` for such F (affine in each parameter). A full
            (non-diagonal) contraction F is NOT covered when r > 1.
        """
        if not isinstance(system, UncertainSystem):
            raise InputError(f"system must be a hinfnav UncertainSystem; got {type(system).__name__}")
        if system.H is None:
            return cls((system_nominal(system),), system.dt, ("nominal",))
        r = min(system.H.shape[1], system.E.shape[0])
        live = [j for j in range(r) if np.any(system.H[:, j]) and np.any(system.E[j])]
        if groups is None:
            groups = [[j] for j in live]
        elif isinstance(groups, str) and groups == "scalar":
            groups = [live]
        else:
            try:
                groups = [[int(j) for j in g] for g in groups]
            except (TypeError, ValueError):
                raise InputError("groups must be None, 'scalar' or a list of lists of channel indices") from None
            if sorted(j for g in groups for j in g) != list(range(r)) and sorted(j for g in groups for j in g) != live:
                raise InputError(f"groups must partition the uncertainty channels 0..{r - 1}")
        if len(groups) > 8:
            raise InputError(f"{len(groups)} uncertain parameters give 2^{len(groups)} vertices; group the channels "
                             "(groups=...) to at most 8 parameters")
        verts, labels = [], []
        for signs in itertools.product((-1.0, 1.0), repeat=len(groups)):
            f = np.zeros(r)
            for s, g in zip(signs, groups):
                f[g] = s
            A = system.A + system.H[:, :r] @ np.diag(f) @ system.E[:r]
            verts.append(UncertainSystem(A, system.B, system.C, system.D, system.L, dt=system.dt))
            labels.append("F = diag(" + ", ".join(f"{v:+g}" for v in f) + ")")
        return cls(tuple(verts), system.dt, tuple(labels))

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n(self) -> int:
        return self.vertices[0].n

    def varying(self) -> tuple[str, ...]:
        """Names of the matrices that differ between vertices."""
        v0 = self.vertices[0]
        return tuple(k for k in MATRIX_KEYS if any(not np.array_equal(getattr(v, k), getattr(v0, k))
                                                   for v in self.vertices[1:]))

    def norm_bounded_cover(self) -> UncertainSystem:
        """A norm-bounded ``A₀ + H F E`` (FᵀF ≤ I) containing a two-vertex polytope in which only A varies.

        ``A₀`` is the midpoint and ``H F E`` with ``H = U Σ``, ``E = Vᵀ`` (the
        SVD of half the difference, rank r) contains ``±(A₁ − A₀)/2`` (F = ±I):
        exact when r = 1 (F a scalar in [−1, 1]), a cover otherwise. Returns
        an :class:`UncertainSystem`.
        """
        if self.n_vertices != 2 or set(self.varying()) - {"A"}:
            raise InputError("norm_bounded_cover needs two vertices that differ in A only")
        v0, v1 = self.vertices
        U, sv, Vt = np.linalg.svd((v1.A - v0.A) / 2.0)
        r = max(1, int(np.sum(sv > 1e-12 * max(sv[0], np.finfo(float).tiny))))
        return UncertainSystem((v0.A + v1.A) / 2.0, v0.B, v0.C, v0.D, v0.L, U[:, :r] * sv[:r], Vt[:r], dt=self.dt)

    def at(self, alpha: ArrayLike) -> UncertainSystem:
        """The nominal system at the convex weights ``alpha`` (shape (N,), ≥ 0, summing to 1)."""
        a = np.asarray(alpha, dtype=float)
        if a.shape != (self.n_vertices,) or np.any(a < -1e-12) or abs(a.sum() - 1.0) > 1e-9:
            raise InputError(f"alpha must be {self.n_vertices} non-negative weights summing to 1; got {alpha!r}")
        mats = {k: sum(ai * getattr(v, k) for ai, v in zip(a, self.vertices)) for k in MATRIX_KEYS}
        return UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], dt=self.dt)

    def center(self) -> UncertainSystem:
        """The system at the barycentre of the vertices."""
        return self.at(np.full(self.n_vertices, 1.0 / self.n_vertices))


def system_nominal(system):
    return UncertainSystem(system.A, system.B, system.C, system.D, system.L, dt=system.dt)


def simplex_grid(n_vertices: int, points: int = 41, n_random: int = 0,
                 seed: int | np.random.Generator = 0) -> NDArray[np.float64]:
    """Convex weights covering the unit simplex: the vertices, a barycentric lattice, random points.

    The lattice has step ``1/k`` with k the largest resolution giving at most
    ``points`` lattice points (all points with ``αᵢ = jᵢ/k``); ``n_random``
    Dirichlet(1, …, 1) points are drawn from ``numpy.random.default_rng(seed)``.

    Returns
    -------
    ndarray, shape (K, n_vertices)
    """
    N = int(n_vertices)
    if N < 1:
        raise InputError(f"n_vertices must be >= 1; got {n_vertices!r}")
    if N == 1:
        return np.ones((1, 1))
    k = 1
    while comb(k + 1 + N - 1, N - 1) <= points:
        k += 1
    pts = [np.eye(N)[i] for i in range(N)]
    if N > 1:
        for c in itertools.combinations(range(k + N - 1), N - 1):
            bars = (-1,) + c + (k + N - 1,)
            pts.append(np.array([bars[i + 1] - bars[i] - 1 for i in range(N)], dtype=float) / k)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    if n_random:
        pts.extend(rng.dirichlet(np.ones(N), size=int(n_random)))
    return np.unique(np.round(np.array(pts), 15), axis=0)


def two_mass_spring(stiffness_range: float = 0.3, *, m1: float = 1.0, m2: float = 1.0, k1: float = 1.0,
                    k2: float = 1.0, c: float = 0.05, dt: float = 0.1) -> PolytopicSystem:
    """Two masses on springs (wall–k1–m1–k2–m2), the coupling stiffness k2 uncertain: a two-vertex polytope.

    States ``x = [q1, q2, v1, v2]`` (m, m/s); the coupling stiffness is
    ``k2 (1 + ρ)``, ``ρ ∈ [−stiffness_range, +stiffness_range]``. Each mass
    has a viscous damper ``c`` to the wall (N s/m). Discretized with the
    semi-implicit (symplectic) Euler step of ``dt`` s
    (``v⁺ = v + dt M⁻¹(−K q − C v)``, ``q⁺ = q + dt v⁺``), which is affine in
    the stiffness, so the polytope of the two extreme stiffnesses holds every
    stiffness in between exactly. Process noise w: a force on each mass
    (N, entering as ``dt M⁻¹``); measurement y: the position of mass 1 plus
    noise v (m); estimated z: both positions.

    Returns
    -------
    PolytopicSystem
        Two vertices (``k2 (1 − ρ̄)``, ``k2 (1 + ρ̄)``).
    """
    rho = float(stiffness_range)
    if not 0 <= rho < 1:
        raise InputError(f"stiffness_range must be in [0, 1); got {stiffness_range!r}")
    for name, val in (("m1", m1), ("m2", m2), ("k1", k1), ("k2", k2), ("dt", dt)):
        as_positive(name, val)
    Minv = np.diag([1.0 / m1, 1.0 / m2])
    Cd = c * np.eye(2)
    verts, labels = [], []
    for s in (-rho, rho) if rho > 0 else (0.0,):
        kk = k2 * (1.0 + s)
        K = np.array([[k1 + kk, -kk], [-kk, kk]])
        Av = np.eye(2) - dt * Minv @ Cd
        Kv = -dt * Minv @ K
        A = np.block([[np.eye(2) + dt * Kv, dt * Av], [Kv, Av]])
        B = np.vstack([dt * dt * Minv, dt * Minv])
        verts.append(UncertainSystem(A, B, np.array([[1.0, 0, 0, 0]]), np.array([[1.0]]),
                                     np.hstack([np.eye(2), np.zeros((2, 2))]), dt=dt))
        labels.append(f"k2 = {kk:g} N/m")
    return PolytopicSystem(tuple(verts), dt, tuple(labels))
