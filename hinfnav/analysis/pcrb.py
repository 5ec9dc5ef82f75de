"""Posterior Cramér–Rao bound of a nonlinear filtering problem (Tichavský, Muravchik & Nehorai 1998).

For ``x(k+1) = f(x(k)) + w(k)``, ``y(k) = h(x(k)) + v(k)`` with white additive
noise, ``w ~ N(0, Q)``, ``v`` of covariance ``R`` and ``x(0) ~ p₀`` of
covariance ``P₀``, every estimator x̂(k) of x(k) from y(0) … y(k) satisfies
``E[(x̂ − x)(x̂ − x)ᵀ] ⪰ J(k)⁻¹`` (the posterior, or Bayesian, CRB). The
information obeys the recursion of Tichavský et al. (1998), specialised to
additive Gaussian process noise (labels (T1)–(T2) are this module's; the
paper itself is not in the workbook's library, so its equation numbers are
not quoted)::

    J(k+1) = D22 − D21 (J(k) + D11)⁻¹ D12,                          (T1)
    D11 = E[Fᵀ Q⁻¹ F],  D12 = D21ᵀ = −E[Fᵀ] Q⁻¹,
    D22 = Q⁻¹ + E[Hᵀ Λ H],                                          (T2)

with ``F = ∂f/∂x`` at x(k), ``H = ∂h/∂x`` at x(k+1), ``Λ`` the Fisher
information of the measurement-noise density (``R⁻¹`` for Gaussian noise)
and the expectations over the true trajectories (here: Monte Carlo over the
given truth runs).

Singular Q
----------
(T1) needs ``Q⁻¹``. Writing ``F = F̄ + δF`` (``F̄ = E[F]``) and applying the
matrix inversion lemma to (T1) gives the algebraically identical form used
here (derived for this module; the same algebra as the linear case)::

    S(k)   = J(k) + E[δFᵀ Q⁻¹ δF],                                  (P1)
    J(k+1) = (Q + F̄ S(k)⁻¹ F̄ᵀ)⁻¹ + E[Hᵀ Λ H].                       (P2)

``Q`` enters (P2) without inversion, so (P2) is exact for singular Q whenever
the Jacobian F is the same on every run (linear dynamics: then it is the
Kalman covariance recursion). ``Q⁻¹`` is left only in the spread term of
(P1), which vanishes for linear f. There, a singular Q is replaced by
``Q_ε = U max(λ, ε λ_max) Uᵀ`` (eigen-decomposition ``Q = U λ Uᵀ``, relative
floor ε, default 1e-9): the bound of the regularised problem, whose ε → 0
limit is a bound for the singular one (if the optimal MSE is continuous in
ε). The spread term does not depend on ε when the Jacobian varies only in
the rows of the noisy states (a pendulum with noise on the rate: identical
bounds for ε = 1e-9 and 1e-6, and the literal (T1) with ``Q + δI`` converges
to it linearly, 3.9e-5 relative at δ = 1e-8; tests/test_pcrb.py). When the
Jacobian of a noise-free state varies over the runs (the pendulum with noise
on the angle only), ε does enter; the bound converges as ε → 0 (measured:
1.6e-4 relative change from ε = 1e-6 to 1e-9, 1.3e-6 from 1e-9 to 1e-12,
the rounding of an information of size 1/ε)
but that limit treats the run-to-run spread of the Jacobian as perfectly
informative, so it may be optimistic (a loose lower bound) there.

Everything is propagated in covariance form, ``P = J⁻¹``; adding an
information ``M = LᵀL`` is the Joseph-form update with the equivalent
measurement ``L`` and unit noise, so a semidefinite P₀ is allowed.

Non-Gaussian measurement noise
------------------------------
The bound computed with Gaussian noise of the same covariance is NOT a bound
for other noise densities: by the scalar Cramér–Rao inequality a
unit-variance density has location Fisher information ``j ≥ 1``, with
equality only for the Gaussian, so any other sensor density (the mixture and
Student-t of :mod:`hinfnav.noise` included) carries more information about x
than a Gaussian one of the same variance. For
``v = D e`` with square invertible D and i.i.d. unit-variance channels of
information j, ``Λ = D⁻ᵀ (j I) D⁻¹ = j R⁻¹`` (:func:`measurement_information`).
The same holds for the other two inputs, not handled here: a non-Gaussian
process noise replaces ``Q⁻¹`` by its Fisher information, and a non-Gaussian
prior has ``J(0) ⪰ P₀⁻¹`` (so P0 must then be the inverse of the prior's
Fisher information, not its covariance). Non-additive noise needs the
general expectations of the paper, not this additive form.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.integrate
import scipy.stats
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import as_covariance, joseph_covariance
from ..core.validation import as_int_at_least, as_matrix, as_positive
from ..noise import GaussianNoise, LaplaceNoise, MixtureNoise, NoiseModel, StudentTNoise

__all__ = ["measurement_information", "noise_fisher_information", "posterior_crb", "rms_bound"]


def _jacobian_source(name, value, rows, n):
    """A callable x (runs, n) -> (runs, rows, n) from a constant, a callable or a model with ``.jacobian``."""
    if hasattr(value, "jacobian") and callable(value.jacobian):
        value = value.jacobian
    if callable(value):
        def evaluate(x):
            try:
                out = np.asarray(value(x), dtype=float)
            except InputError:
                raise
            except (TypeError, ValueError, IndexError, ArithmeticError) as exc:  # a user callable: name the parameter
                raise InputError(f"{name} failed on a batch of states of shape {x.shape}: {exc}") from None
            want = (x.shape[0], rows, n) if rows is not None else None
            if out.ndim != 3 or out.shape[0] != x.shape[0] or out.shape[2] != n or (want and out.shape != want):
                raise InputError(f"{name} must return an array of shape (runs, {rows or 'm'}, {n}) for states of "
                                 f"shape {x.shape}; got {out.shape}")
            if not np.all(np.isfinite(out)):
                raise InputError(f"{name} returned NaN or inf entries")
            return out
        return evaluate
    M = as_matrix(name, value, (rows, n))
    return lambda x: np.broadcast_to(M, (x.shape[0],) + M.shape)


def _add_information(P, M):
    """``(P⁻¹ + M)⁻¹`` for a PSD P (possibly singular) and a PSD information M (Joseph form)."""
    mu, V = np.linalg.eigh(0.5 * (M + M.T))
    scale = max(float(mu[-1]), 0.0)
    keep = mu > 1e-14 * scale
    if not np.any(keep):
        return P
    L = np.sqrt(mu[keep])[:, None] * V[:, keep].T
    LP = L @ P
    S = LP @ L.T + np.eye(L.shape[0])
    K = np.linalg.solve(S, LP).T
    return joseph_covariance(P, K, L, np.eye(L.shape[0]))  # (I − K L) P (I − K L)ᵀ + K Kᵀ, symmetrised


def posterior_crb(truth_states: ArrayLike, dynamics_jacobian: Any,
                  measurement_jacobian: Any, Q: ArrayLike, R: ArrayLike, P0: ArrayLike, *,
                  measurement_information: ArrayLike | None = None, initial_update: bool = True, diagonal_only: bool = False,
                  epsilon: float = 1e-9) -> NDArray[np.float64]:
    """Posterior Cramér–Rao bound J(k)⁻¹ of the state along Monte Carlo truths, eqs. (T1)–(T2), (P1)–(P2).

    Parameters
    ----------
    truth_states : array_like, shape (runs, n_steps, n)
        True trajectories x(0) … x(n_steps−1) over which the expectations
        are averaged (drawn from the prior and the process noise). For linear
        f and h one run suffices: nothing depends on the state.
    dynamics_jacobian : callable, array_like (n, n) or object with ``.jacobian``
        ``F(x) = ∂f/∂x``: called with a batch x(k) of shape (runs, n), returns
        (runs, n, n). A constant matrix (e.g. a LinearSystem's ``Phi``) is
        used on every run.
    measurement_jacobian : callable, array_like (m, n) or measurement model
        ``H(x) = ∂h/∂x`` at x(k), (runs, n) -> (runs, m, n); a measurement
        model's ``.jacobian`` or a constant C.
    Q : array_like, shape (n, n)
        Process-noise covariance per step, positive semidefinite (may be
        singular, see the module notes).
    R : array_like, shape (m, m) or None
        Measurement-noise covariance, positive definite; ``Λ = R⁻¹`` unless
        ``measurement_information`` is given (then R may be None).
    P0 : array_like, shape (n, n)
        Covariance of the prior of x(0), positive semidefinite; J(0) = P0⁻¹.
    measurement_information : array_like, shape (m, m), optional
        Fisher information Λ of the measurement-noise density (units of
        1/measurement²), for non-Gaussian noise; see
        :func:`measurement_information`.
    initial_update : bool
        True (default): the bound at step 0 already uses y(0), like the
        filters of hinfnav, which process the first measurement with P₀.
    diagonal_only : bool
        Return only the diagonals (saves memory on long runs).
    epsilon : float
        Relative eigenvalue floor of a singular Q in the spread term (P1).

    Returns
    -------
    ndarray, shape (n_steps, n, n) or (n_steps, n)
        The bound on the error covariance at each step (units: state²), or
        its diagonal.

    Raises
    ------
    InputError
        Bad shapes or values, naming the parameter.
    """
    try:
        X = np.asarray(truth_states, dtype=float)
    except (TypeError, ValueError):
        raise InputError("truth_states must be a numeric array (runs, n_steps, n); "
                         f"got {type(truth_states).__name__}") from None
    for flag, value in (("initial_update", initial_update), ("diagonal_only", diagonal_only)):
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"{flag} must be True or False; got {value!r}")
    if X.ndim != 3 or min(X.shape) < 1:
        raise InputError(f"truth_states must have shape (runs, n_steps, n) with every size >= 1; got {np.shape(X)}")
    if not np.all(np.isfinite(X)):
        raise InputError("truth_states must contain only finite numbers; it has NaN or inf entries")
    _, n_steps, n = X.shape
    Q = as_covariance("Q", Q, n, definite=False)
    P = as_covariance("P0", P0, n, definite=False)
    eps = as_positive("epsilon", epsilon)
    if eps >= 1:
        raise InputError(f"epsilon must be below 1 (a relative eigenvalue floor); got {epsilon}")
    F_of = _jacobian_source("dynamics_jacobian", dynamics_jacobian, n, n)
    H_of = _jacobian_source("measurement_jacobian", measurement_jacobian, None, n)
    H0 = H_of(X[:, 0, :])
    m = H0.shape[1]
    if measurement_information is not None:
        Lam = as_covariance("measurement_information", measurement_information, m, definite=False)
    elif R is None:
        raise InputError("R must be given (or measurement_information, the noise's Fisher information)")
    else:
        R = as_covariance("R", R, m, definite=True)
        Lam = np.linalg.inv(R)
        Lam = 0.5 * (Lam + Lam.T)
    lam_q, U = np.linalg.eigh(Q)
    lam_max = max(float(lam_q[-1]), 0.0)
    root_q_inv = None
    if lam_max > 0:
        root_q_inv = (U / np.sqrt(np.maximum(lam_q, eps * lam_max))).T      # rootᵀ root = Q_ε⁻¹

    def root(M):                       # Mʰ with Mʰᵀ Mʰ = M for a PSD M (so that E[Gᵀ M G] is one product)
        mu, V = np.linalg.eigh(M)
        return np.sqrt(np.maximum(mu, 0.0))[:, None] * V.T

    def mean_quadratic(G, root_M):     # E[Gᵀ M G] over the runs, as (Mʰ G)ᵀ (Mʰ G) stacked
        A = (root_M @ G).reshape(-1, n)
        return A.T @ A / G.shape[0]

    root_lam = root(Lam)

    def info(H):
        return mean_quadratic(H, root_lam)

    out = np.empty((n_steps, n) if diagonal_only else (n_steps, n, n))
    if initial_update:
        P = _add_information(P, info(H0))
    out[0] = np.diag(P) if diagonal_only else P
    for k in range(n_steps - 1):
        F = F_of(X[:, k, :])
        F_bar = F.mean(axis=0)
        dF = F - F_bar
        scale = max(float(np.max(np.abs(F_bar))), 1.0)
        S_inv = P
        if np.max(np.abs(dF)) > 1e-13 * scale:
            if root_q_inv is None:
                raise InputError("Q is zero but dynamics_jacobian varies over the runs; the bound (P1) needs a "
                                 "process-noise covariance (give a small positive Q)")
            S_inv = _add_information(P, mean_quadratic(dF, root_q_inv))                           # (P1)
        P_pred = F_bar @ S_inv @ F_bar.T + Q                                                        # (P2)
        P = _add_information(0.5 * (P_pred + P_pred.T), info(H_of(X[:, k + 1, :])))
        out[k + 1] = np.diag(P) if diagonal_only else P
    return out


def rms_bound(bound: ArrayLike, start: int = 0, stop: int | None = None) -> NDArray[np.float64]:
    """RMS bound per state component over steps ``start … stop−1``: ``√(mean_k PCRB_ii(k))``.

    The RMS error ``√(mean_k E[e_i(k)²])`` of any estimator over the window
    is at least this (the bound holds at every step).

    Parameters
    ----------
    bound : array_like, shape (n_steps, n, n) or (n_steps, n)
        Output of :func:`posterior_crb` (full or diagonal).
    start, stop : int
        Step window (Python slice convention).

    Returns
    -------
    ndarray, shape (n,)
        Units of the state components.
    """
    B = np.asarray(bound, dtype=float)
    if B.ndim == 3 and B.shape[1] == B.shape[2]:
        B = np.diagonal(B, axis1=1, axis2=2)
    elif B.ndim != 2:
        raise InputError(f"bound must have shape (n_steps, n, n) or (n_steps, n); got {B.shape}")
    n_steps = B.shape[0]
    start = as_int_at_least("start", start, 0)
    stop = n_steps if stop is None else as_int_at_least("stop", stop, 1)
    if not start < stop <= n_steps:
        raise InputError(f"need 0 <= start < stop <= n_steps = {n_steps}; got start={start}, stop={stop}")
    return np.sqrt(np.mean(B[start:stop], axis=0))


def _density(noise):
    """The scipy distribution of a unit-variance noise model of hinfnav.noise, or None for a mixture."""
    if isinstance(noise, GaussianNoise):
        return scipy.stats.norm()
    if isinstance(noise, StudentTNoise):
        return scipy.stats.t(noise.dof, scale=np.sqrt((noise.dof - 2) / noise.dof))
    if isinstance(noise, LaplaceNoise):
        return scipy.stats.laplace(scale=1.0 / np.sqrt(2.0))
    return None


def noise_fisher_information(noise: NoiseModel) -> float:
    """Location Fisher information ``j = ∫ p′(e)²/p(e) de`` of a unit-variance noise model.

    Gaussian: 1. Laplace (scale 1/√2): 2 (closed form, the density has a kink
    at 0). Student-t and the Gaussian mixture of :class:`hinfnav.noise.MixtureNoise`:
    numerical quadrature of the score, ``scipy.integrate.quad`` over ℝ
    (closed form for Student-t with ν dof, unit variance:
    ``ν(ν+1)/((ν+3)(ν−2))``, used in the tests as the check). Always ≥ 1.

    Raises
    ------
    InputError
        For noise without a differentiable white density (uniform: the CRB
        regularity conditions fail; colored: not white).
    """
    if not isinstance(noise, NoiseModel):
        raise InputError(f"noise must be a hinfnav.noise model; got {type(noise).__name__}")
    if isinstance(noise, GaussianNoise):
        return 1.0
    if isinstance(noise, LaplaceNoise):
        return 2.0
    if isinstance(noise, MixtureNoise):
        w = np.array([1.0 - noise.eps, noise.eps])
        s = np.array([noise.sigma1, noise.sigma1 * noise.ratio])

        def integrand(e):
            comp = w * np.exp(-0.5 * (e / s) ** 2) / (np.sqrt(2 * np.pi) * s)
            p = comp.sum()
            dp = -(comp * e / s**2).sum()
            return dp * dp / p if p > 0 else 0.0
    elif isinstance(noise, StudentTNoise):
        dist = _density(noise)
        nu, c2 = float(noise.dof), (noise.dof - 2) / noise.dof

        def integrand(e):
            score = (nu + 1) * e / (nu * c2 + e * e)     # −d log p / de of the scaled t density
            return score * score * dist.pdf(e)
    else:
        raise InputError(f"noise {noise.name!r} has no Fisher information usable in the bound (needs a white, "
                         "differentiable density: gaussian, laplace, student_t or mixture)")
    value, _ = scipy.integrate.quad(integrand, -np.inf, np.inf, limit=200, epsabs=1e-13, epsrel=1e-11)
    return float(value)


def measurement_information(D: ArrayLike, noise: NoiseModel) -> NDArray[np.float64]:
    """Fisher information Λ of ``v = D e``, e i.i.d. unit-variance channels of ``noise``: ``j (D Dᵀ)⁻¹``.

    Parameters
    ----------
    D : array_like, shape (m, m)
        Square invertible noise matrix (a measurement model's ``.D``).
    noise : hinfnav.noise.NoiseModel

    Returns
    -------
    ndarray, shape (m, m)
        Λ for :func:`posterior_crb` (1/measurement units²).
    """
    D = as_matrix("D", D)
    if D.shape[0] != D.shape[1] or np.linalg.cond(D) > 1e12:
        raise InputError(f"D must be square and invertible for a non-Gaussian noise information; got shape {D.shape}")
    j = noise_fisher_information(noise)
    D_inv = np.linalg.inv(D)
    Lam = j * D_inv.T @ D_inv
    return 0.5 * (Lam + Lam.T)
