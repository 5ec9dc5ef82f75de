"""Paper 002 (2018): AEKF, AAEKF and ASTEKF for gyroless attitude from star sensors, reproduced.

"Research on satellite attitude estimation based on star sensors", Navigation
Positioning and Timing 2018 no. 1, pp. 42–47. Its constants (:mod:`.constants`),
scenario (:mod:`.scenario`), registered filters (:mod:`.filters`), studies
(:mod:`.studies`), claims (:mod:`.claims`), figures (:mod:`.figures`), the
transfer of its ideas to Sun 2011's chaser (:mod:`.chaser`) and ``reproduce``.
"""

from .campaign import CampaignScenario
from .chaser import (
    ChaserStudy,
    build_augmented_thrust,
    chaser_study,
    format_chaser_table,
    format_sweeps,
    plot_chaser,
    plot_thrust_estimates,
)
from .claims import CLAIMS, format_claims, measure_claims
from .constants import (
    CITATION,
    PAPER_OMEGA_E_DEG_S,
    Q_SWEEP,
    orbit_rate,
    orbital_period,
    torque_periods,
)
from .filters import (
    ATTITUDE_FILTERS,
    CHASER_FILTERS,
    build_aaekf,
    build_aekf,
    build_astekf,
    build_attitude_filter,
)
from .reproduce import reproduce
from .scenario import AttitudeHold, Scenario, default_epsilon
from .studies import (
    AttitudeStudy,
    FilterStats,
    attitude_study,
    run_batched,
    run_filter,
    sweep_study,
)

__all__ = [
    "CampaignScenario",
    "ATTITUDE_FILTERS",
    "CHASER_FILTERS",
    "CITATION",
    "CLAIMS",
    "PAPER_OMEGA_E_DEG_S",
    "Q_SWEEP",
    "AttitudeHold",
    "AttitudeStudy",
    "ChaserStudy",
    "FilterStats",
    "Scenario",
    "attitude_study",
    "build_aaekf",
    "build_aekf",
    "build_astekf",
    "build_attitude_filter",
    "build_augmented_thrust",
    "chaser_study",
    "default_epsilon",
    "format_chaser_table",
    "format_claims",
    "format_sweeps",
    "measure_claims",
    "orbit_rate",
    "orbital_period",
    "plot_chaser",
    "plot_thrust_estimates",
    "reproduce",
    "run_batched",
    "run_filter",
    "sweep_study",
    "torque_periods",
]
