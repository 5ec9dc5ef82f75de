"""The documented route from a continuous-time parameter family to a discrete filter at a chosen rate.

A plant written in continuous time as a function of physical parameters
``p``, ``ẋ = A_c(p) x + B_c(p) w``, ``y = C(p) x + D(p) v``, ``z = L(p) x``,
sampled at ``dt`` with a zero-order hold on w, is the discrete plant::

    A(p) = e^{A_c(p) dt},   B(p) = ∫₀^dt e^{A_c(p) s} ds B_c(p),   C, D, L unchanged

(:func:`hinfnav.core.linalg.discretize`, exact). :func:`design_discrete_at_rate`
builds the polytope of these discrete plants at the corners of the parameter
box (or at a grid with ``splits``, one cell per sub-box) with
:func:`~hinfnav.systems.polytope_from_parameters`, measures how well it covers
the sampled family with :func:`~hinfnav.systems.polytope_coverage`, and
designs the certified discrete filter with
:func:`~hinfnav.design.synthesize_polytopic`.

**What is covered, and what is not.**

* **Covered** (certified in float64): every discrete plant in the polytope
  (the union of the cells' hulls) — the filter's ℓ2 gain from the sampled
  ``(w_k, v_k)`` to the error ``z_k − ẑ_k`` is below ``gamma`` for every α
  constant in time (parameter-dependent Lyapunov function) or every α(k)
  (common), as ``result.covers`` says.
* **Not covered by the certificate**: the true sampled family itself. The
  map ``p ↦ e^{A_c(p) dt}`` is not affine, so the ZOH of a parameter box is
  not a polytope and the corners' hull misses part of it. ``coverage``
  reports the largest distance (Frobenius, stacked ``[A B; C D; L 0]``) from
  a sampled plant of the family to the polytope: at round-off level the
  family lies in it (at the sampled points); otherwise some true plants are
  outside what is certified by that much (cut the range with ``splits`` to
  shrink it, or inflate the model). Even a plant outside the hull usually
  has an error norm below γ, but nothing here proves it.
* **Not covered either**: the inter-sample behaviour (the bound is on the
  sampled error sequence), a continuous-time w that is not constant over a
  step (the ZOH input model), and a rate other than ``dt`` (redesign).
  ``D`` is used as the discrete measurement-noise gain as given: scale it to
  the sampled noise at this rate yourself.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.exceptions import InputError
from ..core.linalg import discretize
from ..core.validation import as_positive
from ..systems.parametric import Coverage, polytope_coverage, polytope_from_parameters
from ..systems.polytopic import MATRIX_KEYS, PolytopicSystem
from .polytopic import synthesize_polytopic
from .result import DesignResult

__all__ = ["design_discrete_at_rate", "DiscreteAtRate", "zoh_plant"]


def zoh_plant(plant_c: Callable[..., Any], dt: float) -> Callable[..., tuple]:
    """``plant(**p)`` returning the ZOH discretisation ``(e^{A_c dt}, ∫e^{A_c s}ds B_c, C, D, L)`` at rate ``dt``.

    ``plant_c(**p)`` returns the continuous plant as a mapping with
    ``A, B, C, D, L`` or the tuple ``(A, B, C, D, L)``.
    """
    dt = as_positive("dt", dt)

    def plant(**params):
        s = plant_c(**params)
        try:
            mats = [s[k] for k in MATRIX_KEYS] if isinstance(s, Mapping) else list(s)
        except (KeyError, TypeError):
            raise InputError("plant_c(**params) must return a mapping with A, B, C, D, L or the tuple "
                             f"(A, B, C, D, L); got {type(s).__name__}") from None
        if len(mats) != 5:
            raise InputError(f"plant_c(**params) must give 5 matrices (A, B, C, D, L); got {len(mats)}")
        A, B = discretize(mats[0], mats[1], dt)
        return (A, B, *mats[2:])

    return plant


@dataclass(frozen=True, eq=False)
class DiscreteAtRate:
    """A discrete filter designed at rate ``dt`` for a continuous parameter family (:func:`design_discrete_at_rate`).

    Attributes
    ----------
    result : DesignResult
        The certified discrete filter (``result.covers`` says which α).
    polytope : PolytopicSystem
        The discrete plants at the box corners (grid points with ``splits``).
    coverage : Coverage
        Distance from the sampled ZOH family to the polytope (see the module docstring).
    dt : float
    covers : str
        What the certificate covers, and the coverage caveat, in words.
    """

    result: DesignResult
    polytope: PolytopicSystem
    coverage: Coverage
    dt: float
    covers: str


def design_discrete_at_rate(plant_c: Callable[..., Any], ranges: Mapping[str, tuple[float, float]], dt: float, *,
                            splits: Mapping[str, int] | None = None, lyapunov: str = "parameter-dependent",
                            form: str = "general", solver: str | None = None, n_samples: int = 100,
                            seed: int | np.random.Generator = 0) -> DiscreteAtRate:
    """Discrete H∞ filter at rate ``dt`` for a continuous-time parameter family (see the module docstring).

    Parameters
    ----------
    plant_c : callable
        ``plant_c(**params)``: the continuous plant ``(A, B, C, D, L)`` at one parameter point.
    ranges : mapping
        ``{name: (low, high)}`` as in :func:`~hinfnav.systems.polytope_from_parameters`.
    dt : float
        Sampling time of the filter, s.
    splits : mapping, optional
        Cut parameter ranges into sub-ranges (cells): closer coverage, more vertices.
    lyapunov, form, solver
        Passed to :func:`~hinfnav.design.synthesize_polytopic`.
    n_samples, seed
        Random parameter points of the coverage measurement (plus a 5-point lattice per parameter).

    Returns
    -------
    DiscreteAtRate
    """
    dt = as_positive("dt", dt)
    plant = zoh_plant(plant_c, dt)
    poly = polytope_from_parameters(plant, ranges, dt, splits)
    coverage = polytope_coverage(poly, plant, ranges, n_samples=n_samples, seed=seed)
    result = synthesize_polytopic(poly, lyapunov=lyapunov, form=form, solver=solver)
    covers = (f"{result.covers}; the polytope of the ZOH plants at dt = {dt:g} s "
              f"({poly.n_vertices} vertices{f', {len(poly.cells)} cells' if poly.cells else ''}) holds the sampled "
              f"family to within {coverage.max_distance:.3g} ({coverage.relative:.3g} of the vertex spread; "
              f"worst at {coverage.worst_parameters}); sampled error only, w held constant over each step")
    return DiscreteAtRate(result, poly, coverage, dt, covers)
