"""The NIS diagnostics of a compiled run, from its kernel's histories (NumPy; no numba).

A kernel (:mod:`hinfnav.estimators.compiled`) returns the estimates and
covariances of every run and step; the innovation and its covariance, the
diagnostics the consistency tests need (:data:`NIS_DIAGNOSTICS`, the names of
``hinfnav.metrics.NIS_KEYS``), follow from them with the filter's own
equations, vectorised over runs and steps:

* the prior of step k: ``x̂⁻₀ = x̂₀``, ``x̂⁻ₖ = F x̂⁺ₖ₋₁ + G uₖ₋₁`` (a filter that
  reports its prediction reports x̂⁻ itself), the innovation
  ``νₖ = yₖ − H x̂⁻ₖ``;
* ``P⁻₀ = P₀``, ``P⁻ₖ = F P⁺ₖ₋₁ Fᵀ + Q_d``; with strong tracking the faded
  ``Λ^{1/2} F P⁺ₖ₋₁ Fᵀ Λ^{1/2} + Q_d``, Λ from the innovations by (S1)-(S3)
  (the filter's :meth:`~hinfnav.estimators.adaptive.StrongTracking.fade_prior`,
  the NumPy path's functions); ``Sₖ = H P⁻ₖ Hᵀ + R``.

On a linear model these are the NumPy path's numbers up to the order of the
floating-point sums (``tests/test_compiled.py`` compares them to 1e-10).
The recursive H∞ filter reports the innovation only (as on the NumPy path).
"""

from __future__ import annotations

import numpy as np

from ..core.linalg import congruence

__all__ = ["NIS_DIAGNOSTICS", "nis_diagnostics"]

#: The diagnostics a compiled run computes (the innovation and its covariance S).
NIS_DIAGNOSTICS = ("innovation", "innovation_covariance")


def nis_diagnostics(est, keys, *, F, G, H, Qd, R, P_start, x0, y, u, use_input, filtered, xhat, P, strong,
                    with_S=True):
    """``{"innovation": (runs, steps, m), "innovation_covariance": (runs, steps, m, m)}`` (those in ``keys``).

    ``xhat`` (runs, steps, n) and ``P`` (runs or 1, steps, n, n) are the
    kernel's full histories (the estimate the filter reports: posterior when
    ``filtered``, else prior); ``P`` None when only the innovation is needed.
    """
    runs, steps, _ = y.shape
    if filtered:
        x_prior = np.empty_like(xhat)
        x_prior[:, 0] = x0
        x_prior[:, 1:] = xhat[:, :-1] @ F.T
        if use_input:
            x_prior[:, 1:] += u[:, :-1] @ G.T
    else:
        x_prior = xhat
    nu = y - x_prior @ H.T
    out = {"innovation": nu}
    if with_S and "innovation_covariance" in keys and P is not None:
        if filtered:
            P_prior = np.empty(P.shape)
            P_prior[:, 0] = P_start
            PPT = congruence(F, P[:, :-1])
            if strong:  # the filter's own (S1)-(S4)
                V0 = None
                for k in range(1, steps):
                    P_prior[:, k], V0 = est.fade_prior(PPT[:, k - 1], Qd, V0, nu[:, k], H)
            else:
                P_prior[:, 1:] = PPT + Qd
        else:
            P_prior = P
        S = congruence(H, P_prior) + R
        S = 0.5 * (S + np.swapaxes(S, -1, -2))
        out["innovation_covariance"] = np.broadcast_to(S, (runs,) + S.shape[1:]) if S.shape[0] != runs else S
    return {k: v for k, v in out.items() if k in keys}
