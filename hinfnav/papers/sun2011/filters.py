"""Sun et al. (2011)'s estimators by name, registered for the command line, the notebooks and the contract tests.

=========================  ===============================================
name                       estimator
=========================  ===============================================
``published``              the paper's A_F, B_F, C_F (δ̄ = 0.05), told the
                           applied thrust (see :class:`~hinfnav.estimators.LTIFilter`)
``published_closed_loop``  the same matrices run exactly as (12): no input,
                           the filter assumes u = K x
``designed``               the filter from :func:`hinfnav.synthesize` at the
                           scenario's δ̄, told the applied thrust
``designed_closed_loop``   the same run exactly as (12)
``designed_observer``      the robust filter constrained to observer form
                           (``form="observer"``, an extension: its error does
                           not depend on the trajectory), told the thrust
``designed_observer_closed_loop``  the same run exactly as (12) (Table 1 with maneuver)
``ekf``                    the EKF of :mod:`hinfnav.papers.sun2011.ekf`, as the paper describes
                           it (does not know the control law)
``ekf_known_input``        the EKF told the applied thrust
=========================  ===============================================
"""

from __future__ import annotations

from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_choice
from ...estimators.registry import Requires, register_estimator
from .constants import published_filter
from .designs import design_for_scenario
from .ekf import build_ekf
from .scenario import Scenario

if TYPE_CHECKING:
    from ...estimators.base import Estimator

__all__ = ["FILTER_NAMES", "BUILDERS", "make_estimator", "build_published", "build_designed",
           "lti_from_matrices"]

FILTER_NAMES = ("published", "published_closed_loop", "designed", "designed_closed_loop", "designed_observer",
                "designed_observer_closed_loop", "ekf", "ekf_known_input")


def lti_from_matrices(scenario, A_F, B_F, C_F, *, name, uses_input=True, design_dt=None):
    """Wrap filter matrices designed on ``scenario``'s closed loop as an estimator.

    Parameters
    ----------
    scenario : Scenario
        Gives T, K and the design model's input matrix T G₀.
    A_F, B_F, C_F : array_like
        Filter (12).
    name : str
    uses_input : bool
        Tell the filter the applied thrust (the default); False runs (12)
        as printed, assuming u = K x.
    design_dt : float, optional
        The sampling time the filter was designed for, s; an
        :class:`~hinfnav.core.exceptions.InputError` if it is not the
        scenario's (a discrete filter holds only at its own T).

    Notes
    -----
    The thrust correction ``C_F⁻¹ T G₀ (u − K ẑ)`` is exact for a filter in
    observer form (``C_F A_F C_F⁻¹ = A − C_F B_F C``), as the published one
    nearly is (residual 2.6e-4). A filter far from that form (the LMI optimum
    of Corollary 1 is not constrained to it) is only approximately corrected,
    and without maneuver it has no guarantee at all: Lemma 1 needs the
    closed-loop plant it was designed on (see notebook 04).
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    return scenario.lti_filter(A_F, B_F, C_F, name=name, uses_input=uses_input, design_dt=design_dt)


def make_estimator(scenario: Scenario, name: str, **options: Any) -> Estimator:
    """Build an estimator by name (see the module table).

    Parameters
    ----------
    scenario : Scenario
    name : str
        One of :data:`FILTER_NAMES`; each has its own builder, with the
        variant's settings bound (:data:`BUILDERS`).
    **options
        Passed to the estimator's builder (for ``designed``: options of
        :func:`hinfnav.synthesize`; for the EKFs: see :mod:`hinfnav.papers.sun2011.ekf`).
    """
    _check_scenario(scenario)
    return BUILDERS[as_choice("filter", name, FILTER_NAMES)](scenario, **options)


def _check_scenario(scenario):
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")


def build_published(scenario: Scenario, *, name: str, uses_input: bool, **options: Any) -> Estimator:
    """The printed filter (δ̄ = 0.05) as estimator ``name``; told the thrust when ``uses_input``."""
    _check_scenario(scenario)
    if options:
        raise InputError(f"filter {name!r} is the printed filter and takes no options; got {', '.join(sorted(options))}")
    pub = published_filter()
    return lti_from_matrices(scenario, pub.A_F, pub.B_F, pub.C_F, name=name, uses_input=uses_input, design_dt=pub.dt)


def build_designed(scenario: Scenario, *, name: str, uses_input: bool, **options: Any) -> Estimator:
    """The filter of :func:`design_for_scenario` (``options``, e.g. ``form``) as estimator ``name``."""
    _check_scenario(scenario)
    n = scenario.x0.size
    if scenario.L.shape != (n, n) or not np.linalg.cond(scenario.L) < 1e12:
        raise InputError(
            f"filter {name!r} estimates the whole state (x̂ = C_F x_f), so the scenario's L must be square and "
            f"invertible; got L of shape {scenario.L.shape[0]}x{scenario.L.shape[1]}"
            + ("" if scenario.L.shape != (n, n) else f" with condition number {np.linalg.cond(scenario.L):.3g}")
            + " (design_for_scenario designs for any L)"
        )
    res = design_for_scenario(scenario, **options)
    return lti_from_matrices(scenario, res.A_F, res.B_F, res.C_F, name=name, uses_input=uses_input, design_dt=res.dt)


#: Each registered name's builder, with the variant's settings bound (its name, whether it is told the
#: applied thrust, the filter form, whether the EKF knows the input); the options a caller gives are added.
BUILDERS = {
    "published": partial(build_published, name="published", uses_input=True),
    "published_closed_loop": partial(build_published, name="published_closed_loop", uses_input=False),
    "designed": partial(build_designed, name="designed", uses_input=True),
    "designed_closed_loop": partial(build_designed, name="designed_closed_loop", uses_input=False),
    "designed_observer": partial(build_designed, name="designed_observer", uses_input=True, form="observer"),
    "designed_observer_closed_loop": partial(build_designed, name="designed_observer_closed_loop", uses_input=False,
                                             form="observer"),
    "ekf": partial(build_ekf, known_input=False),
    "ekf_known_input": partial(build_ekf, known_input=True),
}

_DESCRIPTIONS = {
    "published": "Sun 2011's printed H-inf filter (delta_bar = 0.05), told the applied thrust",
    "published_closed_loop": "the printed H-inf filter run verbatim as (12), assuming u = Kx",
    "designed": "robust H-inf filter designed here (Corollary 1), told the applied thrust",
    "designed_closed_loop": "the designed filter run verbatim as (12)",
    "designed_observer": "robust H-inf filter constrained to observer form (extension), told the thrust",
    "designed_observer_closed_loop": "the observer-form filter run verbatim as (12)",
    "ekf": "EKF that does not know the control law (Sun 2011's comparison)",
    "ekf_known_input": "EKF told the applied thrust",
}


def _fits(scenario):
    return isinstance(scenario, Scenario)


for _name in FILTER_NAMES:
    register_estimator(_name, BUILDERS[_name], fits=_fits, description=_DESCRIPTIONS[_name],
                       requires=Requires(model="sun2011", linear=not _name.startswith("ekf"),
                                         input=_name in ("ekf_known_input", "published", "designed", "designed_observer")))
