"""Yang et al. (2020)'s estimators, built from a :class:`~hinfnav.papers.yang2020.Scenario` and registered by name.

=========================  ===================================================================
name                       estimator
=========================  ===================================================================
``yang2020_alg1``          Algorithm 1 on the 27-state extended system, measured by Y (9)
``yang2020_alg2``          Algorithm 2 on the three drag-free axes, truncated-normal update (L1)
``yang2020_alg2_ideal``    the same, never treating a reading as clipped (L2, the ideal case)
``yang2020_alg2_skip``     the same, skipping the update on a clipped reading (L3)
``yang2020_fused``         Algorithm 3: Algorithms 1 and 2 (L1) fused, Y and accelerometers (12)
=========================  ===================================================================

Each ``fits`` only a yang2020 :class:`Scenario`; the linear truth each runs on
in the contract suite is ``scenario.truth_model(SUBSYSTEM_OF[name])``.
"""

import numpy as np

from ...core.exceptions import InputError
from ...estimators.extended_state import ExtendedStateKalmanFilter
from ...estimators.saturated_state import FusedExtendedStateFilter, SaturatedExtendedStateFilter
from ...estimators.registry import Requires, register_estimator
from ...systems.linear import LinearSystem
from ...systems.measurements import LinearMeasurement
from .constants import ACCELEROMETER_RANGE, P0_DIAGONAL
from .model import DRAGFREE_INDICES, dragfree_state_spec, extended_state_spec
from .scenario import ACC_LABELS, ACC_UNITS, Y_LABELS, Y_UNITS, LinearTruth, Scenario, check_scenario

__all__ = ["build_alg1", "build_alg2", "KalmanPredictionFilter", "build_fused", "ESTIMATOR_NAMES", "SUBSYSTEM_OF",
           "L_MODES"]

#: The paper's names of the three variants of Algorithm 2 in Fig 5.
L_MODES = {"L1": "truncated", "L2": "ideal", "L3": "skip"}


def build_alg1(scenario, *, steady_tol=None, name="yang2020_alg1"):
    """Algorithm 1 on the extended system (8): Q₁ from q (Assumption 4, l = 9), Q₂ = B_d S B_dᵀ, θ = θ*."""
    sc = check_scenario(scenario)
    m = sc.model
    system = LinearSystem(m.A_d, m.B_d, np.zeros((27, 1)), sc.dt, extended_state_spec(),
                          input_labels=("T_x", "T_y", "T_z", "F_x", "F_y", "F_z", "Ttm_x", "Ttm_y", "Ttm_z"),
                          input_units=("N m",) * 3 + ("N",) * 3 + ("N m",) * 3, name="drag-free extended (8)")
    meas = LinearMeasurement(m.C_d, np.diag(sc.sensor_std), labels=Y_LABELS, units=Y_UNITS)
    return ExtendedStateKalmanFilter(system, meas, P0=sc.P0, B_e=m.B_e, q=sc.q, S=np.diag(sc.input_std**2),
                                     steady_tol=steady_tol, name=name)


class KalmanPredictionFilter(SaturatedExtendedStateFilter):
    """Algorithm 2 with the plain Kalman prior ``A P Aᵀ + Q₁ + Q₂`` (no θ): not the paper's, a reference.

    Used to ask whether L1's bias is θ's doing (:func:`hinfnav.papers.yang2020.studies.theta_readings_study`).
    """

    def prior_covariance(self, P):
        """``A P Aᵀ + Q₁ + Q₂`` per axis."""
        return self.A @ P @ np.swapaxes(self.A, -1, -2) + self.Q1 + self.Q2


def build_alg2(scenario, *, mode="truncated", steady_tol=None, name=None, theta=None, prediction="theta"):
    """Algorithm 2 on the three drag-free axes (12)-(13), accelerometer range ±6e-6 m/s².

    ``theta`` (per axis or one number; default θ* = √(4 q / tr P₀)) and ``prediction``: ``"theta"`` (the
    paper's θ-inflated prior) or ``"kalman"`` (:class:`KalmanPredictionFilter`, θ unused).
    """
    sc = check_scenario(scenario)
    m = sc.model
    lo, up = ACCELEROMETER_RANGE
    cls = {"theta": SaturatedExtendedStateFilter, "kalman": KalmanPredictionFilter}.get(prediction)
    if cls is None:
        raise InputError(f"prediction must be 'theta' or 'kalman'; got {prediction!r}")
    return cls(
        m.axis_A_d, m.axis_B_d, m.axis_C, m.axis_D, R=sc.accel_std**2, S=sc.input_std[3:6] ** 2, q=sc.q[3:6],
        P0=P0_DIAGONAL * np.eye(3), lower=lo, upper=up, dt=sc.dt, mode=mode, state=dragfree_state_spec(),
        measurement_labels=ACC_LABELS, measurement_units=ACC_UNITS, steady_tol=steady_tol,
        theta=theta, name=name or ("yang2020_alg2" if mode == "truncated" else f"yang2020_alg2_{mode}"))


def build_fused(scenario, *, covariance=None, steady_tol=None, name="yang2020_fused"):
    """Algorithm 3 (35)-(43) with Algorithm 2 in L1 mode; ``covariance`` defaults to the scenario's reading."""
    sc = check_scenario(scenario)
    return FusedExtendedStateFilter(build_alg1(sc, steady_tol=steady_tol), build_alg2(sc, steady_tol=steady_tol),
                                    indices=DRAGFREE_INDICES, input_indices=[3, 4, 5],
                                    covariance=covariance or sc.fused_covariance, steady_tol=steady_tol, name=name)


def _fits_for(name):
    """Fits the paper's Scenario, and its linear truth of the subsystem the estimator is built for."""

    def fits(scenario):
        if isinstance(scenario, LinearTruth):
            return scenario.subsystem == SUBSYSTEM_OF[name]
        return isinstance(scenario, Scenario)

    return fits


#: Registered names → the contract truth (``Scenario.truth_model`` subsystem) each runs on.
SUBSYSTEM_OF = {
    "yang2020_alg1": "position",
    "yang2020_alg2": "dragfree",
    "yang2020_alg2_ideal": "dragfree",
    "yang2020_alg2_skip": "dragfree",
    "yang2020_fused": "full",
}
ESTIMATOR_NAMES = tuple(SUBSYSTEM_OF)

_BUILDERS = {
    "yang2020_alg1": (build_alg1,
                      "Yang et al. 2020, Algorithm 1: extended-state Kalman filter, theta-inflated prediction"),
    "yang2020_alg2": (lambda sc, **kw: build_alg2(sc, mode="truncated", **kw),
                      "Yang et al. 2020, Algorithm 2 (L1): saturated accelerometer, truncated-normal update"),
    "yang2020_alg2_ideal": (lambda sc, **kw: build_alg2(sc, mode="ideal", **kw),
                            "Yang et al. 2020, Algorithm 2 without saturation (L2, ideal)"),
    "yang2020_alg2_skip": (lambda sc, **kw: build_alg2(sc, mode="skip", **kw),
                           "Yang et al. 2020, Algorithm 2 skipping clipped readings (L3)"),
    "yang2020_fused": (build_fused, "Yang et al. 2020, Algorithm 3: fusion of Algorithms 1 and 2"),
}
for _name, (_builder, _text) in _BUILDERS.items():
    register_estimator(_name, _builder, fits=_fits_for(_name), description=_text,
                       requires=Requires(model="yang2020", linear=True, measurement=({"position": "displacement_attitude", "dragfree": "saturated_accelerometer", "full": "displacement_attitude+saturated_accelerometer"}[SUBSYSTEM_OF[_name]],)))
