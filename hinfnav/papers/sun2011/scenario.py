"""The paper's scenario (Section 4), transcribed once.

Everything numeric that the paper prints lives here: ω₀, chaser mass, the
feedback gain K (from Gao, Yang & Shi 2009), the initial truth and filter
states, the noise matrices B and D, L, and the published filter
(A_F, B_F, C_F) designed at δ̄ = 0.05. What the paper does not print (the
sampling time, the run length, the error window) is a documented choice.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...control.feedback import LinearFeedback
from ...core.exceptions import InputError
from ...core.linalg import discretize, spectral_radius
from ...core.validation import as_choice, as_matrix, as_nonnegative, as_positive, as_real, as_vector
from ...design.result import DesignResult
from ...estimators.lti import LTIFilter
from ...estimators.registry import Offers
from ...sim.scenario import Scenario as BaseScenario
from ...sim.truth import TruthModel
from ...systems.hill import (
    delta_A1,
    hill_matrices,
    hill_system,
    measurement_matrix,
    position_measurement,
    uncertainty_structure,
)
from ...systems.uncertain import UncertainSystem
from .constants import DEFAULT_P0_STD, PAPER_K

if TYPE_CHECKING:
    from ...systems.linear import LinearSystem
    from ...systems.measurements import LinearMeasurement

__all__ = ["Scenario", "paper_scenario"]

#: Truth discretizations: exact zero-order hold (default) or the paper's Euler (6).
DISCRETIZATIONS = ("exact", "euler")

def _readonly(name, value, shape):
    arr = as_matrix(name, value, shape)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class Scenario(BaseScenario):
    """Settings of one relative-navigation scenario; defaults are the paper's.

    Attributes
    ----------
    omega0 : float
        Nominal orbital rate of the target, rad/s (24 h orbit: 7.2722e-5).
    mass : float
        Chaser mass, kg (1000).
    dt : float
        Sampling time T, s. Not printed in the paper; 0.1 s is read off the
        published filter by :func:`infer_sampling_time`.
    K : ndarray, shape (3, 6)
        State-feedback gain of (3), u = K x, N per (m, m/s).
    x0 : ndarray, shape (6,)
        Initial relative state (600, 550, 1040, 0.02, −0.08, 0.03), m and m/s.
    xhat0 : ndarray, shape (6,)
        Initial state estimate of the filters (630, 520, 1000, 0, 0, 0).
    B : ndarray, shape (6, 6)
        Process-noise matrix diag(0.05, 0.05, 0.05, 0.001, 0.001, 0.001).
    D : ndarray, shape (3, 3)
        Measurement-noise matrix diag(0.1, 0.1, 0.1) (0.1 m accuracy).
    L : ndarray, shape (6, 6)
        Estimated signal z = L x; the identity (the whole state).
    delta_bar : float
        Uncertainty bound δ̄ of the design (0.05 for the published filter).
    duration_s : float
        Simulated time, s. Not printed in the paper; 1000 s covers the
        ~500 s thrust phase of Fig 6 and a steady part after it.
    rms_window_s : tuple of float
        Time window (start, end) of the RMS error, s. Starts at 100 s, after
        every filter's initial transient (the initial estimate is 30–40 m
        off) and inside the EKF's 500 s failure with maneuver.
    """

    omega0: float = 7.2722e-5
    #: What it offers the estimators (issue 18: fitting by declared requirements); a class attribute, not a setting.
    offers = Offers(error_form="additive", measurement="position", input=True, linear=True,
                    models=("sun2011", "kalman"))

    mass: float = 1000.0
    dt: float = 0.1
    K: np.ndarray = field(default_factory=lambda: PAPER_K.copy())
    x0: np.ndarray = field(default_factory=lambda: np.array([600.0, 550.0, 1040.0, 0.02, -0.08, 0.03]))
    xhat0: np.ndarray = field(default_factory=lambda: np.array([630.0, 520.0, 1000.0, 0.0, 0.0, 0.0]))
    B: np.ndarray = field(default_factory=lambda: np.diag([0.05, 0.05, 0.05, 0.001, 0.001, 0.001]))
    D: np.ndarray = field(default_factory=lambda: np.diag([0.1, 0.1, 0.1]))
    L: np.ndarray = field(default_factory=lambda: np.eye(6))
    delta_bar: float = 0.05
    duration_s: float = 1000.0
    rms_window_s: tuple = (100.0, 1000.0)

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)
        set_("omega0", as_positive("omega0", self.omega0))
        set_("mass", as_positive("mass", self.mass))
        set_("dt", as_positive("dt", self.dt))
        set_("delta_bar", as_nonnegative("delta_bar", self.delta_bar))
        set_("duration_s", as_positive("duration_s", self.duration_s))
        set_("K", _readonly("K", self.K, (3, 6)))
        for name in ("x0", "xhat0"):
            v = as_vector(name, getattr(self, name), 6)
            v.setflags(write=False)
            set_(name, v)
        set_("B", _readonly("B", self.B, (6, None)))
        set_("D", _readonly("D", self.D, (3, None)))
        set_("L", _readonly("L", self.L, (None, 6)))
        set_("rms_window_s", self.checked_window("rms_window_s"))
        if self.duration_s < self.dt:
            raise InputError(f"duration_s must be at least one sampling time dt = {self.dt}; got {self.duration_s}")

    def continuous_matrices(self, delta: float = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(A₀(ω₀(1+δ)), G₀)`` of (2), shapes (6, 6) and (6, 3)."""
        delta = as_real("delta", delta)
        return hill_matrices(self.omega0 * (1.0 + delta), self.mass)

    def truth_matrices(self, delta: float = 0.0, discretization: str = "exact") -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Discrete truth model ``x(k+1) = Φ x(k) + Γ u(k)`` (open loop).

        Parameters
        ----------
        delta : float
            True orbital-rate error δ of (4), any real number > −1 (the
            truth is not bound by δ̄).
        discretization : {"exact", "euler"}

        Returns
        -------
        Phi : ndarray, shape (6, 6)
        Gamma : ndarray, shape (6, 3)
        """
        delta = as_real("delta", delta)
        if delta <= -1:
            raise InputError(f"delta must be > -1 (the orbital rate ω₀(1+δ) must be positive); got {delta}")
        limit = np.pi / (self.omega0 * self.dt) - 1.0
        if not delta < limit:
            raise InputError(
                f"delta must be < {limit:.6g} at T = {self.dt:g} s; got {delta:g}: the orbital rate ω₀(1+δ) would turn "
                "through half a revolution or more per sample (ω T ≥ π), so the sampled Hill model aliases"
            )
        A0, G0 = self.continuous_matrices(delta)
        return discretize(A0, G0, self.dt, discretization)

    def design_model(self, delta_bar: float | None = None) -> UncertainSystem:
        """The uncertain discrete closed-loop system ψ_d of (6)–(11).

        ``A = I + T(A₁ + G₀K)`` (Euler, as in the paper), ``H = T H_a`` and
        ``E = E_a`` of Section 4 (the zero columns of H_a / rows of E_a are
        kept here; the synthesis drops them), ``C = [I 0]``.

        Parameters
        ----------
        delta_bar : float, optional
            Uncertainty bound; defaults to ``self.delta_bar``. With 0 the
            system is returned without H and E (nominal design).

        Returns
        -------
        UncertainSystem
        """
        Ha, Ea = uncertainty_structure(self.omega0, self.delta_bar if delta_bar is None else delta_bar)  # checks δ̄
        A1, G0 = hill_matrices(self.omega0, self.mass)
        A = np.eye(6) + self.dt * (A1 + G0 @ self.K)
        H, E = (self.dt * Ha, Ea) if np.any(Ea) else (None, None)  # δ̄ = 0: nominal
        return UncertainSystem(A, self.B, measurement_matrix(), self.D, self.L, H, E, self.dt)

    def design_A(self, delta: float = 0.0) -> NDArray[np.float64]:
        """Euler closed-loop matrix with a given δ: ``I + T(A₁ + ΔA₁(δ) + G₀K)``."""
        A1, G0 = hill_matrices(self.omega0, self.mass)
        return np.eye(6) + self.dt * (A1 + delta_A1(self.omega0, delta) + G0 @ self.K)

    def input_matrix_design(self) -> NDArray[np.float64]:
        """Input matrix of the Euler design model, ``T G₀``, shape (6, 3)."""
        _, G0 = hill_matrices(self.omega0, self.mass)
        return self.dt * G0

    # -- the objects the generic layers read ---------------------------------------

    def system(self, delta: float = 0.0, discretization: str = "exact", *, closed_loop: bool = False) -> LinearSystem:
        """The truth dynamics as a :class:`~hinfnav.systems.LinearSystem`.

        Parameters
        ----------
        delta : float
            True orbital-rate error δ of (4), > −1.
        discretization : {"exact", "euler"}
        closed_loop : bool
            True: ``Φ + Γ K`` with no input (the model of a filter that assumes
            u = K x). False: ``Φ`` with the thrust as input.
        """
        Phi, Gamma = self.truth_matrices(delta, discretization)
        sysm = hill_system(self.omega0 * (1.0 + as_real("delta", delta)), self.mass, self.dt, self.B,
                           discretization=discretization)
        if closed_loop:
            return dataclasses.replace(sysm, Phi=Phi + Gamma @ self.K, Gamma=np.zeros((6, 0)), input_labels=(),
                                       input_units=(), name=sysm.name + " (closed loop u = Kx)")
        return dataclasses.replace(sysm, Phi=Phi, Gamma=Gamma)

    @property
    def measurement(self) -> LinearMeasurement:
        """The indirect position measurement (8), ``y = [I 0] x + D v``."""
        return position_measurement(self.D)

    def kalman_model(self) -> dict:
        """The generic filters' model (the benchmark's ``model_*`` filters): the truth's Hill model at δ = 0 told the
        applied thrust, the position measurement (8), P₀ = diag(DEFAULT_P0_STD)² (the EKF's); for the adaptive
        filter, which estimates the input (the thrust) instead of being told it, a thrust rate of at most 100 N/s
        (the truth's largest is 93 N/s) and an initial σ of 3000 N (the order of Fig 6's largest thrust): the
        documented scales of :mod:`hinfnav.papers.attitude2018.chaser`."""
        return {"system": self.system(), "measurement": self.measurement, "P0": np.diag(DEFAULT_P0_STD**2),
                "uses_input": True, "input_rate_max": 100.0, "input_std0": 3000.0}

    def controller(self, maneuver: bool = True, source: str = "truth") -> LinearFeedback | None:
        """The orbit-maneuver law u = K x of (3) (``source="estimate"``: u = K x̂), or None without maneuver."""
        if not isinstance(maneuver, (bool, np.bool_)):
            raise InputError(f"maneuver must be True or False; got {maneuver!r}")
        return LinearFeedback(self.K, source=source, name="orbit maneuver u = Kx (3)") if maneuver else None

    def lti_filter(self, A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike, *, name: str, uses_input: bool = True,
                   design_dt: float | None = None) -> LTIFilter:
        """The filter (12) designed on this scenario's closed loop, as an estimator.

        ``uses_input=True`` tells it the applied thrust through
        ``C_F⁻¹ T G₀ (u − K ẑ)``; False runs (12) verbatim, assuming u = K x.
        ``design_dt`` (s) is checked against ``dt``: a discrete filter only holds
        at the sampling time it was designed for.
        """
        if design_dt is not None and abs(float(design_dt) - self.dt) > 1e-12 * self.dt:
            raise InputError(
                f"filter {name!r} was designed for sampling time T = {float(design_dt):g} s but the scenario has "
                f"dt = {self.dt:g} s: a discrete filter only holds at its own T (design one at this T, e.g. "
                "filter 'designed')"
            )
        system, meas = self.system(), self.measurement
        if uses_input:
            return LTIFilter(A_F, B_F, C_F, system, meas, name=name, input_matrix=self.input_matrix_design(), K=self.K)
        return LTIFilter(A_F, B_F, C_F, system, meas, name=name)

    def estimator_from_design(self, design: DesignResult, *, verbatim: bool = False,
                              name: str = "design") -> LTIFilter:
        """An estimator from a :class:`~hinfnav.design.DesignResult` designed for this scenario.

        Parameters
        ----------
        design : DesignResult
        verbatim : bool
            Run (12) exactly as designed, assuming u = K x (what Table 1 does
            with maneuver); default: told the applied thrust.
        name : str
        """
        if not isinstance(design, DesignResult):
            raise InputError(f"design must be a hinfnav DesignResult; got {type(design).__name__}")
        if design.domain != "discrete":
            raise InputError(f"design must be a discrete-time filter (this one is {design.domain} time): design it "
                             "for the scenario's sampled model")
        dt = None if design.dt is True else design.dt
        return self.lti_filter(design.A_F, design.B_F, design.C_F, name=name, uses_input=not verbatim, design_dt=dt)

    def truth_model(self, maneuver: bool = True, delta: float = 0.0, discretization: str = "exact") -> TruthModel:
        """What the simulation layer needs: system, measurement, x₀, length and the law on the true state.

        Parameters
        ----------
        maneuver : bool
            True: u = K x (3). False: u = 0 (free Hill motion).
        delta : float
            True orbital-rate error δ of (4), > −1; not bound by δ̄.
        discretization : {"exact", "euler"}

        Returns
        -------
        hinfnav.sim.TruthModel
        """
        if not isinstance(maneuver, (bool, np.bool_)):
            raise InputError(f"maneuver must be True or False; got {maneuver!r}")
        delta = as_real("delta", delta)
        as_choice("discretization", discretization, DISCRETIZATIONS)
        settings = {"maneuver": bool(maneuver), "delta": delta, "discretization": discretization}
        system = self.system(delta, discretization)
        if maneuver:
            rho = spectral_radius(system.transition_matrix(self.K))
            if not rho < 1.0:
                raise InputError(
                    f"the closed loop u = K x is unstable at delta = {delta:g} (spectral radius {rho:.6g} >= 1 with "
                    f"this K and T = {self.dt:g} s): the true state would diverge. The paper's K keeps the loop "
                    "stable for delta up to about 376; check delta and K"
                )
        return TruthModel(system, self.measurement, self.x0, self.n_steps, self.controller(bool(maneuver)), settings)


def paper_scenario(**changes):
    """The paper's scenario, optionally with some settings changed."""
    return Scenario(**changes)
