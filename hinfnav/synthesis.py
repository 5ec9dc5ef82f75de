"""Robust H∞ filter synthesis by LMI: Theorem 1 and Corollary 1 of the paper.

:func:`synthesize` solves

    min γ²  subject to LMI (20) in R, S, Ā_F, B̄_F, C̄_F, λ      (Corollary 1)

and rebuilds the filter (12) by (21): ``A_F = S⁻¹Ā_F``, ``B_F = S⁻¹B̄_F``,
``C_F = C̄_F``. The returned filter is *certified*, independently of the
solver's status:

1. LMI (20) is evaluated in float64 at the returned filter
   (``Ā_F = S A_F``, ``B̄_F = S B_F``) and the solver's R, S, λ, and the
   smallest γ making it negative definite is found by a Schur complement and
   confirmed by an eigenvalue test (:func:`hinfnav.hinfnorm.schur_gamma`).
   By Theorem 1 that γ bounds ``‖Ψ‖∞`` for every admissible F (10)–(11).
   This γ is the result's ``gamma``.
2. The H∞ norm of the error system (13)–(15) is computed (SLICOT ab13dd) at
   sampled uncertainties (the δ grid with its vertices for the paper's
   system); every sample must be Schur stable with a norm ≤ ``gamma``.

Numerics (the paper's model is badly scaled: ω₀ ≈ 7e-5, uncertainty blocks
~1e-6 beside identity blocks, plant eigenvalues of modulus ≈ 0.999):

* zero columns of H and zero rows of E are dropped;
* the factorization ``ΔA = H F E`` is balanced: column j of H times s_j and
  row j of E divided by s_j when F is diagonal (``structure="diagonal"``,
  the paper's F_Δa), one common scalar otherwise;
* the state coordinates are scaled by a diagonal matrix Σ of powers of two
  (``x = Σ x̃``), so that scaling and unscaling are exact in floating point;
* strictness is imposed as ``LMI ≤ −margin·I``, and ``R ≤ 1e8·I`` bounds
  every variable;
* Clarabel is tried first; CVXOPT is the fallback and, by default, also
  polishes a certified Clarabel solution (one more minimization; the smaller
  certified γ wins): on this model Clarabel stops about 1e-5 (relative) short
  of the optimum, CVXOPT about 1e-8;
* when the direct minimization of γ² does not certify, or certifies a γ
  more than ``rtol`` above the solver's, γ is bisected with feasibility
  problems that maximize the margin t in (20) ≤ −t·I; a problem with no
  solution for any γ is recognized by the γ-free part of (20) having no
  interior point (:class:`~hinfnav.exceptions.InfeasibleLMIError`).

With ``form="observer"`` the filter is constrained to a predictor observer
(``C_F = −L``, ``A_F = A + B_F C``; see :func:`synthesize`): its estimation
error then does not depend on the plant trajectory, which the unconstrained
optimum's does (it is not in observer form, and the H∞ bound assumes a zero
initial state).

The LMI is the paper's, with its single multiplier λ (Lemma 2). For the
paper's diagonal F_Δa, balancing H and E channel by channel (the default of
:func:`design_for_scenario`) changes which full-block contractions the LMI
guards against, and makes it much less conservative at large δ̄; the paper's
LMI as printed is ``structure="full"`` (see notebook 03).
"""

import math
import time
import warnings
from dataclasses import dataclass, field

import control
import cvxpy as cp
import numpy as np
import scipy.linalg

from .exceptions import CertificationError, InfeasibleLMIError, InputError, UnstablePlantError
from .hinfnorm import WorstCase, channel_norms, error_system, hinf_norm, robust_bounded_real_lmi, schur_gamma, spectral_radius, worst_case_norm
from .models import UncertainSystem, uncertainty_F
from .validation import as_choice, as_int_at_least, as_matrix, as_nonnegative, as_positive

__all__ = [
    "SOLVERS",
    "FORMS",
    "DEFAULT_DELTA_BARS",
    "SynthesisResult",
    "GammaSweep",
    "lmi20_matrix",
    "observer_lmi_matrix",
    "prepare_uncertainty",
    "default_uncertainty_samples",
    "synthesize",
    "design_for_scenario",
    "delta_grid",
    "gamma_sweep",
    "design_report",
    "format_design_report",
    "observer_form",
    "compare_with_published",
    "simulation_comparison",
]

#: Solvers :func:`synthesize` accepts (cvxpy names).
SOLVERS = ("CLARABEL", "CVXOPT", "SCS")

#: Filter structures :func:`synthesize` accepts.
FORMS = ("general", "observer")

#: The δ̄ values of the design sweep (issue 3, item 6).
DEFAULT_DELTA_BARS = (0.0, 0.01, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)

_INFEASIBLE = ("infeasible", "infeasible_inaccurate")


# ----------------------------------------------------------------------------
# The LMI
# ----------------------------------------------------------------------------


def lmi20_matrix(A, B, C, D, L, H, E, R, S, Abar_F, Bbar_F, Cbar_F, lam, gamma2, bmat=np.block):
    """The matrix of LMI (20) (Theorem 1), negative definite iff the bound holds.

    Block rows/columns: ``[n, n, n, n, p, q, l, r]`` (the last one only when
    ``H`` is given)::

        [ −R  −S  RA + B̄_F C   Ā_F   RB   B̄_F D    0     RH  ]
        [  *  −S  SA + B̄_F C   Ā_F   SB   B̄_F D    0     SH  ]
        [  *   *  −R + λEᵀE    −S     0    0       Lᵀ     0   ]
        [  *   *   *           −S     0    0     −C̄_Fᵀ    0   ]
        [  *   *   *            *   −γ²I   0       0      0   ]
        [  *   *   *            *     *  −γ²I      0      0   ]
        [  *   *   *            *     *    *      −I      0   ]
        [  *   *   *            *     *    *       *    −λI   ]

    Parameters
    ----------
    A, B, C, D, L : ndarray
        The plant ψ_d (9), shapes (n, n), (n, p), (m, n), (m, q), (l, n).
    H, E : ndarray or None
        Uncertainty factors, shapes (n, r1) and (r2, n) (``ΔA = H F E``);
        ``None`` for the nominal LMI (no λ block).
    R, S : ndarray or cvxpy expression, shape (n, n)
    Abar_F : shape (n, n)
    Bbar_F : shape (n, m)
    Cbar_F : shape (l, n)
    lam : float or cvxpy expression
        λ = 1/ε of Lemma 2.
    gamma2 : float or cvxpy expression
        γ².
    bmat : callable, optional
        ``np.block`` for a numeric matrix, ``cvxpy.bmat`` for an expression.

    Returns
    -------
    ndarray or cvxpy expression, shape (4n + p + q + l [+ r1],) * 2
    """
    n, p = B.shape
    q = D.shape[1]
    l = L.shape[0]
    Z = np.zeros
    I = np.eye
    RA = R @ A + Bbar_F @ C
    SA = S @ A + Bbar_F @ C
    BD = Bbar_F @ D
    rows = [
        [-R, -S, RA, Abar_F, R @ B, BD, Z((n, l))],
        [-S, -S, SA, Abar_F, S @ B, BD, Z((n, l))],
        [RA.T, SA.T, -R, -S, Z((n, p)), Z((n, q)), L.T],
        [Abar_F.T, Abar_F.T, -S, -S, Z((n, p)), Z((n, q)), -Cbar_F.T],
        [(R @ B).T, (S @ B).T, Z((p, n)), Z((p, n)), -gamma2 * I(p), Z((p, q)), Z((p, l))],
        [BD.T, BD.T, Z((q, n)), Z((q, n)), Z((q, p)), -gamma2 * I(q), Z((q, l))],
        [Z((l, n)), Z((l, n)), L, -Cbar_F, Z((l, p)), Z((l, q)), -I(l)],
    ]
    if H is not None:
        r = H.shape[1]
        rows[2][2] = -R + lam * (E.T @ E)
        extra = [R @ H, S @ H] + [Z((k, r)) for k in (n, n, p, q, l)]
        for row, blk in zip(rows, extra):
            row.append(blk)
        rows.append([(R @ H).T, (S @ H).T, Z((r, n)), Z((r, n)), Z((r, p)), Z((r, q)), Z((r, l)), -lam * I(r)])
    return bmat(rows)


def observer_lmi_matrix(A, B, C, D, L, H, E, X, S, Bbar_F, lam, gamma2, bmat=np.block):
    """LMI (20) for an observer-form filter, in error coordinates (congruent to (20)).

    With the observer constraints ``Ā_F = S A + B̄_F C`` and ``C̄_F = −L``
    substituted, ``R = S + X``, and the congruence ``Tᵀ M T`` with
    ``T = diag(T₀, T₀, I, I, I[, I])``, ``T₀ = [[I, 0], [−I, I]]`` (the change
    of coordinates ``(x, x_f) → (x, e = x + x_f)``), LMI (20) becomes::

        [ −X   0    XA         0         XB     0      0    XH  ]
        [  *  −S    0        SA + B̄_F C  SB   B̄_F D    0    SH  ]
        [  *   *   −X + λEᵀE   0          0     0      0    0   ]
        [  *   *    *         −S          0     0      Lᵀ   0   ]
        [  *   *    *          *        −γ²I    0      0    0   ]
        [  *   *    *          *          *   −γ²I     0    0   ]
        [  *   *    *          *          *     *     −I    0   ]
        [  *   *    *          *          *     *      *  −λI   ]

    It is negative definite iff (20) is (congruence with an invertible T),
    at ``R = S + X``, ``Ā_F = S A + B̄_F C``, ``C̄_F = −L``. In these
    coordinates the Lyapunov matrix ``[[R, S], [S, S]]`` of (20) is
    ``diag(X, S)``: X weighs the plant state, S the estimation error, and
    the two are coupled only through the uncertainty (H, E) and the common
    −γ²I row of w. At δ̄ = 0 the infimum has X → 0 (the plant state does
    not reach the error), a boundary of the feasible set. On the paper's
    model, (20) with the constraints merely substituted makes Clarabel and
    CVXOPT stop with numerical errors near the optimum (δ̄ = 0 … 5, γ off by
    up to 6e-3 after bisection); on this form CVXOPT converges to ~1e-7.

    Parameters
    ----------
    A, B, C, D, L, H, E
        As in :func:`lmi20_matrix` (``L`` square); ``H = None`` for the
        nominal LMI.
    X, S : ndarray or cvxpy expression, shape (n, n)
    Bbar_F : shape (n, m)
    lam, gamma2 : float or cvxpy expression
    bmat : callable, optional

    Returns
    -------
    ndarray or cvxpy expression, same shape as :func:`lmi20_matrix`'s
    """
    n, p = B.shape
    q = D.shape[1]
    l = L.shape[0]
    Z = np.zeros
    I = np.eye
    XA = X @ A
    SA = S @ A + Bbar_F @ C
    BD = Bbar_F @ D
    rows = [
        [-X, Z((n, n)), XA, Z((n, n)), X @ B, Z((n, q)), Z((n, l))],
        [Z((n, n)), -S, Z((n, n)), SA, S @ B, BD, Z((n, l))],
        [XA.T, Z((n, n)), -X, Z((n, n)), Z((n, p)), Z((n, q)), Z((n, l))],
        [Z((n, n)), SA.T, Z((n, n)), -S, Z((n, p)), Z((n, q)), L.T],
        [(X @ B).T, (S @ B).T, Z((p, n)), Z((p, n)), -gamma2 * I(p), Z((p, q)), Z((p, l))],
        [Z((q, n)), BD.T, Z((q, n)), Z((q, n)), Z((q, p)), -gamma2 * I(q), Z((q, l))],
        [Z((l, n)), Z((l, n)), Z((l, n)), L, Z((l, p)), Z((l, q)), -I(l)],
    ]
    if H is not None:
        r = H.shape[1]
        rows[2][2] = -X + lam * (E.T @ E)
        extra = [X @ H, S @ H] + [Z((k, r)) for k in (n, n, p, q, l)]
        for row, blk in zip(rows, extra):
            row.append(blk)
        rows.append([(X @ H).T, (S @ H).T, Z((r, n)), Z((r, n)), Z((r, p)), Z((r, q)), Z((r, l)), -lam * I(r)])
    return bmat(rows)


def _gamma_index(n, p, q):
    return np.arange(4 * n, 4 * n + p + q)


# ----------------------------------------------------------------------------
# Preprocessing: drop, balance, scale
# ----------------------------------------------------------------------------


def _pow2(x):
    """Nearest power of two (exact scaling in floating point)."""
    return float(2.0 ** round(math.log2(x)))


@dataclass(frozen=True, eq=False)
class _Prepared:
    """Scaled data of one synthesis problem (internal)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray
    H: np.ndarray  # balanced, zero columns dropped, state-scaled; None if nominal
    E: np.ndarray
    sigma: np.ndarray  # x = diag(sigma) x~
    H_balanced: np.ndarray  # balanced factors in the original state coordinates
    E_balanced: np.ndarray
    form: str = "general"  # "observer": Ā_F = S A + B̄_F C and C̄_F = −L (scaled data) are substituted


def prepare_uncertainty(H, E, structure="diagonal", tol=0.0):
    """Drop the zero columns of H / rows of E and balance the factorization.

    Parameters
    ----------
    H : ndarray, shape (n, r)
    E : ndarray, shape (r, n)
    structure : {"diagonal", "full"}
        ``"diagonal"``: F is diagonal (the paper's F_Δa, Section 4); pair j
        is dropped when column j of H or row j of E is zero, and balanced by
        its own power of two ``s_j ≈ sqrt(‖E_j‖/‖H_j‖)`` (``H diag(s) F
        diag(s)⁻¹ E = H F E`` because diagonal matrices commute). ``"full"``:
        F is any contraction; zero columns of H and zero rows of E are dropped
        independently and one common power of two balances ``‖H‖₂`` and ``‖E‖₂``.
    tol : float, optional
        Norms ≤ tol count as zero.

    Returns
    -------
    H_b : ndarray, shape (n, r1) or None
    E_b : ndarray, shape (r2, n) or None
        ``None`` when nothing uncertain is left (nominal design).
    keep : tuple of ndarray
        Indices of the kept columns of H and rows of E.

    Notes
    -----
    With per-column balancing LMI (20) bounds the error over the set
    ``{H diag(s) F̃ diag(s)⁻¹ E : ‖F̃‖ ≤ 1}``, which contains every diagonal
    contraction F but is not the set the paper's unbalanced LMI covers: the
    two bounds can differ (Lemma 2 with one λ is conservative for diagonal
    F, and the balancing changes by how much).
    """
    structure = as_choice("structure", structure, ("diagonal", "full"))
    H = as_matrix("H", H)
    E = as_matrix("E", E, (None, H.shape[0]))
    hn = np.linalg.norm(H, axis=0)
    en = np.linalg.norm(E, axis=1)
    if structure == "diagonal":
        if H.shape[1] != E.shape[0]:
            raise InputError(f"H has {H.shape[1]} columns but E has {E.shape[0]} rows")
        keep = np.flatnonzero((hn > tol) & (en > tol))
        if keep.size == 0:
            return None, None, (keep, keep)
        s = np.array([_pow2(math.sqrt(en[j] / hn[j])) for j in keep])
        return H[:, keep] * s, E[keep, :] / s[:, None], (keep, keep)
    kh = np.flatnonzero(hn > tol)
    ke = np.flatnonzero(en > tol)
    if kh.size == 0 or ke.size == 0:
        return None, None, (kh, ke)
    Hk, Ek = H[:, kh], E[ke, :]
    s = _pow2(math.sqrt(np.linalg.norm(Ek, 2) / np.linalg.norm(Hk, 2)))
    return Hk * s, Ek / s, (kh, ke)


def _state_scaling(A, mode):
    """Powers of two σ_i for the coordinates ``x = diag(σ) x̃`` (internal).

    ``"balance"``: LAPACK gebal balancing (``scipy.linalg.matrix_balance``,
    no permutation) of the off-diagonal part of ``|A|``, so that the
    position (m) and velocity (m/s) couplings of the Hill model are of
    comparable size (for the paper's A: positions in units of 16 m). An
    array gives σ directly (rounded to powers of two); ``"none"``: σ = 1.
    """
    n = A.shape[0]
    if not isinstance(mode, str):
        sig = np.asarray(mode, dtype=float).ravel()
        if sig.shape != (n,) or not np.all(np.isfinite(sig)) or np.any(sig <= 0):
            raise InputError(f"state_scaling must be 'balance', 'none' or {n} positive numbers; got {mode!r}")
        return np.array([_pow2(v) for v in sig])
    as_choice("state_scaling", mode, ("balance", "none"))
    M = np.abs(A - np.diag(np.diag(A)))
    if mode == "none" or not np.any(M):
        return np.ones(n)
    _, (sca, _) = scipy.linalg.matrix_balance(M, permute=False, separate=True)
    return np.array([_pow2(v) for v in sca])


def _prepare(system, structure, state_scaling, form="general"):
    H_b = E_b = None
    if system.H is not None:
        H_b, E_b, _ = prepare_uncertainty(system.H, system.E, structure)
    sigma = _state_scaling(system.A, state_scaling)
    Si = 1.0 / sigma
    A = Si[:, None] * system.A * sigma[None, :]
    B = Si[:, None] * system.B
    C = system.C * sigma[None, :]
    L = system.L * sigma[None, :]
    H = E = None
    if H_b is not None:
        H = Si[:, None] * H_b
        E = E_b * sigma[None, :]
    return _Prepared(A, B, C, system.D, L, H, E, sigma, H_b, E_b, form)


# ----------------------------------------------------------------------------
# Result objects
# ----------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class SynthesisResult:
    """A certified robust H∞ filter (12) from Theorem 1 / Corollary 1.

    Attributes
    ----------
    A_F : ndarray, shape (n, n)
    B_F : ndarray, shape (n, m)
    C_F : ndarray, shape (l, n)
        The filter ``x_f(k+1) = A_F x_f(k) + B_F y(k)``, ``z_f = C_F x_f``,
        rebuilt by (21), in the plant's (unscaled) state coordinates.
    gamma : float
        Certified level: LMI (20) holds (float64 eigenvalue test) at the
        returned filter with this γ, so ``‖Ψ‖∞ < gamma`` for every admissible
        F (Theorem 1); every sampled norm is ≤ ``gamma``.
    lmi_gamma : float
        The γ the solver reached (minimum of Corollary 1, or the last feasible
        level of the bisection).
    verified_norm : float
        Largest H∞ norm of the error system (13)–(15) over the samples
        (SLICOT ab13dd), a lower bound of the true worst case.
    sample_norms : ndarray, shape (k,)
        The norm at each uncertainty sample.
    worst_sample : int
        Index of the worst sample.
    spectral_radius : float
        Largest spectral radius of the error system over the samples (< 1).
    solver : str
        Solver of the accepted solution.
    solve_time_s : float
        Wall time spent in the solvers (all attempts), s.
    total_time_s : float
        Wall time of the whole synthesis with certification, s.
    method : str
        ``"minimize"`` (Corollary 1 directly) or ``"bisection"``.
    dt : float or True
        Sampling time of :meth:`statespace`.
    variables : dict
        LMI variables in the original coordinates: ``R``, ``S``, ``Abar_F``,
        ``Bbar_F``, ``Cbar_F`` (= ``S A_F``, ``S B_F``, ``C_F``), ``lam``; and
        the balanced uncertainty factors ``H``, ``E`` they go with (``None``
        for a nominal design).
    attempts : tuple of str
        Log of the solves tried and why each was accepted or refused.
    structure : str
        Uncertainty structure assumed (``"diagonal"`` or ``"full"``).
    samples : tuple
        The uncertainty matrices F that were checked.
    delta_bar : float or None
        δ̄ of a design from :func:`design_for_scenario`.
    deltas : ndarray or None
        The δ of each sample (same order as ``sample_norms``), for
        :func:`design_for_scenario`.
    form : str
        ``"general"`` (LMI (20) as in the paper) or ``"observer"`` (filter
        constrained to ``C_F = −L``, ``A_F = A + B_F C``; see :func:`synthesize`).
    """

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    gamma: float
    lmi_gamma: float
    verified_norm: float
    sample_norms: np.ndarray
    worst_sample: int
    spectral_radius: float
    solver: str
    solve_time_s: float
    total_time_s: float
    method: str
    dt: object = True
    variables: dict = field(default_factory=dict)
    attempts: tuple = ()
    structure: str = "full"
    samples: tuple = ()
    delta_bar: float = None
    deltas: np.ndarray = None
    form: str = "general"

    def statespace(self):
        """The filter as a discrete :class:`control.StateSpace` (y → z_f), with ``dt``."""
        return control.ss(self.A_F, self.B_F, self.C_F, np.zeros((self.C_F.shape[0], self.B_F.shape[1])), self.dt)

    @property
    def worst_delta(self):
        """δ of the worst sample (None outside :func:`design_for_scenario`)."""
        return None if self.deltas is None else float(self.deltas[self.worst_sample])

    def error_system(self, system, F=None):
        """Error system (13)–(15) of this filter on ``system`` at uncertainty F."""
        Ap = system.A if F is None else system.perturbed_A(F)
        return error_system(Ap, system.B, system.C, system.D, system.L, self.A_F, self.B_F, self.C_F, self.dt)


# ----------------------------------------------------------------------------
# Uncertainty samples
# ----------------------------------------------------------------------------


def default_uncertainty_samples(system, structure="full", n_random=4, seed=0, max_vertices=64):
    """Uncertainty matrices F at which a design is checked.

    F = 0, ±I, the sign vertices ``diag(±1)`` of a diagonal F (all of them
    for up to ``log2(max_vertices)`` uncertain channels, a seeded random
    subset otherwise), and ``n_random`` seeded random contractions (diagonal
    with entries uniform in [−1, 1] for ``structure="diagonal"``, Gaussian
    matrices scaled to spectral norm 1 for ``"full"``).

    Parameters
    ----------
    system : UncertainSystem
    structure : {"diagonal", "full"}
    n_random : int
    seed : int or numpy.random.Generator
    max_vertices : int

    Returns
    -------
    list of ndarray, shape (r, r) each (``[None]`` for a nominal system)
    """
    if system.H is None:
        return [None]
    r1, r2 = system.H.shape[1], system.E.shape[0]
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    k = min(r1, r2)
    eye = np.eye(r1, r2)
    out = [np.zeros((r1, r2)), eye, -eye]
    if 2**k <= max_vertices:
        signs = [np.array([1 if (i >> j) & 1 else -1 for j in range(k)]) for i in range(2**k)]
    else:
        signs = [rng.choice([-1, 1], size=k) for _ in range(max_vertices)]
    for sg in signs:
        F = np.zeros((r1, r2))
        F[np.arange(k), np.arange(k)] = sg
        out.append(F)
    for _ in range(n_random):
        if structure == "diagonal":
            F = np.zeros((r1, r2))
            F[np.arange(k), np.arange(k)] = rng.uniform(-1, 1, k)
        else:
            F = rng.standard_normal((r1, r2))
            F /= np.linalg.norm(F, 2)
        out.append(F)
    return out


def _check_samples(samples, system, structure):
    if system.H is None:
        return [None]
    shape = (system.H.shape[1], system.E.shape[0])
    checked = []
    for i, F in enumerate(samples):
        if F is None:
            checked.append(np.zeros(shape))
            continue
        F = as_matrix(f"uncertainty_samples[{i}]", F, shape)
        if np.linalg.norm(F, 2) > 1.0 + 1e-9:
            raise InputError(
                f"uncertainty_samples[{i}] must be a contraction (FᵀF ≤ I, (11)); its spectral norm is {np.linalg.norm(F, 2):.6g}"
            )
        if structure == "diagonal" and np.any(F - np.diag(np.diag(F)) != 0):
            raise InputError(f"uncertainty_samples[{i}] must be diagonal with structure='diagonal'")
        checked.append(F)
    if not checked:
        raise InputError("uncertainty_samples must contain at least one matrix F")
    return checked


_UNSTABLE_MSG = (
    "the plant is not robustly Schur stable: A + H F E has spectral radius {rho:.12g} >= 1 at {where}. "
    "Lemma 1 bounds the error system (13), whose state contains the plant state x "
    "(Ā = [[A + ΔA, 0], [B_F C, A_F]] is block triangular, so its eigenvalues include those of A + ΔA); "
    "no filter can make it stable and no finite γ exists. The unforced Hill model (the no-maneuver case, "
    "A = I + T·A₁, spectral radius >= 1) is such a plant: design on the closed loop u = Kx, "
    "A = I + T(A₁ + G₀K), instead (Scenario.design_model)."
)


def _check_plant(system, samples, labels=None):
    """Raise UnstablePlantError unless A and every A + H F E sampled are Schur stable (internal)."""
    rho = spectral_radius(system.A)
    if not rho < 1.0:
        raise UnstablePlantError(_UNSTABLE_MSG.format(rho=rho, where="the nominal plant (F = 0)"))
    for i, F in enumerate(samples):
        if F is None:
            continue
        rho = spectral_radius(system.perturbed_A(F))
        if not rho < 1.0:
            what = "" if labels is None else f" ({labels[i]})"
            raise UnstablePlantError(_UNSTABLE_MSG.format(rho=rho, where=f"uncertainty sample {i}{what}"))


# ----------------------------------------------------------------------------
# Solving and certifying
# ----------------------------------------------------------------------------


@dataclass
class _Solution:
    status: str
    gamma2: float
    R: np.ndarray = None
    S: np.ndarray = None
    Abar_F: np.ndarray = None
    Bbar_F: np.ndarray = None
    Cbar_F: np.ndarray = None
    lam: float = 0.0
    margin: float = float("nan")
    seconds: float = 0.0


def _solver_kwargs(solver, accuracy):
    if solver == "CLARABEL":
        return {"tol_gap_abs": accuracy, "tol_gap_rel": accuracy, "tol_feas": accuracy, "max_iter": 400}
    if solver == "CVXOPT":
        return {"abstol": accuracy, "reltol": accuracy, "feastol": accuracy, "max_iters": 400}
    if solver == "SCS":
        return {"eps_abs": accuracy * 10, "eps_rel": accuracy * 10, "max_iters": 200000}
    return {}


def _solve_lmi(P, solver, margin, accuracy, gamma2=None, bound=1e8):
    """One cvxpy solve of LMI (20) on prepared data (internal).

    ``gamma2=None``: minimize γ² subject to (20) ≤ −margin·I (Corollary 1).
    ``gamma2`` a number: feasibility at that level, maximizing the margin t
    in (20) ≤ −t·I up to a cap (an interior point, which certifies well).
    ``gamma2="free"``: the same for the γ-free part of (20) (its rows and
    columns without −γ²I); it is feasible iff (20) is for some finite γ.
    The solution's ``gamma2`` is then NaN (the certificate finds γ).

    With ``P.form == "observer"`` the equality constraints
    ``Ā_F = S A + B̄_F C`` and ``C̄_F = −L`` (in the scaled coordinates of
    ``P``) are eliminated by substitution, and the LMI is posed in its
    congruent form :func:`observer_lmi_matrix` (variables X = R − S, S,
    B̄_F, λ), on which the solvers converge (on (20) with the substitution
    they stop with numerical errors near the optimum).
    """
    n, p = P.B.shape
    m = P.C.shape[0]
    q = P.D.shape[1]
    l = P.L.shape[0]
    observer = P.form == "observer"
    # (variables created in the same order as before the observer option: identical general-form problems)
    X = cp.Variable((n, n), symmetric=True)  # R in the general form, R − S in the observer form
    S = cp.Variable((n, n), symmetric=True)
    AbF = None if observer else cp.Variable((n, n))
    BbF = cp.Variable((n, m))
    CbF = None if observer else cp.Variable((l, n))
    lam = cp.Variable() if P.H is not None else 0.0
    if gamma2 is None:
        g = cp.Variable()
    elif isinstance(gamma2, str):
        g = 0.0
    else:
        g = float(gamma2)
    if observer:
        R = X + S
        M = observer_lmi_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, X, S, BbF, lam, g, bmat=cp.bmat)
    else:
        R = X
        M = lmi20_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, R, S, AbF, BbF, CbF, lam, g, bmat=cp.bmat)
    if isinstance(gamma2, str):
        keep = np.setdiff1d(np.arange(M.shape[0]), _gamma_index(n, p, q))
        M = M[keep, :][:, keep]
    N = M.shape[0]
    Msym = 0.5 * (M + M.T)
    # R ≤ bound·I bounds every variable when (20) holds (S < R, ‖Ā_F‖² ≤ ‖R‖‖S‖, λ‖E‖² < ‖R‖, ...)
    box = [R << bound * np.eye(n)]
    if gamma2 is None:
        t = margin
        prob = cp.Problem(cp.Minimize(g), [Msym << -margin * np.eye(N)] + box)
    else:
        # the margin is capped: with a cap near the natural scale of (20) (its −I and −γ²I blocks) the
        # solvers (CVXOPT above all) often fail or report "unbounded"
        cap = 1e-3 * min(1.0, 1.0 if isinstance(gamma2, str) else float(gamma2))
        t = cp.Variable()
        prob = cp.Problem(cp.Maximize(t), [Msym << -t * np.eye(N), t <= cap] + box)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # a solver that cannot reach the requested accuracy (CVXOPT's residuals often stall near 1e-7 and it
        # stops with a singular KKT matrix) is asked again with 100x looser tolerances
        for acc in (accuracy, 100.0 * accuracy):
            try:
                prob.solve(solver=solver, **_solver_kwargs(solver, acc))
                break
            except (cp.error.SolverError, ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
                error = exc  # CVXOPT raises ArithmeticError from inside LAPACK on near-singular steps
        else:
            return _Solution(f"solver error ({error})", float("nan"), seconds=time.perf_counter() - start)
    seconds = time.perf_counter() - start
    status = str(prob.status)
    if X.value is None or S.value is None:
        return _Solution(status, float("nan"), seconds=seconds)
    sym = lambda Y: 0.5 * (Y + Y.T)  # noqa: E731
    S_val = sym(S.value)
    if observer:
        R_val = S_val + sym(X.value)
        Abar, Cbar = S_val @ P.A + BbF.value @ P.C, -P.L.copy()
    else:
        R_val = sym(X.value)
        Abar, Cbar = AbF.value.copy(), CbF.value.copy()
    if gamma2 is None:
        gval = float(g.value)
    elif isinstance(gamma2, str):
        gval = float("nan")
    else:
        gval = float(gamma2)
    tval = margin if gamma2 is None else float(t.value)
    return _Solution(
        status,
        gval,
        R_val,
        S_val,
        Abar,
        BbF.value.copy(),
        Cbar,
        float(lam.value) if P.H is not None else 0.0,
        tval,
        seconds,
    )


@dataclass
class _Check:
    ok: bool
    reason: str
    gamma: float = float("inf")
    A_F: np.ndarray = None
    B_F: np.ndarray = None
    C_F: np.ndarray = None
    wc: WorstCase = None
    variables: dict = None


def _rebuild_and_certify(P, sol, system, samples, dt):
    """Filter by (21), LMI certificate, sampled norms (internal)."""
    n = P.A.shape[0]
    condS = np.linalg.cond(sol.S)
    if not np.isfinite(condS) or condS > 1e14:
        return _Check(False, f"S is singular to working precision (cond {condS:.3g}); (21) cannot be applied")
    sig = P.sigma
    # (21) in scaled coordinates
    BFs = np.linalg.solve(sol.S, sol.Bbar_F)
    if P.form == "observer":
        # the structure is imposed on the returned filter itself, in the original coordinates
        # (S⁻¹(S Ã + B̄_F C̃) equals Ã + B̃_F C̃ only to round-off): B_F = Σ B̃_F, C_F = −L,
        # A_F = A + B_F C; the certificate below is evaluated at exactly this filter, scaled back
        # by powers of two (exact): Ã_F = Σ⁻¹ A_F Σ, C̃_F = C_F Σ = −L̃
        B_F_obs = sig[:, None] * BFs
        A_F_obs = system.A + B_F_obs @ system.C
        AFs = A_F_obs * sig[None, :] / sig[:, None]
        CFs = -P.L
    else:
        AFs = np.linalg.solve(sol.S, sol.Abar_F)
        CFs = sol.Cbar_F
    if not (np.all(np.isfinite(AFs)) and np.all(np.isfinite(BFs)) and np.all(np.isfinite(CFs))):
        return _Check(False, "the rebuilt filter has non-finite entries")
    # certificate: (20) at the returned filter (Abar_F = S A_F, Bbar_F = S B_F)
    M0 = lmi20_matrix(P.A, P.B, P.C, P.D, P.L, P.H, P.E, sol.R, sol.S, sol.S @ AFs, sol.S @ BFs, CFs, sol.lam, 0.0)
    p, q = P.B.shape[1], P.D.shape[1]
    gamma_c, info = schur_gamma(M0, _gamma_index(n, p, q))
    # undo the state scaling exactly (powers of two): x_f = Σ x̃_f
    if P.form == "observer":
        A_F, B_F, C_F = A_F_obs, B_F_obs, -system.L
    else:
        A_F = sig[:, None] * AFs / sig[None, :]
        B_F = sig[:, None] * BFs
        C_F = CFs / sig[None, :]
    Si = 1.0 / sig
    variables = {
        "R": Si[:, None] * sol.R * Si[None, :],
        "S": Si[:, None] * sol.S * Si[None, :],
        "lam": sol.lam,
        "H": P.H_balanced,
        "E": P.E_balanced,
    }
    variables["Abar_F"] = variables["S"] @ A_F
    variables["Bbar_F"] = variables["S"] @ B_F
    variables["Cbar_F"] = C_F.copy()
    if not np.isfinite(gamma_c):
        return _Check(
            False,
            f"LMI (20) is not negative definite at the solver's variables for any γ "
            f"(largest eigenvalue of its γ-free part {info['max_eig_OO']:.3g})",
            A_F=A_F,
            B_F=B_F,
            C_F=C_F,
        )
    wc = worst_case_norm(system, A_F, B_F, C_F, samples, dt=1.0)
    if not wc.stable:
        return _Check(
            False,
            f"error system not Schur stable at sample {int(np.argmax(wc.spectral_radii))} "
            f"(spectral radius {np.max(wc.spectral_radii):.10g})",
            gamma_c,
            A_F,
            B_F,
            C_F,
            wc,
        )
    if wc.norm > gamma_c * (1.0 + 1e-9):
        return _Check(
            False,
            f"sampled H∞ norm {wc.norm:.10g} exceeds the LMI-certified level {gamma_c:.10g}",
            gamma_c,
            A_F,
            B_F,
            C_F,
            wc,
        )
    return _Check(True, "certified", gamma_c, A_F, B_F, C_F, wc, variables)


def synthesize(
    A,
    B,
    C,
    D,
    L,
    H=None,
    E=None,
    *,
    dt=True,
    solver=None,
    structure="full",
    uncertainty_samples=None,
    n_random_samples=4,
    seed=0,
    method="auto",
    margin=1e-8,
    accuracy=1e-8,
    rtol=1e-4,
    state_scaling="balance",
    max_bisection=40,
    polish=True,
    form="general",
    _labels=None,
    _deltas=None,
    _delta_bar=None,
):
    """Robust H∞ filter for ψ_d (9)–(11) by Corollary 1, certified.

    Parameters
    ----------
    A : array_like, shape (n, n)
        Plant matrix (must be Schur stable for every admissible F).
    B : array_like, shape (n, p)
        Process-noise matrix.
    C : array_like, shape (m, n)
        Measurement matrix.
    D : array_like, shape (m, q)
        Measurement-noise matrix.
    L : array_like, shape (l, n)
        Estimated signal ``z = L x``.
    H, E : array_like, shapes (n, r) and (r, n), optional
        ``ΔA = H F E`` with ``FᵀF ≤ I`` (10)–(11). Leave out (or give zeros)
        for the nominal H∞ filter.
    dt : float or True, optional
        Sampling time of :meth:`SynthesisResult.statespace` (True: discrete,
        unspecified).
    solver : {"CLARABEL", "CVXOPT", "SCS"}, optional
        Only this solver. Default: Clarabel, then CVXOPT. (SCS, a
        first-order method, is slow and inaccurate on these LMIs: on the
        paper's model it reports "optimal" at a point that is not feasible,
        and the bisection that follows takes minutes.)
    structure : {"full", "diagonal"}, optional
        Whether F is any contraction or diagonal (as in the paper, Section 4);
        decides how H and E are balanced (see :func:`prepare_uncertainty`)
        and which default samples are checked.
    uncertainty_samples : sequence of array_like, optional
        Contractions F (shape (r, r)) at which the error system is checked;
        default :func:`default_uncertainty_samples`.
    n_random_samples : int, optional
        Random contractions in the default samples.
    seed : int or numpy.random.Generator, optional
        Seed of the random samples.
    method : {"auto", "minimize", "bisection"}, optional
        ``"auto"``: minimize γ² directly, and bisect on γ with
        maximum-margin feasibility problems when that does not certify or
        certifies a γ more than ``rtol`` above the solver's.
    margin : float, optional
        Strictness margin of (20) in the scaled problem, as ``−margin·I``.
    accuracy : float, optional
        Solver tolerances (gap and feasibility).
    rtol : float, optional
        Relative accuracy of the bisection on γ, and the acceptable excess of
        the certified γ over the solver's γ.
    state_scaling : {"balance", "none"} or array_like, optional
        Diagonal state-coordinate scaling (rounded to powers of two).
    max_bisection : int, optional
        Largest number of bisection steps per solver.
    polish : bool, optional
        With the default solvers, also solve with CVXOPT after a certified
        Clarabel solution and keep the smaller certified γ (Clarabel stops
        about 1e-5 short of the optimum on the paper's model, CVXOPT about
        1e-8). ``False``: stop at the first certified solution.
    form : {"general", "observer"}, optional
        ``"general"`` (default): LMI (20) as in the paper, any full-order
        filter (12). ``"observer"``: the filter is constrained to a
        predictor observer, ``C_F = −L`` and ``A_F = A + B_F C`` (see Notes);
        needs ``L`` square and invertible.

    Returns
    -------
    SynthesisResult

    Raises
    ------
    InputError
        Mismatched shapes, non-finite entries, bad options (an unknown
        ``form``, or ``form="observer"`` with ``L`` not square and invertible).
    UnstablePlantError
        ``A + H F E`` is not Schur stable at some sample (no finite γ).
    InfeasibleLMIError
        Every solver found LMI (20) infeasible (message carries the status).
    CertificationError
        No solution passed the certification (message says why).

    Notes
    -----
    Theorem 1 / Corollary 1, LMI (20), filter (21). The error system is
    (13)–(15); its norm bound (16) holds for all F with ``FᵀF ≤ I``. The
    LMI is the paper's, with a single multiplier λ (Lemma 2): for diagonal F
    it is conservative.

    **Observer form.** With ``C_F = −L`` and, for ``L = I``, ``x̂ = −x_f``,
    the predictor observer ``x̂⁺ = A x̂ + G (y − C x̂)`` reads
    ``x_f⁺ = (A − G C) x_f − G y``: it is the filter (12) with
    ``B_F = −G`` and ``A_F = A + B_F C``. By (21), ``A_F = S⁻¹Ā_F`` and
    ``B_F = S⁻¹B̄_F``, so multiplying by S turns these into constraints that
    are *linear* in the LMI variables::

        C̄_F = −L,      Ā_F = S A + B̄_F C.

    They are added to (20) by substitution (Ā_F and C̄_F are no longer free
    variables), so Corollary 1 with them is still an SDP and its optimum
    γ_observer ≥ γ* (a restriction). The estimation error
    ``e = x − x̂ = x + x_f`` then obeys

        e⁺ = (A − G C) e + ΔA x + B w − G D v,

    which does not involve the plant trajectory at ΔA = 0: an initial
    state, or a thrust the filter is told exactly, does not leak into the
    error (the general optimum's error depends on x). For an invertible
    ``L ≠ I`` the same filter estimates ``z = L x`` by ``z_f = L x̂`` (its
    error is ``L e``); :func:`observer_form`, which compares
    ``C_F A_F C_F⁻¹`` with A, reports a zero residual only for ``L = I``.

    The state scaling ``x = Σ x̃`` of the numerics is applied to the
    constraints as well (``C̄_F = −L Σ``, ``Ā_F = S Σ⁻¹AΣ + B̄_F C Σ``), and
    the returned filter is rebuilt in the original coordinates as
    ``B_F = Σ S⁻¹B̄_F``, ``A_F = A + B_F C``, ``C_F = −L``: the identities
    hold to the round-off of one product and sum. The solvers get the
    substituted LMI in a congruent form, :func:`observer_lmi_matrix` (in the
    coordinates (x, e); on (20) itself they stall near the optimum).
    Certification is unchanged: (20) by eigenvalues at exactly the returned
    filter, and the sampled norms.

    The derivation itself only uses ``C_F = −L`` (the filter state is
    always a full state estimate); ``L`` is required square and invertible
    so that ``x̂ = C_F x_f`` is that estimate, as in the paper (L = I).
    """
    t_start = time.perf_counter()
    system = UncertainSystem(A, B, C, D, L, H, E, dt=1.0)
    dt_value = True if dt is True else as_positive("dt", dt)
    structure = as_choice("structure", structure, ("full", "diagonal"))
    method = as_choice("method", method, ("auto", "minimize", "bisection"))
    margin = as_positive("margin", margin)
    accuracy = as_positive("accuracy", accuracy)
    rtol = as_positive("rtol", rtol)
    max_bisection = as_int_at_least("max_bisection", max_bisection, 1)
    n_random_samples = as_int_at_least("n_random_samples", n_random_samples, 0)
    if not isinstance(form, str):
        raise InputError(f"form must be a string, one of {', '.join(FORMS)}; got {form!r}")
    form = as_choice("form", form, FORMS)
    if form == "observer":
        n_state, l_out = system.A.shape[0], system.L.shape[0]
        if l_out != n_state:
            raise InputError(
                f"form='observer' needs the filter to estimate the whole state: L must be square and invertible, "
                f"got L of shape {l_out}x{n_state}"
            )
        condL = np.linalg.cond(system.L)
        if not condL < 1e12:
            raise InputError(
                f"form='observer' needs L square and invertible (C_F = −L); L is singular (cond {condL:.3g})"
            )
    if solver is None:
        solvers = ["CLARABEL", "CVXOPT"]
    else:
        if not isinstance(solver, str):
            raise InputError(f"solver must be a string, one of {', '.join(SOLVERS)}; got {solver!r}")
        solvers = [as_choice("solver", solver.upper(), SOLVERS)]
    if system.H is not None and not (np.any(system.H) and np.any(system.E)):
        system = UncertainSystem(system.A, system.B, system.C, system.D, system.L, None, None, 1.0)
    if uncertainty_samples is None:
        samples = default_uncertainty_samples(system, structure, n_random_samples, seed)
    else:
        samples = _check_samples(list(uncertainty_samples), system, structure)
    checked_samples = samples if system.H is not None else [None]
    _check_plant(system, checked_samples, _labels)

    P = _prepare(system, structure, state_scaling, form)
    log = []
    statuses = []
    candidates = []
    times = [0.0]

    def certify(sol):
        times[0] += sol.seconds
        if sol.R is None:
            return None
        return _rebuild_and_certify(P, sol, system, checked_samples, dt_value)

    for slv in solvers:
        # once a solution is certified, the other solvers only polish it (one minimization each)
        how = method if not candidates else "minimize"
        found = _run_solver(P, slv, how, margin, accuracy, rtol, max_bisection, certify, log, statuses)
        candidates.extend(found)
        if candidates and not polish:
            break

    if candidates:
        chk, sol, slv, how = min(candidates, key=lambda c: c[0].gamma)
        return SynthesisResult(
            A_F=chk.A_F,
            B_F=chk.B_F,
            C_F=chk.C_F,
            gamma=float(chk.gamma),
            lmi_gamma=float(math.sqrt(max(sol.gamma2, 0.0))),
            verified_norm=chk.wc.norm,
            sample_norms=chk.wc.norms,
            worst_sample=chk.wc.index,
            spectral_radius=float(np.max(chk.wc.spectral_radii)),
            solver=slv,
            solve_time_s=times[0],
            total_time_s=time.perf_counter() - t_start,
            method=how,
            dt=dt_value,
            variables=chk.variables,
            attempts=tuple(log),
            structure=structure,
            samples=tuple(checked_samples),
            delta_bar=_delta_bar,
            deltas=None if _deltas is None else np.asarray(_deltas, dtype=float),
            form=form,
        )
    if any(st in _INFEASIBLE or st.startswith("infeasible") for _, st in statuses):
        hint = (
            " With structure='full' F may be any contraction; if F is diagonal (as in the paper), "
            "structure='diagonal' balances H and E channel by channel and is less conservative."
            if structure == "full" and system.H is not None and min(system.H.shape[1], system.E.shape[0]) > 1
            else ""
        )
        if form == "observer":
            hint += (
                " The observer-form constraints (C_F = −L, A_F = A + B_F C) were imposed; "
                "form='general' may be feasible."
            )
        raise InfeasibleLMIError(
            "LMI (20) is infeasible: no R, S, λ make the error system quadratically stable for every admissible F, "
            "so Theorem 1 gives no filter for any γ (solver status: "
            + "; ".join(f"{slv} {st}" for slv, st in statuses)
            + ")."
            + hint
        )
    raise CertificationError(
        "no solution of LMI (20) passed certification (LMI eigenvalue test at the rebuilt filter and H∞ norms of "
        "the error system at the uncertainty samples); last attempts: " + " | ".join(log[-5:])
    )


def _run_solver(P, slv, method, margin, accuracy, rtol, max_bisection, certify, log, statuses):
    """Minimize, then bisect if needed, with one solver; certified candidates (internal)."""
    cands = []
    lo = 0.0
    if method in ("auto", "minimize"):
        sol = _solve_lmi(P, slv, margin, accuracy)
        statuses.append((slv, sol.status))
        chk = certify(sol)
        if chk is None:
            log.append(f"{slv} minimize: status {sol.status}, no solution")
            if method == "minimize" or sol.status in _INFEASIBLE:
                return cands
        else:
            lmi_g = math.sqrt(max(sol.gamma2, 0.0))
            log.append(f"{slv} minimize: status {sol.status}, solver γ = {lmi_g:.10g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
            if chk.ok:
                cands.append((chk, sol, slv, "minimize"))
                if method == "minimize" or chk.gamma <= lmi_g * (1.0 + rtol):
                    return cands
            elif method == "minimize":
                return cands
            # the solver's γ is a lower-bound hint only: bisection never returns an uncertified point
            lo = lmi_g * (1.0 - (10.0 * rtol if sol.status == "optimal" else 1e-2))
            if not chk.ok and lmi_g > 0:
                # the solver's point is (slightly) infeasible: look for a certifiable level just above it
                for step in (1e-4, 1e-3, 1e-2, 1e-1, 1.0):
                    level = lmi_g * (1.0 + step)
                    sol2 = _solve_lmi(P, slv, margin, accuracy, gamma2=level**2)
                    chk2 = certify(sol2)
                    if chk2 is not None and sol2.margin > 0 and chk2.ok:
                        log.append(f"{slv} feasibility at γ = {level:.10g}: margin {sol2.margin:.3g}, certified γ = {chk2.gamma:.10g}")
                        cands.append((chk2, sol2, slv, "bisection"))
                        break
                    log.append(f"{slv} feasibility at γ = {level:.10g}: status {sol2.status}, not certified")
    # bisection on γ with maximum-margin feasibility problems
    hi = min((c[0].gamma for c in cands), default=None)
    if hi is None:
        # the most interior point of the γ-free part of (20): feasible iff (20) is for some γ
        sol = _solve_lmi(P, slv, margin, accuracy, gamma2="free")
        chk = certify(sol)
        if chk is None:
            log.append(f"{slv} γ-free feasibility: status {sol.status}, no solution")
            statuses.append((slv, sol.status))
            return cands
        if not sol.margin > 0:
            log.append(f"{slv} γ-free feasibility: status {sol.status}, largest margin {sol.margin:.3g} <= 0")
            statuses.append((slv, f"infeasible (status {sol.status}, largest margin t = {sol.margin:.3g} <= 0)"))
            return cands
        log.append(f"{slv} γ-free feasibility: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
        if not chk.ok:
            return cands
        sol.gamma2 = chk.gamma**2
        cands.append((chk, sol, slv, "bisection"))
        hi = chk.gamma
    if lo >= hi:
        lo = 0.0  # the solver's γ was no lower bound (it is above a certified level): start from scratch
    for _ in range(max_bisection):
        if hi - lo <= rtol * hi:
            break
        mid = 0.5 * (lo + hi)
        sol = _solve_lmi(P, slv, margin, accuracy, gamma2=mid**2)
        chk = certify(sol)
        if chk is None or not sol.margin > 0:
            log.append(f"{slv} feasibility at γ = {mid:.10g}: status {sol.status}, margin {sol.margin:.3g}: infeasible")
            lo = mid
            continue
        log.append(f"{slv} feasibility at γ = {mid:.10g}: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
        if chk.ok and chk.gamma < hi:
            cands.append((chk, sol, slv, "bisection"))
            hi = chk.gamma
        if not chk.ok or chk.gamma > mid:
            lo = mid  # the solver's claim of feasibility at this level is not confirmed
    return cands


# ----------------------------------------------------------------------------
# The paper's system
# ----------------------------------------------------------------------------


def delta_grid(delta_bar, points=21):
    """δ values checked for a design: ``points`` evenly spaced in [−δ̄, δ̄].

    An odd ``points`` includes δ = 0; the vertices ±δ̄ are always included.

    Returns
    -------
    ndarray, shape (points,) (``[0.]`` when δ̄ = 0)
    """
    delta_bar = as_nonnegative("delta_bar", delta_bar)
    points = as_int_at_least("points", points, 2)
    if delta_bar == 0:
        return np.zeros(1)
    grid = np.linspace(-delta_bar, delta_bar, points)
    return np.unique(np.concatenate([grid, [0.0]]))


def design_for_scenario(scenario=None, delta_bar=None, *, delta_points=21, **options):
    """Design the robust filter for a scenario's closed-loop model at δ̄.

    Builds ψ_d from ``scenario.design_model(delta_bar)`` (A = I + T(A₁ + G₀K),
    H = T·H_a, E = E_a of Section 4), treats F as diagonal (the paper's
    F_Δa) and certifies on the δ grid :func:`delta_grid` (vertices ±δ̄ and 0
    included), with F(δ) from :func:`hinfnav.models.uncertainty_F`.

    Parameters
    ----------
    scenario : hinfnav.scenario.Scenario, optional
        Default: the paper's.
    delta_bar : float, optional
        Default ``scenario.delta_bar``.
    delta_points : int, optional
        Points of the δ grid.
    **options
        Passed to :func:`synthesize` (``solver``, ``method``, ``form``, ...).

    Returns
    -------
    SynthesisResult
        With ``delta_bar`` and ``deltas`` set, ``dt = scenario.dt``.
    """
    from .scenario import Scenario

    scenario = Scenario() if scenario is None else scenario
    delta_bar = scenario.delta_bar if delta_bar is None else as_nonnegative("delta_bar", delta_bar)
    system = scenario.design_model(delta_bar)
    deltas = delta_grid(delta_bar, delta_points)
    if delta_bar > 0:
        samples = [uncertainty_F(d, delta_bar) for d in deltas]
    else:
        samples = None
    options.setdefault("structure", "diagonal")
    options.setdefault("dt", scenario.dt)
    return synthesize(
        system.A,
        system.B,
        system.C,
        system.D,
        system.L,
        system.H,
        system.E,
        uncertainty_samples=samples,
        _labels=[f"δ = {d:.6g}" for d in deltas],
        _deltas=deltas,
        _delta_bar=delta_bar,
        **options,
    )


@dataclass(frozen=True, eq=False)
class GammaSweep:
    """Certified designs across δ̄ (the curve γ*(δ̄)).

    Attributes
    ----------
    delta_bars : ndarray, shape (k,)
    results : tuple of SynthesisResult
    """

    delta_bars: np.ndarray
    results: tuple

    @property
    def gammas(self):
        """Certified γ per δ̄, shape (k,)."""
        return np.array([r.gamma for r in self.results])

    @property
    def lmi_gammas(self):
        """Solver γ per δ̄, shape (k,)."""
        return np.array([r.lmi_gamma for r in self.results])

    @property
    def verified_norms(self):
        """Worst sampled norm per δ̄, shape (k,)."""
        return np.array([r.verified_norm for r in self.results])

    @property
    def solve_times(self):
        """Solver wall time per δ̄, s, shape (k,)."""
        return np.array([r.solve_time_s for r in self.results])

    @property
    def nondecreasing(self):
        """Whether the certified γ*(δ̄) is non-decreasing (δ̄ sorted ascending)."""
        order = np.argsort(self.delta_bars)
        return bool(np.all(np.diff(self.gammas[order]) >= 0))

    def table(self):
        """Rows ``(δ̄, γ, lmi_γ, verified norm, worst δ, solver, method, time)`` as dicts."""
        return [
            {
                "delta_bar": float(d),
                "gamma": r.gamma,
                "lmi_gamma": r.lmi_gamma,
                "verified_norm": r.verified_norm,
                "worst_delta": r.worst_delta,
                "solver": r.solver,
                "method": r.method,
                "solve_time_s": r.solve_time_s,
            }
            for d, r in zip(self.delta_bars, self.results)
        ]


def gamma_sweep(delta_bars=DEFAULT_DELTA_BARS, scenario=None, progress=False, **options):
    """Certified designs for several δ̄ (Corollary 1 at each).

    Parameters
    ----------
    delta_bars : sequence of float, optional
        Default :data:`DEFAULT_DELTA_BARS` (0 … 5).
    scenario : Scenario, optional
    progress : bool, optional
        Show a tqdm progress bar.
    **options
        Passed to :func:`design_for_scenario` (``form="observer"`` for the
        observer-form curve).

    Returns
    -------
    GammaSweep
    """
    from tqdm import tqdm

    dbs = np.array([as_nonnegative("delta_bars entry", d) for d in delta_bars], dtype=float)
    results = []
    for d in tqdm(dbs, disable=not progress, desc="γ*(δ̄)", unit="design"):
        results.append(design_for_scenario(scenario, d, **options))
    return GammaSweep(dbs, tuple(results))


def design_report(delta_bar, solver=None, scenario=None, form="general"):
    """JSON-ready summary of one certified design (for ``python -m hinfnav design``).

    Parameters
    ----------
    delta_bar : float
        Uncertainty bound δ̄ ≥ 0.
    solver : str, optional
        ``"CLARABEL"``, ``"CVXOPT"`` or ``"SCS"`` (default: Clarabel, CVXOPT fallback).
    scenario : Scenario, optional
    form : {"general", "observer"}, optional
        Filter structure (see :func:`synthesize`).

    Returns
    -------
    dict
        ``delta_bar``, ``form``, ``gamma`` (certified), ``lmi_gamma``,
        ``verified_norm``, ``worst_delta``, ``spectral_radius``, ``solver``,
        ``method``, ``solve_time_s``, ``total_time_s``, ``dt``, ``A_F``,
        ``B_F``, ``C_F`` (nested lists), ``deltas_checked``, ``attempts``.
    """
    res = design_for_scenario(scenario, delta_bar, solver=solver, form=form)
    return {
        "delta_bar": float(res.delta_bar),
        "form": res.form,
        "gamma": res.gamma,
        "lmi_gamma": res.lmi_gamma,
        "verified_norm": res.verified_norm,
        "worst_delta": res.worst_delta,
        "spectral_radius": res.spectral_radius,
        "solver": res.solver,
        "method": res.method,
        "solve_time_s": res.solve_time_s,
        "total_time_s": res.total_time_s,
        "dt": float(res.dt),
        "A_F": res.A_F.tolist(),
        "B_F": res.B_F.tolist(),
        "C_F": res.C_F.tolist(),
        "deltas_checked": [float(d) for d in res.deltas],
        "attempts": list(res.attempts),
    }


def _fmt_matrix(M, indent="    "):
    M = np.asarray(M, dtype=float)
    return "\n".join(indent + " ".join(f"{v: .5e}" for v in row) for row in M)


def format_design_report(report):
    """Readable text version of :func:`design_report`'s dict.

    Parameters
    ----------
    report : dict

    Returns
    -------
    str
    """
    form = report.get("form", "general")
    form_text = {
        "general": "general (LMI (20) as in the paper)",
        "observer": "observer (C_F = −L, A_F = A + B_F C imposed on LMI (20))",
    }.get(form, str(form))
    lines = [
        f"Robust H∞ filter, Corollary 1 of Sun et al. (2011), δ̄ = {report['delta_bar']:g}",
        f"  filter form        : {form_text}",
        f"  certified γ        : {report['gamma']:.8g}   (LMI (20) verified by eigenvalues at the returned filter)",
        f"  solver γ           : {report['lmi_gamma']:.8g}   ({report['solver']}, {report['method']})",
        f"  worst sampled norm : {report['verified_norm']:.8g}   at δ = {report['worst_delta']:.6g} "
        f"({len(report['deltas_checked'])} δ checked, slycot ab13dd)",
        f"  spectral radius    : {report['spectral_radius']:.8g}   (error system, worst sample)",
        f"  solve time         : {report['solve_time_s']:.3f} s   (total with certification {report['total_time_s']:.3f} s)",
        f"  sampling time T    : {report['dt']:g} s",
        "  A_F =",
        _fmt_matrix(report["A_F"]),
        "  B_F =",
        _fmt_matrix(report["B_F"]),
        "  C_F =",
        _fmt_matrix(report["C_F"]),
    ]
    return "\n".join(lines)


# ----------------------------------------------------------------------------
# The published filter
# ----------------------------------------------------------------------------


def observer_form(A_F, B_F, C_F, A, C):
    """Express a filter with invertible ``C_F`` as an observer for ``x̂ = C_F x_f``.

    In the coordinates ``x̂ = C_F x_f`` the filter (12) reads
    ``x̂⁺ = Â x̂ + G y`` with ``Â = C_F A_F C_F⁻¹`` and ``G = C_F B_F``. It is
    a predictor observer ``x̂⁺ = A x̂ + G (y − C x̂)`` exactly when
    ``Â = A − G C``.

    Parameters
    ----------
    A_F, B_F, C_F : array_like
        The filter (``C_F`` square).
    A : array_like, shape (n, n)
        Plant matrix of the design model.
    C : array_like, shape (m, n)

    Returns
    -------
    dict
        ``G`` (n, m), ``A_hat`` (n, n), ``residual`` = ``max |Â − (A − G C)|``,
        ``observer_eigenvalues`` (eigenvalues of A_F).
    """
    A_F = as_matrix("A_F", A_F)
    C_F = as_matrix("C_F", C_F, A_F.shape)
    B_F = as_matrix("B_F", B_F, (A_F.shape[0], None))
    A = as_matrix("A", A, A_F.shape)
    C = as_matrix("C", C, (B_F.shape[1], A_F.shape[0]))
    A_hat = C_F @ np.linalg.solve(C_F.T, A_F.T).T
    G = C_F @ B_F
    return {
        "G": G,
        "A_hat": A_hat,
        "residual": float(np.max(np.abs(A_hat - (A - G @ C)))),
        "observer_eigenvalues": np.linalg.eigvals(A_F),
    }


def compare_with_published(scenario=None, solver=None, delta_points=21, design=None):
    """The published filter (δ̄ = 0.05) against the re-synthesized optimum.

    Both filters are evaluated on the same error system (13)–(15) of the
    scenario's design model at δ̄ = 0.05:

    * the worst sampled H∞ norm over the δ grid :func:`delta_grid` (slycot),
    * a certified bound over every admissible F: the robust bounded real
      LMI of Lemmas 1–3 with the filter fixed
      (:func:`hinfnav.hinfnorm.robust_bounded_real_lmi`, with the same
      balanced H, E as the synthesis),
    * the nominal (δ = 0) norm and the frequency of its peak,
    * the observer form ``x̂⁺ = A x̂ + G (y − C x̂)`` in ``x̂ = C_F x_f``
      (:func:`observer_form`).

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's (T = 0.1 s).
    solver : str, optional
        Solver of the synthesis and of the robust bound (default: both).
    delta_points : int, optional
    design : SynthesisResult, optional
        A design at δ̄ = 0.05 to reuse (default: synthesized here).

    Returns
    -------
    dict
        ``delta_bar``; ``published`` and ``optimal``: dicts with
        ``worst_norm``, ``worst_delta``, ``sample_norms``, ``nominal_norm``,
        ``peak_frequency`` (rad/s), ``robust_bound``, ``observer_gain``
        (shape (6, 3)), ``observer_residual``, ``filter_eigenvalues``,
        ``spectral_radius``; ``optimal`` also ``gamma``, ``lmi_gamma``;
        ``ratio`` = published worst norm / optimal certified γ;
        ``excess_percent``; ``deltas``; ``design`` (the SynthesisResult).
    """
    from .scenario import Scenario, published_filter

    scenario = Scenario() if scenario is None else scenario
    pub = published_filter()
    db = pub.delta_bar
    if design is None:
        design = design_for_scenario(scenario, db, solver=solver, delta_points=delta_points)
    system = scenario.design_model(db)
    deltas = delta_grid(db, delta_points)
    samples = [uncertainty_F(d, db) for d in deltas]
    H_b, E_b, _ = prepare_uncertainty(system.H, system.E, "diagonal")

    def evaluate(A_F, B_F, C_F):
        wc = worst_case_norm(system, A_F, B_F, C_F, samples, dt=scenario.dt)
        nominal = error_system(system.A, system.B, system.C, system.D, system.L, A_F, B_F, C_F, scenario.dt)
        g0, w0 = hinf_norm(nominal, return_peak=True)
        Hbar = np.vstack([H_b, np.zeros_like(H_b)])
        Ebar = np.hstack([E_b, np.zeros_like(E_b)])
        cert = robust_bounded_real_lmi(nominal.A, nominal.B, nominal.C, Hbar, Ebar, solver=solver)
        obs = observer_form(A_F, B_F, C_F, system.A, system.C)
        p, q = system.B.shape[1], system.D.shape[1]
        chans = channel_norms(
            nominal, {"w": slice(0, p), "v": slice(p, p + q)}, {"position": slice(0, 3), "velocity": slice(3, 6)}
        )
        return {
            "worst_norm": wc.norm,
            "worst_delta": float(deltas[wc.index]),
            "sample_norms": wc.norms,
            "nominal_norm": g0,
            "peak_frequency": w0,
            "robust_bound": cert.gamma,
            "observer_gain": obs["G"],
            "observer_residual": obs["residual"],
            "filter_eigenvalues": obs["observer_eigenvalues"],
            "spectral_radius": float(np.max(wc.spectral_radii)),
            "channel_norms": chans,
        }

    published = evaluate(pub.A_F, pub.B_F, pub.C_F)
    optimal = evaluate(design.A_F, design.B_F, design.C_F)
    optimal["gamma"] = design.gamma
    optimal["lmi_gamma"] = design.lmi_gamma
    return {
        "delta_bar": db,
        "published": published,
        "optimal": optimal,
        "ratio": published["worst_norm"] / design.gamma,
        "excess_percent": 100.0 * (published["worst_norm"] / design.gamma - 1.0),
        "deltas": deltas,
        "design": design,
    }


def simulation_comparison(design=None, scenario=None, runs=20, seed=0, *, observer=None, starts=("paper", "rest")):
    """Monte Carlo RMS errors of the published and the re-synthesized filters.

    The filters run on the same simulated truths (:func:`hinfnav.simulation.simulate_truth`),
    with and without maneuver, from the paper's initial state and from rest
    (x₀ = 0, x̂₀ = 0, where only the noise excites the error, the setting of
    the H∞ bound). With maneuver the filters run exactly as (12); without
    maneuver they are told the applied thrust u = 0
    (:func:`hinfnav.filters.lti_from_matrices`), since (12) assumes u = Kx.
    That correction is exact only for a filter in observer form.

    Parameters
    ----------
    design : SynthesisResult, optional
        The general (LMI (20)) design; default :func:`design_for_scenario`
        at δ̄ = 0.05.
    scenario : Scenario, optional
    runs : int, optional
        Monte Carlo runs per case.
    seed : int, optional
    observer : SynthesisResult or bool, optional
        A third filter, in observer form (:func:`synthesize` with
        ``form="observer"``): a result to reuse, or True to design it at
        the δ̄ of ``design`` (0.05 if unset). None or False: two filters.
    starts : sequence of {"paper", "rest"}, optional
        Initial conditions to simulate.

    Returns
    -------
    list of dict
        One row per (start, maneuver, filter): ``start``, ``maneuver``,
        ``filter`` (``"published"``, ``"re-synthesized"``, ``"observer form"``),
        ``pos_rms`` (3,) m, ``vel_rms`` (3,) m/s over the scenario's RMS
        window (default 100–1000 s); and the filter's noise-only stationary
        standard deviations ``stationary_pos_std`` (3,) m and
        ``stationary_vel_std`` (3,) m/s (Euler truth, δ = 0, the design
        model), which a filter whose error does not depend on the trajectory
        approaches from any start once its initial error has decayed:

        * with maneuver, (12) run verbatim on the closed loop,
          :func:`hinfnav.kalman.lti_error_covariance`;
        * without maneuver, for a filter exactly in observer form
          (:func:`observer_form` residual ≤ 1e-9·max|A|) told the thrust,
          whose error obeys ``e⁺ = (I + T A₁ − G C) e + B w − G D v`` (the
          correction removes the ``−T G₀ K`` of the closed loop, so the error
          decays without the controller's damping); NaN for the other
          filters, whose error depends on the drifting plant state and has no
          stationary covariance.
    """
    from .filters import lti_from_matrices
    from .kalman import lti_error_covariance
    from .metrics import rms_error
    from .scenario import Scenario, published_filter
    from .simulation import run_estimator, simulate_truth

    scenario = Scenario() if scenario is None else scenario
    design = design_for_scenario(scenario, 0.05) if design is None else design
    starts = [as_choice("start", st, ("paper", "rest")) for st in starts]
    pub = published_filter()
    filters = {"published": (pub.A_F, pub.B_F, pub.C_F), "re-synthesized": (design.A_F, design.B_F, design.C_F)}
    if observer is True:
        db = 0.05 if design.delta_bar is None else design.delta_bar
        observer = design_for_scenario(scenario, db, form="observer")
    if observer is not None and observer is not False:
        filters["observer form"] = (observer.A_F, observer.B_F, observer.C_F)
    design_A = scenario.design_model(0.0).A
    C = scenario.design_model(0.0).C
    open_loop = design_A - scenario.input_matrix_design() @ scenario.K  # I + T A₁ (Euler, u = 0)
    stationary = {}
    for name, (A_F, B_F, C_F) in filters.items():
        std = np.sqrt(np.diag(lti_error_covariance(A_F, B_F, C_F, scenario, discretization="euler")))
        stationary[name, True] = (std[:3], std[3:])
        std = np.full(6, np.nan)
        obs = observer_form(A_F, B_F, C_F, design_A, C)
        if obs["residual"] <= 1e-9 * np.max(np.abs(design_A)):
            G = obs["G"]
            Ae = open_loop - G @ C
            if spectral_radius(Ae) < 1:
                Q = scenario.B @ scenario.B.T + G @ scenario.D @ scenario.D.T @ G.T
                std = np.sqrt(np.diag(scipy.linalg.solve_discrete_lyapunov(Ae, Q)))
        stationary[name, False] = (std[:3], std[3:])
    rows = []
    for start in starts:
        sc = scenario if start == "paper" else scenario.replace(x0=np.zeros(6), xhat0=np.zeros(6))
        for maneuver in (True, False):
            truth = simulate_truth(sc, maneuver=maneuver, runs=runs, seed=seed)
            for name, (A_F, B_F, C_F) in filters.items():
                est = lti_from_matrices(A_F, B_F, C_F, sc, name=name, uses_input=not maneuver)
                res = run_estimator(est, truth, sc.xhat0)
                pos, vel = rms_error(res.error, res.t, sc.rms_window_s)
                rows.append(
                    {
                        "start": start,
                        "maneuver": maneuver,
                        "filter": name,
                        "pos_rms": pos,
                        "vel_rms": vel,
                        "stationary_pos_std": stationary[name, maneuver][0],
                        "stationary_vel_std": stationary[name, maneuver][1],
                    }
                )
    return rows
