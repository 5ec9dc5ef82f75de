"""What every estimator checks at its door: the reading size limit, the known diagnostics, the initial estimates.

Split from :mod:`hinfnav.estimators.base` (which re-exports these names) to keep that module short.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_vector

__all__ = ["READING_LIMIT", "KNOWN_DIAGNOSTICS", "initial_estimates", "check_reading_size"]

#: Largest magnitude of a reading a filter accepts: beyond it a squared innovation (an innovation moment, a Huber weight, a
#: converted range) overflows double precision, and the NumPy and compiled paths would fail differently.
READING_LIMIT = 1e150

#: Every diagnostic name a hinfnav filter reports (collected over the registered estimators). A name asked of
#: :meth:`Estimator.estimate` that is neither among these nor reported by the filter is refused (issue 36: a
#: misspelt name is never ignored); a known name a filter does not report is left out, so one list can be asked
#: of several filters (the consistency statistics ask every filter for the NIS inputs, a study for the weights).
KNOWN_DIAGNOSTICS = ("converged", "existence_margin", "existence_ok", "fading", "fading_c", "gate_count",
                     "gate_distance", "gate_recovery", "gate_rejected", "innovation", "innovation_covariance",
                     "input_estimate", "input_rate", "iterations", "noise_variance", "q_adapted", "saturated",
                     "scale_measurement", "scale_prior", "theta", "theta_alg2", "vb_alpha", "vb_beta", "weights")


def initial_estimates(xhat0: ArrayLike, n_state: int, runs: int) -> NDArray[np.float64]:
    """``xhat0`` checked: one prior estimate (n,) for every run, or one per run (runs, n); finite floats."""
    arr = np.asarray(xhat0, dtype=float) if not isinstance(xhat0, np.ndarray) else xhat0.astype(float, copy=False)
    if arr.ndim == 2:
        if arr.shape != (runs, n_state):
            raise InputError(f"xhat0 must have shape (n,) = ({n_state},) or (runs, n) = ({runs}, {n_state}); "
                             f"got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise InputError("xhat0 must contain only finite numbers; it has NaN or inf entries")
        return arr
    return as_vector("xhat0", xhat0, n_state)


def check_reading_size(y, what):
    """Refuse a reading ``y`` with an entry beyond :data:`READING_LIMIT` (``what`` names it)."""
    big = np.nanmax(np.abs(y), initial=0.0)
    if big > READING_LIMIT:
        raise InputError(f"{what} has an entry of magnitude {big:.3g}, beyond {READING_LIMIT:g}: its square overflows "
                         "double precision inside a filter (check the units, or the reading is corrupt)")
