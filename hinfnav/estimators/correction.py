"""The Kalman correction of every Kalman-type filter, and the exact removal of missing channels.

:func:`joseph_update` is the one Joseph-form update of the package (the EKF,
the Huber filter's Kalman start, the augmented and attitude filters, the
extended-state Algorithm 1 and, through it, Algorithm 3); its covariance (J2)
is :func:`hinfnav.core.linalg.joseph_covariance` (re-exported here), which
Algorithm 2 and the posterior Cramér–Rao bound call directly:

* ``S = H P Hᵀ + R``, ``K = P Hᵀ S⁻¹``, ``δx = K ν``                       (J1)
* ``P⁺ = (I − K H) P (I − K H)ᵀ + K R Kᵀ``                              (J2)

batched over runs (P shared (n, n) or per run (runs, n, n); H (m, n) or
(runs, m, n); R (m, m) or (runs, m, m)).

:func:`drop_missing` removes the channels a reading lacks (NaN, with
``missing="skip"``) *exactly*: for run r with channel j missing, row j of H
and the innovation's entry j are set to 0 and row/column j of R to 0 with
``R_jj = 1``. Then ``S`` is block diagonal with ``S_jj = 1``, column j of
``K = P Hᵀ S⁻¹`` is exactly 0, and the rest of K, δx and P⁺ are those of the
filter built without channel j (the kept block of S is that filter's S, and
the zero rows of H contribute nothing to (J1)-(J2)). Per run, with different
masks; when every run lacks the same channels, H and R stay shared and a
shared P stays shared. The Huber regression on such rows is exact as well:
a zero row of the whitened regression has residual 0 whatever the state.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.linalg import inv_spd, joseph_covariance, matmul_shared

__all__ = ["KalmanCorrection", "drop_missing", "joseph_covariance", "joseph_update", "kalman_gain"]


def _swap(M):
    return np.swapaxes(M, -1, -2)


def drop_missing(P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64], innovation: NDArray[np.float64],
                 mask: NDArray[np.bool_] | None) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(P, H, R, innovation)`` with the channels ``~mask`` removed exactly (see the module docstring).

    Parameters
    ----------
    P : ndarray, shape (n, n) or (runs, n, n)
    H : ndarray, shape (m, n) or (runs, m, n)
    R : ndarray, shape (m, m) or (runs, m, m)
    innovation : ndarray, shape (runs, m)
        NaN allowed on the missing channels.
    mask : ndarray of bool, shape (runs, m), or None
        True where the channel is available; None: all are.

    Returns
    -------
    tuple
        P is broadcast to one covariance per run when the masks differ
        between runs (a shared P otherwise stays shared).
    """
    if mask is None:
        return P, H, R, innovation
    innovation = np.where(mask, innovation, 0.0)
    if np.all(mask == mask[:1]):
        keep = mask[0]
        H = np.where(keep[:, None], H, 0.0)
        both = keep[:, None] & keep[None, :]
    else:
        H = np.where(mask[:, :, None], H, 0.0)
        both = mask[:, :, None] & mask[:, None, :]
        if P.ndim == 2:
            P = np.broadcast_to(P, (mask.shape[0],) + P.shape).copy()
    R = np.where(both, R, 0.0) + np.eye(R.shape[-1]) * ~both.diagonal(axis1=-2, axis2=-1)[..., None, :]
    return P, H, R, innovation


def kalman_gain(P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64], *, symmetrize: bool = True) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Gain and Joseph-form posterior covariance (J1)-(J2), batched; returns ``(K, P⁺, S)``.

    Shapes as in :func:`joseph_update`; K is (n, m) when P, H and R are shared,
    else (runs, n, m).
    """
    HT = _swap(H)
    PHT = matmul_shared(P, HT)
    if PHT.ndim == 2 or not symmetrize:
        S = H @ PHT + R
    else:  # H P Hᵀ = (P Hᵀ)ᵀ Hᵀ (P symmetric): the order of the sums of the augmented core, whose numbers it keeps
        S = matmul_shared(_swap(PHT), HT) + R
    K = PHT @ inv_spd(S)
    return K, joseph_covariance(P, K, H, R, symmetrize=symmetrize), S


def joseph_update(P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64], innovation: NDArray[np.float64], *,
                  symmetrize: bool = True) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The Kalman correction (J1)-(J2), batched; returns ``(δx, P⁺, S)``.

    Parameters
    ----------
    P : ndarray, shape (n, n) or (runs, n, n)
        Prior covariance (symmetric positive definite).
    H : ndarray, shape (m, n) or (runs, m, n)
    R : ndarray, shape (m, m) or (runs, m, m)
    innovation : ndarray, shape (runs, m)
    symmetrize : bool
        Return the symmetric part of P⁺ (True) or (J2) as computed.

    Returns
    -------
    dx : ndarray, shape (runs, n)
    P_post : ndarray, shape of P (per run if H or R is)
    S : ndarray, shape (m, m) when shared, else (runs, m, m)
        The innovation covariance.
    """
    K, P_post, S = kalman_gain(P, H, R, symmetrize=symmetrize)
    if K.ndim == 2:
        dx = innovation @ K.T
    else:
        dx = (K @ innovation[..., None])[..., 0]
    return dx, P_post, S


class KalmanCorrection:
    """The correction hook shared by both Kalman cores: (J1)-(J2) in error coordinates.

    ``correct_error(P, H, R, innovation) -> (δx, P⁺, diagnostics)``; the
    diagnostics hold ``innovation_covariance`` S, (runs, m, m). A mixin such
    as :class:`~hinfnav.estimators.huber_filter.HuberCorrection` replaces it
    (the Huber M-estimation) on any filter that has it.
    """

    #: Return the symmetric part of P⁺ (the augmented core) or (J2) as computed (the EKF).
    symmetric_posterior = True

    def correct_error(self, P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64], innovation: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
        dx, P_post, S = joseph_update(P, H, R, innovation, symmetrize=self.symmetric_posterior)
        runs = innovation.shape[0]
        return dx, P_post, {"innovation_covariance": S if S.ndim == 3 else np.broadcast_to(S, (runs,) + S.shape)}
