"""Polytopes from physical parameters, and how well they cover the true family.

A plant written as a function of its physical parameters ``p`` (frequency,
damping, stiffness, mass), ``(A, B, C, D, L)(p)``, with each parameter in an
interval, is a polytope exactly when the matrices are affine in p: then
the ``2^k`` corners of the box are its vertices (a multilinear family is
covered too, since a box's image under a multilinear map lies in the hull of
the corner images). Most discretisations are not affine (the zero-order
hold ``e^{A_c(p) T}``): the corners' hull then misses part of the family,
and a certificate on the polytope says nothing about a plant outside it.
:func:`polytope_coverage` measures that: for sampled parameter points it
finds the closest point of the hull (a least-squares problem on the simplex,
in the stacked matrices ``[A B; C D; L 0]``, Frobenius norm) and reports the
largest distance, absolute and relative to the spread of the vertices. A
distance at round-off level means the hull holds the family (at the sampled
points); a larger one says by how much the model must be inflated (or the
parameter written differently, e.g. ω² instead of ω for a stiffness) before
the certificate covers the true plants.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least
from .polytopic import MATRIX_KEYS, PolytopicSystem
from .uncertain import UncertainSystem

__all__ = ["polytope_from_parameters", "polytope_coverage", "Coverage"]


def _ranges(ranges):
    if not isinstance(ranges, Mapping) or not ranges:
        raise InputError("ranges must be a non-empty mapping {parameter name: (low, high)}")
    out = {}
    for k, v in ranges.items():
        try:
            lo, hi = (float(x) for x in v)
        except (TypeError, ValueError):
            raise InputError(f"ranges[{k!r}] must be a pair (low, high) of numbers; got {v!r}") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise InputError(f"ranges[{k!r}] must be finite with low <= high; got ({lo}, {hi})")
        out[str(k)] = (lo, hi)
    return out


def _system(plant, params, dt):
    s = plant(**params)
    if isinstance(s, UncertainSystem):
        if s.H is not None:
            raise InputError("plant(**params) must return a nominal system (no H, E)")
        return s
    if isinstance(s, Mapping):
        return UncertainSystem(*(s[k] for k in MATRIX_KEYS), dt=dt)
    try:
        return UncertainSystem(*s, dt=dt)
    except TypeError:
        raise InputError("plant(**params) must return an UncertainSystem, a mapping with A, B, C, D, L, or the "
                         f"tuple (A, B, C, D, L); got {type(s).__name__}") from None


def polytope_from_parameters(plant: Callable[..., object], ranges: Mapping[str, tuple[float, float]],
                             dt: float = 1.0, splits: Mapping[str, int] | None = None) -> PolytopicSystem:
    """The polytope of the corners of a parameter box.

    Parameters
    ----------
    plant : callable
        ``plant(**params)`` returns the plant at one parameter point: an
        :class:`UncertainSystem` (nominal), a mapping with ``A, B, C, D, L``,
        or the tuple ``(A, B, C, D, L)``.
    ranges : mapping
        ``{name: (low, high)}``; a parameter with ``low == high`` is fixed.
    dt : float
        Sampling time, s (used when ``plant`` returns matrices).
    splits : mapping, optional
        ``{name: k}``: cut that parameter's range into k equal sub-ranges.
        The vertices are then the grid points and the polytope's ``cells``
        the sub-boxes: the family is the union of the sub-boxes' hulls, much
        closer to the true family than the hull of the corners when the
        plant is far from affine (a lightly damped mode over a wide
        frequency range).

    Returns
    -------
    PolytopicSystem
        One vertex per corner (``2^k`` for k varying parameters; per grid
        point with ``splits``), labelled ``"name=value, …"``. It contains the
        family exactly when the matrices are affine (or multilinear) in the
        parameters; check with :func:`polytope_coverage` otherwise.
    """
    r = _ranges(ranges)
    names = list(r)
    splits = dict(splits or {})
    unknown = sorted(set(splits) - set(names))
    if unknown:
        raise InputError(f"splits names {unknown[0]!r}, which is not in ranges ({', '.join(names)})")
    axes = []
    for k, (lo, hi) in r.items():
        cuts = as_int_at_least(f"splits[{k!r}]", splits.get(k, 1), 1)
        axes.append([lo] if lo == hi else list(np.linspace(lo, hi, cuts + 1)))
    grid = list(itertools.product(*[range(len(a)) for a in axes]))
    index = {g: i for i, g in enumerate(grid)}
    verts, labels = [], []
    for g in grid:
        params = {k: float(axes[j][g[j]]) for j, k in enumerate(names)}
        verts.append(_system(plant, params, dt))
        labels.append(", ".join(f"{k}={v:g}" for k, v in params.items()))
    cells = ()
    if any(len(a) > 2 for a in axes):
        starts = itertools.product(*[range(max(len(a) - 1, 1)) for a in axes])
        cells = tuple(tuple(sorted({index[tuple(min(s[j] + d[j], len(axes[j]) - 1) for j in range(len(axes)))]
                                    for d in itertools.product((0, 1), repeat=len(axes))}))
                      for s in starts)
    return PolytopicSystem(tuple(verts), verts[0].dt, tuple(labels), cells)


def _stack(s):
    return np.concatenate([np.ravel(getattr(s, k)) for k in MATRIX_KEYS])


@dataclass(frozen=True, eq=False)
class Coverage:
    """How well a polytope's hull holds a parameter family (:func:`polytope_coverage`).

    Attributes
    ----------
    max_distance : float
        Largest distance (Frobenius, stacked matrices) from a sampled plant to the hull.
    relative : float
        ``max_distance`` over the largest distance between two vertices.
    worst_parameters : dict
        The parameter point of the largest distance.
    distances : ndarray
    samples : list of dict
    """

    max_distance: float
    relative: float
    worst_parameters: dict
    distances: np.ndarray
    samples: list


def _hull_distance(V, p):
    """Distance from p to conv(columns of V): NNLS with a heavily weighted Σα = 1 row, then renormalised α."""
    rho = 1e6 * max(1.0, np.abs(V).max())
    M = np.vstack([V, rho * np.ones((1, V.shape[1]))])
    alpha, _ = nnls(M, np.concatenate([p, [rho]]), maxiter=50 * V.shape[1])
    alpha = alpha / alpha.sum()
    return float(np.linalg.norm(V @ alpha - p))


def polytope_coverage(poly: PolytopicSystem, plant: Callable[..., object], ranges: Mapping[str, tuple[float, float]],
                      n_samples: int = 200, seed: int | np.random.Generator = 0, grid: int = 5) -> Coverage:
    """Largest distance from sampled plants of the family to the polytope's hull (the union of its cells' hulls).

    Parameters
    ----------
    poly : PolytopicSystem
    plant, ranges
        As in :func:`polytope_from_parameters`.
    n_samples : int
        Uniform random parameter points, plus a ``grid``-point lattice per parameter.
    seed : int or numpy.random.Generator

    Returns
    -------
    Coverage
    """
    r = _ranges(ranges)
    n_samples = as_int_at_least("n_samples", n_samples, 0)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    names = list(r)
    lo = np.array([v[0] for v in r.values()])
    hi = np.array([v[1] for v in r.values()])
    pts = [np.array(c) for c in itertools.product(*[np.linspace(a, b, grid) for a, b in zip(lo, hi)])]
    pts += list(lo + (hi - lo) * rng.random((n_samples, len(names))))
    V = np.column_stack([_stack(v) for v in poly.vertices])
    spread = max((np.linalg.norm(V[:, i] - V[:, j]) for i in range(V.shape[1]) for j in range(i)), default=0.0)
    groups = [list(c) for c in poly.cells] or [list(range(V.shape[1]))]
    dist, samples = [], []
    for x in pts:
        params = dict(zip(names, (float(t) for t in x)))
        samples.append(params)
        p = _stack(_system(plant, params, poly.dt))
        dist.append(min(_hull_distance(V[:, g], p) for g in groups))  # to the union of the cells' hulls
    dist = np.array(dist)
    k = int(np.argmax(dist))
    return Coverage(float(dist[k]), float(dist[k] / spread) if spread > 0 else 0.0, samples[k], dist, samples)
