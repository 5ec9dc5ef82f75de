"""Runs and metrics of the GRACE study: every filter on every measurement variant, against the POD truth.

:func:`run_filter` is the step loop with dropouts: on an epoch without a measurement the Kalman-family
filters (``ExtendedKalmanFilter`` and the augmented filters) skip the update (predict only), and the
filters that must see a reading every step (the recursive H∞ filter, the LTI filters) are fed their own
predicted measurement, i.e. a zero innovation. (H1's ``missing="skip"`` of ``Estimator.estimate``
replaces this loop when merged.)

:func:`nees` is a small local function (H3's metrics function replaces it at merge): the normalised
estimation error squared ``ε_k = e_kᵀ P_k⁻¹ e_k`` of the 6-state error, averaged over the epochs after
:data:`SETTLE_S` (its expectation is 6 for a consistent filter).
"""

import numpy as np

from ...core.exceptions import InputError
from ...estimators import ExtendedKalmanFilter
from ...estimators.augmented import AugmentedEKF
from ...estimators.lti import LTIFilter

__all__ = ["SETTLE_S", "run_filter", "nees", "error_metrics"]

#: Errors before this time (s) are left out of the day's RMS and NEES (the initial transient).
SETTLE_S = 600.0


def _skips(est):
    return isinstance(est, (ExtendedKalmanFilter, AugmentedEKF))


def run_filter(est, y, available, x0, P0=None):
    """Run ``est`` on one day of readings ``y`` (n, m); returns ``(xhat (n, 6), P (n, 6, 6) or None)``."""
    y = np.asarray(y, float)
    available = np.asarray(available, bool)
    if y.ndim != 2 or available.shape != (y.shape[0],):
        raise InputError(f"y must be (n, m) and available (n,); got {y.shape} and {available.shape}")
    n = y.shape[0]
    state = est.start(x0, P0, runs=1)
    xhat = np.empty((n, 6))
    P_hist = np.full((n, 6, 6), np.nan)
    has_P = False
    for k in range(n):
        if available[k] or not _skips(est):
            yk = y[k]
            if not available[k]:
                if isinstance(est, LTIFilter):
                    yk = (state.x @ est.C_F.T)[0, :3]
                else:
                    yk = est.measurement.function(state.x)[0]
            state, out = est.update(state, yk[None, :])
            xhat[k] = out.xhat[0]
            if out.P is not None:
                P_hist[k] = np.asarray(out.P)[0] if np.ndim(out.P) == 3 else out.P
                has_P = True
        else:
            x = est.report(state.x) if isinstance(est, AugmentedEKF) else state.x
            P = est.report_covariance(state.P) if isinstance(est, AugmentedEKF) else state.P
            xhat[k] = x[0]
            P_hist[k] = P[0] if P.ndim == 3 else P
        if k < n - 1:
            state = est.predict(state, None)
    return xhat, (P_hist if has_P else None)


def nees(error, P, t, settle_s=SETTLE_S):
    """Mean NEES of the 6-state error after ``settle_s`` (module notes); NaN without a covariance."""
    if P is None:
        return float("nan")
    keep = t >= settle_s
    e, Pk = error[keep], P[keep]
    ok = np.all(np.isfinite(Pk), axis=(1, 2))
    return float(np.mean(np.einsum("ki,ki->k", e[ok], np.linalg.solve(Pk[ok], e[ok][..., None])[..., 0])))


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
