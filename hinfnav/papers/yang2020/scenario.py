"""The paper's simulation (Section 3) as a scenario: every ambiguity a named reading.

:class:`Scenario` holds the length of the closed loop and the readings of
:data:`~hinfnav.papers.yang2020.constants.READINGS` (default first), and
derives from Table 2 what the filters, the controllers and the loop need:
the discrete model, ω_d, the increment bounds q, the per-step noise
standard deviations, the attitude command. Its :meth:`Scenario.truth_model`
gives the linear truths on which the registered estimators are checked by
the contract suite (the closed loop itself is :func:`~hinfnav.papers.yang2020.loop.run_closed_loop`).
"""

from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from ...control.adrc import DragFreeADRC, NonlinearPID
from ...control.feedback import LinearFeedback
from ...core.exceptions import InputError
from ...core.validation import as_choice, as_int_at_least, as_positive, as_real
from ...sim.scenario import Scenario as BaseScenario
from ...sim.truth import TruthModel
from ...systems.linear import LinearSystem
from ...systems.measurements import LinearMeasurement, Saturated
from .constants import (
    ACCELEROMETER_NOISE_DENSITY,
    ACCELEROMETER_RANGE,
    ACTUATOR_BOUND,
    D_ROT,
    D_TRANS,
    FAL_ALPHA,
    FAL_DELTA,
    H,
    I_SC,
    I_TM,
    INPUT_NOISE_DENSITY,
    K_ROT,
    K_TRANS,
    M_SC,
    M_TM,
    NLPID_GAINS,
    P0_DIAGONAL,
    PID_GAINS,
    READINGS,
    SENSOR_NOISE_DENSITY,
    STEP_COMMAND,
    STEP_OFF,
    STEP_ON,
)
from .model import (
    DRAGFREE_INDICES,
    dragfree_state_spec,
    drag_free_model,
    extended_state_spec,
    increment_bounds,
    noise_std,
    omega_d,
)

__all__ = ["Scenario", "LinearTruth", "CONTROLLERS", "SUBSYSTEMS", "Y_LABELS", "Y_UNITS", "ACC_LABELS", "ACC_UNITS",
           "check_scenario"]

#: Closed-loop controllers: the NLPID ADRC of Section 3, the ADRC of Fig 9 (tuned PID + compensation), the PID,
#: and the ADRC with the drag-free loop open (F_Csc = 0: the accelerometers saturate, the setting of Fig 5).
CONTROLLERS = ("adrc", "adrc_pid", "pid", "dragfree_off")
#: Linear truths for the contract suite: the whole extended system measured by Y and the accelerometers,
#: by Y only (Algorithm 1), the three drag-free axes measured by the accelerometers (Algorithm 2).
SUBSYSTEMS = ("full", "position", "dragfree")
#: Labels and units of the measurements Y (5) and of the accelerometers (11).
Y_LABELS = ("phi_pitch", "phi_yaw", "phi_roll", "r_x", "r_y", "r_z", "phirel_pitch", "phirel_yaw", "phirel_roll")
Y_UNITS = ("rad",) * 3 + ("m",) * 3 + ("rad",) * 3
ACC_LABELS = ("a_x", "a_y", "a_z")
ACC_UNITS = ("m/s^2",) * 3


@lru_cache(maxsize=4)
def _model(k_rot_sign):
    return drag_free_model(h=H, k_rot_sign=k_rot_sign)


@dataclass(frozen=True)
class Scenario(BaseScenario):
    """Yang et al. (2020), Section 3, with its readings.

    Attributes
    ----------
    n_steps : int
        Closed-loop length in steps of h (3×10⁵: both attitude steps and the 1–30 mHz band).
    omega_d, noise, k_rot_sign, fused_covariance, integral, residual, timing : str
        Readings (see ``READINGS`` and ``READING_REASONS`` in :mod:`.constants`).
    steady_tol : float or None
        Freeze the filter gains once the covariance recursions change by less
        than this (relative) per step; None runs the full recursion every step.
    step_on, step_off : int
        Steps at which the attitude command switches on and back off.
    settle_s : float
        Start of the window of the residual-acceleration spectrum, s.
    """

    n_steps: int = 300_000
    omega_d: str = "hz"
    noise: str = "one_sided"
    k_rot_sign: str = "printed"
    fused_covariance: str = "symmetric"
    integral: str = "off"
    residual: str = "test_mass"
    timing: str = "posterior"
    steady_tol: float = 1e-6
    step_on: int = STEP_ON
    step_off: int = STEP_OFF
    settle_s: float = 2000.0

    def __post_init__(self):
        object.__setattr__(self, "n_steps", as_int_at_least("n_steps", self.n_steps, 1))
        for key, choices in READINGS.items():
            if key != "phase_time":
                as_choice(f"{key} reading", getattr(self, key), choices)
        if self.steady_tol is not None:
            object.__setattr__(self, "steady_tol", as_positive("steady_tol", self.steady_tol))
        object.__setattr__(self, "step_on", as_int_at_least("step_on", self.step_on, 0))
        object.__setattr__(self, "step_off", as_int_at_least("step_off", self.step_off, self.step_on))
        object.__setattr__(self, "settle_s", as_real("settle_s", self.settle_s))

    # -- derived quantities -------------------------------------------------------------

    @property
    def dt(self):
        """h, s."""
        return H

    @property
    def duration_s(self):
        return self.n_steps * H

    @property
    def readings(self):
        """The readings in force, by name."""
        return {key: getattr(self, key) for key in READINGS if key != "phase_time"} | {"phase_time": "with_t"}

    @cached_property
    def model(self):
        """The :class:`~hinfnav.papers.yang2020.model.DragFreeModel` (read-only, shared by equal scenarios)."""
        return _model(self.k_rot_sign)

    @property
    def w_d(self):
        """ω_d, rad/s."""
        return omega_d(self.omega_d)

    @property
    def q(self):
        """Increment bounds of the 9 disturbances, (N·m)² and N²."""
        return increment_bounds(self.w_d, H)

    @property
    def sensor_std(self):
        """Per-step std of the 9 displacement/attitude readings, m and rad."""
        return noise_std(np.full(9, SENSOR_NOISE_DENSITY), H, self.noise)

    @property
    def input_std(self):
        """Per-step std of the input noise w = [w_TCsc, w_FCsc, w_TCtm], N·m and N."""
        return noise_std(np.repeat(INPUT_NOISE_DENSITY, 3), H, self.noise)

    @property
    def accel_std(self):
        """Per-step std of the accelerometer noise d, m/s²."""
        return noise_std(np.full(3, ACCELEROMETER_NOISE_DENSITY), H, self.noise)

    @property
    def xhat0(self):
        """Initial estimates of Algorithms 1-3: zero (Section 3)."""
        return np.zeros(27)

    @property
    def P0(self):
        """Initial error covariance: 0.01 on the diagonal (Section 3)."""
        return P0_DIAGONAL * np.eye(27)

    @property
    def x0(self):
        """Initial true plant state (not printed): at rest, zero displacement and attitudes."""
        return np.zeros(18)

    def attitude_reference(self, n_samples=None):
        """Commanded φ_sc at each step, rad: (n_samples, 3); the step of Section 3 between step_on and step_off."""
        n1 = self.n_steps + 1 if n_samples is None else int(n_samples)
        ref = np.zeros((n1, 3))
        ref[self.step_on:self.step_off] = STEP_COMMAND
        return ref

    # -- controllers ------------------------------------------------------------------------

    def controller(self, kind="adrc"):
        """The closed-loop law: ``adrc`` (NLPID + compensation, Section 3), ``adrc_pid`` (Fig 9's ADRC:
        the tuned PID + compensation), ``pid`` (Fig 9's PID, no compensation of the drag-free loop),
        ``dragfree_off`` (the ADRC on the attitudes, no drag-free force: an estimation experiment)."""
        as_choice("controller", kind, CONTROLLERS)
        nl = dict(alpha=FAL_ALPHA, delta=FAL_DELTA, integral=self.integral, dt=H)
        att = NonlinearPID(*NLPID_GAINS["attitude"], **nl)
        rel = NonlinearPID(*NLPID_GAINS["relative_attitude"], **nl)
        if kind == "adrc":
            df = NonlinearPID(*NLPID_GAINS["dragfree"], **nl)
        elif kind == "dragfree_off":
            df = NonlinearPID(0.0, 0.0, 0.0, **nl)
        else:
            df = NonlinearPID(*PID_GAINS, integral="printed", dt=H, linear=True)  # K_I = 0: the reading is moot
        sign = self.model.k_rot_sign
        return DragFreeADRC(I_sc=I_SC, I_tm=I_TM, m_sc=M_SC, m_tm=M_TM, K_trans=K_TRANS, D_trans=D_TRANS,
                            K_rot=sign * K_ROT, D_rot=sign * D_ROT, attitude=att, dragfree=df, relative=rel,
                            bound=ACTUATOR_BOUND, dragfree_compensation=kind in ("adrc", "adrc_pid"))

    def linear_feedback_gain(self):
        """The ADRC in fal's linear zone without integrals and with exact compensation, as a gain on X (9×27).

        ``u = K X`` reproduces :meth:`controller` (``adrc``, integral off) for
        errors below δ = 0.01 when the estimate is the truth: the stable loop
        of the contract truths.
        """
        slope = FAL_DELTA ** (FAL_ALPHA - 1.0)
        (ap, _, ad), (fp, _, fd), (rp, _, rd) = (NLPID_GAINS[k] for k in ("attitude", "dragfree", "relative_attitude"))
        sign = self.model.k_rot_sign
        K = np.zeros((9, 27))
        I3 = np.eye(3)
        K[0:3, 0:3], K[0:3, 3:6], K[0:3, 6:9] = -slope * ap * I_SC, -slope * ad * I_SC, -I3
        K[3:6, 9:12] = slope * fp * I3 - (M_SC / M_TM) * K_TRANS
        K[3:6, 12:15] = slope * fd * I3 - (M_SC / M_TM) * D_TRANS
        K[3:6, 15:18] = -I3
        K[6:9, 18:21] = -slope * rp * I_TM - sign * K_ROT
        K[6:9, 21:24] = -slope * rd * I_TM - sign * D_ROT
        K[6:9, 24:27] = -I3
        return K

    # -- linear truths for the contract suite ------------------------------------------------

    def truth_model(self, subsystem="full", *, disturbance=-3e-3, n_steps=None, feedback=True):
        """A linear truth on which the registered estimators run (contract suite).

        Parameters
        ----------
        subsystem : {"full", "position", "dragfree"}
            ``full``: the 27-state extended system (8) measured by Y and the
            three accelerometers (12 channels; Algorithm 3); ``position``: by Y
            only (Algorithm 1); ``dragfree``: the three axes ``[r, ṙ, f]``
            measured by the accelerometers (Algorithm 2).
        disturbance : float
            Initial value of every disturbance, N or N·m (−3 mN keeps the
            accelerometers inside their range; −12.8 mN saturates them).
        n_steps : int, optional
            Default: the scenario's.
        feedback : bool
            Close the loop with :meth:`linear_feedback_gain` on the true state
            (a stable problem); False: zero input.

        Notes
        -----
        The increments G_k are white with variance q (Assumption 4 at its
        bound); the accelerometer reading omits the input part D u (see
        :mod:`hinfnav.estimators.extended_state`).
        """
        as_choice("subsystem", subsystem, SUBSYSTEMS)
        d0 = as_real("disturbance", disturbance)
        n_steps = self.n_steps if n_steps is None else as_int_at_least("n_steps", n_steps, 1)
        m = self.model
        Bn = np.hstack([m.B_d * self.input_std, m.B_e * np.sqrt(self.q)])
        x0 = np.zeros(27)
        x0[[6, 7, 8, 15, 16, 17]] = d0
        x0[[0, 1, 2, 18, 19, 20]] = 1e-4
        x0[[9, 10, 11]] = 1e-6
        settings = {"subsystem": subsystem, "disturbance": d0, "feedback": bool(feedback)}
        K = self.linear_feedback_gain()
        lo, up = ACCELEROMETER_RANGE
        if subsystem == "dragfree":
            idx = DRAGFREE_INDICES
            system = LinearSystem(m.A_d[np.ix_(idx, idx)], m.B_d[idx][:, 3:6], Bn[idx][:, [3, 4, 5, 12, 13, 14]], H,
                                  dragfree_state_spec(), input_labels=("F_x", "F_y", "F_z"),
                                  input_units=("N",) * 3, name="drag-free axes")
            C = np.zeros((3, 9))
            for a in range(3):
                C[a, [a, 3 + a, 6 + a]] = m.axis_C[a]
            meas = Saturated(LinearMeasurement(C, np.diag(self._accel_eff_std()), labels=ACC_LABELS, units=ACC_UNITS),
                             lo, up)
            ctrl = LinearFeedback(K[3:6][:, idx], source="truth", name="linear ADRC (drag-free)") if feedback else None
            return TruthModel(system, meas, x0[idx], n_steps, ctrl, settings)
        system = LinearSystem(m.A_d, m.B_d, Bn, H, extended_state_spec(),
                              input_labels=("T_x", "T_y", "T_z", "F_x", "F_y", "F_z", "Ttm_x", "Ttm_y", "Ttm_z"),
                              input_units=("N m",) * 3 + ("N",) * 3 + ("N m",) * 3, name="drag-free extended (8)")
        ctrl = LinearFeedback(K, source="truth", name="linear ADRC") if feedback else None
        if subsystem == "position":
            meas = LinearMeasurement(m.C_d, np.diag(self.sensor_std), labels=Y_LABELS, units=Y_UNITS)
            return TruthModel(system, meas, x0, n_steps, ctrl, settings)
        C = np.vstack([m.C_d, self._accel_rows()])
        D = np.diag(np.r_[self.sensor_std, self._accel_eff_std()])
        meas = Saturated(LinearMeasurement(C, D, labels=Y_LABELS + ACC_LABELS, units=Y_UNITS + ACC_UNITS),
                         np.r_[np.full(9, -np.inf), np.full(3, lo)],
                         np.r_[np.full(9, np.inf), np.full(3, up)])
        return TruthModel(system, meas, x0, n_steps, ctrl, settings)

    def linear_truth(self, subsystem):
        """This scenario's linear truth ``subsystem`` as a scenario object for :func:`hinfnav.simulate`."""
        return LinearTruth(self, as_choice("subsystem", subsystem, SUBSYSTEMS))

    def _accel_rows(self):
        C = np.zeros((3, 27))
        for a in range(3):
            C[a, DRAGFREE_INDICES[[a, 3 + a, 6 + a]]] = self.model.axis_C[a]
        return C

    def _accel_eff_std(self):
        """√(R + D² S): the accelerometer noise plus the force noise seen through D = 1/m_sc."""
        return np.sqrt(self.accel_std**2 + (self.input_std[3:6] / M_SC) ** 2)


@dataclass(frozen=True)
class LinearTruth:
    """One linear truth of :meth:`Scenario.truth_model` as a scenario for the generic simulation.

    ``truth_model(**conditions)`` is the parent's with the subsystem fixed and
    ``xhat0`` is zero of that subsystem's size, so ``hinfnav.simulate(
    scenario.linear_truth("dragfree"), "yang2020_alg2")`` runs Algorithm 2 on it.
    """

    parent: Scenario
    subsystem: str

    @property
    def xhat0(self):
        return np.zeros(9 if self.subsystem == "dragfree" else 27)

    def truth_model(self, **conditions):
        return self.parent.truth_model(self.subsystem, **conditions)


def check_scenario(scenario):
    """The yang2020 :class:`Scenario` behind ``scenario`` (itself, or a :class:`LinearTruth`'s parent)."""
    if isinstance(scenario, LinearTruth):
        return scenario.parent
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav yang2020 Scenario; got {type(scenario).__name__}")
    return scenario
