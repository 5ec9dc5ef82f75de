"""Norm-bounded, quadratic-polytopic and parameter-dependent designs of one plant, side by side.

:func:`compare_uncertainty_models` designs a certified H∞ filter for the same
polytope three ways — Corollary 1 on a norm-bounded cover (arbitrarily
time-varying F(k)), one common Lyapunov matrix on the vertices (arbitrarily
time-varying α(k)) and parameter-dependent Lyapunov matrices (α constant in
time) — and reports each certified γ with the worst H∞ norm sampled on a
dense grid of the simplex, or why the design does not exist.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.exceptions import HinfnavError, InputError
from ..systems.polytopic import PolytopicSystem
from .explain import small_gain_number
from .polytopic import sampled_norms, synthesize_polytopic
from .robust_hinf import synthesize

if TYPE_CHECKING:
    from ..systems.uncertain import UncertainSystem

__all__ = ["compare_uncertainty_models"]


def compare_uncertainty_models(system: PolytopicSystem, *, form: str = "general",
                               norm_bounded: bool | UncertainSystem = True, grid_points: int | None = None,
                               solver: str | None = None) -> list[dict[str, Any]]:
    """One row per uncertainty model: ``model``, ``covers``, ``gamma``, ``worst_sampled``, ``status``.

    Parameters
    ----------
    system : PolytopicSystem
    form : {"general", "observer"}
    norm_bounded : bool or UncertainSystem
        Also design Corollary 1 on :meth:`PolytopicSystem.norm_bounded_cover`
        (True), on a given norm-bounded system, or not (False).
    grid_points : int, optional
        Simplex lattice points of the sampled norms.
    solver : str, optional

    Returns
    -------
    list of dict
        ``gamma`` and ``worst_sampled`` are NaN when the design does not
        exist; ``status`` then holds the reason (first sentence).
    """
    if not isinstance(system, PolytopicSystem):
        raise InputError(f"system must be a hinfnav PolytopicSystem; got {type(system).__name__}")
    rows = []
    if norm_bounded is not False:
        nb = system.norm_bounded_cover() if norm_bounded is True else norm_bounded
        row = {"model": "norm-bounded (Corollary 1)", "covers": "every time-varying F(k), FᵀF ≤ I",
               "small_gain": small_gain_number(nb.A, nb.H, nb.E)}
        try:
            r = synthesize(dataclasses.replace(nb, dt=system.dt), form=form, solver=solver)
            worst = np.max(sampled_norms(system, r.A_F, r.B_F, r.C_F, "general", None)[0]) if form == "general" \
                else r.verified_norm
            rows.append(dict(row, gamma=r.gamma, worst_sampled=float(worst), status="certified"))
        except HinfnavError as exc:
            rows.append(dict(row, gamma=float("nan"), worst_sampled=float("nan"), status=_first(exc)))
    for lyap, name in (("common", "polytope, common Lyapunov"), ("parameter-dependent", "polytope, PDL")):
        try:
            r = synthesize_polytopic(system, lyapunov=lyap, form=form, grid_points=grid_points, solver=solver)
            rows.append({"model": name, "covers": r.covers, "gamma": r.gamma, "worst_sampled": r.verified_norm,
                         "status": "certified"})
        except HinfnavError as exc:
            rows.append({"model": name, "covers": "", "gamma": float("nan"), "worst_sampled": float("nan"),
                         "status": _first(exc)})
    return rows


def _first(exc):
    text = str(exc)
    return text.split(". ")[0][:160]
