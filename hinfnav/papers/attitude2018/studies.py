"""The measurements behind paper 002's figures and claims: one truth, many filter passes, batched.

Every pass runs all Monte Carlo runs at once; a parameter sweep (Q, ρ/β, ε)
is one pass too, its values batched as runs (the same truth repeated, one
parameter value per block). Each pass is reduced at once to
:class:`FilterStats` over the RMS window (the last orbit), so that nothing
of size runs × steps × 9 outlives it.

Error decomposition (claims 1–4). The torque T_d(t) is the same in every run,
so the ensemble mean of the error over runs, ``b(t) = mean_r e_r(t)``, is the
deterministic (periodic, "oscillating") error and ``e_r(t) − b(t)`` the random
error. With R runs the ensemble mean still holds σ²/R of the random error;
the split is made unbiased: random RMS² = R/(R−1) · mean (e − b)², oscillating
RMS² = mean b² − mean (e − b)²/(R − 1), so that RMS² = oscillating² + random²
in expectation (one run: everything counts as oscillating).
"""

from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from ...core.validation import as_int_at_least
from ...metrics.errors import window_mask
from ...metrics.intervals import mean_interval
from ...sim.truth import Truth, simulate_truth
from .chaser import run_passes
from .constants import (
    DEFAULT_AA,
    DEFAULT_ST,
    PAPER_Q_ASTEKF,
    PAPER_Q_BEST_AEKF,
    Q_SWEEP,
)
from .filters import build_aaekf, build_aekf, build_astekf
from .scenario import Scenario, default_epsilon

__all__ = [
    "EPSILON_FACTORS",
    "AttitudeStudy",
    "FilterStats",
    "attitude_study",
    "filter_stats",
    "run_batched",
    "run_filter",
    "sweep_study",
]

#: Strong-tracking settings swept at Q = 1e-16: (ρ, β).
ST_GRID = ((0.95, 1.0), (0.95, 1.25), (0.95, 1.5), (0.95, 2.0), (0.95, 3.0), (0.95, 4.0), (0.5, 1.0), (0.8, 1.0),
           (0.99, 1.0))
#: AAEKF compression factors swept, as multiples of :func:`default_epsilon`.
EPSILON_FACTORS = (0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)
#: AAEKF rate windows m swept (steps), besides the default 60.
WINDOW_VALUES = (20, 200)


def dominant_period(signal, dt):
    """Period (s) of the largest spectral line of each column of ``signal`` (mean removed), shape (n,)."""
    s = np.asarray(signal) - np.mean(signal, axis=0)
    spec = np.abs(np.fft.rfft(s, axis=0))
    freq = np.fft.rfftfreq(s.shape[0], dt)
    k = np.argmax(spec[1:], axis=0) + 1
    return 1.0 / freq[k]


@dataclass(frozen=True, eq=False)
class FilterStats:
    """One filter pass reduced over the RMS window.

    Attributes
    ----------
    label : str
    params : dict
    euler_rms_deg, torque_rms_Nm, rate_rms : ndarray, shape (3,)
        Per-axis RMS pooled over runs and window (deg, N·m, rad/s).
    euler_bias_deg, euler_random_deg, torque_bias_Nm, torque_random_Nm : ndarray, shape (3,)
        RMS of the oscillating error b(t) and of the random error e − b
        (unbiased split, see the module docstring).
    euler_run_deg, torque_run_Nm : ndarray, shape (runs,)
        Per-run RMS over axes (for 95 % intervals).
    corr_rate, corr_torque : ndarray, shape (3,)
        Correlation over runs and window of ``|torque error|`` with ``|dT_d/dt|`` and with ``|T_d|``.
    corr_rate_euler : ndarray, shape (3,)
        Correlation of ``|Euler error|`` with ``|dT_d/dt|`` of the same axis.
    period_s : ndarray, shape (3,)
        Period of the strongest line of b(t) (torque error), s.
    crest_torque, crest_euler : ndarray, shape (3,)
        ``max|b| / RMS(b)`` over the window (√2 for a sinusoid, < √2 for a flat top).
    plateau_torque : ndarray, shape (3,)
        Fraction of the window where ``|b| ≥ 0.8 max|b|`` (0.41 for a sinusoid).
    rate_elasticity : ndarray, shape (3,)
        Slope of ``log|b_T|`` against ``log|dT_d/dt|`` over the samples with
        ``|dT_d/dt| ≥`` half its maximum (around the zero crossings, where the
        error peaks): 1 when the oscillating error is proportional to the
        rate (a lag), 0 for a plateau.
    t, run0, mean : ndarray or None
        Time, error history of run 0 and b(t), (n_samples, 9), when kept.
    diagnostics : dict
        Run 0's diagnostics histories (fading factors, adapted Q …), when kept.
    """

    label: str
    params: dict
    euler_rms_deg: np.ndarray
    torque_rms_Nm: np.ndarray
    rate_rms: np.ndarray
    euler_bias_deg: np.ndarray
    euler_random_deg: np.ndarray
    torque_bias_Nm: np.ndarray
    torque_random_Nm: np.ndarray
    euler_run_deg: np.ndarray
    torque_run_Nm: np.ndarray
    corr_rate: np.ndarray
    corr_torque: np.ndarray
    corr_rate_euler: np.ndarray
    period_s: np.ndarray
    crest_torque: np.ndarray
    crest_euler: np.ndarray
    plateau_torque: np.ndarray
    rate_elasticity: np.ndarray
    peak_torque: np.ndarray
    t: np.ndarray = None
    run0: np.ndarray = None
    mean: np.ndarray = None
    diagnostics: dict = field(default_factory=dict)

    @property
    def euler_deg(self):
        """One number: RMS over the three Euler angles, deg."""
        return float(np.sqrt(np.mean(self.euler_rms_deg**2)))

    @property
    def torque_Nm(self):
        """One number: RMS over the three torque components, N·m."""
        return float(np.sqrt(np.mean(self.torque_rms_Nm**2)))

    def ci95(self, what="euler"):
        """95 % interval of the mean over runs of the per-run RMS (over axes): (low, high)."""
        run = self.euler_run_deg if what == "euler" else self.torque_run_Nm
        _, low, high = mean_interval(run)  # Student t; NaN bounds with one run
        return low, high


def _corr(a, b):
    a = a - a.mean(axis=0)
    b = b - b.mean(axis=0)
    return np.sum(a * b, axis=0) / np.sqrt(np.sum(a * a, axis=0) * np.sum(b * b, axis=0))


def _elasticity(b, rate, low=0.5):
    out = np.empty(b.shape[1])
    for i in range(b.shape[1]):
        sel = rate[:, i] >= low * rate[:, i].max()
        out[i] = np.polyfit(np.log(rate[sel, i]), np.log(b[sel, i] + 1e-300), 1)[0]
    return out


def filter_stats(scenario, label, error, t, *, params=None, keep=False, diagnostics=None):
    """Reduce an error history (runs, n_samples, 9) to :class:`FilterStats` over the scenario's window."""
    mask = window_mask(t, scenario.rms_window_s)
    e = error[:, mask]
    deg = np.degrees(1.0)
    b = e.mean(axis=0)
    r = e - b
    rms = lambda v, ax: np.sqrt(np.mean(v**2, axis=ax))
    pooled = rms(e, (0, 1))
    runs = e.shape[0]
    # unbiased split: E[mean_r(e − ē)²] = σ²(R−1)/R and E[ē²] = b² + σ²/R
    s2 = np.mean(r**2, axis=(0, 1))
    random_rms = np.sqrt(s2 * runs / (runs - 1)) if runs > 1 else np.zeros(e.shape[-1])
    bias_rms = np.sqrt(np.maximum(np.mean(b**2, axis=0) - (s2 / (runs - 1) if runs > 1 else 0.0), 0.0))
    tw = t[mask]
    rate = np.abs(scenario.torque_rate(tw))
    torque = np.abs(scenario.torque(tw))
    absT = np.abs(e[..., 6:9]).reshape(-1, 3)
    absE = np.abs(e[..., :3]).reshape(-1, 3)
    rate_all = np.tile(rate, (runs, 1))
    bT = np.abs(b[:, 6:9])
    return FilterStats(
        label=label,
        params=dict(params or {}),
        euler_rms_deg=pooled[:3] * deg,
        torque_rms_Nm=pooled[6:9],
        rate_rms=pooled[3:6],
        euler_bias_deg=bias_rms[:3] * deg,
        euler_random_deg=random_rms[:3] * deg,
        torque_bias_Nm=bias_rms[6:9],
        torque_random_Nm=random_rms[6:9],
        euler_run_deg=np.sqrt(np.mean(e[..., :3] ** 2, axis=(1, 2))) * deg,
        torque_run_Nm=np.sqrt(np.mean(e[..., 6:9] ** 2, axis=(1, 2))),
        corr_rate=_corr(absT, rate_all),
        corr_torque=_corr(absT, np.tile(torque, (runs, 1))),
        corr_rate_euler=_corr(absE, rate_all),
        period_s=dominant_period(b[:, 6:9], scenario.dt),
        crest_torque=bT.max(axis=0) / rms(bT, 0),
        crest_euler=np.abs(b[:, :3]).max(axis=0) / rms(b[:, :3], 0),
        plateau_torque=np.mean(bT >= 0.8 * bT.max(axis=0), axis=0),
        rate_elasticity=_elasticity(bT, rate),
        peak_torque=bT.max(axis=0),
        t=t if keep else None,
        run0=error[0] if keep else None,
        mean=error.mean(axis=0) if keep else None,
        diagnostics={k: v[0] for k, v in (diagnostics or {}).items()} if keep else {},
    )


def first_runs(truth, k):
    """The first ``k`` runs of a truth (identical to simulating ``k`` runs with the same seed)."""
    return Truth(t=truth.t, x=truth.x[:k], u=truth.u[:k], y=truth.y[:k], settings=dict(truth.settings, runs=k),
                 state=truth.state, measurement=truth.measurement)


def run_filter(scenario, label, estimator, truth, *, params=None, keep=False, diagnostics=()):
    """One pass of an estimator over every run of ``truth``, reduced to :class:`FilterStats`."""
    hist = estimator.estimate(truth.y, truth.u, scenario.xhat0, keep_covariance=False,
                              diagnostics=tuple(diagnostics) if keep else ())
    err = truth.state.error(truth.x, hist.xhat)
    return filter_stats(scenario, label, err, truth.t, params=params, keep=keep, diagnostics=hist.diagnostics)


def run_batched(scenario, builder, key, values, truth, *, labels=None, keep=False, extra=None, **fixed):
    """A parameter sweep as one pass: ``builder(scenario, **{key: per-run values}, **fixed)`` over the repeated truth.

    ``key`` may be a tuple of names with ``values`` a sequence of tuples. ``extra``
    maps further names to per-value sequences batched the same way.

    Returns
    -------
    list of FilterStats, one per value
    """
    R = truth.x.shape[0]
    keys = key if isinstance(key, tuple) else (key,)
    vals = [v if isinstance(v, tuple) else (v,) for v in values]
    per_run = {k: np.repeat([v[i] for v in vals], R) for i, k in enumerate(keys)}
    est = builder(scenario, **per_run, **fixed)
    y = np.concatenate([truth.y] * len(vals))
    u = np.concatenate([truth.u] * len(vals))
    xhat = est.estimate(y, u, scenario.xhat0, keep_covariance=False).xhat
    out = []
    for i, v in enumerate(vals):
        err = truth.state.error(truth.x, xhat[i * R:(i + 1) * R])
        params = dict(zip(keys, v))
        label = labels[i] if labels else ", ".join(f"{k}={x:g}" for k, x in params.items())
        out.append(filter_stats(scenario, label, err, truth.t, params=params, keep=keep))
    return out


def _main_and_sweeps(scenario, builder, key, diag, truth, main_params, sweeps, eps0):
    """The main runs of one filter (histories kept) and its sweeps, one pass; returns (main stats, [sweep stats]).

    ``sweeps``: ``(truth, run parameters, recorded parameters, label, keep histories)`` per sweep value.
    """
    passes = [(truth, main_params)] + [(small, params) for small, params, _, _, _ in sweeps]
    errors, hist = run_passes(scenario, builder, passes, diagnostics=diag)
    diagnostics = hist.diagnostics
    main = filter_stats(scenario, key, errors[0], truth.t, params=dict(est_params(key, eps0)), keep=True,
                        diagnostics=diagnostics)
    out = [filter_stats(scenario, label, err, small.t, params=record, keep=keep)
           for err, (small, _, record, label, keep) in zip(errors[1:], sweeps)]
    return main, out


@dataclass(frozen=True, eq=False)
class AttitudeStudy:
    """Everything the figures, the claims and ``summary.json`` read.

    Attributes
    ----------
    scenario : Scenario
    truth_t : ndarray
        Sample times, s.
    main : dict
        ``aekf`` (Q = 1e-14), ``astekf`` (Q = 1e-16), ``aaekf`` (defaults) on
        every run, with run-0 and mean histories and diagnostics.
    q_sweep : dict
        ``Q`` (list) and ``aekf``/``astekf``: lists of FilterStats (histories kept).
    st_grid : list of FilterStats
        ASTEKF at Q = 1e-16 over (ρ, β) of :data:`ST_GRID`.
    epsilon_sweep, window_sweep : list of FilterStats
        AAEKF over ε (× default) and over the window m.
    settings : dict
    """

    scenario: Scenario
    truth_t: np.ndarray
    main: dict
    q_sweep: dict
    st_grid: list
    epsilon_sweep: list
    window_sweep: list
    settings: dict


def attitude_study(scenario=None, *, runs=20, seed=0, sweep_runs=None, Qs=Q_SWEEP, progress=False):
    """Run every filter pass of the reproduction.

    Parameters
    ----------
    scenario : Scenario, optional
    runs : int
        Monte Carlo runs of the three filters at the paper's settings (Figs 8–9).
    seed : int
    sweep_runs : int, optional
        Runs of each sweep value (default min(runs, 4)); the first runs of the same truth.
    Qs : sequence of float
        Torque noise densities of the Q sweep, (N·m)²/s.

    Returns
    -------
    AttitudeStudy
    """
    scenario = Scenario() if scenario is None else scenario
    runs = as_int_at_least("runs", runs, 1)
    sweep_runs = min(runs, 4) if sweep_runs is None else min(as_int_at_least("sweep_runs", sweep_runs, 1), runs)
    bar = tqdm(total=9, disable=not progress, desc="attitude2018", unit="pass")
    truth = simulate_truth(scenario.truth_model(), runs=runs, seed=seed)
    small = first_runs(truth, sweep_runs)
    bar.update(1)
    eps0 = default_epsilon(omega_e=scenario.omega_e)
    Qs = [float(q) for q in Qs]
    labels = [f"Q={q:.0e}" for q in Qs]
    sweep = {"Q": Qs}
    main = {}
    # each filter's main runs and its sweeps in one pass (run_passes): the numbers of separate passes
    q_sweep = [(small, {"Q": q}, {"Q": q}, label, True) for q, label in zip(Qs, labels)]
    main["aekf"], sweep["aekf"] = _main_and_sweeps(scenario, build_aekf, "aekf", (), truth, {"Q": PAPER_Q_BEST_AEKF},
                                                   q_sweep, eps0)
    bar.update(2)
    st = dict(Q=PAPER_Q_ASTEKF, rho=DEFAULT_ST["rho"], beta=DEFAULT_ST["beta"])
    st_sweeps = [(small, dict(st, Q=q), {"Q": q}, label, True) for q, label in zip(Qs, labels)]
    st_sweeps += [(small, dict(st, rho=r, beta=b), {"rho": r, "beta": b}, f"rho={r:g}, beta={b:g}", False)
                  for r, b in ST_GRID]
    main["astekf"], st_out = _main_and_sweeps(scenario, build_astekf, "astekf", ("fading", "fading_c"), truth, st,
                                              st_sweeps, eps0)
    sweep["astekf"], st_grid = st_out[:len(Qs)], st_out[len(Qs):]
    bar.update(3)
    eps_sweeps = [(small, {"epsilon": f * eps0}, {"epsilon": f * eps0}, f"ε={f:g}×default", False)
                  for f in EPSILON_FACTORS]
    main["aaekf"], eps_sweep = _main_and_sweeps(scenario, build_aaekf, "aaekf", ("q_adapted", "input_rate"), truth,
                                                {"epsilon": eps0}, eps_sweeps, eps0)
    bar.update(2)
    win_sweep = [run_filter(scenario, f"m={m}", build_aaekf(scenario, epsilon=eps0, memory_steps=m), small, params={"window": m})
                 for m in WINDOW_VALUES]
    bar.update(1)
    bar.close()
    settings = {"runs": runs, "sweep_runs": sweep_runs, "seed": seed, "epsilon_default_s_per_Nm": eps0,
                "rms_window_s": list(scenario.rms_window_s), "duration_s": scenario.duration_s, "dt_s": scenario.dt,
                "n_steps": scenario.n_steps}
    return AttitudeStudy(scenario=scenario, truth_t=truth.t, main=main, q_sweep=sweep, st_grid=st_grid,
                         epsilon_sweep=eps_sweep, window_sweep=win_sweep, settings=settings)


def sweep_study(scenario=None, *, runs=2, seed=0, filters=("aekf",), Qs=Q_SWEEP):
    """Only the Q sweep (of the AEKF, or also the ASTEKF): an :class:`AttitudeStudy` with ``main`` and the grids empty.

    For notebooks that show claims 1–2 without the cost of the whole study.
    """
    scenario = Scenario() if scenario is None else scenario
    truth = simulate_truth(scenario.truth_model(), runs=as_int_at_least("runs", runs, 1), seed=seed)
    Qs = [float(q) for q in Qs]
    labels = [f"Q={q:.0e}" for q in Qs]
    builders = {"aekf": build_aekf, "astekf": build_astekf}
    sweep = {"Q": Qs}
    for name in filters:
        sweep[name] = run_batched(scenario, builders[name], "Q", Qs, truth, labels=labels, keep=True)
    settings = {"runs": runs, "sweep_runs": runs, "seed": seed, "rms_window_s": list(scenario.rms_window_s)}
    return AttitudeStudy(scenario=scenario, truth_t=truth.t, main={}, q_sweep=sweep, st_grid=[], epsilon_sweep=[],
                         window_sweep=[], settings=settings)


def est_params(key, eps0):
    """The parameters of the three filters at the paper's settings (for the record)."""
    return {
        "aekf": {"Q": PAPER_Q_BEST_AEKF},
        "astekf": {"Q": PAPER_Q_ASTEKF, **DEFAULT_ST},
        "aaekf": {"Q0": DEFAULT_AA["Q0"], "epsilon": eps0, "window": DEFAULT_AA["memory_steps"], "floor": DEFAULT_AA["floor"]},
    }[key]
