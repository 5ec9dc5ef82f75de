"""Continuous-time robust observer-form filters on a polytope, certified by the continuous-time norm.

Plant vertices ``ẋ = Aᵢ x + Bᵢ w``, ``y = Cᵢ x + Dᵢ v``, ``z = Lᵢ x``; filter
``ẋ_f = A_F x_f + B_F y``, ``z_f = C_F x_f`` in observer form on the centre
model (``A_F = A₀ + B_F C₀``, ``C_F = −L₀``). The error is the output of the
augmented system ``ζ = [x_s; e]`` of :mod:`hinfnav.analysis.marginal`
(continuous-time version: the read part ``T A Tᵀ`` must be Hurwitz at every
vertex). The bound is (C2) of :mod:`hinfnav.lmi.continuous` on ζ, with the
slacks ``F = [[F₁₁, 0], [F₂₁, F₂₂]]``, ``G = ε F`` and ``F̂ = F₂₂ B_F``, which
makes ``F Ā``, ``G Ā``, ``F B̄``, ``G B̄`` linear for a fixed ε (a line search
over ε). Certificate: (C2) in float64 at every vertex with the returned
witness (:func:`~hinfnav.lmi.continuous.certify_continuous`), and the
continuous-time norm of ζ at sampled convex weights
(:func:`~hinfnav.analysis.continuous.hinf_norm_continuous`). It covers every
α constant in time (parameter-dependent ``Pᵢ``).

Not covered here: a discrete filter at a chosen rate (discretising the
uncertain plant does not give a polytope in general: design on the discrete
plant's polytope with :func:`hinfnav.systems.polytope_from_parameters` and
measure its coverage instead; :func:`hinfnav.design.discretised.design_discrete_at_rate`).

From a TOML file with ``dt = 0``: :func:`design_continuous_system` (what
``design --system FILE --form observer`` calls) returns a
:class:`ContinuousResult`. Saving it (``--save``) is refused: the design-file
format and ``--recertify`` carry discrete-time certificates only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..analysis.continuous import hinf_norm_continuous
from ..analysis.marginal import read_part
from ..core.exceptions import CertificationError, UnstablePlantError
from ..lmi.continuous import certify_continuous, solve_continuous_observer
from ..systems.continuous import ContinuousPolytope
from ..systems.polytopic import simplex_grid

__all__ = ["synthesize_continuous_observer", "ContinuousResult", "design_continuous_system"]

COVERS_CONTINUOUS = ("every α constant in time in the simplex (parameter-dependent Lyapunov function), "
                     "continuous time")


def continuous_augmented(vertex, B_F, T, nominal):
    """``(Ā, B̄, C̄, 0)`` of ζ at one vertex ``(A, B, C, D, L)`` (continuous time)."""
    A, B, C, D, L = (np.atleast_2d(np.asarray(M, dtype=float)) for M in vertex)
    A0, C0, L0 = nominal
    ns, n = T.shape
    A_F = A0 + B_F @ C0
    Abar = np.block([[T @ A @ T.T, np.zeros((ns, n))], [(A - A0 + B_F @ (C - C0)) @ T.T, A_F]])
    Bbar = np.block([[T @ B, np.zeros((ns, D.shape[1]))], [B, B_F @ D]])
    Cbar = np.hstack([(L - L0) @ T.T, L0])
    return Abar, Bbar, Cbar, np.zeros((Cbar.shape[0], Bbar.shape[1]))


def synthesize_continuous_observer(vertices: Sequence[Sequence[ArrayLike]], *, eps: Sequence[float] = (0.01, 0.1, 1.0),
                                   solver: str = "CLARABEL", points: int = 41) -> dict[str, Any]:
    """Certified continuous-time observer-form H∞ filter for every constant α (see the module docstring).

    Returns
    -------
    dict
        ``A_F, B_F, C_F, gamma`` (certified), ``lmi_gamma``, ``verified_norm`` (largest sampled norm),
        ``eps``, ``witness``, ``states`` (read by the uncertainty).
    """
    verts = [tuple(np.atleast_2d(np.asarray(M, dtype=float)) for M in v) for v in vertices]
    N = len(verts)
    A0, C0, L0 = (sum(v[k] for v in verts) / N for k in (0, 2, 4))
    part = read_part(verts, (A0, C0, L0))
    T = part.T if part.T.shape[0] else np.zeros((0, A0.shape[0]))
    for i, As in enumerate(part.A_s):
        if As.size and not np.all(np.linalg.eigvals(As).real < -1e-12):
            raise UnstablePlantError(f"the part of the state the uncertainty reads (states {part.states}) is not "
                                     f"Hurwitz at vertex {i}: no filter has a bounded error")
    alphas = simplex_grid(N, points=points)
    best, log = None, []
    for e in eps:
        sol = solve_continuous_observer(verts, T, (A0, C0, L0), e, solver)
        if "B_F" not in sol:
            log.append(f"ε = {e:g}: {sol['status']}")
            continue
        aug = [continuous_augmented(v, sol["B_F"], T, (A0, C0, L0)) for v in verts]
        gamma = certify_continuous(aug, sol)
        log.append(f"ε = {e:g}: {sol['status']}, solver γ = {sol['gamma']:.8g}, certified γ = {gamma:.8g}")
        if np.isfinite(gamma) and (best is None or gamma < best["gamma"]):
            best = {"gamma": gamma, "lmi_gamma": sol["gamma"], "B_F": sol["B_F"], "eps": e,
                    "witness": {k: sol[k] for k in ("P", "F", "G")}}
    if best is None:
        raise CertificationError("no continuous-time observer design certified: " + "; ".join(log))
    B_F = best["B_F"]
    norms = []
    for a in alphas:
        v = tuple(sum(ai * vv[k] for ai, vv in zip(a, verts)) for k in range(5))
        norms.append(hinf_norm_continuous(*continuous_augmented(v, B_F, T, (A0, C0, L0))))
    if not max(norms) <= best["gamma"] * (1 + 1e-9):
        raise CertificationError(f"a sampled norm {max(norms):.8g} exceeds the certified γ {best['gamma']:.8g}")
    return dict(best, A_F=A0 + B_F @ C0, C_F=-L0, verified_norm=float(max(norms)), states=part.states,
                attempts=tuple(log), sample_norms=np.array(norms))


@dataclass(frozen=True)
class ContinuousResult:
    """A certified continuous-time observer-form filter ``ẋ_f = A_F x_f + B_F y``, ``ẑ = C_F x_f``."""

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    gamma: float
    lmi_gamma: float
    verified_norm: float
    sample_norms: np.ndarray
    system: ContinuousPolytope
    solver: str
    eps: float
    witness: dict = field(repr=False)
    form: str = "observer"
    lyapunov: str = "parameter-dependent"
    covers: str = COVERS_CONTINUOUS
    objective: str = "hinf"


def design_continuous_system(system: ContinuousPolytope, *, solver: str | None = None,
                             eps: Sequence[float] = (0.01, 0.1, 1.0), points: int = 41) -> ContinuousResult:
    """Observer-form design for a :class:`~hinfnav.systems.continuous.ContinuousPolytope` (see the module docstring).

    ``sample_norms`` are the continuous-time norms of the error system at a
    simplex grid of ``points`` per edge (one sample for a nominal plant).
    """
    solver = solver or "CLARABEL"
    out = synthesize_continuous_observer(system.vertices, eps=eps, solver=solver, points=points)
    return ContinuousResult(out["A_F"], out["B_F"], out["C_F"], float(out["gamma"]), float(out["lmi_gamma"]),
                            float(out["verified_norm"]), np.asarray(out["sample_norms"]), system, solver,
                            float(out["eps"]), out["witness"])
