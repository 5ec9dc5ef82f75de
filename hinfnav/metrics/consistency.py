"""Is a filter's covariance honest? NEES and NIS with χ² bounds, and a divergence flag that is never silent.

For a filter that reports a covariance P(k) of its estimate, the normalized
estimation error squared (Bar-Shalom, Li & Kirubarajan, *Estimation with
Applications to Tracking and Navigation*, 2001, §5.4.2)::

    ε(k) = e(k)ᵀ P(k)⁻¹ e(k),   e(k) = state.error(x(k), x̂(k))           (C1)

uses the state's own error definition (a quaternion state has a
multiplicative error whose dimension n, the covariance's, differs from the
stored state's). For a filter that reports its innovation ν(k) and the
innovation covariance S(k) = H P⁻ Hᵀ + R (the diagnostic
``innovation_covariance``), the normalized innovation squared is::

    ε_ν(k) = ν(k)ᵀ S(k)⁻¹ ν(k)                                              (C2)

For a consistent filter (linear-Gaussian, the model true) ε(k) ~ χ²(n) and
ε_ν(k) ~ χ²(m). Averaged over N independent runs, N ε̄(k) ~ χ²(N n), so the
two-sided 95 % bounds of the run-average at each step are::

    [χ²_{0.025}(N n) / N,  χ²_{0.975}(N n) / N]                              (C3)

(:func:`chi2_bounds`, with :data:`scipy.stats.chi2`). Reported per window:
the window mean of ε̄(k) and the fraction of the window's steps at which
ε̄(k) lies inside (C3) — 0.95 expected for a consistent filter, less when
the steps are few or strongly correlated. The window mean itself has no
closed-form bound (consecutive steps are correlated).

**Never silent.** A filter is flagged ``diverged`` (and a
:class:`~hinfnav.core.exceptions.FilterDivergenceWarning` is issued) when

* a run's error is not finite, or
* a run's error norm ‖e(k)‖ exceeds :data:`DIVERGENCE_FACTOR` (10³) times
  that run's initial error scale s₀ = max(‖e(x(0), x̂₀)‖, √tr P(0), ‖e(0)‖)
  (the prior's error, the filter's own first covariance, its first reported
  error; ‖·‖ the Euclidean norm in the state's units), at any step — a
  filter whose covariance grows with its error (strong tracking) can keep
  its NEES small while it runs away, so this bound does not use P(k); or
* a window's mean NEES exceeds the upper bound of (C3) — the covariance is
  too small for the error (over-confident: level 1) — or exceeds
  :data:`NEES_FACTOR` (10) times that bound (grossly over-confident, the
  covariance is dishonest: level 2), or is negative or not finite (the
  covariance is no longer positive definite: level 2). The summary's
  ``diverged_level`` is 0 (consistent), 1 or 2 (the two runaway criteria
  above are level 2 too); ``diverged`` is ``diverged_level >= 1``. A filter
  5× over-confident (P a fifth of the error's covariance) has a mean NEES of
  about 5n, beyond the bound (C3) but below 10× it: flagged at level 1
  (before issue 35 only level 2 was flagged, and such a filter passed).

**Missing channels** (``missing="skip"``: a NaN innovation channel). The NIS
of a run at a step uses the channels present only: ν_pᵀ S_pp⁻¹ ν_p, with
m_i(k) ≤ m degrees of freedom, and Σ_i ε_ν,i(k) ~ χ²(D(k)) with
D(k) = Σ_i m_i(k); the reported NIS is scaled to the full
m channels, ε̄_ν(k) = m Σ_i ε_ν,i(k) / D(k) (the average over the channels
present, times m; equal to the plain run average when nothing is missing),
and its per-step 95 % bounds are m χ²_{0.025, 0.975}(D(k)) / D(k), used for
the fraction inside. A step at which no run has a channel has no NIS (NaN)
and is left out of the window statistics; ``nis_dof_mean`` in a window is the
mean of D(k)/N over its steps.

Memory does not grow with the runs: :class:`ConsistencyAccumulator` keeps
per step the sums of ε and ε_ν over the runs (and counts), fed batch by
batch; it is composed into the streaming statistics of
:func:`hinfnav.metrics.monte_carlo_statistics` and of a campaign cell.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.stats import chi2

from ..core.exceptions import FilterDivergenceWarning, InputError
from ..core.validation import as_int_at_least
from .errors import window_mask

if TYPE_CHECKING:
    from ..sim.montecarlo import SimulationResult

__all__ = [
    "DIVERGENCE_FACTOR",
    "NEES_FACTOR",
    "NIS_KEYS",
    "ConsistencyAccumulator",
    "ConsistencyStatistics",
    "chi2_bounds",
    "consistency",
    "initial_scale",
    "normalized_squared",
    "warn_if_diverged",
]

#: ‖e(k)‖ beyond this multiple of the run's initial error scale: diverged.
DIVERGENCE_FACTOR = 1e3
#: A window's mean NEES beyond this multiple of the 95 % upper bound (C3): diverged (the covariance is dishonest).
NEES_FACTOR = 10.0
#: Diagnostics the NIS needs (the estimator's ``update`` reports them).
NIS_KEYS = ("innovation", "innovation_covariance")


def chi2_bounds(dof: int, runs: int = 1, level: float = 0.95) -> tuple[float, float]:
    """Two-sided bounds (C3) of the average over ``runs`` runs of a χ²(``dof``) statistic.

    Parameters
    ----------
    dof : int
        Degrees of freedom of one run's statistic (n for the NEES, m for the NIS).
    runs : int
        N, the number of runs averaged.
    level : float
        Probability inside, 0 < level < 1 (0.95).

    Returns
    -------
    (float, float)
        ``χ²_{(1−level)/2}(N·dof)/N`` and ``χ²_{(1+level)/2}(N·dof)/N``.
    """
    dof = as_int_at_least("dof", dof, 1)
    runs = as_int_at_least("runs", runs, 1)
    if not (isinstance(level, (int, float)) and 0 < level < 1):
        raise InputError(f"level must be a probability in (0, 1); got {level!r}")
    lo, hi = chi2.ppf([(1 - level) / 2, (1 + level) / 2], runs * dof) / runs
    return float(lo), float(hi)


def _inverse(C):
    """Inverses of a stack of matrices; NaN where a matrix is not finite or is singular."""
    C = np.asarray(C, dtype=float)
    bad = ~np.all(np.isfinite(C), axis=(-2, -1))
    if bad.any():
        C = np.where(bad[..., None, None], np.eye(C.shape[-1]), C)
    try:
        out = np.linalg.inv(C)
    except np.linalg.LinAlgError:
        flat = C.reshape((-1,) + C.shape[-2:])
        out = np.empty_like(flat)
        for i, Ci in enumerate(flat):
            try:
                out[i] = np.linalg.inv(Ci)
            except np.linalg.LinAlgError:
                out[i] = np.nan
        out = out.reshape(C.shape)
    out[bad] = np.nan
    return out


def normalized_squared(e: ArrayLike, C: ArrayLike) -> NDArray[np.float64]:
    """``eᵀ C⁻¹ e`` over stacks: the NEES (C1) with (error, P), the NIS (C2) with (innovation, S).

    Parameters
    ----------
    e : array_like, shape (..., n)
    C : array_like, shape (..., n, n), broadcastable against ``e``
        Covariances; a stack broadcast with stride 0 (a covariance shared by
        every run) is inverted once.

    Returns
    -------
    ndarray, shape of ``e`` without its last axis
        NaN where C is singular or not finite.
    """
    e = np.asarray(e, dtype=float)
    C = np.asarray(C, dtype=float)
    if C.ndim < 2 or C.shape[-1] != C.shape[-2] or C.shape[-1] != e.shape[-1]:
        raise InputError(f"C must be square covariances matching the error's {e.shape[-1]} components; got {C.shape}")
    if C.ndim >= 3 and C.shape[0] > 1 and C.strides[0] == 0:
        Ci = np.broadcast_to(_inverse(C[0]), C.shape)
    else:
        Ci = _inverse(C)
    with np.errstate(all="ignore"):
        return np.einsum("...i,...ij,...j->...", e, Ci, e)


def initial_scale(e_prior0: ArrayLike, P0: ArrayLike | None = None, e0: ArrayLike | None = None) -> NDArray[np.float64]:
    """Per-run initial error scale s₀ (see the module docstring), shape (runs,).

    Parameters
    ----------
    e_prior0 : array_like, shape (runs, n)
        ``state.error(x(0), x̂₀)``: the error of the filters' initial estimate.
    P0 : array_like, shape (runs, n, n) or None
        The first covariance the filter reports.
    e0 : array_like, shape (runs, n) or None
        The first reported error.
    """
    s = np.linalg.norm(np.asarray(e_prior0, dtype=float), axis=-1)
    if P0 is not None:
        with np.errstate(invalid="ignore"):
            s = np.fmax(s, np.sqrt(np.maximum(np.trace(np.asarray(P0), axis1=-2, axis2=-1), 0.0)))
    if e0 is not None:
        s = np.fmax(s, np.linalg.norm(np.asarray(e0, dtype=float), axis=-1))
    return s


def _covariance_history(C, shape):
    """A (runs, samples, k, k) view of a history that may be shared by the runs ((samples, k, k))."""
    C = np.asarray(C)
    if C.ndim == len(shape):  # (samples, k, k): shared by the runs
        return np.broadcast_to(C, (shape[0],) + C.shape)
    return C


class ConsistencyAccumulator:
    """Per-step sums of NEES and NIS over runs, and the divergence counts, fed batch by batch.

    Parameters
    ----------
    runs : int
        Total number of runs.
    """

    def __init__(self, runs: int) -> None:
        self.runs = as_int_at_least("runs", runs, 1)
        self.t = None
        self.nees_sum = self.nis_sum = self.nis_dof = None
        self.n = self.m = None
        self.nees_note = self.nis_note = None
        self.nonfinite_runs = 0
        self.grown_runs = 0
        self.max_growth = 0.0
        self.added = 0

    def add(self, t: NDArray[np.float64], err: NDArray[np.float64], P: NDArray[np.float64] | None = None, innovation: NDArray[np.float64] | None = None,
            S: NDArray[np.float64] | None = None, scale0: NDArray[np.float64] | None = None) -> None:
        """Add one batch.

        Parameters
        ----------
        t : ndarray, shape (samples,)
        err : ndarray, shape (batch, samples, n)
            Errors by the state's definition.
        P : ndarray, shape (batch, samples, n, n) or None
            The reported covariance (None: the filter carries none).
        innovation : ndarray, shape (batch, samples, m) or None
        S : ndarray, shape (batch, samples, m, m) or (samples, m, m) or None
            The innovation covariance (None: the filter does not report it).
        scale0 : ndarray, shape (batch,), optional
            Initial error scales (:func:`initial_scale`); default from ``err`` and ``P`` at the first sample.
        """
        err = np.asarray(err, dtype=float)
        b, n1, n = err.shape
        if self.t is None:
            self.t, self.n = np.asarray(t, dtype=float), n
            if P is None:
                self.nees_note = "the filter carries no covariance (a fixed-gain filter): no NEES"
            elif np.shape(P)[-1] != n:
                self.nees_note = (f"the filter's covariance has {np.shape(P)[-1]} coordinates but the state's error has "
                                  f"{n}: no NEES")
            else:
                self.nees_sum = np.zeros(n1)
            if S is None or innovation is None:
                self.nis_note = "the filter does not report its innovation covariance S: no NIS"
            else:
                self.m = np.shape(innovation)[-1]
                self.nis_sum = np.zeros(n1)
                self.nis_dof = np.zeros(n1)
        finite = np.all(np.isfinite(err), axis=(1, 2))
        self.nonfinite_runs += int((~finite).sum())
        if scale0 is None:
            scale0 = initial_scale(err[:, 0], None if P is None else np.asarray(P)[:, 0])
        with np.errstate(all="ignore"):
            growth = np.max(np.linalg.norm(err, axis=-1), axis=1) / np.asarray(scale0, dtype=float)
        grown = finite & (growth > DIVERGENCE_FACTOR)
        self.grown_runs += int(grown.sum())
        if np.any(finite & np.isfinite(growth)):
            self.max_growth = max(self.max_growth, float(np.max(growth[finite & np.isfinite(growth)])))
        if self.nees_sum is not None:
            self.nees_sum += normalized_squared(err, _covariance_history(P, err.shape)).sum(axis=0)
        if self.nis_sum is not None:
            nu = np.asarray(innovation, dtype=float)
            present = ~np.isnan(nu)
            C = _covariance_history(S, nu.shape)
            if not present.all():  # missing channels: the NIS of the channels present (module docstring)
                both = present[..., :, None] & present[..., None, :]
                C = np.where(both, C, 0.0) + np.eye(nu.shape[-1]) * ~present[..., None, :]
                nu = np.where(present, nu, 0.0)
            self.nis_sum += normalized_squared(nu, C).sum(axis=0)
            self.nis_dof += present.sum(axis=(0, 2))
        self.added += b

    def result(self, name: str = "filter") -> ConsistencyStatistics:
        """The :class:`ConsistencyStatistics` of the runs added."""
        if self.added != self.runs:
            raise InputError(f"the consistency accumulator was given {self.added} runs of {self.runs}")
        N = self.runs
        nis = nis_dof = None
        if self.nis_sum is not None:
            full = self.nis_dof == N * self.m
            with np.errstate(all="ignore"):
                nis = np.where(full, self.nis_sum / N, np.where(self.nis_dof > 0, self.m * self.nis_sum / self.nis_dof,
                                                                np.nan))
            nis_dof = None if full.all() else self.nis_dof / N
        return ConsistencyStatistics(
            t=self.t, nees=None if self.nees_sum is None else self.nees_sum / N,
            nis=nis, n=self.n, m=self.m, runs=N, nis_dof=nis_dof,
            nonfinite_runs=self.nonfinite_runs, grown_runs=self.grown_runs, max_growth=self.max_growth,
            notes=tuple(x for x in (self.nees_note, self.nis_note) if x), name=str(name))


@dataclass(frozen=True, eq=False)
class ConsistencyStatistics:
    """Run-averaged NEES and NIS per step, and what the divergence checks found.

    Attributes
    ----------
    t : ndarray, shape (samples,)
        s.
    nees, nis : ndarray, shape (samples,) or None
        ε̄(k), ε̄_ν(k) (C1)–(C2) averaged over the runs; None when the filter
        carries no covariance / reports no S (see ``notes``).
    n, m : int or None
        Degrees of freedom of one run's NEES and NIS.
    runs : int
    nonfinite_runs, grown_runs : int
        Runs whose error is not finite, and runs whose error norm exceeded
        :data:`DIVERGENCE_FACTOR` times their initial scale.
    max_growth : float
        Largest ‖e(k)‖/s₀ over the finite runs.
    notes : tuple of str
        Why a quantity is missing.
    name : str
        The filter.
    nis_dof : ndarray, shape (samples,) or None
        D(k)/N, the mean number of channels present per run at each step, when
        some were missing (None: all m were present at every step).
    """

    t: np.ndarray
    nees: np.ndarray
    nis: np.ndarray
    n: int
    m: int
    runs: int
    nonfinite_runs: int = 0
    grown_runs: int = 0
    max_growth: float = 0.0
    notes: tuple = ()
    name: str = "filter"
    nis_dof: np.ndarray = None

    @property
    def nees_bounds(self) -> tuple[float, float] | None:
        """95 % bounds (C3) of the run-averaged NEES, or None."""
        return None if self.nees is None else chi2_bounds(self.n, self.runs)

    @property
    def nis_bounds(self) -> tuple[float, float] | None:
        """95 % bounds (C3) of the run-averaged NIS, or None."""
        return None if self.nis is None else chi2_bounds(self.m, self.runs)

    def window(self, window: Sequence[float]) -> dict[str, Any]:
        """Window mean and fraction of steps inside the bounds, for the NEES and the NIS; a JSON-ready dict."""
        mask = window_mask(self.t, window)
        out = {"window": [float(v) for v in window]}
        for key, values, bounds in (("nees", self.nees, self.nees_bounds), ("nis", self.nis, self.nis_bounds)):
            if values is None:
                out[key] = out[f"{key}_inside"] = None
                continue
            v = values[mask]
            if key == "nis" and self.nis_dof is not None:  # channels missing: per-step dof and bounds
                D = self.runs * self.nis_dof[mask]
                ok = D > 0
                lo, hi = (self.m * chi2.ppf(q, D[ok]) / D[ok] for q in (0.025, 0.975))
                v = v[ok]
                out["nis"] = float(np.mean(v)) if v.size else None
                out["nis_inside"] = float(np.mean((v >= lo) & (v <= hi))) if v.size else None
                out["nis_dof_mean"] = float(np.mean(D[ok])) / self.runs if v.size else 0.0
                continue
            with np.errstate(all="ignore"):
                out[key] = float(np.mean(v))
                out[f"{key}_inside"] = float(np.mean((v >= bounds[0]) & (v <= bounds[1])))
        return out

    def divergence(self, windows: Iterable[Sequence[float]] = ()) -> tuple[bool, list[str]]:
        """``(diverged, reasons)`` by the criteria of the module docstring, over the given windows."""
        lev, reasons = self.divergence_level(windows)
        return lev >= 1, reasons

    def divergence_level(self, windows: Iterable[Sequence[float]] = ()) -> tuple[int, list[str]]:
        """``(level, reasons)``: 0 consistent, 1 over-confident (mean NEES beyond its 95 % bound), 2 runaway or
        grossly over-confident (beyond :data:`NEES_FACTOR` times the bound); see the module docstring."""
        reasons, lev = [], 0
        if self.nonfinite_runs:
            reasons.append(f"{self.nonfinite_runs} of {self.runs} runs have non-finite estimates")
            lev = 2
        if self.grown_runs:
            reasons.append(f"{self.grown_runs} of {self.runs} runs have an error norm beyond {DIVERGENCE_FACTOR:g} "
                           f"times their initial error scale (largest ratio {self.max_growth:.3g})")
            lev = 2
        if self.nees is not None:
            hi = self.nees_bounds[1]
            for w in windows:
                mean = self.window(w)["nees"]
                if not np.isfinite(mean) or mean < 0:
                    reasons.append(f"mean NEES {mean:.4g} over t = {w[0]:g}..{w[1]:g} s: the covariance is not finite "
                                   "or not positive definite")
                    lev = 2
                elif mean > NEES_FACTOR * hi:
                    reasons.append(f"mean NEES {mean:.4g} over t = {w[0]:g}..{w[1]:g} s is beyond {NEES_FACTOR:g} "
                                   f"times its 95 % upper bound {hi:.4g} (n = {self.n}, {self.runs} runs): grossly "
                                   "over-confident")
                    lev = 2
                elif mean > hi:
                    reasons.append(f"mean NEES {mean:.4g} over t = {w[0]:g}..{w[1]:g} s is beyond its 95 % upper bound "
                                   f"{hi:.4g} (n = {self.n}, {self.runs} runs): over-confident")
                    lev = max(lev, 1)
        return lev, reasons

    def summary(self, windows: Mapping[str, Sequence[float]]) -> dict[str, Any]:
        """JSON-ready: bounds, per-window NEES/NIS, ``diverged`` and its reasons, the notes.

        Parameters
        ----------
        windows : dict
            Name → (start, end), s.
        """
        level, reasons = self.divergence_level(windows.values())
        diverged = level >= 1
        lo_hi = lambda b: None if b is None else list(b)
        return {"nees_dof": self.n if self.nees is not None else None, "nis_dof": self.m if self.nis is not None else None,
                "nees_bounds": lo_hi(self.nees_bounds), "nis_bounds": lo_hi(self.nis_bounds),
                "windows": {name: self.window(w) for name, w in windows.items()},
                "diverged": diverged, "diverged_level": level, "diverged_reasons": reasons, "nonfinite_runs": self.nonfinite_runs,
                "diverged_runs": self.grown_runs + self.nonfinite_runs, "notes": list(self.notes)}


def warn_if_diverged(summary: Mapping[str, Any], name: str, stacklevel: int = 2) -> None:
    """Issue a :class:`FilterDivergenceWarning` when a :meth:`ConsistencyStatistics.summary` says ``diverged``."""
    if summary.get("diverged"):
        warnings.warn(f"filter {name!r} diverged: " + "; ".join(summary["diverged_reasons"]), FilterDivergenceWarning,
                      stacklevel=stacklevel + 1)


def consistency(result: SimulationResult | ArrayLike, xhat0: ArrayLike | None = None,
                windows: Mapping[str, Sequence[float]] | None = None, *, xhat: ArrayLike | None = None,
                P: ArrayLike | None = None, t: ArrayLike | None = None, innovation: ArrayLike | None = None,
                S: ArrayLike | None = None, state: Any = None,
                name: str = "filter") -> tuple[ConsistencyStatistics, dict[str, Any]]:
    """Consistency of a :class:`~hinfnav.sim.SimulationResult` (full histories), or of plain arrays; warns when it diverged.

    Parameters
    ----------
    result : SimulationResult or array_like, shape (runs, n_samples, n_stored)
        A simulation result with its covariance ``P`` (a kept diagonal only,
        ``keep_covariance="diagonal"``, gives no NEES) and, for the NIS, the
        diagnostics :data:`NIS_KEYS` (``hinfnav.simulate`` keeps them;
        unless told ``keep_covariance=False`` or
        ``diagnostics=False``); or the true states x, with ``xhat`` and ``P``.
    xhat0 : array_like, shape (n_stored,) or (runs, n_stored), optional
        The filters' initial estimate(s) (for the initial error scale; default
        ``result.xhat0``).
    windows : dict, optional
        Name → (start, end) s; default the whole run.
    xhat, P : array_like, optional
        With an array ``result``: the estimates (runs, n_samples, n_stored)
        and their covariances (runs, n_samples, n, n) (or (n_samples, n, n)
        shared; None: no NEES).
    t : array_like, shape (n_samples,), optional
        Sample times, s (default 0, 1, 2 …).
    innovation, S : array_like, optional
        Innovations (runs, n_samples, m) and their covariances, for the NIS.
    state : StateSpec, optional
        The state's error definition (default x − x̂).
    name : str
        The filter's name (arrays only).

    Returns
    -------
    (ConsistencyStatistics, dict)
        The statistics and their :meth:`~ConsistencyStatistics.summary`.
    """
    if hasattr(result, "error") and hasattr(result, "xhat"):
        if any(v is not None for v in (xhat, P, t, innovation, S, state)):
            raise InputError("consistency: give a SimulationResult alone, or true states with xhat=, P= … (arrays)")
        t, x, xh, P, spec = result.t, result.x, result.xhat, result.P, result.state
        diag = result.diagnostics or {}
        innovation, S = diag.get(NIS_KEYS[0]), diag.get(NIS_KEYS[1])
        xhat0 = result.xhat0 if xhat0 is None else xhat0
        name = result.settings.get("filter", "filter")
    else:
        x = np.asarray(result, dtype=float)
        if xhat is None:
            raise InputError("consistency: with the true states as an array, give the estimates xhat= (and P=)")
        xh, spec = np.asarray(xhat, dtype=float), state
        if x.ndim != 3 or xh.shape != x.shape:
            raise InputError(f"consistency: the true states {x.shape} and xhat {xh.shape} must both be "
                             "(runs, n_samples, n)")
        t = np.arange(x.shape[1], dtype=float) if t is None else np.asarray(t, dtype=float)
        if t.shape != (x.shape[1],):
            raise InputError(f"consistency: t must have shape ({x.shape[1]},); got {t.shape}")
        if P is not None:
            P = np.asarray(P, dtype=float)
            if P.ndim == 3 and P.shape[0] == x.shape[1] and P.shape[1] == P.shape[2]:  # one history for every run
                P = np.broadcast_to(P, (x.shape[0],) + P.shape)
            if P.ndim != 4 or P.shape[:2] != x.shape[:2] or P.shape[2] != P.shape[3]:
                raise InputError(f"consistency: P must be (runs, n_samples, n, n) matching x {x.shape}; got {P.shape}")
    windows = {"all": (float(t[0]), float(t[-1]))} if windows is None else dict(windows)
    err = spec.error(x, xh) if spec is not None else x - xh
    if P is not None and P.ndim == 3:  # a kept diagonal only: no NEES
        P = None
    scale0 = None
    if xhat0 is not None:
        x0 = x[:, 0]
        e_prior = spec.error(x0, np.broadcast_to(np.asarray(xhat0, dtype=float), x0.shape)) \
            if spec is not None else x0 - np.asarray(xhat0, dtype=float)
        scale0 = initial_scale(e_prior, None if P is None else P[:, 0], err[:, 0])
    acc = ConsistencyAccumulator(x.shape[0])
    acc.add(t, err, P, innovation, S, scale0)
    stats = acc.result(name)
    summary = stats.summary(windows)
    warn_if_diverged(summary, name)
    return stats, summary
