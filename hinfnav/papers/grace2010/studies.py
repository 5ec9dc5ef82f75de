"""Runs and metrics of the GRACE study: every filter on every measurement variant, against the POD truth.

:func:`run_filter` runs one filter over the day with ``missing="skip"``: on an epoch without a
measurement the Kalman-family filters (``ExtendedKalmanFilter`` and the augmented filters) skip the update
(predict only), and the filters whose gains do not depend on the data (the recursive H∞ filter, the LTI
filters) are given their own predicted measurement, i.e. a zero innovation.

:func:`nees` is the normalised estimation error squared ``ε_k = e_kᵀ P_k⁻¹ e_k`` of the 6-state error
(:func:`hinfnav.metrics.normalized_squared`), averaged over the epochs after :data:`SETTLE_S` (its
expectation is 6 for a consistent filter).
"""

import numpy as np

from ...core.exceptions import InputError
from ...metrics import normalized_squared

__all__ = ["SETTLE_S", "run_filter", "nees", "error_metrics"]

#: Errors before this time (s) are left out of the day's RMS and NEES (the initial transient).
SETTLE_S = 600.0


def run_filter(est, y, available, x0, P0=None):
    """Run ``est`` on one day of readings ``y`` (n, m); returns ``(xhat (n, 6), P (n, 6, 6) or None)``.

    An unavailable reading is a missing one (``missing="skip"``): the Kalman-type filters skip the
    update there, the fixed-gain filters (LTI, recursive H∞) are given the reading they predict.
    Several variants of the day's readings under one measurement model run as one batch: ``y`` (runs, n, m)
    and ``available`` (runs, n) give ``xhat`` (runs, n, 6) and ``P`` (runs, n, 6, 6) (the runs are
    independent in the batched filters: each run's numbers are its own pass's, to rounding).
    """
    y = np.asarray(y, float)
    available = np.asarray(available, bool)
    one = y.ndim == 2
    if one:
        y, available = y[None], available[None]
    if y.ndim != 3 or available.shape != y.shape[:2]:
        raise InputError(f"y must be (n, m) or (runs, n, m) and available (n,) or (runs, n); got {np.shape(y)} and "
                         f"{np.shape(available)}")
    runs, n = y.shape[:2]
    est.missing = "skip"
    hist = est.estimate(np.where(available[..., None], y, np.nan), np.zeros((runs, n, est.n_input)), x0, P0)
    P = None if hist.P is None else np.asarray(hist.P)
    return (hist.xhat[0], None if P is None else P[0]) if one else (hist.xhat, P)


def nees(error, P, t, settle_s=SETTLE_S):
    """Mean NEES of the 6-state error after ``settle_s`` (module notes); NaN without a covariance."""
    if P is None:
        return float("nan")
    keep = t >= settle_s
    e, Pk = error[keep], P[keep]
    ok = np.all(np.isfinite(Pk), axis=(1, 2))
    return float(np.mean(normalized_squared(e[ok], Pk[ok])))


def error_metrics(xhat, P, truth, t, period_s, settle_s=SETTLE_S):
    """RMS errors per axis over the day (after ``settle_s``) and per orbit, and the NEES.

    Returns
    -------
    dict
        ``rms_per_axis`` (x, y, z m; vx, vy, vz m/s), ``rms_position_m``, ``rms_velocity_m_s``,
        ``rms_position_per_orbit_m`` (one per started orbit of GRACE-B), ``max_position_m``, ``nees``.
    """
    e = xhat - truth
    keep = t >= settle_s
    rms = np.sqrt(np.mean(e[keep] ** 2, axis=0))
    orbit = np.floor(t / period_s).astype(int)
    pos2 = np.sum(e[:, :3] ** 2, axis=1)
    per_orbit = [float(np.sqrt(np.mean(pos2[(orbit == i) & keep]))) for i in range(orbit.max() + 1)
                 if np.any((orbit == i) & keep)]
    return {"rms_per_axis": rms.tolist(), "rms_position_m": float(np.sqrt(np.sum(rms[:3] ** 2))),
            "rms_velocity_m_s": float(np.sqrt(np.sum(rms[3:] ** 2))), "rms_position_per_orbit_m": per_orbit,
            "max_position_m": float(np.sqrt(pos2[keep].max())), "nees": nees(e, P, t, settle_s)}
