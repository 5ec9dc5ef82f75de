"""The one steady-gain freeze of the package.

A filter whose covariance recursion does not depend on the data (the
extended-state Algorithms 1-3 on unclipped readings, the recursive H∞ filter)
may freeze its gains once the recursion has converged: every ``every`` steps
(default :data:`CHECK_EVERY`) each covariance P of the recursion is compared
with its value ``every`` steps before, and when every one has changed by at
most ``steady_tol`` per step the current covariances (and, at the next update,
the gains) are kept from then on. Two measures of the change (``rule``):

* ``"entrywise"`` (default): ``|ΔP_ij| ≤ every · tol · √(P_ii P_jj)`` for every entry      (F1)
* ``"frobenius"``: ``‖P − P_old‖_F ≤ every · tol · ‖P_old‖_F``                              (F2)

:func:`freeze_gain` is the check; the filter keeps the returned record in
``FilterState.extra["steady"]`` and the compared values in
``extra["check_<name>"]``.
"""

import numpy as np

from ..core.validation import as_choice, as_int_at_least

__all__ = ["CHECK_EVERY", "RULES", "freeze_gain"]

#: The convergence of P⁻ is checked every CHECK_EVERY steps (against P⁻ of CHECK_EVERY steps before).
CHECK_EVERY = 64
#: The measures of the change of P: (F1) entry by entry, (F2) in the Frobenius norm.
RULES = ("entrywise", "frobenius")


def _converged(new, old, tol, rule):
    """Whether P changed by at most ``tol`` (already times the steps between checks) by (F1) or (F2)."""
    if old is None or np.shape(new) != np.shape(old):
        return False
    if rule == "frobenius":
        return bool(np.linalg.norm(new - old) <= tol * np.linalg.norm(old))
    d = np.sqrt(np.abs(np.diagonal(new, axis1=-2, axis2=-1)))
    scale = d[..., :, None] * d[..., None, :]
    return bool(np.all(np.abs(new - old) <= tol * scale))


def freeze_gain(steady_tol, k, extra, *, every=CHECK_EVERY, rule="entrywise", **priors):
    """The steady record ``{name: P}`` when every covariance has converged at step k, else None.

    Parameters
    ----------
    steady_tol : float or None
        Largest relative change of P per step (None: never freeze).
    k : int
        Index of the step (the check runs when k + 1 is a multiple of ``every``).
    extra : dict
        The filter state's extra items; the covariances of this check are stored in it (``check_<name>``),
        and a ``check_<name>`` put there beforehand (e.g. P₀) is the first value compared.
    every : int
        Steps between checks (default :data:`CHECK_EVERY`; 1: every step, against the previous P).
    rule : {"entrywise", "frobenius"}
        The measure of the change, (F1) or (F2).
    **priors : ndarray
        The covariances by name.
    """
    every = as_int_at_least("every", every, 1)
    if steady_tol is None or (k + 1) % every:
        return None
    tol = steady_tol * every
    rule = as_choice("rule", rule, RULES)
    done = all(_converged(P, extra.get("check_" + key), tol, rule) for key, P in priors.items())
    extra.update({"check_" + key: P for key, P in priors.items()})
    return dict(priors) if done else None
