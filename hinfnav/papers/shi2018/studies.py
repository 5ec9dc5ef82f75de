"""The three cases of Shi & Wang (2018) §3, run as Monte Carlo sets, and their statistics.

=============  ===============================================================
case           truth
=============  ===============================================================
``gaussian``   Gaussian sensor errors of the (calibrated) Table 1 (§3.1)
``mixture``    sensor errors from the mixture (23), ε = 0.6, σ₂ = 2σ₁, the
               narrow component at Table 1's σ (§3.2); the filters are told σ₁
``maneuver``   Gaussian sensor errors and the target's 0.1 m/s maneuver at
               500 s, away from the chaser along x (§3.3), which no filter models
=============  ===============================================================

Both filters run on the same truths (paired comparison). The accuracy
statistic of a run is the RMS of its error over the window, taken over the
three axes (``sqrt((rms_x² + rms_y² + rms_z²)/3)``, as the workbook reads Sun
2011's Table 1); "single run" is run 0, the Monte Carlo value is the mean over
runs with its 95 % interval (Student t, mean ± t s/√runs), and the HBF − EKF gap is
given as the mean of the paired per-run differences with its 95 % interval.
"""

from dataclasses import dataclass, field

import numpy as np

from ...core.exceptions import InputError
from ...core.validation import as_choice, as_int_at_least
from ...metrics.errors import window_mask
from ...metrics.intervals import mean_interval
from ...sim.engine import Sink, run_monte_carlo
from .constants import MIXTURE_EPS, MIXTURE_RATIO
from .filters import EKF, HBF
from .scenario import ContaminatedNoise, Scenario

__all__ = [
    "CASES",
    "FilterStats",
    "CaseResult",
    "case_conditions",
    "run_case",
    "accuracy",
    "filter_summary",
    "paired_gap",
    "maneuver_reaction",
    "maneuver_windows",
]

#: The paper's cases (§3.1–3.3).
CASES = ("gaussian", "mixture", "maneuver")


def maneuver_windows(scenario):
    """The maneuver case's extra windows, s: ``{"before": …, "reaction": …, "final": …}`` (500 s, 1000 s run:
    200–500, 500–700, 800–1000)."""
    start, end = scenario.rms_window_s
    tm = scenario.maneuver_time_s
    return {"before": (start, tm), "reaction": (tm, min(tm + 200.0, end)), "final": (max(end - 200.0, tm), end)}


@dataclass(frozen=True, eq=False)
class FilterStats:
    """What one filter's Monte Carlo set leaves behind (histories of run 0 and of the run statistics only).

    Attributes
    ----------
    per_run : ndarray, shape (runs, 6)
        Per-axis RMS error over the window, per run.
    windows : dict
        Window label → per-axis RMS per run (runs, 6) over that window.
    jitter : ndarray, shape (runs, 6)
        RMS over the window of the error's step-to-step change ``e(k+1) − e(k)``,
        per run: how rough the error curve is (the paper's "smoother").
    max_abs : ndarray, shape (runs, 6)
        Largest absolute error over the window, per run.
    mean_error : ndarray, shape (n_samples, 6)
        Mean over runs of the error at each sample (the bias after a maneuver).
    rms_error : ndarray, shape (n_samples, 6)
        RMS over runs of the error at each sample.
    single : ndarray, shape (n_samples, 6)
        The error history of run 0.
    down_weighted : float or None
        Fraction of the measurement rows the HBF down-weighted (ψ < 1) over the window.
    """

    per_run: np.ndarray
    windows: dict
    jitter: np.ndarray
    max_abs: np.ndarray
    mean_error: np.ndarray
    rms_error: np.ndarray
    single: np.ndarray
    down_weighted: float = None


@dataclass(frozen=True, eq=False)
class CaseResult:
    """One case of §3: every filter's statistics on the same truths.

    Attributes
    ----------
    case : str
    t : ndarray, shape (n_samples,)
    runs, seed : int
    window_s : (float, float)
    filters : dict
        Filter label → :class:`FilterStats`.
    settings : dict
    """

    case: str
    t: np.ndarray
    runs: int
    seed: int
    window_s: tuple
    filters: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)


def case_conditions(case, *, mixture_eps=MIXTURE_EPS, mixture_ratio=MIXTURE_RATIO):
    """Truth options of a case: ``{"maneuver": bool, "measurement_noise": NoiseModel or "gaussian"}``."""
    case = as_choice("case", case, CASES)
    noise = ContaminatedNoise(eps=mixture_eps, ratio=mixture_ratio) if case == "mixture" else "gaussian"
    return {"maneuver": case == "maneuver", "measurement_noise": noise}


def default_filters(scenario):
    """The paper's pair on a scenario: ``{"hbf": HBF, "ekf": EKF}``, both told the true sensor errors."""
    return {"hbf": HBF(scenario), "ekf": EKF(scenario)}


def _rms_axes(err, mask):
    return np.sqrt(np.mean(err[:, mask] ** 2, axis=1))


class _CaseSink(Sink):
    """The statistics :func:`run_case` keeps of each batch (the engine's sink; memory of one batch)."""

    def __init__(self, names, n1, mask, win_masks):
        self.mask, self.win_masks = mask, win_masks
        self.acc = {name: {"per_run": [], "windows": {k: [] for k in win_masks}, "jitter": [], "max_abs": [],
                           "sum": np.zeros((n1, 6)), "sumsq": np.zeros((n1, 6)), "single": None, "down": [0, 0]}
                    for name in names}

    def add(self, name, start, truth, history):
        err = truth.state.error(truth.x, history.xhat)
        a, mask = self.acc[name], self.mask
        a["per_run"].append(_rms_axes(err, mask))
        for k, m in self.win_masks.items():
            a["windows"][k].append(_rms_axes(err, m))
        d = np.diff(err[:, mask], axis=1)
        a["jitter"].append(np.sqrt(np.mean(d**2, axis=1)))
        a["max_abs"].append(np.max(np.abs(err[:, mask]), axis=1))
        a["sum"] += err.sum(axis=0)
        a["sumsq"] += (err**2).sum(axis=0)
        if start == 0:
            a["single"] = err[0].copy()
        if "weights" in history.diagnostics:
            w = history.diagnostics["weights"][:, mask, :truth.measurement.n_meas]
            a["down"][0] += int(np.count_nonzero(w < 1.0))
            a["down"][1] += w.size

    def result(self):
        return self.acc


def run_case(scenario, case, filters=None, *, runs=100, seed=0, batch_size=100, progress=False,
             mixture_eps=MIXTURE_EPS, mixture_ratio=MIXTURE_RATIO):
    """Run filters on one case's truths through the Monte Carlo engine (:func:`hinfnav.sim.run_monte_carlo`),
    batch by batch (memory of one batch).

    Parameters
    ----------
    scenario : Scenario
    case : {"gaussian", "mixture", "maneuver"}
    filters : dict, optional
        Label → Estimator (default :func:`default_filters`).
    runs : int
        Monte Carlo runs (run r always draws from the r-th child of ``seed``).
    seed : int
    batch_size : int
        Runs simulated together; the numbers do not depend on it.
    progress : bool
    mixture_eps, mixture_ratio : float
        Of the mixture case (23).

    Returns
    -------
    CaseResult
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Shi 2018 Scenario; got {type(scenario).__name__}")
    conditions = case_conditions(case, mixture_eps=mixture_eps, mixture_ratio=mixture_ratio)
    filters = default_filters(scenario) if filters is None else dict(filters)
    if not filters:
        raise InputError("filters must name at least one estimator")
    runs = as_int_at_least("runs", runs, 1)
    batch_size = as_int_at_least("batch_size", batch_size, 1)
    t = scenario.time
    mask = window_mask(t, scenario.rms_window_s)
    win_masks = {}
    if case == "maneuver":
        win_masks = {k: window_mask(t, w) for k, w in maneuver_windows(scenario).items() if w[0] < w[1]}
    sink = _CaseSink(filters, t.size, mask, win_masks)
    acc = run_monte_carlo(scenario, filters, sink=sink, runs=runs, seed=seed, batch_size=batch_size, noise="gaussian",
                          measurement_noise=conditions["measurement_noise"], keep_covariance=False,
                          diagnostics=("weights",), progress=progress, maneuver=conditions["maneuver"])
    stats = {}
    for name, a in acc.items():
        stats[name] = FilterStats(
            per_run=np.concatenate(a["per_run"]),
            windows={k: np.concatenate(v) for k, v in a["windows"].items()},
            jitter=np.concatenate(a["jitter"]),
            max_abs=np.concatenate(a["max_abs"]),
            mean_error=a["sum"] / runs,
            rms_error=np.sqrt(a["sumsq"] / runs),
            single=a["single"],
            down_weighted=(a["down"][0] / a["down"][1]) if a["down"][1] else None,
        )
    noise = conditions["measurement_noise"]
    settings = {"case": case, "maneuver": conditions["maneuver"],
                "measurement_noise": noise if isinstance(noise, str) else
                {"name": noise.name, "eps": noise.eps, "ratio": noise.ratio, "variance": noise.variance},
                "process_noise": "gaussian", "runs": runs, "seed": seed}
    return CaseResult(case=case, t=t, runs=runs, seed=seed, window_s=scenario.rms_window_s, filters=stats,
                      settings=settings)


def accuracy(per_axis):
    """The reproduction's statistic from per-axis values (..., 6): ``(pos, vel)``, RMS over the three axes."""
    per_axis = np.asarray(per_axis, dtype=float)
    if per_axis.shape[-1] != 6:
        raise InputError(f"per_axis must have 6 components (x, y, z, vx, vy, vz) last; got shape {per_axis.shape}")
    return np.sqrt(np.mean(per_axis[..., :3] ** 2, axis=-1)), np.sqrt(np.mean(per_axis[..., 3:] ** 2, axis=-1))


def mc_interval(values):
    """Mean over runs and its 95 % interval (Student t; NaN bounds with one run): ``(mean, [low, high])``."""
    mean, low, high = mean_interval(values)
    return mean, [low, high]


def filter_summary(stats, window=None):
    """The summary of one filter in one case: single run, Monte Carlo mean with 95 % interval, per axis.

    ``window``: a label of ``stats.windows`` to summarise that window instead
    of the case's (jitter and maxima stay the case window's).

    Returns
    -------
    dict
        ``pos_m``, ``vel_mps`` (run 0), ``mc_mean_pos_m``, ``mc_ci95_pos_m``,
        ``mc_mean_vel_mps``, ``mc_ci95_vel_mps``, ``mc_axes`` (mean per-axis
        RMS), ``mc_jitter_pos_m``, ``mc_jitter_vel_mps``, ``mc_max_pos_m``,
        ``mc_max_vel_mps`` and, for the HBF, ``down_weighted``.
    """
    per_run = stats.per_run if window is None else stats.windows[window]
    pos, vel = accuracy(per_run)
    mp, cp = mc_interval(pos)
    mv, cv = mc_interval(vel)
    jp, jv = accuracy(stats.jitter)
    xp, xv = accuracy(stats.max_abs)
    out = {"pos_m": float(pos[0]), "vel_mps": float(vel[0]), "mc_mean_pos_m": mp, "mc_ci95_pos_m": cp,
           "mc_mean_vel_mps": mv, "mc_ci95_vel_mps": cv, "mc_axes": [float(v) for v in per_run.mean(axis=0)],
           "mc_jitter_pos_m": float(jp.mean()), "mc_jitter_vel_mps": float(jv.mean()),
           "mc_max_pos_m": float(xp.mean()), "mc_max_vel_mps": float(xv.mean())}
    if stats.down_weighted is not None:
        out["down_weighted"] = float(stats.down_weighted)
    return out


def paired_gap(a, b, values="per_run"):
    """``a − b`` of two filters' statistics on the same runs: mean and 95 % interval, and the ratio of means.

    Parameters
    ----------
    a, b : FilterStats
    values : {"per_run", "jitter"} or a window label
    """

    def pick(s):
        return getattr(s, values) if values in ("per_run", "jitter", "max_abs") else s.windows[values]

    pa, va = accuracy(pick(a))
    pb, vb = accuracy(pick(b))
    mp, cp = mc_interval(pa - pb)
    mv, cv = mc_interval(va - vb)
    return {"pos_m": mp, "pos_ci95_m": cp, "vel_mps": mv, "vel_ci95_mps": cv,
            "pos_ratio": float(pa.mean() / pb.mean()), "vel_ratio": float(va.mean() / vb.mean())}


def maneuver_reaction(scenario, result, dv=None):
    """How each filter follows the unmodelled maneuver, from its bias (mean error over runs).

    Parameters
    ----------
    result : CaseResult
        Of the ``maneuver`` case.
    scenario : Scenario
    dv : float, optional
        The velocity change along x, m/s (default the scenario's, signed).

    Returns
    -------
    dict
        Per filter: ``t_half_s`` (time after the maneuver at which the mean
        x-velocity error first falls below Δv/2, NaN if it never does; the
        first crossing, so that later Monte Carlo noise around Δv/2 does not
        move it), ``vel_bias_area_m`` (its integral
        over the 200 s after the maneuver, m: how much velocity error the
        filter lets through), ``peak_pos_bias_m`` (largest mean x-position
        error after the maneuver, m) and ``peak_time_s``.
    """
    dv = float(scenario.maneuver_dv()[3]) if dv is None else float(dv)
    t = result.t
    after = t >= scenario.maneuver_time_s - 1e-9
    ta = t[after] - scenario.maneuver_time_s
    first = ta <= 200.0 + 1e-9
    out = {}
    for name, st in result.filters.items():
        bias_v = st.mean_error[after, 3] * np.sign(dv)
        bias_x = st.mean_error[after, 0] * np.sign(dv)
        below = np.flatnonzero(bias_v < 0.5 * abs(dv))
        t_half = float(ta[below[0]]) if below.size else float("nan")
        k = int(np.argmax(np.abs(bias_x)))
        out[name] = {"t_half_s": t_half, "vel_bias_area_m": float(np.trapezoid(bias_v[first], ta[first])),
                     "peak_pos_bias_m": float(bias_x[k]), "peak_time_s": float(ta[k])}
    return out
