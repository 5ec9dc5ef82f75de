"""Design a certified filter for a system read from a TOML file (``design --system``).

Nominal and norm-bounded systems with ``lyapunov="common"`` go to
:func:`~hinfnav.design.synthesize` (Corollary 1: arbitrarily time-varying F);
a norm-bounded system with ``lyapunov="parameter-dependent"`` is first
written as the polytope of its sign vertices
(:meth:`~hinfnav.systems.PolytopicSystem.from_norm_bounded`, F diagonal), and
polytopes go to :func:`~hinfnav.design.synthesize_polytopic`. A
continuous-time file (``dt = 0``) goes to
:func:`~hinfnav.design.continuous.design_continuous_system` (observer form,
parameter-dependent, H∞ only).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..io.provenance import provenance
from ..core.validation import as_choice
from ..systems.files import read_system_file
from ..core.exceptions import InputError
from ..systems.continuous import ContinuousPolytope
from ..systems.polytopic import PolytopicSystem
from .continuous import design_continuous_system
from .polytopic import LYAPUNOV, synthesize_polytopic
from ..lmi.solve import SolverOptions
from .robust_hinf import synthesize

if TYPE_CHECKING:
    from .result import DesignResult

__all__ = ["design_from_system_file", "design_summary"]


def design_summary(result: DesignResult) -> dict[str, Any]:
    """JSON-ready summary of a certified design (any design: its fields say what it certifies)."""
    return {
        "gamma": float(result.gamma),
        "lmi_gamma": float(result.lmi_gamma),
        "verified_worst_norm": float(result.verified_norm),
        "n_samples": int(np.size(result.sample_norms)),
        "objective": result.objective,
        "lyapunov": result.lyapunov,
        "form": result.form,
        "covers": result.covers,
        "solver": result.solver,
        "A_F": result.A_F.tolist(),
        "B_F": result.B_F.tolist(),
        "C_F": result.C_F.tolist(),
        "provenance": provenance(),
    }


def design_from_system_file(path: str | os.PathLike[str], *, lyapunov: str | None = None, form: str = "general",
                            objective: str = "hinf", solver: str | None = None
                            ) -> tuple[DesignResult, dict[str, Any]]:
    """Read ``path`` (:func:`~hinfnav.systems.read_system_file`) and design a certified H∞ filter.

    Parameters
    ----------
    lyapunov : {"common", "parameter-dependent"}, optional
        Default: parameter-dependent for a polytope, common otherwise.
    form : {"general", "observer"}
    objective : {"hinf", "h2"}
        ``"h2"``: the extended H2 LMIs (E2) on the polytope (a norm-bounded
        system as its sign-vertex polytope, F diagonal; a nominal one as one
        vertex); the summary's ``gamma`` is then the certified H2 bound.
    solver : str, optional

    Returns
    -------
    (DesignResult, dict)
        The result (with its ``system``) and :func:`design_summary`.
    """
    objective = as_choice("objective", objective, ("hinf", "h2"))
    if lyapunov is not None:
        lyapunov = as_choice("lyapunov", lyapunov, LYAPUNOV)
    form = as_choice("form", form, ("general", "observer"))
    system = read_system_file(path)
    if isinstance(system, ContinuousPolytope):
        if form != "observer" or objective != "hinf" or lyapunov == "common":
            raise InputError(f"{path}: dt = 0 (continuous time) designs the observer form, H∞, parameter-dependent "
                             "only (pass --form observer; no --objective h2, no --lyapunov common); got "
                             f"form {form!r}, objective {objective!r}, lyapunov {lyapunov!r}")
        result = design_continuous_system(system, solver=solver)
        return result, design_summary(result)
    if objective == "h2":  # H2: the extended LMIs (E2) on the polytope (one vertex when nominal)
        if not isinstance(system, PolytopicSystem):
            system = PolytopicSystem.from_norm_bounded(system)
        lyapunov = lyapunov or ("parameter-dependent" if system.n_vertices > 1 else "common")
        result = synthesize_polytopic(system, lyapunov=lyapunov, form=form, solver=solver, objective="h2",
                                      state_scaling="units")
    elif isinstance(system, PolytopicSystem):
        result = synthesize_polytopic(system, lyapunov=lyapunov or "parameter-dependent", form=form, solver=solver,
                                      state_scaling="units")
    elif system.H is not None and lyapunov == "parameter-dependent":
        result = synthesize_polytopic(PolytopicSystem.from_norm_bounded(system), lyapunov=lyapunov, form=form,
                                      solver=solver, state_scaling="units")
    else:
        # the state units of a file must not change the design (issue 36): the unit-free scaling
        result = synthesize(system, form=form, options=SolverOptions.only(solver, state_scaling="units"),
                            structure="full")
    return result, design_summary(result)
