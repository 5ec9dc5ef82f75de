"""The estimators run on the real day (issue 20, item 4), built from today's package.

Every filter estimates GRACE-A's Hill state relative to GRACE-B (6 states, m and m/s) at 10 s:

``ekf_hill``            EKF on the Hill/CW model of paper 000 (``hinfnav.systems.hill``), Q = the second
                        moment of the Hill model's measured one-step mismatch (:func:`.mismatch.one_step_mismatch`;
                        an oracle tuning: it uses the truth, said so);
``ekf_two_body_j2``     EKF whose mean prediction integrates both spacecraft with two-body + J2 (RK4), GRACE-B's
                        inertial state taken from its POD orbit (the chief's own navigation, assumed known); the
                        covariance is propagated with the CW transition (``predict_mean`` / covariance hooks of
                        :class:`~hinfnav.estimators.ExtendedKalmanFilter`); Q = that model's one-step mismatch;
``huber_hill``          the Huber filter (γ = 1.345) on ``ekf_hill``;
``stkf_hill_accel``     strong tracking, :class:`~hinfnav.estimators.augmented.AugmentedInputSTKF`: the Hill model
                        with the unmodelled acceleration (m/s²) estimated as a random walk;
``adaptive_hill_accel`` the same with the rate-adaptive input noise (``AugmentedInputAdaptiveKF``);
``recursive_hinf_hill`` Simon's recursive H∞ filter on the Hill model (θ = 0.1 × its largest admissible θ);
``robust_lmi_hill``     the certified robust H∞ filter (Corollary 1, observer form) for ω = ω₀(1 + δ), |δ| ≤ δ̄;
``mixed_h2hinf_hill``   the robust mixed H2/H∞ filter at twice the robust filter's certified γ.

The LMI designs (:func:`lmi_designs`) need a Schur-stable plant; the Hill transition is only marginally
stable (eigenvalues on the unit circle, a Jordan block at 1), so they are designed for ``ρ Φ(ω₀)`` with
ρ = :data:`DESIGN_DAMPING` and run with the undamped Φ(ω₀) and their observer gain
``G = C_F B_F`` (:func:`hinfnav.analysis.observer.observer_form`): ``x̂⁺ = Φ x̂ + G (y − C x̂)``. Their
certified γ therefore covers the damped design model with |δ| ≤ δ̄, not the real run: a departure forced by
the marginal plant, reported beside the real error.
"""

import warnings

import numpy as np

from ...analysis.observer import observer_form
from ...core.exceptions import HinfnavError, LooseBoundWarning, SolverAccuracyWarning
from ...design import SampleSet, SolverOptions, synthesize, synthesize_mixed
from ...estimators import (
    ExtendedKalmanFilter,
    HuberFilter,
    RecursiveHInfinityFilter,
)
from ...estimators.augmented import AugmentedInputAdaptiveKF, AugmentedInputSTKF
from ...estimators.lti import LTIFilter
from ...systems.hill import (
    hill_system,
    measurement_matrix,
    uncertainty_F,
    uncertainty_structure,
)
from ...systems.uncertain import UncertainSystem
from .constants import DT_S
from .dataset import hill_to_inertial, inertial_to_hill
from .dynamics import MODELS, pair, rk4
from .mismatch import SUBSTEPS, hill_transition

__all__ = ["NonlinearPredictionEKF", "DESIGN_DAMPING", "P0_STD", "model_mismatch_moment",
           "lmi_designs", "build_filters", "FILTER_NAMES"]

#: Damping of the LMI design model (see the module notes): ρ Φ(ω₀).
DESIGN_DAMPING = 0.99
#: Choice: 1σ of the initial estimate per axis (m, m/s); the initial error is drawn from it.
P0_STD = np.array([10.0, 10.0, 10.0, 0.05, 0.05, 0.05])
#: Choice: white acceleration (m/s², 1σ per step) of the augmented filters' state noise.
Q_ACCEL = 1e-4
#: Choice: random-walk density of the augmented filters' unknown acceleration, (m/s²)²/s.
Q_INPUT_DENSITY = 1e-9

FILTER_NAMES = ("ekf_hill", "ekf_two_body_j2", "huber_hill", "stkf_hill_accel", "adaptive_hill_accel",
                "recursive_hinf_hill", "robust_lmi_hill", "mixed_h2hinf_hill")


class NonlinearPredictionEKF(ExtendedKalmanFilter):
    """EKF with a nonlinear (two-body or two-body + J2) mean prediction of the Hill state.

    Parameters
    ----------
    chief : tuple of ndarray
        GRACE-B's inertial ``(r (n, 3), v (n, 3))`` at every epoch (m, m/s).
    model : {"two_body", "two_body_j2"}
        The nonlinear mean prediction.
    **kwargs
        The parameters of :class:`~hinfnav.estimators.ExtendedKalmanFilter`.
    """

    name = "ekf_two_body_j2"

    def __init__(self, system, measurement, *, chief, model="two_body_j2", **kwargs):
        super().__init__(system, measurement, **kwargs)
        self.chief = chief
        self._f = pair(MODELS[model])

    def predict_mean(self, x, u, t=0.0):
        """The core's mean-prediction hook: x̂(k|k) at t = k Δt through the nonlinear pair model (P through Φ)."""
        k = int(round(t / self.dt))
        r_c, v_c = self.chief[0][k], self.chief[1][k]
        r_d, v_d = hill_to_inertial(r_c, v_c, x)
        runs = x.shape[0]
        X = np.concatenate([np.broadcast_to(r_c, (runs, 3)), np.broadcast_to(v_c, (runs, 3)), r_d, v_d], axis=-1)
        X = rk4(self._f, X, k * DT_S, DT_S, 1)  # one 10 s RK4 step: within 3e-8 m of 5 s steps
        return inertial_to_hill(X[:, :3], X[:, 3:6], X[:, 6:9], X[:, 9:12])


def model_mismatch_moment(data, model):
    """Second moment (6, 6) of the one-step mismatch of a nonlinear model (chief from POD), m², m²/s²."""
    f = pair(MODELS[model])
    X = np.concatenate([data.rB[:-1], data.vB[:-1], data.rA[:-1], data.vA[:-1]], axis=-1)
    X = rk4(f, X, 0.0, DT_S / SUBSTEPS, SUBSTEPS)
    e = inertial_to_hill(X[:, :3], X[:, 3:6], X[:, 6:9], X[:, 9:12]) - data.truth[1:]
    return e.T @ e / e.shape[0]


def _quiet(fn, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LooseBoundWarning)
        warnings.simplefilter("ignore", SolverAccuracyWarning)
        return fn(*args, **kwargs)


def lmi_designs(omega0, delta_bar, Q, D, *, mixed_factor=2.0):
    """The robust H∞ (observer form) and mixed H2/H∞ designs on ``ρ Φ(ω₀)`` with ``|δ| ≤ δ̄`` (module notes).

    Parameters
    ----------
    omega0 : float
        rad/s.
    delta_bar : float
        δ̄ of ω = ω₀(1 + δ); ΔA = T H_a F(δ) E_a (Section 4 of paper 000).
    Q : ndarray (6, 6)
        Process-noise covariance per step; B = its Cholesky factor.
    D : ndarray (3, 3)
        Measurement-noise matrix of the position measurement.
    mixed_factor : float
        The mixed design's H∞ bound is this × the robust filter's certified γ.

    Returns
    -------
    dict
        ``robust`` and ``mixed`` → ``{"result", "G", "gamma", ...}`` or ``{"error": message}``.
    """
    A = DESIGN_DAMPING * hill_transition(omega0)
    B = np.linalg.cholesky(Q + 1e-10 * np.eye(6))
    C = measurement_matrix()
    Ha, Ea = uncertainty_structure(omega0, delta_bar)
    deltas = np.array([-delta_bar, 0.0, delta_bar])
    samples = SampleSet(tuple(uncertainty_F(d, delta_bar) for d in deltas), tuple(f"δ = {d:g}" for d in deltas),
                        deltas, delta_bar)
    system = UncertainSystem(A, B, C, D, np.eye(6), DT_S * Ha, Ea, dt=DT_S)
    common = dict(structure="diagonal", uncertainty_samples=samples, options=SolverOptions(polish=False))
    out = {}
    try:
        r = _quiet(synthesize, system, form="observer", **common)
        obs = observer_form(r.A_F, r.B_F, r.C_F, A, C)
        out["robust"] = {"result": r, "G": obs["G"], "gamma": r.gamma, "sampled_norm": r.verified_norm,
                         "observer_residual": float(obs["residual"])}
    except HinfnavError as exc:
        out["robust"] = {"error": f"{type(exc).__name__}: {exc}"}
    if "gamma" in out["robust"]:
        try:
            m = _quiet(synthesize_mixed, system, gamma=mixed_factor * out["robust"]["gamma"], **common)
            obs = observer_form(m.A_F, m.B_F, m.C_F, A, C)
            out["mixed"] = {"result": m, "G": obs["G"], "gamma": m.gamma, "nu": getattr(m, "nu", None),
                            "gamma_bound": mixed_factor * out["robust"]["gamma"],
                            "observer_residual": float(obs["residual"])}
        except HinfnavError as exc:
            out["mixed"] = {"error": f"{type(exc).__name__}: {exc}"}
    else:
        out["mixed"] = {"error": "no robust design to bound the mixed one"}
    return out


def _observer(G, omega0, system, measurement, name):
    Phi = hill_transition(omega0)
    C = measurement_matrix()
    # x_f = −x̂ (C_F = −I): x_f⁺ = (Φ − G C) x_f − G y
    return LTIFilter(Phi - G @ C, -G, -np.eye(6), system, measurement, name=name)


def build_filters(data, model, linear, Q_hill, Q_j2, designs=None, *, theta_fraction=0.1):
    """The estimators of the module notes: name → ``(estimator, form)``, form "direct" or "linear".

    ``model`` is the variant's measurement model, ``linear`` its linear (position) form.
    """
    w0 = data.orbital_rate
    P0 = np.diag(P0_STD**2)
    sys_hill = hill_system(w0, 1.0, DT_S, np.linalg.cholesky(Q_hill + 1e-12 * np.eye(6)))
    ekf = ExtendedKalmanFilter(sys_hill, model, P0=P0, Q=Q_hill, name="ekf_hill")
    out = {"ekf_hill": (ekf, "direct"),
           "ekf_two_body_j2": (NonlinearPredictionEKF(sys_hill, model, chief=(data.rB, data.vB), P0=P0, Q=Q_j2,
                                                      name="ekf_two_body_j2"), "direct"),
           "huber_hill": (HuberFilter.from_ekf(ekf, name="huber_hill"), "direct")}
    Qa = np.diag(np.r_[np.full(3, (0.5 * Q_ACCEL * DT_S**2) ** 2), np.full(3, (Q_ACCEL * DT_S) ** 2)])
    aug = dict(Q_input=Q_INPUT_DENSITY * np.eye(3), P0=P0, P0_input=(1e-2) ** 2 * np.eye(3), Q=Qa)
    out["stkf_hill_accel"] = (AugmentedInputSTKF(sys_hill, model, name="stkf_hill_accel", **aug), "direct")
    out["adaptive_hill_accel"] = (AugmentedInputAdaptiveKF(sys_hill, model, name="adaptive_hill_accel", **aug), "direct")
    rh = RecursiveHInfinityFilter(sys_hill, linear, theta=0.0, P0=P0, Q=Q_hill, uses_input=False)
    theta = theta_fraction * rh.theta_max()
    out["recursive_hinf_hill"] = (RecursiveHInfinityFilter(sys_hill, linear, theta=theta, P0=P0, Q=Q_hill,
                                                           uses_input=False, name="recursive_hinf_hill"), "linear")
    for key, name in (("robust", "robust_lmi_hill"), ("mixed", "mixed_h2hinf_hill")):
        if designs is not None and "G" in designs.get(key, {}):
            out[name] = (_observer(designs[key]["G"], w0, sys_hill, linear, name), "linear")
    return out
