"""Moment rules of the Kalman core: how the predicted reading and its covariances are computed.

Every filter of the Kalman core (:class:`~hinfnav.estimators.kalman.KalmanCore`) corrects its prior with the
moments of the predicted reading: its mean ``ȳ``, the innovation covariance ``S = P_yy + R`` and the cross
covariance ``P_xy``. A *moment rule* computes them from the prior ``(x̂⁻, P⁻)``; the ideas that act on the
correction (Huber's M-estimation, :mod:`hinfnav.estimators.huber_filter`) or on the prior (strong tracking's
fading, :mod:`hinfnav.estimators.adaptive`) read the moments and never the rule, so any idea combines with any
rule (:mod:`hinfnav.estimators.strategies`).

* :data:`LINEARISED` — ``ȳ = h(x̂⁻)`` and the Jacobian ``H`` at the prior (the EKF): ``P_xy = P⁻ Hᵀ``,
  ``P_yy = H P⁻ Hᵀ``. The filter's ``observe`` hook gives ``(ȳ, H)``.
* :class:`~hinfnav.estimators.sigma_point.SigmaPointRule` — the unscented transform (or the cubature rule) of the
  prior through h (and of the posterior through f for the prediction): ``ȳ``, ``P_yy = Σ W^c dY dYᵀ``,
  ``P_xy = Σ W^c dX dYᵀ``.

An idea written for the linearised form ``(H, R)`` meets a sigma-point rule through its *statistical linear
regression* (SLR; Lefebvre, Bruyninckx & De Schutter, IEEE TAC 47(8), 2002; the Huber-based sigma-point filters
of Karlgaard & Schaub, JGCD 30(3), 2007, linearise the same way)::

    H̃ = P_xyᵀ (P⁻)⁻¹,      R̃ = R + P_yy − H̃ P⁻ H̃ᵀ                                   (M1)

which has ``H̃ P⁻ H̃ᵀ + R̃ = S`` and ``P⁻ H̃ᵀ = P_xy``: the Kalman correction (J1)-(J2) with ``(H̃, R̃)`` is the
sigma-point correction ``K = P_xy S⁻¹``, ``P⁺ = P⁻ − K S Kᵀ`` (expand (J2): ``P⁻ − K P_xyᵀ − P_xy Kᵀ + K S Kᵀ``).
``R̃ − R`` is the Schur complement of the sigma points' joint covariance, positive semidefinite when every
``W^c ≥ 0``. The plain sigma-point filter uses ``K = P_xy S⁻¹`` directly; only an idea reads (M1).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from .base import FilterState

__all__ = ["LINEARISED", "LinearisedRule", "Moments", "statistical_linearisation"]


class Moments(NamedTuple):
    """The moments of one predicted reading, all runs at once.

    Fields: ``yhat`` (runs, m), the predicted reading ȳ; ``H`` (m, n) or (runs, m, n), the Jacobian at the
    prior (linearised rule; None for a sigma-point rule); ``dX`` (runs, N, n), the deviations of the state's
    sigma points from the prior, and ``dY`` (runs, N, m), those of their predicted readings from ȳ
    (sigma-point rule; None for the linearised one).
    """

    yhat: NDArray[np.float64]
    H: NDArray[np.float64] | None = None
    dX: NDArray[np.float64] | None = None
    dY: NDArray[np.float64] | None = None


def statistical_linearisation(P: NDArray[np.float64], Pxy: NDArray[np.float64],
                              S: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(H̃, R̃)`` of (M1) from the prior P (runs, n, n), ``P_xy`` (runs, n, m) and ``S = P_yy + R`` (runs, m, m).

    ``R̃ = S − H̃ P H̃ᵀ`` (symmetrised) equals ``R + P_yy − H̃ P H̃ᵀ``; a channel removed from S (unit diagonal,
    zero row of ``P_xy``) keeps its unit row in R̃ and a zero row in H̃, as
    :func:`~hinfnav.estimators.correction.drop_missing` removes it.
    """
    H = np.swapaxes(np.linalg.solve(P, Pxy), -1, -2)
    R = S - H @ P @ np.swapaxes(H, -1, -2)
    return H, 0.5 * (R + np.swapaxes(R, -1, -2))


class LinearisedRule:
    """The linearised moment rule (the EKF's): ``(h(x̂⁻), H)`` from the filter's ``observe`` hook.

    The prediction of a filter on this rule is its own ``_predict`` (``Φ P Φᵀ + Q`` with Φ the transition matrix
    or the dynamics' Jacobian, or an augmented filter's); :data:`LINEARISED` is the one instance.
    """

    #: The moments depend on P⁻ (drawn from it): False here (H depends on x̂⁻ only)
    sigma_points = False
    name = "linearised"

    def measurement_moments(self, core: Any, x: NDArray[np.float64], P: NDArray[np.float64], k: int) -> Moments:
        """``Moments(ȳ, H)`` at the prior ``x`` (runs, n_x); P and k are not used."""
        yhat, H = core.observe(x)
        return Moments(yhat, H)

    def predict(self, core: Any, state: FilterState, u: NDArray[np.float64] | None) -> FilterState:
        """The filter's own linearised prediction (its ``_predict``)."""
        return core._predict(state, u)

    def __repr__(self) -> str:
        return "LinearisedRule()"


#: The linearised rule of every Kalman-core filter that does not set another.
LINEARISED = LinearisedRule()
