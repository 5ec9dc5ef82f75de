"""The two ideas of paper 002 as small hooks on one EKF: strong tracking and rate-adapted noise.

Both override one hook each. Strong tracking (hook ``complete_prior``) acts
on either Kalman core: :class:`~hinfnav.estimators.ExtendedKalmanFilter` (a
linear system or any dynamics model, e.g. a constant-turn target) and
:class:`~hinfnav.estimators.augmented.AugmentedEKF` (an EKF whose last error
coordinates are random-walk augmented states). Rate-adapted noise (hook
``process_noise``) acts on both as well: on the augmented states of the
augmented core, or on the states named by ``states`` of an EKF.

**Strong tracking** (suboptimal multiple fading factors; Zhou, Xi & Zhang,
Acta Automatica Sinica 17(6), 1991, rebuilt there from; paper 002 §2.3):
with the innovation γ(k+1) = y(k+1) − h(x̂(k+1|k)),

* ``V₀(1) = γ₁γ₁ᵀ``, ``V₀(k+1) = (ρ V₀(k) + γγᵀ)/(1 + ρ)``  (S1)
* ``N = V₀ − β R − H Q_d Hᵀ``,  ``M = Φ P Φᵀ Hᵀ H``           (S2)
* ``c = tr N / Σᵢ aᵢ Mᵢᵢ``,  ``λᵢ = max(1, aᵢ c)``             (S3)
* ``P(k+1|k) = Λ^{1/2} Φ P Φᵀ Λ^{1/2} + Q_d``                 (S4)

ρ ∈ (0, 1] is the forgetting factor, β ≥ 1 the weakening factor and aᵢ ≥ 1
the prior weights. Paper 002 prints ``Λ Φ P Φᵀ``, which is not symmetric;
(S4) is the symmetric reading: it has the same diagonal (λᵢ (ΦPΦᵀ)ᵢᵢ), scales
the off-diagonal terms by √(λᵢλⱼ) and is identical to ΛΦPΦᵀ when all λ are
equal (documented choice). Since λ(k+1) needs γ(k+1), the covariance
prediction is completed when y(k+1) arrives (the mean prediction does not
depend on λ). With every λ = 1 the filter is the plain EKF, exactly.

**Rate-adapted noise** (paper 002 §2.2, AAEKF):
``Q(t_k) = Q(t₀) F[ε κ(t_k)]``, ``κ(t_k) = (β̂_k − β̂_{k−m}) / (m Δt)``
(the augmented states' rate over the last m steps) (R1). The printed
``F[x] = x xᵀ`` is rank one (it would give no noise at all to every direction
orthogonal to κ, and none at all where κ = 0); the reading used here is
element-wise with a floor, ``Q_ii(t_k) = Q_ii(t₀) max(f_min, (ε κᵢ)²)`` (R2):
each channel's noise grows with the square of its own rate once
``|ε κᵢ| > √f_min``, and never falls below f_min Q(t₀) (documented choice). ε
carries the unit s per unit of the augmented state. Before m steps have
passed κ uses the steps available.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import matmul_shared
from ..core.validation import as_int_at_least, as_nonnegative, as_positive

if TYPE_CHECKING:
    from .base import FilterState

__all__ = [
    "RateAdaptive",
    "StrongTracking",
    "StrongTrackingStrategy",
    "strong_tracking_prior",
    "fade",
    "fading_factors",
    "innovation_moment",
    "input_rate",
    "rate_adapted_density",
]


def per_run_parameter(name, value, check):
    """A scalar parameter, or one value per run (a parameter sweep batched as runs), validated by ``check``.

    Returns a float or a read-only 1-D array.
    """
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return check(name, float(arr))
    if arr.ndim != 1 or arr.size == 0:
        raise InputError(f"{name} must be a number or a 1-D array with one value per run; got shape {arr.shape}")
    out = np.array([check(f"{name}[{i}]", float(v)) for i, v in enumerate(arr)])
    out.setflags(write=False)
    return out


def _column(p, ndim):
    """Broadcast a per-run parameter against arrays whose leading axis is the run."""
    p = np.asarray(p)
    return p if p.ndim == 0 else p.reshape(p.shape + (1,) * (ndim - 1))


def innovation_moment(V0, innovation, rho):
    """The innovation second moment (S1), batched: shape (runs, m, m).

    ``V0`` None starts the recursion with γγᵀ.
    """
    gg = innovation[..., :, None] * innovation[..., None, :]
    if V0 is None:
        return gg
    rho = _column(rho, 3)
    return (rho * V0 + gg) / (1.0 + rho)


def fading_factors(V0, H, PhiPPhiT, Qd, R, *, beta, a):
    """Multiple fading factors λ of (S2)–(S3), shape (runs, n), and c, shape (runs,).

    Parameters
    ----------
    V0 : ndarray, shape (runs, m, m)
    H : ndarray, shape (m, n) or (runs, m, n)
    PhiPPhiT : ndarray, shape (n, n) or (runs, n, n)
    Qd : ndarray, shape (n, n) or (runs, n, n)
        Process noise per step, Δt Γ Q Γᵀ.
    R : ndarray, shape (m, m)
    beta : float
    a : ndarray, shape (n,)
    """
    HT = np.swapaxes(H, -1, -2)
    N = V0 - _column(beta, 3) * R - H @ Qd @ HT
    trN = np.trace(N, axis1=-2, axis2=-1)
    Mdiag = np.sum(matmul_shared(PhiPPhiT, HT) * HT, axis=-1)  # diag(Φ P Φᵀ Hᵀ H)
    den = np.sum(a * Mdiag, axis=-1)
    c = trN / np.where(den > 0, den, np.inf)
    lam = np.maximum(1.0, a * np.atleast_1d(c)[..., None])
    return lam, c


def fade(PhiPPhiT, lam):
    """``Λ^{1/2} Φ P Φᵀ Λ^{1/2}`` (S4, symmetric reading), batched."""
    s = np.sqrt(lam)
    return s[..., :, None] * PhiPPhiT * s[..., None, :]


def input_rate(history, count, m, dt):
    """Rate of the augmented states (R1) from a ring buffer of estimates.

    Parameters
    ----------
    history : ndarray, shape (m + 1, runs, n_aug)
        The last estimates, slot ``j % (m + 1)`` holding step j.
    count : int
        Number of estimates pushed so far (the newest is step count − 1).
    m : int
    dt : float

    Returns
    -------
    ndarray, shape (runs, n_aug)
        ``(β̂_newest − β̂_oldest) / (span Δt)``, span = min(m, count − 1); zero
        before two estimates exist.
    """
    if count < 2:
        return np.zeros(history.shape[1:])
    span = min(m, count - 1)
    newest = history[(count - 1) % (m + 1)]
    oldest = history[(count - 1 - span) % (m + 1)]
    return (newest - oldest) / (span * dt)


def rate_adapted_density(Q0_diag, kappa, epsilon, floor):
    """``Q_ii = Q0_ii max(floor, (ε κᵢ)²)`` of (R2), shape (runs, n_aug)."""
    return Q0_diag * np.maximum(floor, (_column(epsilon, 2) * kappa) ** 2)


def _check_rho(name, value):
    value = as_positive(name, value)
    if value > 1:
        raise InputError(f"{name} (forgetting factor) must be in (0, 1]; got {value}")
    return value


def _check_beta(name, value):
    value = as_positive(name, value)
    if value < 1:
        raise InputError(f"{name} (weakening factor) must be >= 1; got {value}")
    return value


def strong_tracking_prior(PhiPPhiT: NDArray[np.float64], Qd: NDArray[np.float64], state: FilterState,
                          innovation: NDArray[np.float64], H: NDArray[np.float64], mask: NDArray[np.bool_] | None, *,
                          R: NDArray[np.float64], rho: Any, beta: Any, a: NDArray[np.float64]
                          ) -> tuple[NDArray[np.float64], dict[str, Any], dict[str, Any]]:
    """(S1)-(S4) at a reading: ``(P(k+1|k), diagnostics, extra)`` (the ``complete_prior`` hook's return).

    ``innovation`` and H are zero on the channels ``~mask`` a reading lacks (mask None: none); the moment V₀
    is read from and returned in ``state.extra``. With missing channels the moment and N use the channels
    the reading has; a run without any channel keeps V₀ and takes λ = 1 (a prediction only).
    """
    V0_old = state.extra.get("V0")
    V0 = innovation_moment(V0_old, innovation, rho)
    keep = {}
    if mask is not None or "V0_started" in state.extra:  # some run has skipped a whole reading
        runs = innovation.shape[0]
        gone = np.zeros(runs, dtype=bool) if mask is None else ~mask.any(axis=1)
        started = state.extra.get("V0_started", np.full(runs, V0_old is not None))
        fresh = innovation_moment(None, innovation, rho)
        if V0_old is not None:  # (S1) from γγᵀ in the runs without a moment yet; unchanged in the skipped ones
            V0 = np.where(gone[:, None, None], V0_old, np.where(started[:, None, None], V0, fresh))
        keep = {"V0_started": started | ~gone}
    if mask is not None:
        R = np.where(mask[:, :, None] & mask[:, None, :], R, 0.0)
    lam, c = fading_factors(V0, H, PhiPPhiT, Qd, R, beta=beta, a=a)
    if mask is not None:
        lam = np.where(gone[:, None], 1.0, lam)
    P = fade(PhiPPhiT, lam) + Qd
    return P, {"fading": lam, "fading_c": np.broadcast_to(c, (innovation.shape[0],))}, dict(keep, V0=V0)


def _check_per_run(pairs, runs):
    for key, val in pairs:
        if isinstance(val, np.ndarray) and val.size != runs:
            raise InputError(f"runs must equal the number of per-run values of {key} ({val.size}); got {runs}")


class StrongTrackingStrategy:
    """Strong tracking (S1)–(S4) as a prior-fading *strategy*: composed onto any filter of the Kalman core
    (:func:`~hinfnav.estimators.strategies.compose`; ``fading="strong_tracking"``), whatever its moment rule.

    On the linearised rule it is :class:`StrongTracking`'s fading, bitwise; on the sigma-point rule ``Φ P Φᵀ``
    is the propagated points' covariance ``Σ W^c dX dXᵀ`` and H the statistical linearisation (M1) of
    :mod:`hinfnav.estimators.moments` at the uncompleted prior (the sigma points are then redrawn from the
    faded prior). Parameters ``rho``, ``beta``, ``a`` as :class:`StrongTracking`'s; the filter needs a
    constant R. Diagnostics ``fading``, ``fading_c``.
    """

    name = "strong_tracking"

    def __init__(self, rho: float = 0.95, beta: float = 1.0, a: ArrayLike | None = None) -> None:
        self.rho = per_run_parameter("rho", rho, _check_rho)
        self.beta = per_run_parameter("beta", beta, _check_beta)
        self.a = None if a is None else np.asarray(a, dtype=float)

    def __repr__(self) -> str:
        return f"StrongTrackingStrategy(rho={self.rho}, beta={self.beta}, a={self.a})"

    def bind(self, estimator: Any) -> None:
        """Check that ``estimator`` can take this fading: a constant R, and ``a`` of its covariance's size."""
        if getattr(estimator, "R", None) is None:
            raise InputError("strong tracking needs a constant R (N of (S2) subtracts β R); give R to the filter")
        n = estimator.n_cov
        if self.a is not None and (self.a.shape != (n,) or not np.all(np.isfinite(self.a)) or np.any(self.a < 1)):
            raise InputError(f"a (prior weights of the fading factors) must be {n} numbers >= 1; got {self.a}")

    def check_runs(self, runs: int) -> None:
        """A per-run ρ or β must have one value per run."""
        _check_per_run((("rho", self.rho), ("beta", self.beta)), runs)

    def complete_prior(self, estimator: Any, PhiPPhiT: NDArray[np.float64], Qd: NDArray[np.float64], state: FilterState,
                       innovation: NDArray[np.float64], H: NDArray[np.float64],
                       mask: NDArray[np.bool_] | None = None) -> tuple[NDArray[np.float64], dict[str, Any], dict[str, Any]]:
        """(S1)-(S4) by :func:`strong_tracking_prior` with the filter's R."""
        a = np.ones(estimator.n_cov) if self.a is None else self.a
        return strong_tracking_prior(PhiPPhiT, Qd, state, innovation, H, mask, R=estimator.R, rho=self.rho,
                                     beta=self.beta, a=a)

    def initial_diagnostics(self, estimator: Any, runs: int) -> dict[str, Any]:
        """``fading`` 1 and ``fading_c`` NaN before the first completed prior."""
        return {"fading": np.ones((runs, estimator.n_cov)), "fading_c": np.full(runs, np.nan)}


class StrongTracking:
    """Mixin: strong tracking by multiple fading factors (S1)–(S4).

    Put it before an :class:`~hinfnav.estimators.ExtendedKalmanFilter` or
    :class:`~hinfnav.estimators.augmented.AugmentedEKF` (sub)class in the
    bases; the host needs a constant R. Keyword parameters (besides the host's):

    Parameters
    ----------
    rho : float or array_like, shape (runs,)
        Forgetting factor of (S1), 0 < ρ ≤ 1 (0.95).
    beta : float or array_like, shape (runs,)
        Weakening factor of (S2), β ≥ 1 (1.0). ρ and β may hold one value
        per run (a parameter sweep batched as runs).
    a : array_like, shape (n_cov,), optional
        Prior weights aᵢ ≥ 1 of (S3), one per error coordinate (all 1: no
        coordinate is singled out, i.e. one common fading factor).

    Diagnostics: ``fading`` (runs, n_cov) — the λᵢ of this step (1 at the
    first measurement, processed with P₀) — and ``fading_c`` (runs,).
    """

    data_dependent_covariance = True
    defers_prior = True
    #: The prior is faded by (S1)-(S4) (read by the compiled kernels).
    strong_tracking = True

    def __init__(self, *args: Any, rho: float = 0.95, beta: float = 1.0, a: ArrayLike | None = None,
                 **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if getattr(self, "R", None) is None:
            raise InputError("strong tracking needs a constant R (N of (S2) subtracts β R); give R to the filter")
        self.rho = per_run_parameter("rho", rho, _check_rho)
        self.beta = per_run_parameter("beta", beta, _check_beta)
        a = np.ones(self.n_cov) if a is None else np.asarray(a, dtype=float)
        if a.shape != (self.n_cov,) or not np.all(np.isfinite(a)) or np.any(a < 1):
            raise InputError(f"a (prior weights of the fading factors) must be {self.n_cov} numbers >= 1; got {a}")
        self.a = a

    def fade_prior(self, PhiPPhiT: NDArray[np.float64], Qd: NDArray[np.float64], V0: NDArray[np.float64] | None,
                   innovation: NDArray[np.float64], H: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(S1)-(S4) on arrays, every channel read: ``(P⁻, V₀)`` from the moment ``V0`` (None at the first
        reading), the innovation (runs, m) and ``Φ P Φᵀ``; what :meth:`complete_prior` computes without missing
        channels (the compiled path's NIS diagnostics use it)."""
        V0 = innovation_moment(V0, innovation, self.rho)
        lam, _ = fading_factors(V0, H, PhiPPhiT, Qd, self.R, beta=self.beta, a=self.a)
        return fade(PhiPPhiT, lam) + Qd, V0

    def complete_prior(self, PhiPPhiT: NDArray[np.float64], Qd: NDArray[np.float64], state: FilterState, innovation: NDArray[np.float64], H: NDArray[np.float64],
                       mask: NDArray[np.bool_] | None = None) -> tuple[NDArray[np.float64], dict[str, Any], dict[str, Any]]:
        """(S1)-(S4). With missing channels (``~mask``; innovation and H zero there) the moment and N use the
        channels the reading has; a run without any channel keeps V₀ and takes λ = 1 (a prediction only)."""
        return strong_tracking_prior(PhiPPhiT, Qd, state, innovation, H, mask, R=self.R, rho=self.rho,
                                     beta=self.beta, a=self.a)

    def _start(self, xhat0, P0, runs):
        _check_per_run((("rho", self.rho), ("beta", self.beta)), runs)
        return super()._start(xhat0, P0, runs)

    def initial_diagnostics(self, runs: int) -> dict[str, Any]:
        out = super().initial_diagnostics(runs)
        out.update(fading=np.ones((runs, self.n_cov)), fading_c=np.full(runs, np.nan))
        return out


class RateAdaptive:
    """Mixin: process noise of the rate-adapted states from their estimated rate (R1)–(R2).

    On :class:`~hinfnav.estimators.augmented.AugmentedEKF` the adapted states
    are its augmented states and the host's ``Q`` is their density Q(t₀):
    ``Q_d = Q_base + Δt Γ diag(q) Γᵀ``. On
    :class:`~hinfnav.estimators.ExtendedKalmanFilter` (a linear system or any
    dynamics model) ``states`` names them and the host's per-step ``Q`` is
    Q(t₀): ``Q_d`` is ``Q`` with its diagonal entries ``(i, i)``, i in
    ``states``, replaced by the adapted ``q_i`` (R2) (the other entries kept).

    Parameters
    ----------
    memory_steps : int
        m, the number of steps over which the rate is estimated (≥ 1).
    epsilon : float or array_like, shape (runs,)
        Compression factor ε, s per unit of the adapted state (> 0); one
        value per run batches an ε sweep.
    floor : float
        f_min of (R2), ≥ 0 (1: Q(t₀) is the least noise).
    states : sequence of int, optional
        Indices of the adapted states in the estimated state (required on an
        EKF; not allowed on a host with augmented states, which adapts those).

    Diagnostics: ``q_adapted`` (runs, n_adapted), the noise used for the
    prior of this step, and ``input_rate`` κ (runs, n_adapted).
    """

    data_dependent_covariance = True
    defers_prior = True

    def __init__(self, *args: Any, memory_steps: int = 60, epsilon: float = 1.0, floor: float = 1.0,
                 states: Any = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.memory_steps = as_int_at_least("memory_steps", memory_steps, 1)
        self.epsilon = per_run_parameter("epsilon", epsilon, as_positive)
        self.floor = as_nonnegative("floor", floor)
        if hasattr(self, "n_aug"):  # augmented host: its augmented states, Q their density
            if states is not None:
                raise InputError("states must not be given on a filter with augmented states (they are adapted)")
            self._rate_states = None
            self._n_rate = self.n_aug
        else:
            if states is None:
                raise InputError("states (indices of the states whose noise is rate-adapted) must be given on "
                                 "this filter")
            idx = np.asarray(states)
            if (idx.ndim != 1 or idx.size == 0 or not np.issubdtype(idx.dtype, np.integer)
                    or np.any(idx < 0) or np.any(idx >= self.n_state) or np.unique(idx).size != idx.size):
                raise InputError(f"states must be distinct indices in [0, {self.n_state}); got {states!r}")
            self._rate_states = idx
            self._n_rate = idx.size
        self._Q0_diag = np.diag(self.Q).copy() if self._rate_states is None else np.diag(self.Q)[self._rate_states]

    transient_keys = ("prior", "PhiPPhiT", "Qd", "q_used", "kappa_used")

    def rate_states(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The estimate of the adapted states, (runs, n_adapted)."""
        return self.augmented(x) if self._rate_states is None else x[:, self._rate_states]

    def process_noise(self, state: FilterState) -> tuple[NDArray[np.float64], dict[str, Any]]:
        extra = state.extra
        kappa = input_rate(extra["rate_history"], extra["rate_count"], self.memory_steps, self.dt)
        q = rate_adapted_density(self._Q0_diag, kappa, self.epsilon, self.floor)
        if self._rate_states is None:
            Qd = self.base_noise + self.dt * ((self.E * q[:, None, :]) @ self.E.T)  # Δt Γ diag(q) Γᵀ per run
        else:
            Qd = np.broadcast_to(self.Q, (q.shape[0],) + self.Q.shape).copy()
            Qd[:, self._rate_states, self._rate_states] = q
        return Qd, {"q_used": q, "kappa_used": kappa}

    def _start(self, xhat0, P0, runs):
        state = super()._start(xhat0, P0, runs)
        history = np.zeros((self.memory_steps + 1, runs, self._n_rate))
        state.extra.update(rate_history=history, rate_count=0)
        return state

    def after_update(self, state: FilterState, x_post: NDArray[np.float64]) -> dict[str, Any]:
        out = super().after_update(state, x_post)
        history = state.extra["rate_history"].copy()
        count = state.extra["rate_count"]
        history[count % (self.memory_steps + 1)] = self.rate_states(x_post)
        out.update(rate_history=history, rate_count=count + 1)
        return out

    def step_diagnostics(self, state: FilterState) -> dict[str, Any]:
        out = super().step_diagnostics(state)
        runs = state.x.shape[0]
        q = state.extra.get("q_used")
        kappa = state.extra.get("kappa_used")
        out["q_adapted"] = np.broadcast_to(self._Q0_diag, (runs, self._n_rate)) if q is None else q
        out["input_rate"] = np.zeros((runs, self._n_rate)) if kappa is None else kappa
        return out
