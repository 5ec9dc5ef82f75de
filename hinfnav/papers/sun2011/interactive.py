"""The computation behind the interactive chapter (notebook 91): design at δ̄, simulate, plot.

One call of :func:`interactive_design_view` does what a reader's move of a
control asks for: the robust filter of Corollary 1 designed at δ̄ (certified
γ), one run of the chosen filter on the paper's scenario (Section 4, with
maneuver) at the uncertainty's bound δ = δ̄ and the chosen noise model, and
the error figure in the layout of Figs 2–7. The notebook's widgets only call
it; the widgets themselves are built in the notebook, so the package does not
depend on ipywidgets.
"""

import dataclasses
import functools

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_choice, as_int_at_least, as_nonnegative
from ...metrics.errors import rms_per_run
from ...noise import NOISE_NAMES
from ...sim.montecarlo import simulate
from .designs import design_for_scenario
from .figures import figure_errors
from .filters import lti_from_matrices, make_estimator
from .scenario import Scenario
from .studies import pos_vel

__all__ = ["INTERACTIVE_FILTERS", "InteractiveView", "interactive_design_view"]

#: Filters a reader can pick: the one designed here at δ̄, the paper's printed one, the paper's EKF.
INTERACTIVE_FILTERS = ("designed", "published", "ekf")


@dataclasses.dataclass(frozen=True)
class InteractiveView:
    """What the interactive chapter shows for one setting of its controls.

    Attributes
    ----------
    delta_bar : float
        Uncertainty bound δ̄ of the design and δ of the run (dimensionless).
    gamma : float
        Certified H∞ bound γ of the filter designed at δ̄ (Corollary 1,
        certified on the δ grid of :func:`.designs.delta_grid`), dimensionless.
    filter_name, noise : str
    seed : int
    rms_position, rms_velocity : ndarray, shape (3,)
        RMS error per axis after ``t_from`` s, m and m/s.
    t_from : float
        Start of the RMS window, s.
    figure : matplotlib.figure.Figure
        Per-axis position and velocity errors against time.
    """

    delta_bar: float
    gamma: float
    filter_name: str
    noise: str
    seed: int
    rms_position: np.ndarray
    rms_velocity: np.ndarray
    t_from: float
    figure: object

    @property
    def gamma_text(self):
        """The line the chapter shows, e.g. ``certified γ = 0.3586 (δ̄ = 0.05)``."""
        return f"certified γ = {self.gamma:.4f} (δ̄ = {self.delta_bar:g})"

    @property
    def summary_html(self):
        """γ and the RMS errors as a short HTML block (for an ipywidgets ``HTML``)."""
        pos = ", ".join(f"{v:.3g}" for v in self.rms_position)
        vel = ", ".join(f"{v:.3g}" for v in self.rms_velocity)
        return (f"<b class='hinfnav-gamma'>{self.gamma_text}</b><br>"
                f"{self.filter_name} filter, {self.noise} noise, seed {self.seed}: RMS error after {self.t_from:g} s "
                f"— position (x, y, z) {pos} m; velocity {vel} m/s")


@functools.lru_cache(maxsize=32)
def _design(delta_bar):
    """Corollary 1 at δ̄ on the paper's scenario (about 1 s; cached, since a slider revisits values)."""
    return design_for_scenario(Scenario(), delta_bar)


def interactive_design_view(delta_bar=0.05, noise="gaussian", filter_name="designed", seed=0, *, t_from=5.0,
                            size="default"):
    """Design at δ̄, run one simulation and plot its errors (the interactive chapter's callback).

    Parameters
    ----------
    delta_bar : float
        Uncertainty bound δ̄ ≥ 0 (dimensionless): the design's bound and the run's δ.
    noise : str
        Noise model of w and v, one of :data:`hinfnav.noise.NOISE_NAMES`.
    filter_name : str
        One of :data:`INTERACTIVE_FILTERS`.
    seed : int
        Seed of the run (``numpy.random.Generator`` via :func:`hinfnav.sim.simulate`).
    t_from : float
        Start of the RMS window and of the figure's y limits, s.
    size : {"default", "single", "double"}
        Figure size (see :func:`.figures.figure_errors`).

    Returns
    -------
    InteractiveView
    """
    delta_bar = round(as_nonnegative("delta_bar", delta_bar), 12)
    as_choice("noise", noise, NOISE_NAMES)
    as_choice("filter_name", filter_name, INTERACTIVE_FILTERS)
    seed = as_int_at_least("seed", seed, 0)
    t_from = as_nonnegative("t_from", t_from)
    scenario = Scenario()
    if t_from >= scenario.duration_s:
        raise InputError(f"t_from must be below the scenario's duration {scenario.duration_s:g} s; got {t_from:g}")
    design = _design(delta_bar)
    if filter_name == "designed":
        estimator = lti_from_matrices(scenario, design.A_F, design.B_F, design.C_F, name="designed",
                                      design_dt=design.dt)
    else:
        estimator = make_estimator(scenario, filter_name)
    result = simulate(scenario, estimator, maneuver=True, delta=delta_bar, noise=noise, runs=1, seed=seed)
    rms_pos, rms_vel = pos_vel(rms_per_run(result.error, result.t, (t_from, result.t[-1]))[0], result.state)
    title = (f"{filter_name} filter, δ = δ̄ = {delta_bar:g}, {noise} noise, with maneuver (seed {seed}): "
             "position (m) and velocity (m/s) errors")
    fig = figure_errors(result, title, t_zoom_from=t_from, size=size)
    return InteractiveView(delta_bar=float(delta_bar), gamma=float(design.gamma), filter_name=filter_name, noise=noise,
                           seed=seed, rms_position=np.asarray(rms_pos), rms_velocity=np.asarray(rms_vel),
                           t_from=float(t_from), figure=fig)
