"""Systems layer: what is estimated.

State specifications (labels, units, groups, error definition), discrete
linear dynamics, measurement models, the Hill relative motion of a chaser and
the norm-bounded uncertain system of Sun et al. (2011).
"""

from .hill import (
    delta_A1,
    hill_matrices,
    hill_system,
    measurement_matrix,
    position_measurement,
    uncertainty_F,
    uncertainty_structure,
)
from .dynamics import ConstantTurn, ContinuousDynamics, DiscreteDynamics, DynamicsModel, constant_turn_state_spec
from .linear import LinearSystem
from .measurements import (
    ConvertedPosition,
    LinearMeasurement,
    MeasurementModel,
    RangeAzimuthElevation,
    Saturated,
    as_measurement_model,
    position_from_range_angles,
    range_angles,
    range_angles_jacobian,
    wrap_angle,
)
from .continuous import ContinuousPolytope
from .files import read_system_file
from .planar import ConvertedRangeBearing, RangeBearing
from .polytopic import PolytopicSystem, simplex_grid, two_mass_spring
from .parametric import Coverage, polytope_coverage, polytope_from_parameters
from .flexible import flexible_attitude, flexible_attitude_closed_loop, flexible_attitude_matrices
from .state import StateSpec, chaser_state_spec
from .uncertain import UncertainSystem
from .timed import TimedReadings, TimedSystem, merge_readings, read_timed_csv

__all__ = [
    "ConvertedPosition",
    "ContinuousPolytope",
    "StateSpec",
    "chaser_state_spec",
    "LinearSystem",
    "DynamicsModel",
    "DiscreteDynamics",
    "ContinuousDynamics",
    "ConstantTurn",
    "constant_turn_state_spec",
    "MeasurementModel",
    "LinearMeasurement",
    "RangeAzimuthElevation",
    "Saturated",
    "RangeBearing",
    "ConvertedRangeBearing",
    "as_measurement_model",
    "range_angles",
    "range_angles_jacobian",
    "position_from_range_angles",
    "wrap_angle",
    "hill_matrices",
    "hill_system",
    "delta_A1",
    "uncertainty_structure",
    "uncertainty_F",
    "measurement_matrix",
    "position_measurement",
    "UncertainSystem",
    "PolytopicSystem",
    "simplex_grid",
    "two_mass_spring",
    "polytope_from_parameters",
    "polytope_coverage",
    "Coverage",
    "flexible_attitude",
    "flexible_attitude_closed_loop",
    "flexible_attitude_matrices",
    "read_system_file",
    "TimedSystem",
    "TimedReadings",
    "merge_readings",
    "read_timed_csv",
]
