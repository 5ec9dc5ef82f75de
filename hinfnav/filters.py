"""Estimators by name, for the command line and the notebooks.

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
``ekf``                    the EKF of :mod:`hinfnav.ekf`, as the paper describes
                           it (does not know the control law)
``ekf_known_input``        the EKF told the applied thrust
=========================  ===============================================
"""

from .estimators import LTIFilter
from .scenario import Scenario, published_filter
from .validation import as_choice

__all__ = ["FILTER_NAMES", "make_estimator", "lti_from_matrices"]

FILTER_NAMES = ("published", "published_closed_loop", "designed", "designed_closed_loop", "designed_observer", "ekf", "ekf_known_input")


def lti_from_matrices(A_F, B_F, C_F, scenario, *, name, uses_input=True):
    """Wrap filter matrices designed on ``scenario``'s closed loop as an estimator.

    Parameters
    ----------
    A_F, B_F, C_F : array_like
        Filter (12).
    scenario : Scenario
        Gives T, K and the design model's input matrix T G₀.
    name : str
    uses_input : bool
        Tell the filter the applied thrust (the default); False runs (12)
        as printed, assuming u = K x.

    Notes
    -----
    The thrust correction ``C_F⁻¹ T G₀ (u − K ẑ)`` is exact for a filter in
    observer form (``C_F A_F C_F⁻¹ = A − C_F B_F C``), as the published one
    nearly is (residual 2.6e-4). A filter far from that form (the LMI optimum
    of Corollary 1 is not constrained to it) is only approximately corrected,
    and without maneuver it has no guarantee at all: Lemma 1 needs the
    closed-loop plant it was designed on (see notebook 04).
    """
    if uses_input:
        return LTIFilter(A_F, B_F, C_F, dt=scenario.dt, name=name, input_matrix=scenario.input_matrix_design(), K=scenario.K)
    return LTIFilter(A_F, B_F, C_F, dt=scenario.dt, name=name)


def make_estimator(name, scenario=None, **options):
    """Build an estimator by name (see the module table).

    Parameters
    ----------
    name : str
    scenario : Scenario, optional
        Defaults to the paper's.
    **options
        Passed to the estimator's builder (for ``designed``: options of
        :func:`hinfnav.synthesize`; for the EKFs: see :mod:`hinfnav.ekf`).
    """
    scenario = Scenario() if scenario is None else scenario
    as_choice("filter", name, FILTER_NAMES)
    if name in ("published", "published_closed_loop"):
        pub = published_filter()
        return lti_from_matrices(pub.A_F, pub.B_F, pub.C_F, scenario, name=name, uses_input=(name == "published"))
    if name in ("designed", "designed_closed_loop", "designed_observer"):
        from .synthesis import design_for_scenario

        if name == "designed_observer":
            options.setdefault("form", "observer")
        res = design_for_scenario(scenario, **options)
        return lti_from_matrices(res.A_F, res.B_F, res.C_F, scenario, name=name, uses_input=(name != "designed_closed_loop"))
    from .ekf import build_ekf

    return build_ekf(scenario, known_input=(name == "ekf_known_input"), **options)
