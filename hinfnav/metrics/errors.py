"""Error metrics of simulated estimation runs, for any state dimension.

Every function works on error histories of shape (runs, n_samples, n) (or
(n_samples, n) for one run) and returns one number per state component; the
state's groups (``"position"``, ``"velocity"`` …, from its
:class:`~hinfnav.systems.StateSpec`) select components by name
(:func:`by_group`, :func:`group_rms`), so no metric slices ``[:3]``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from .intervals import t_half_width

if TYPE_CHECKING:
    from ..systems.state import StateSpec

__all__ = [
    "window_mask",
    "rms_error",
    "rms_per_run",
    "max_error",
    "convergence_time",
    "check_tolerance",
    "MonteCarloSummary",
    "monte_carlo_summary",
    "by_group",
    "group_rms",
    "axes_rms",
]


def _float_array(name, value):
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be an array of real numbers; got {type(value).__name__} ({exc})") from None


def _check_error(error, t):
    error = _float_array("error", error)
    if error.ndim == 2:
        error = error[None]
    if error.ndim != 3 or min(error.shape) < 1:
        raise InputError(f"error must have shape (runs, n_samples, n) or (n_samples, n), none of them 0; "
                         f"got {np.shape(error)}")
    t = _float_array("t", t)
    if t.shape != (error.shape[1],):
        raise InputError(f"t must have shape ({error.shape[1]},) to match error; got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InputError("t must contain only finite times (s); it has NaN or inf entries")
    if not np.all(np.isfinite(error)):
        bad = np.argwhere(~np.isfinite(error))[0]
        raise InputError(
            f"error must be finite; it has NaN or inf (first at run {bad[0]}, sample {bad[1]}, component {bad[2]}): "
            "the estimator diverged or the data are corrupt, so an RMS would be meaningless"
        )
    return error, t


def window_mask(t: ArrayLike, window: Sequence[float]) -> NDArray[np.bool_]:
    """Boolean mask of the samples with ``start <= t <= end``.

    Raises
    ------
    InputError
        If the window is not a pair with start < end or holds no sample.
    """
    t = np.asarray(t, dtype=float)
    try:
        start, end = (float(w) for w in window)
    except (TypeError, ValueError):
        raise InputError(f"window must be a pair (start, end) in seconds; got {window!r}") from None
    if not start < end:
        raise InputError(f"window must have start < end; got ({start}, {end})")
    mask = (t >= start - 1e-9) & (t <= end + 1e-9)
    if not mask.any():
        raise InputError(f"window ({start}, {end}) s holds no sample of t in [{t[0]}, {t[-1]}] s")
    return mask


def rms_per_run(error: ArrayLike, t: ArrayLike, window: Sequence[float]) -> NDArray[np.float64]:
    """RMS of each error component over a time window, per run.

    Parameters
    ----------
    error : array_like, shape (runs, n_samples, n)
    t : array_like, shape (n_samples,)
    window : (float, float)
        Start and end time, s.

    Returns
    -------
    ndarray, shape (runs, n)
        In the units of each state component.
    """
    error, t = _check_error(error, t)
    mask = window_mask(t, window)
    return np.sqrt(np.mean(error[:, mask] ** 2, axis=1))


def rms_error(error: ArrayLike, t: ArrayLike, window: Sequence[float]) -> NDArray[np.float64]:
    """RMS of each error component pooled over the runs and a time window, shape (n,)."""
    error, t = _check_error(error, t)
    mask = window_mask(t, window)
    return np.sqrt(np.mean(error[:, mask] ** 2, axis=(0, 1)))


def max_error(error: ArrayLike, t: ArrayLike, window: Sequence[float]) -> NDArray[np.float64]:
    """Largest absolute error per component over runs and window, shape (n,)."""
    error, t = _check_error(error, t)
    mask = window_mask(t, window)
    return np.max(np.abs(error[:, mask]), axis=(0, 1))


def check_tolerance(tol: ArrayLike, n: int) -> NDArray[np.float64]:
    """Per-component tolerance (one number or ``n``), finite and > 0, as an array of shape (n,)."""
    tol = _float_array("tol", tol)
    if tol.ndim > 1 or tol.size not in (1, n):
        raise InputError(f"tol must be one number or one per component ({n}); got shape {tol.shape}")
    tol = np.broadcast_to(tol, (n,))
    if not np.all(np.isfinite(tol)) or np.any(tol <= 0):
        raise InputError(f"tol must be finite and > 0 for every component; got {tol}")
    return tol


def convergence_time(error: ArrayLike, t: ArrayLike, tol: ArrayLike, *, nonfinite: str = "refuse") -> NDArray[np.float64]:
    """Time after which every error component stays within its tolerance (the package's one convergence time).

    Parameters
    ----------
    error : array_like, shape (runs, n_samples, n)
    t : array_like, shape (n_samples,)
    tol : array_like, shape (n,) or float
        Tolerance of each component, in its units (> 0).
    nonfinite : {"refuse", "outside"}
        A NaN or infinite error is refused (InputError), or counts as outside
        the tolerance (streaming statistics of runs that may diverge).

    Returns
    -------
    ndarray, shape (runs,)
        The first t_k from which ``|e_i(t_j)| <= tol_i`` for all j ≥ k and all
        components; ``nan`` for a run that never settles (outside at the last sample).
    """
    if nonfinite not in ("refuse", "outside"):
        raise InputError(f"nonfinite must be 'refuse' or 'outside'; got {nonfinite!r}")
    if nonfinite == "refuse":
        error, t = _check_error(error, t)
    else:
        error, t = _float_array("error", error), _float_array("t", t)
        if error.ndim != 3 or t.shape != (error.shape[1],):
            raise InputError(f"error must have shape (runs, n_samples, n) and t (n_samples,); got {error.shape}, {t.shape}")
    tol = check_tolerance(tol, error.shape[2])
    with np.errstate(invalid="ignore"):
        outside = ~np.all(np.abs(error) <= tol, axis=2)  # (runs, n_samples); NaN is outside
    n = t.size
    last = np.where(outside.any(axis=1), n - 1 - np.argmax(outside[:, ::-1], axis=1), -1)
    out = np.full(error.shape[0], np.nan)
    ok = last < n - 1
    out[ok] = t[last[ok] + 1]
    return out


@dataclass(frozen=True, eq=False)
class MonteCarloSummary:
    """Statistics of per-run RMS errors over Monte Carlo runs.

    Attributes
    ----------
    runs : int
    mean : ndarray, shape (n,)
        Mean over runs of the per-run RMS error (units of each component).
    ci95 : ndarray, shape (2, n)
        95 % confidence interval of that mean (Student t,
        :func:`hinfnav.metrics.intervals.t_half_width`; NaN with one run).
    spread95 : ndarray, shape (2, n)
        2.5 and 97.5 percentiles of the per-run RMS (what one run may give).
    pooled : ndarray, shape (n,)
        RMS pooled over all runs and samples.
    """

    runs: int
    mean: np.ndarray
    ci95: np.ndarray
    spread95: np.ndarray
    pooled: np.ndarray


def monte_carlo_summary(error: ArrayLike, t: ArrayLike, window: Sequence[float]) -> MonteCarloSummary:
    """Summarize Monte Carlo runs by the statistics of their per-run RMS."""
    per_run = rms_per_run(error, t, window)
    runs = per_run.shape[0]
    mean = per_run.mean(axis=0)
    half = t_half_width(per_run, axis=0)  # NaN with one run: no interval
    error, t = _check_error(error, t)
    mask = window_mask(t, window)
    pooled = np.sqrt(np.mean(error[:, mask] ** 2, axis=(0, 1)))
    return MonteCarloSummary(
        runs=runs,
        mean=mean,
        ci95=np.vstack([mean - half, mean + half]),
        spread95=np.percentile(per_run, [2.5, 97.5], axis=0),
        pooled=pooled,
    )


def by_group(values: ArrayLike, state: StateSpec) -> dict[str, NDArray[np.float64]]:
    """Split per-component values (last axis = state) into the state's groups: ``{group: values}``."""
    return {g: state.select(values, g) for g in state.groups}


def group_rms(values: ArrayLike, state: StateSpec, group: str) -> float:
    """One number for a group: ``sqrt(mean(v²))`` over its components (how a table cell is formed)."""
    return axes_rms(state.select(values, group))


def axes_rms(values: ArrayLike) -> float:
    """One number from per-axis values: ``sqrt(mean(v²))`` over the last axis."""
    return float(np.sqrt(np.mean(np.square(values))))
