"""The one steady-gain freeze of the package.

A filter whose covariance recursion does not depend on the data (the
extended-state Algorithms 1-3 on unclipped readings) may freeze its gains once
the recursion has converged: every ``CHECK_EVERY`` steps each prior covariance
P⁻ is compared with its value ``CHECK_EVERY`` steps before, entry by entry
relative to √(P_ii P_jj); when every entry has changed by at most
``steady_tol`` per step, the current priors (and, at the next update, the
gains) are kept from then on. :func:`freeze_gain` is the check; the filter
keeps the returned record in ``FilterState.extra["steady"]``.
"""

import numpy as np

__all__ = ["CHECK_EVERY", "freeze_gain"]

#: The convergence of P⁻ is checked every CHECK_EVERY steps (against P⁻ of CHECK_EVERY steps before).
CHECK_EVERY = 64


def _converged(new, old, tol):
    """Largest change of P⁻ since the last check, each entry relative to √(P_ii P_jj), at most ``tol`` per step."""
    if tol is None or old is None or np.shape(new) != np.shape(old):
        return False
    tol = tol * CHECK_EVERY
    d = np.sqrt(np.abs(np.diagonal(new, axis1=-2, axis2=-1)))
    scale = d[..., :, None] * d[..., None, :]
    return bool(np.all(np.abs(new - old) <= tol * scale))


def freeze_gain(steady_tol, k, extra, **priors):
    """The steady record ``{name: P⁻}`` when every prior has converged at step k, else None.

    Parameters
    ----------
    steady_tol : float or None
        Largest relative change of P⁻ per step (None: never freeze).
    k : int
        Index of the step just predicted from (the check runs when k + 1 is a multiple of ``CHECK_EVERY``).
    extra : dict
        The filter state's extra items; the priors of this check are stored in it (``check_<name>``).
    **priors : ndarray
        The prior covariances by name.
    """
    if steady_tol is None or (k + 1) % CHECK_EVERY:
        return None
    done = all(_converged(P, extra.get("check_" + key), steady_tol) for key, P in priors.items())
    extra.update({"check_" + key: P for key, P in priors.items()})
    return dict(priors) if done else None
