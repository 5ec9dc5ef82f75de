"""Confidence interval of a mean over Monte Carlo runs: the one interval function of the package.

For ``n`` independent runs with sample mean :math:`\\bar x` and standard
deviation :math:`s` (``ddof = 1``), the two-sided interval of level ``1 − α``
is (Student, 1908; e.g. Montgomery & Runger, *Applied Statistics*, eq. 8-16)

.. math::

    \\bar x \\pm t_{1-\\alpha/2,\\,n-1} \\, s / \\sqrt{n},

exact for Gaussian per-run values and, unlike the normal quantile 1.96, right
for the 2–5 runs of the short sweeps (``t_{0.975, 1} = 12.7``, ``t_{0.975, 4} = 2.78``).
With one run there is no interval: the half-width is NaN (reported as "n/a").
"""

from __future__ import annotations

import numpy as np
import scipy.stats
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError

__all__ = ["t_half_width", "mean_interval", "format_interval"]


def t_half_width(values: ArrayLike, axis: int = 0, level: float = 0.95) -> float | NDArray[np.float64]:
    """Half-width :math:`t_{(1+level)/2,\\,n-1}\\, s/\\sqrt{n}` of the interval of the mean along ``axis``.

    Parameters
    ----------
    values : array_like
        Per-run values (units of the statistic), runs along ``axis``.
    axis : int, optional
    level : float, optional
        Confidence level in (0, 1); default 0.95.

    Returns
    -------
    float or ndarray
        The half-width (units of ``values``); NaN where fewer than 2 runs.
    """
    values = np.asarray(values, dtype=float)
    if values.ndim == 0:
        raise InputError("values must hold one value per run (an array); got a scalar")
    level = float(level)
    if not 0.0 < level < 1.0:
        raise InputError(f"level must be in (0, 1); got {level}")
    n = values.shape[axis]
    if n < 2:
        shape = np.delete(np.array(values.shape), axis % values.ndim)
        out = np.full(tuple(shape), np.nan)
        return float(out) if out.ndim == 0 else out
    half = scipy.stats.t.ppf(0.5 + level / 2.0, n - 1) * values.std(axis=axis, ddof=1) / np.sqrt(n)
    return float(half) if np.ndim(half) == 0 else half


def mean_interval(values: ArrayLike, axis: int = 0,
                  level: float = 0.95) -> tuple[float | NDArray[np.float64], float | NDArray[np.float64], float | NDArray[np.float64]]:
    """Mean along ``axis`` and its Student-t interval: ``(mean, low, high)`` (NaN bounds for one run)."""
    values = np.asarray(values, dtype=float)
    half = t_half_width(values, axis=axis, level=level)
    mean = values.mean(axis=axis)
    mean = float(mean) if np.ndim(mean) == 0 else mean
    return mean, mean - half, mean + half


def format_interval(low: float | None, high: float | None, fmt: str = ".3g", sep: str = "–") -> str:
    """``"low–high"``, or ``"n/a (1 run)"`` when the interval is undefined (NaN or None bounds)."""
    if low is None or high is None or not (np.isfinite(low) and np.isfinite(high)):
        return "n/a (1 run)"
    return f"{low:{fmt}}{sep}{high:{fmt}}"
