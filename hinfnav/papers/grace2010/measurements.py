"""Measurements of the GRACE study (issue 20, item 3): the real K-band range, simulated angles and GNSS.

Variants (:data:`VARIANTS`), every one on the 8640 epochs 00:00:00 … 23:59:50 where the K-band file has
data; every random number from one ``numpy.random.Generator`` (the ``seed``):

``kband_angles``
    The **real** K-band range (its noise measured by :func:`kband_noise`), with line-of-sight azimuth
    and elevation simulated from the truth with 1σ :data:`.constants.ANGLE_SIGMA_RAD` (paper 000's
    range/angle sensor, :class:`~hinfnav.systems.measurements.RangeAzimuthElevation`, sensor frame =
    Hill frame). The range's σ in the filters is the RMS of K-band minus POD baseline (the truth's own
    error is part of what a filter sees).
``gnss``
    Relative GNSS positions: the true Hill position plus white Gaussian noise, 1σ
    :data:`.constants.GNSS_SIGMA_M` per axis.
``gnss_outliers``
    As ``gnss``, and at a random :data:`.constants.OUTLIER_FRACTION` of the epochs an extra error of
    1σ :data:`.constants.OUTLIER_SCALE` × σ per axis (the filters are not told).
``gnss_dropouts``
    As ``gnss``, with no measurement in random blocks of 30 epochs (5 min) covering
    :data:`.constants.DROPOUT_FRACTION` of the day (``available`` False); the runner
    (:mod:`.studies`) skips the update on those steps.

Filters that need a linear measurement (the recursive H∞, LMI and mixed filters) use the range/angle
readings converted to a position (eq. (7) of paper 000) with the constant noise matrix of the
conversion at the day's mean reading (:func:`linear_form`).
"""

from dataclasses import dataclass

import numpy as np
from scipy.signal import savgol_coeffs, savgol_filter

from ...core.exceptions import InputError
from ...core.validation import as_choice, as_seed
from ...systems.hill import position_measurement
from ...systems.measurements import (
    ConvertedPosition,
    LinearMeasurement,
    RangeAzimuthElevation,
    position_from_range_angles,
    range_angles,
)
from .constants import (
    ANGLE_SIGMA_RAD,
    DROPOUT_FRACTION,
    GNSS_SIGMA_M,
    OUTLIER_FRACTION,
    OUTLIER_SCALE,
)

__all__ = ["VARIANTS", "MeasurementSet", "kband_noise", "make_measurements", "linear_form",
           "shared_model_groups"]

VARIANTS = ("kband_angles", "gnss", "gnss_outliers", "gnss_dropouts")
#: Length of one dropout block, epochs.
DROPOUT_BLOCK = 30


@dataclass(frozen=True, eq=False)
class MeasurementSet:
    """One variant's readings.

    Attributes
    ----------
    name : str
    y : ndarray, shape (n, m)
        Readings (m, or m and rad).
    model : MeasurementModel
        The model the Kalman-family filters use.
    available : ndarray of bool, shape (n,)
        False on dropout epochs.
    notes : str
    """

    name: str
    y: np.ndarray
    model: object
    available: np.ndarray
    notes: str


def kband_noise(data, savgol_length=11, order=3):
    """The K-band range's noise from the data (two independent estimates).

    1. Residual of a smooth fit: a Savitzky–Golay filter (``savgol_length`` epochs, polynomial ``order``) through
       the K-band series; the RMS residual, scaled by √(1/(1 − h₀)) for the fit's own leverage
       h₀ (the centre weight of the filter), is the white-noise σ at 10 s.
    2. Against the POD baseline: mean (a bias), standard deviation and max of ``K-band − |r_A − r_B|``.

    Returns
    -------
    dict (m)
    """
    k = data.kband
    res = k - savgol_filter(k, savgol_length, order)
    h0 = savgol_coeffs(savgol_length, order)[savgol_length // 2]
    inner = res[savgol_length:-savgol_length]
    d = k - data.baseline[: k.size]
    return {"savgol_window": savgol_length, "savgol_order": order,
            "sigma_smooth_fit_m": float(np.sqrt(np.mean(inner**2) / (1 - h0))),
            "kband_minus_pod_mean_m": float(d.mean()), "kband_minus_pod_std_m": float(d.std()),
            "kband_minus_pod_rms_m": float(np.sqrt(np.mean(d**2))), "kband_minus_pod_maxabs_m": float(np.abs(d).max())}


def make_measurements(data, variant, *, seed=0):
    """Build one variant (module notes) with the Generator of ``seed``; a :class:`MeasurementSet`."""
    variant = as_choice("variant", variant, VARIANTS)
    rng = np.random.default_rng(as_seed("seed", seed))
    n = data.kband.size
    truth = data.truth[:n]
    available = np.ones(n, dtype=bool)
    if variant == "kband_angles":
        noise = kband_noise(data)
        sigma_r = noise["kband_minus_pod_rms_m"]
        angles = range_angles(truth)[:, 1:] + ANGLE_SIGMA_RAD * rng.standard_normal((n, 2))
        y = np.column_stack([data.kband, angles])
        model = RangeAzimuthElevation(6, sigma_r, ANGLE_SIGMA_RAD)
        notes = (f"real K-band range (σ in the filters {sigma_r:.4f} m = RMS of K-band − POD baseline), simulated "
                 f"azimuth/elevation σ = {ANGLE_SIGMA_RAD:g} rad")
        return MeasurementSet(variant, y, model, available, notes)
    y = truth[:, :3] + GNSS_SIGMA_M * rng.standard_normal((n, 3))
    notes = f"simulated relative GNSS position, σ = {GNSS_SIGMA_M:g} m per Hill axis"
    if variant == "gnss_outliers":
        hit = rng.random(n) < OUTLIER_FRACTION
        y[hit] += OUTLIER_SCALE * GNSS_SIGMA_M * rng.standard_normal((int(hit.sum()), 3))
        notes += f"; outliers ({OUTLIER_SCALE:g} σ) at {hit.sum()} epochs ({hit.mean():.1%})"
    elif variant == "gnss_dropouts":
        blocks = int(round(DROPOUT_FRACTION * n / DROPOUT_BLOCK))
        starts = rng.choice(np.arange(1, n // DROPOUT_BLOCK), size=blocks, replace=False) * DROPOUT_BLOCK
        for s in starts:
            available[s: s + DROPOUT_BLOCK] = False
        notes += f"; no measurement at {(~available).sum()} epochs ({(~available).mean():.1%}) in {DROPOUT_BLOCK}-epoch blocks"
    return MeasurementSet(variant, y, position_measurement(GNSS_SIGMA_M * np.eye(3)), available, notes)


def linear_form(mset):
    """``(y_position (n, 3), LinearMeasurement)`` of a variant: positions as they are, or the range/angle
    readings converted by eq. (7) with the conversion's noise at the mean reading."""
    if not isinstance(mset, MeasurementSet):
        raise InputError(f"mset must be a MeasurementSet; got {type(mset).__name__}")
    if isinstance(mset.model, LinearMeasurement):
        return mset.y, mset.model
    R = ConvertedPosition(mset.model).noise_covariance(mset.y.mean(axis=0))
    return position_from_range_angles(mset.y), position_measurement(np.linalg.cholesky(R))


def shared_model_groups(sets):
    """The variants (name → :class:`MeasurementSet`) grouped by measurement model, in their order.

    Variants whose models are linear with equal H and R (the GNSS ones) form one group: the filters built
    for one of them are those of every one, so they run as one batch; any other variant is a group alone.
    """
    groups = []
    for name, ms in sets.items():
        for group in groups:
            m0 = sets[group[0]].model
            if (isinstance(ms.model, LinearMeasurement) and isinstance(m0, LinearMeasurement)
                    and np.array_equal(ms.model.H, m0.H) and np.array_equal(ms.model.R, m0.R)):
                group.append(name)
                break
        else:
            groups.append([name])
    return groups
