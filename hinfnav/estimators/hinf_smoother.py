"""An H∞ fixed-lag smoother: Simon's recursive H∞ filter on the state augmented with its lagged copies.

For ``x(k+1) = F x(k) + Γ u(k) + w(k)``, ``y(k) = H x(k) + v(k)`` and a lag ℓ ≥ 0, the augmented state
``X_k = [x_k; x_{k−1}; …; x_{k−ℓ−1}]`` (ℓ + 2 blocks) evolves as

.. math::

    X_{k+1} = \\begin{bmatrix} F & 0 & \\cdots & 0 \\\\ I & 0 & & \\\\ & \\ddots & \\ddots & \\\\ 0 & & I & 0
    \\end{bmatrix} X_k + \\begin{bmatrix} Γ \\\\ 0 \\end{bmatrix} u_k + \\begin{bmatrix} w_k \\\\ 0 \\end{bmatrix},
    \\qquad y_k = [H\\; 0 \\cdots 0]\\, X_k + v_k                                                    (H1)

and Simon's a-priori H∞ filter (:class:`~hinfnav.estimators.RecursiveHInfinityFilter`, Simon 2006 §11.3)
run on (H1) with the estimated combination ``z_k = [0 … 0 L] X_k = L x_{k−ℓ−1}`` (its weight S and bound θ)
reports at t_k the a-priori ``X̂(k|k−1)``, whose last block is the estimate of ``x_{k−ℓ−1}`` from
``y_0 … y_{k−1}``: the H∞ fixed-lag estimate ``x̂(j | j+ℓ)`` at ``j = k−ℓ−1`` — the game's bound holds for
the error of that lagged combination, under the existence condition of the augmented recursion at every step
(checked by the filter, as for filtering). This is the augmented-state form of the H∞ fixed-lag smoothing
problem (Zhang, Xie & Soh, IEEE TAC 50(9), 2005, who also give a cheaper recursion for the same estimate);
with θ = 0 it is the Kalman fixed-lag smoother (tested against :func:`~hinfnav.estimators.smooth` with
``lag=ℓ``). The lagged blocks before t_0 start independent with covariance P₀ each (they are never
observed and do not affect the estimates of x_0 … x_{N−1}). The last ℓ + 1 samples are read from the
a-priori estimate one step past the record (``x̂(j | N−1)``), as the fixed-lag smoother of
:mod:`~hinfnav.estimators.smoothers` does. P of an H∞ filter is a Riccati bound, not a covariance: none
is returned.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import block_diag

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least
from ..systems.linear import LinearSystem
from ..systems.measurements import LinearMeasurement
from ..systems.state import StateSpec
from .base import EstimateHistory
from .recursive_hinf import RecursiveHInfinityFilter
from .smoothers import record_inputs

__all__ = ["hinf_fixed_lag"]


def _augmented(est: RecursiveHInfinityFilter, lag: int) -> RecursiveHInfinityFilter:
    n, b = est.n_state, lag + 2
    Fa = np.zeros((b * n, b * n))
    Fa[:n, :n] = est.F
    Fa[n:, :-n] = np.eye((b - 1) * n)
    Ga = np.zeros((b * n, est.Gamma.shape[1]))
    Ga[:n] = est.Gamma
    Qa = np.zeros((b * n, b * n))
    Qa[:n, :n] = est.Q
    lam, V = np.linalg.eigh(Qa)
    labels = tuple(f"{lab}[k-{i}]" for i in range(b) for lab in est.system.state.labels)
    system = LinearSystem(Fa, Ga, V * np.sqrt(np.clip(lam, 0.0, None)), est.system.dt,
                          StateSpec(labels, tuple(est.system.state.units) * b), name="lag-augmented system")
    Ha = np.zeros((est.H.shape[0], b * n))
    Ha[:, :n] = est.H
    meas = LinearMeasurement(Ha, np.linalg.cholesky(est.R))
    La = np.zeros((est.L.shape[0], b * n))
    La[:, -n:] = est.L
    return RecursiveHInfinityFilter(system, meas, theta=est.theta, P0=block_diag(*[est.P0] * b), Q=Qa, R=est.R,
                                    L=La, S=est.S, uses_input=est.uses_input, on_violation=est.on_violation,
                                    steady_tol=est.steady_tol, name=f"{est.name}_fixed_lag", missing=est.missing)


def hinf_fixed_lag(estimator: RecursiveHInfinityFilter, y: ArrayLike, u: ArrayLike | None, xhat0: ArrayLike,
                   lag: int) -> EstimateHistory:
    """The H∞ fixed-lag estimates ``x̂(k | min(k+lag, N−1))`` of a batch of records (module docstring).

    Parameters
    ----------
    estimator : RecursiveHInfinityFilter
        Gives F, Γ, H, Q, R, θ, L, S, P₀ and its options.
    y : array_like, shape (runs, N, m)
    u : array_like, shape (runs, N, n_input), or None (a filter that does not use its input)
    xhat0 : array_like, shape (n,) or (runs, n)
    lag : int
        ℓ ≥ 0, in samples.

    Returns
    -------
    EstimateHistory
        ``xhat`` (runs, N, n); ``P`` None; diagnostics ``existence_margin`` (runs, N + 1) of the augmented
        recursion.
    """
    if not isinstance(estimator, RecursiveHInfinityFilter):
        raise InputError(f"estimator must be a RecursiveHInfinityFilter; got {type(estimator).__name__}")
    lag = as_int_at_least("lag", lag, 0)
    y, u, x0 = record_inputs(estimator, y, u, xhat0, u_width=estimator.Gamma.shape[1])
    runs, N, _ = y.shape
    n, b = estimator.n_state, lag + 2
    aug = _augmented(estimator, lag)
    pad = lambda a: np.concatenate([a, np.zeros((runs, 1, a.shape[2]))], axis=1)  # X̂(N|N−1) does not read y_N
    X0 = np.tile(x0, (1,) * (x0.ndim - 1) + (b,))
    h = aug.estimate(pad(y), pad(u), X0, keep_covariance=False, diagnostics=["existence_margin"])
    blocks = h.xhat.reshape(runs, N + 1, b, n)
    xs = np.empty((runs, N, n))
    j = np.arange(N)
    k = np.minimum(j + lag + 1, N)          # the stamp whose a-priori estimate holds x̂(j | min(j+lag, N−1))
    xs[:, j] = blocks[:, k, k - j]
    return EstimateHistory(xhat=xs, P=None, state=estimator.system.state,
                           diagnostics={"existence_margin": h.diagnostics["existence_margin"]})
