"""The H∞ filters of the benchmark on any scenario's declared Kalman model with linear dynamics (issue 18).

A scenario that offers the ``"kalman"`` model and linear dynamics (:class:`~hinfnav.estimators.registry.Offers`)
gets two more generic filters beside those of :mod:`.estimators`, built from its ``kalman_model()`` (system Φ, Γ,
B; measurement; P₀; whether the filters are told the applied input):

``model_hinf``
    Simon's a-priori recursive H∞ filter (2006, §11.3; :mod:`hinfnav.estimators.recursive_hinf`) with
    Q = B Bᵀ, R = D Dᵀ, the model's P₀, z = W⁻¹ x (L = W⁻¹, S = I; W below), told the input as the model says, and
    θ = ``theta_fraction`` · θ_max (default one half, as Sun 2011's ``recursive_hinf``), θ_max the largest θ with a
    steady state (:func:`hinfnav.analysis.max_admissible_theta`) or, if smaller, the largest θ the first step from
    P₀ admits (:func:`model_theta_max`). A linear measurement runs
    :class:`~hinfnav.estimators.recursive_hinf.RecursiveHInfinityFilter`; a nonlinear one (range/angle) the
    *extended* H∞ filter :class:`~hinfnav.estimators.recursive_hinf.ExtendedHInfinityFilter`, the measurement
    linearized at the prior estimate as the EKF does, θ_max then taken at the Jacobian at the scenario's initial
    estimate x̂₀. The condition then depends on each run's linearization: on Shi & Wang's target θ_max/2 fails
    on some runs within ten steps from P₀ and on 10 % of all steps over a run (measured: 50 runs × 10⁴ steps, no
    maneuver); taking θ = 0 at those steps (``on_violation="kalman"``) still leaves steps with a margin barely
    above 0, whose huge P̄ made the estimate diverge (10⁷ m on 3 runs of 300 steps). No θ rule is safe there
    without tuning on the truth, so the registered ``model_hinf`` does not fit a nonlinear measurement (the
    reason says so); :func:`build_model_hinf` still builds the extended filter when called directly. Both report
    the a-priori estimate x̂(k|k−1).
``model_lmi``
    the nominal H∞ filter in observer form designed by LMI (:func:`hinfnav.design.synthesize`, ``form="observer"``:
    only (Φ, H) detectable is needed, the plant may be marginally stable; certified independently of the solver
    as every design of the package), run as the LTI filter
    ``x̂⁺ = Φ x̂ + Γ u + G (y − H x̂)`` (:class:`~hinfnav.estimators.LTIFilter`, told the input where the model
    is). The model gives no uncertainty, so the design is nominal (γ from (w, v) to the weighted error), the
    readings scaled by their noise σ for the solver.

Both weight the error as z = W⁻¹ x with W = the stationary Kalman standard deviations
(:func:`kalman_weights`; H at x̂₀ for a nonlinear measurement): each state's error counted relative to its Kalman
limit (documented choice: a state in mixed units — m, m/s, N — has no natural L = I; with L = I on the drag-free
axes the recursive filter's transient from P₀ violates the existence condition at every θ tried down to a tenth of
the first step's bound). So θ is dimensionless.

``model_lmi`` is solved by CLARABEL (:data:`SOLVER`), designed once per model (cached by its matrices). It needs
a linear measurement: on a nonlinear one (Shi & Wang's range/angle: its converted position has a reading-dependent
covariance, no fixed D) it does not fit, with that reason; neither where the design finds no certified filter
(the reason carries the solver's message and the spectral radius of the Kalman error dynamics).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...analysis.hinf_riccati import max_admissible_theta
from ...analysis.riccati import steady_state_kalman
from ...core.exceptions import HinfnavError, InputError
from ...core.linalg import spectral_radius
from ...core.validation import as_nonnegative
from ...design.result import DesignResult
from ...design.robust_hinf import synthesize
from ...estimators.lti import LTIFilter
from ...estimators.recursive_hinf import ExtendedHInfinityFilter, RecursiveHInfinityFilter
from ...estimators.registry import Requires, register_estimator
from ...systems.uncertain import UncertainSystem
from .estimators import _has_model, _model

__all__ = ["LinearDesign", "build_model_hinf", "build_model_lmi", "model_lmi_design",
           ]

#: The LMI solver of ``model_lmi`` (interior point; the designs take about 0.1 s on the benchmark's models).
SOLVER = "CLARABEL"

_DESIGNS: dict = {}


def _linearized(scenario):
    """``(model, H)``: the Kalman model and its measurement matrix (the Jacobian at x̂₀ when nonlinear) (internal)."""
    m = _model(scenario)
    meas = m["measurement"]
    H = meas.H if meas.linear else meas.jacobian(np.asarray(scenario.xhat0, dtype=float))
    return m, np.asarray(H, dtype=float)


def kalman_weights(system, H, R):
    """W: the stationary Kalman standard deviations of x⁺ = Φ x + B w, y = H x + v (cov R), units of x.

    The weighting of both H∞ filters here (z = W⁻¹ x). Raises an InputError naming the cause when (Φ, H) is not
    detectable (:func:`hinfnav.analysis.steady_state_kalman`).
    """
    P = steady_state_kalman(system.Phi, H, system.B @ system.B.T, R)[0]
    W = np.sqrt(np.diag(P))
    if not np.all(W > 0):
        raise InputError("the stationary Kalman covariance has a zero standard deviation: no weighting z = W⁻¹ x")
    return W


def model_theta_max(scenario) -> float:
    """The largest θ of ``model_hinf`` on ``scenario``'s Kalman model (dimensionless: z = W⁻¹ x).

    The smaller of θ_max, the largest θ with a steady state (:func:`hinfnav.analysis.max_admissible_theta`), and
    the largest θ the first step admits from the model's P₀, ``λ_min(W(P₀⁻¹ + HᵀR⁻¹H)W)`` (the existence condition
    ``P₀⁻¹ − θ W⁻² + HᵀR⁻¹H > 0``): a P₀ larger than the steady P can violate it where the steady state does
    not. H is the Jacobian at x̂₀ for a nonlinear measurement.
    """
    m, H = _linearized(scenario)
    system, R = m["system"], m["measurement"].R
    W = kalman_weights(system, H, R)
    first = W[:, None] * (np.linalg.inv(m["P0"]) + H.T @ np.linalg.solve(R, H)) * W[None, :]
    theta_first = float(np.linalg.eigvalsh(0.5 * (first + first.T))[0])
    return min(max_admissible_theta(system.Phi, H, system.B @ system.B.T, R, L=np.diag(1.0 / W)), theta_first)


def build_model_hinf(scenario, *, theta=None, theta_fraction=0.5, **options):
    """``model_hinf`` (module docstring): θ = ``theta_fraction`` · θ_max unless ``theta`` is given.

    Parameters
    ----------
    scenario : object with ``kalman_model()`` and ``xhat0``
    theta : float, optional
        Performance bound θ ≥ 0, 1/(units of x)².
    theta_fraction : float
        In [0, 1), used when ``theta`` is None.
    **options
        To the filter's class (``on_violation``, ``output``…).

    Returns
    -------
    RecursiveHInfinityFilter or ExtendedHInfinityFilter
    """
    m, H = _linearized(scenario)
    system, meas = m["system"], m["measurement"]
    if theta is None:
        frac = as_nonnegative("theta_fraction", theta_fraction)
        if not frac < 1:
            raise InputError(f"theta_fraction must be in [0, 1); got {frac}")
        theta = frac * model_theta_max(scenario)
    cls = RecursiveHInfinityFilter if meas.linear else ExtendedHInfinityFilter
    if not meas.linear:
        options.setdefault("on_violation", "kalman")
    options.setdefault("name", "model_hinf")
    options.setdefault("L", np.diag(1.0 / kalman_weights(system, H, meas.R)))
    return cls(system, meas, theta=theta, P0=m["P0"], uses_input=m["uses_input"], **options)


@dataclass(frozen=True, eq=False)
class LinearDesign:
    """The observer of ``model_lmi`` in the model's coordinates.

    Attributes
    ----------
    A_F, B_F, C_F : ndarray
        Filter (12) in observer form: ``A_F = Φ + B_F H``, ``C_F = −I``, the gain ``G = −B_F``.
    weights : ndarray, shape (n,)
        W: the design weights z = W⁻¹ x (stationary Kalman standard deviations, units of x).
    output_scale : ndarray, shape (m,)
        The readings' noise σ the design divided them by.
    gamma : float
        Certified H∞ level from (w, v) to W⁻¹ e (dimensionless).
    result : DesignResult
        The synthesis in the scaled coordinates (solver, times, certificate).
    """

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    weights: np.ndarray
    output_scale: np.ndarray
    gamma: float
    result: DesignResult


def _key(system, meas):
    return tuple(np.ascontiguousarray(a, dtype=float).tobytes() for a in (system.Phi, system.B, meas.H, meas.D)) \
        + (float(system.dt),)


def model_lmi_design(scenario) -> LinearDesign:
    """The LMI design of ``model_lmi`` on ``scenario``'s Kalman model (cached by its matrices; module docstring).

    Raises
    ------
    InputError
        The measurement is not linear, or no certified filter was found (the message says why).
    """
    m = _model(scenario)
    system, meas = m["system"], m["measurement"]
    if not (getattr(meas, "linear", False) and getattr(meas, "H", None) is not None):
        raise InputError(
            f"the LMI design needs a linear measurement y = H x + D v; the scenario's Kalman model reads "
            f"{type(meas).__name__} (nonlinear) and offers no linear one with a fixed noise matrix D")
    key = _key(system, meas)
    if key not in _DESIGNS:
        _DESIGNS[key] = _design(system, meas)
    out = _DESIGNS[key]
    if isinstance(out, str):
        raise InputError(out)
    return out


def _design(system, meas):
    """The design (or the reason there is none, as a string) (internal)."""
    Phi, B, H, D, R = system.Phi, system.B, meas.H, meas.D, meas.R
    try:
        W = kalman_weights(system, H, R)
    except (InputError, HinfnavError) as exc:
        return f"the LMI design weights the error by the stationary Kalman standard deviations: {exc}"
    s = np.sqrt(np.diag(R))
    scaled = UncertainSystem(Phi * W[None, :] / W[:, None], B / W[:, None], H * W[None, :] / s[:, None],
                             D / s[:, None], np.eye(system.n), None, None, system.dt)
    try:
        res = synthesize(scaled, form="observer", solver=SOLVER)
    except HinfnavError as exc:
        K = steady_state_kalman(Phi, H, B @ B.T, R)[2]
        rho = spectral_radius(Phi - Phi @ K @ H)
        return (f"the LMI design found no certified filter on this model ({type(exc).__name__}: {str(exc)[:160]}…); "
                f"its optimal (Kalman) error dynamics has spectral radius 1 − {1.0 - rho:.2g}: a mode barely "
                "observable, too close to the unit circle for an LMI margin in double precision")
    B_F = W[:, None] * res.B_F / s[None, :]
    return LinearDesign(A_F=Phi + B_F @ H, B_F=B_F, C_F=-np.eye(system.n), weights=W, output_scale=s,
                        gamma=float(res.gamma), result=res)


def build_model_lmi(scenario, **options):
    """``model_lmi`` (module docstring): the LTI observer of :func:`model_lmi_design`, told the input as the model
    says; ``options`` to :class:`~hinfnav.estimators.LTIFilter` (``missing``)."""
    m = _model(scenario)
    d = model_lmi_design(scenario)
    system = m["system"]
    if m["uses_input"] and system.n_input:
        options.update(input_matrix=system.Gamma, K=np.zeros((system.n_input, system.n)))
    options.setdefault("name", "model_lmi")
    return LTIFilter(d.A_F, d.B_F, d.C_F, system, m["measurement"], **options)


def _lmi_fits(scenario):
    if not _has_model(scenario):
        return False
    try:
        model_lmi_design(scenario)
    except InputError as exc:
        return str(exc)
    return True


_REQUIRES = Requires(error_form="additive", model="kalman", linear=True)

def _hinf_fits(scenario):
    if not _has_model(scenario):
        return False
    meas = _model(scenario)["measurement"]
    if not getattr(meas, "linear", False):
        return (f"the recursive H-inf filter needs a linear measurement here: linearized at each run's estimate "
                f"({type(meas).__name__}) its existence condition depends on the data, and theta = theta_max/2 of the "
                "initial geometry fails on some runs and lets others diverge (measured; see "
                "hinfnav.papers.benchmark.linear_designs)")
    return True


register_estimator("model_hinf", build_model_hinf, fits=_hinf_fits, requires=_REQUIRES,
                   description="Simon's recursive H-inf filter of the scenario's declared Kalman model (error weighted "
                               "by the Kalman sigmas), theta = theta_max/2")
register_estimator("model_lmi", build_model_lmi, fits=_lmi_fits, requires=_REQUIRES,
                   description="nominal H-inf observer designed by LMI (certified) on the scenario's declared Kalman "
                               "model, told the input")
