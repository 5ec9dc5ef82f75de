"""Conditioning of the synthesis LMIs: drop, balance and scale, all exactly undoable.

* zero columns of H and zero rows of E are dropped;
* the factorization ``ΔA = H F E`` is balanced channel by channel when F is
  diagonal, by one common scalar otherwise (:func:`prepare_uncertainty`);
* the state coordinates are scaled by powers of two (``x = Σ x̃``), so that
  scaling and unscaling are exact in floating point;
* badly scaled noise and output blocks are normalised by powers of two
  (:func:`normalize`): a common factor ρ on the noise inputs (B, D) and a
  factor ν on the estimated signal (L), only above
  :data:`NORMALIZE_THRESHOLD`. Both are a congruence of LMI (20), undone
  exactly (see :func:`normalize`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg
from scipy.sparse.csgraph import connected_components
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_matrix

if TYPE_CHECKING:
    from ..systems.uncertain import UncertainSystem

__all__ = [
    "Prepared",
    "prepare_uncertainty",
    "prepare",
    "state_scaling",
    "unit_scaling",
    "round_mantissa",
    "pow2",
    "NORMALIZE_THRESHOLD",
    "block_scales",
    "normalize",
    "noise_scale",
    "solver_data",
    "lmi20_diagonal",
]


def pow2(x: float) -> float:
    """Nearest power of two (exact scaling in floating point)."""
    return float(2.0 ** round(math.log2(x)))


@dataclass(frozen=True, eq=False)
class Prepared:
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
    rho: float = 1.0  # B, D above are the state-scaled ones divided by rho (a power of two), see normalize()
    nu: float = 1.0  # L above is the state-scaled one divided by nu (a power of two)
    noise_ref: float = 0.0  # > 0: normalize() divides B, D by exactly this (noise_scale(), a real factor), 0: off

    @property
    def normalized(self) -> bool:
        """Whether the noise or output blocks are normalised (ρ ≠ 1 or ν ≠ 1)."""
        return self.rho != 1.0 or self.nu != 1.0

    def unnormalized(self) -> Prepared:
        """The same data with the normalisation of :func:`normalize` undone (exact: powers of two)."""
        if not self.normalized:
            return self
        return dataclasses.replace(self, B=self.B * self.rho, D=self.D * self.rho, L=self.L * self.nu, rho=1.0, nu=1.0)


def prepare_uncertainty(H: ArrayLike, E: ArrayLike, structure: str = "diagonal", tol: float = 0.0
                        ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None, tuple[NDArray[np.intp], NDArray[np.intp]]]:
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
        s = np.array([pow2(math.sqrt(en[j] / hn[j])) for j in keep])
        return H[:, keep] * s, E[keep, :] / s[:, None], (keep, keep)
    kh = np.flatnonzero(hn > tol)
    ke = np.flatnonzero(en > tol)
    if kh.size == 0 or ke.size == 0:
        return None, None, (kh, ke)
    Hk, Ek = H[:, kh], E[ke, :]
    s = pow2(math.sqrt(np.linalg.norm(Ek, 2) / np.linalg.norm(Hk, 2)))
    return Hk * s, Ek / s, (kh, ke)


def state_scaling(A: ArrayLike, mode: str | ArrayLike) -> NDArray[np.float64]:
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
        return np.array([pow2(v) for v in sig])
    as_choice("state_scaling", mode, ("balance", "none"))  # ("units" is handled by prepare())
    M = np.abs(A - np.diag(np.diag(A)))
    if mode == "none" or not np.any(M):
        return np.ones(n)
    _, (sca, _) = scipy.linalg.matrix_balance(M, permute=False, separate=True)
    return np.array([pow2(v) for v in sca])


def unit_scaling(A: ArrayLike, inputs: ArrayLike, outputs: ArrayLike, sweeps: int = 200) -> NDArray[np.float64]:
    """State scaling σ that does not depend on the units the states are written in (internal).

    With ``x = diag(d) x'`` (new units), ``A' = D⁻¹AD``, the input rows
    ``[B, H]' = D⁻¹[B, H]`` and the output columns ``[C; L; E]' = [C; L; E]D``,
    and this function returns ``σ' = D⁻¹σ`` (to the convergence of the
    iteration, ~1e-13 relative): the data in the coordinates ``x = diag(σ) x̃``
    are the same whatever the units, so the design is too (issue 36).

    The state-to-state couplings ``K = |A| + |[B, H]| |[C; L; E]|`` (off
    the diagonal) are balanced by Osborne's iteration with real factors
    (``σ_i ← σ_i (c_i / r_i)^{1/2}``, r and c the 2-norms of row and column
    i of the scaled K): the balanced matrix is unique up to one factor per
    irreducible block of K, and that factor is fixed so that, within the
    block, the input rows and the output columns have the same norm.
    """
    A = np.abs(np.asarray(A, dtype=float))
    U, V = np.abs(np.asarray(inputs, dtype=float)), np.abs(np.asarray(outputs, dtype=float))
    n = A.shape[0]
    K = A + U @ (V if U.shape[1] == V.shape[0] else np.zeros((U.shape[1], n)))
    K = K - np.diag(np.diag(K))
    sig = np.ones(n)
    for _ in range(sweeps):
        change = 0.0
        for i in range(n):
            r = np.linalg.norm(K[i, :] / sig[i] * sig)
            c = np.linalg.norm(K[:, i] * sig[i] / sig)
            if r > 0 and c > 0:
                f = math.sqrt(r / c)
                sig[i] *= f
                change = max(change, abs(f - 1.0))
        if change < 1e-14:
            break
    _, comp = connected_components(K + K.T > 0, directed=False)
    for k in np.unique(comp):
        idx = comp == k
        u = np.linalg.norm(U[idx, :] / sig[idx, None])
        v = np.linalg.norm(V[:, idx] * sig[None, idx])
        if u > 0 and v > 0:
            sig[idx] *= math.sqrt(u / v)
    return sig


def noise_scale(system: UncertainSystem) -> float:
    """Scale of the noise inputs that scales with them and does not depend on the state units (internal).

    ``ρ₀ = max(‖D‖₂, ‖[C; L] Aʲ B‖₂)`` with j the first power (0 … n−1)
    at which the Markov parameter is nonzero: with ``x = diag(d) x'`` the
    products ``[C; L] Aʲ B`` are unchanged, and with B, D × k they are
    multiplied by k, so ``ρ₀`` is multiplied by k exactly (to rounding).
    1.0 when B and D reach no output (nothing to normalise).
    """
    rho = float(np.linalg.norm(system.D, 2)) if system.D.size else 0.0
    out = np.vstack([system.C, system.L])
    M = np.asarray(system.B, dtype=float)
    for _ in range(system.A.shape[0]):
        markov = float(np.linalg.norm(out @ M, 2))
        if markov > 0:
            rho = max(rho, markov)
            break
        M = system.A @ M
    return rho if rho > 0 and math.isfinite(rho) else 1.0


def prepare(system: UncertainSystem, structure: str, scaling: str | ArrayLike, form: str = "general",
            normalize_noise: bool = False) -> Prepared:
    """Drop, balance and scale the data of one synthesis (see the module docstring).

    ``scaling="units"``: first the unit-free scaling :func:`unit_scaling`
    (real factors), then the power-of-two balancing of the result's A
    (:func:`state_scaling`); so γ does not depend on the state units (to
    ~1e-12 relative, measured on Sun et al. (2011)'s chaser written with
    states ×1e-6 … ×1e6). Not exact in floating point (real factors): the
    certificate is evaluated on the scaled data at the solver's variables
    and the filter scaled back (rounding ~1e-16 relative, well inside the
    eigenvalue test's margin). ``"balance"`` (the default of
    :class:`~hinfnav.lmi.SolverOptions`, kept because the papers'
    published designs depend on it): the power-of-two balancing of A alone.

    ``normalize_noise=True`` (with ``"units"``; the path of ``design
    --system``): the noise inputs are measured by :func:`noise_scale` (ρ₀,
    invariant to the state units, proportional to B and D), the unit-free
    scaling is computed on the data with B / ρ₀, and :func:`normalize`
    divides B and D by exactly ρ₀: the solver sees the same problem (to
    rounding) whatever the noise scale, and γ comes back × ρ₀ (issue 36:
    γ scales with B, D × k to ~1e-9 relative for k = 1e-6 … 1e6, where the
    power-of-two normalisation above a threshold left 4e-5). Not used by the
    papers' designs (``"balance"``), which stay bitwise unchanged.
    """
    H_b = E_b = None
    rho0 = noise_scale(system) if normalize_noise and isinstance(scaling, str) and scaling == "units" else 0.0
    if isinstance(scaling, str) and scaling == "units":
        B_in = system.B / rho0 if rho0 > 0 else system.B
        ins = B_in if system.H is None else np.hstack([B_in, system.H])
        outs = np.vstack([system.C, system.L] + ([] if system.E is None else [system.E]))
        s0 = unit_scaling(system.A, ins, outs)
        sigma = s0 * state_scaling(system.A * s0[None, :] / s0[:, None], "balance")
        if system.H is not None:
            # H and E balanced in the unit-free coordinates (so that the balancing does not depend on the units
            # either), then written back in the original ones
            H_t, E_t, _ = prepare_uncertainty(system.H / sigma[:, None], system.E * sigma[None, :], structure)
            if H_t is not None:
                H_b, E_b = H_t * sigma[:, None], E_t / sigma[None, :]
    else:
        if system.H is not None:
            H_b, E_b, _ = prepare_uncertainty(system.H, system.E, structure)
        sigma = state_scaling(system.A, scaling)
    Si = 1.0 / sigma
    A = Si[:, None] * system.A * sigma[None, :]
    B = Si[:, None] * system.B
    C = system.C * sigma[None, :]
    L = system.L * sigma[None, :]
    H = E = None
    if H_b is not None:
        H = Si[:, None] * H_b
        E = E_b * sigma[None, :]
    return Prepared(A, B, C, system.D, L, H, E, sigma, H_b, E_b, form, noise_ref=rho0)




#: Block scale above which :func:`normalize` acts (see there for the measurements behind it).
NORMALIZE_THRESHOLD = 64.0


def block_scales(P):
    """Scales of the blocks :func:`normalize` acts on, in the state-scaled data of ``P``.

    Returns
    -------
    dict
        ``"inputs"``: ``max(‖B̃‖₂, ‖D‖₂)`` (the noise channels w, v);
        ``"output"``: ``‖L̃‖₂`` (the estimated signal z).
    """
    Q = P.unnormalized()
    return {
        "inputs": float(max(np.linalg.norm(Q.B, 2), np.linalg.norm(Q.D, 2))),
        "output": float(np.linalg.norm(Q.L, 2)),
    }


def normalize(P, threshold=NORMALIZE_THRESHOLD):
    """Normalise badly scaled noise and output blocks of LMI (20) by powers of two.

    With ``B' = B/ρ``, ``D' = D/ρ`` (one factor for both noise channels)
    and ``L' = L/ν``, LMI (20) of the normalised data at the variables
    ``R' = R/ν²``, ``S' = S/ν²``, ``Ā'_F = Ā_F/ν²``, ``B̄'_F = B̄_F/ν²``,
    ``C̄'_F = C̄_F/ν``, ``λ' = λ/ν²`` and level ``γ' = γ/(νρ)`` is
    ``T⁻¹ M T⁻¹`` with ``T = diag(ν I₄ₙ, νρ I_{p+q}, I_l, ν I_r)``, M being
    (20) of the original data: the two are negative definite together, and
    the filter is the same (``A_F``, ``B_F`` unchanged, ``C_F = ν C'_F``).
    ρ and ν are powers of two, so the scaling is undone exactly in floating
    point (:meth:`Prepared.unnormalized`, and
    :func:`hinfnav.lmi.lmi20.solve_lmi` returns its solutions in the
    original units). Input scaling of w and v *separately* is not a
    congruence (it changes the H∞ problem), so it is not done.

    A block is normalised only when its scale (:func:`block_scales`, its
    norm against the unit blocks −I of (20)) is above ``threshold``.
    Measured (November 2026) on 30 random uncertain systems (n = 3,
    p = m = q = l = r = 2, ρ(A) = 0.8, ‖H‖ = ‖E‖ = √0.05, state-balanced)
    with B × k and D ÷ k, k = 64 … 1024: without normalisation 77 of 150
    designs fail (mostly a false
    :class:`~hinfnav.core.exceptions.InfeasibleLMIError` before issue 8, no
    certified point after), the smallest failing noise
    scale being 386, none below; with it, none of 150 (scales up to 5806).
    With L × k alone, designs failed from an output scale of 4220 (before
    the γ-free confirmation of :func:`hinfnav.design.synthesize`). The
    default 64 is a factor 6 below the smallest failing scale and 4 above
    the largest block of Sun et al. (2011)'s model (output 16 after the
    state scaling, noise 0.1), whose designs are therefore unchanged to the
    last bit. Small scales are not normalised (no failure measured down to
    1/16384).

    Parameters
    ----------
    P : Prepared
        Data of :func:`prepare` (not yet normalised).
    threshold : float, optional
        Scale above which a block is normalised (``0``: always, ``inf``:
        never).

    Returns
    -------
    Prepared
        With ``rho`` and ``nu`` set (1 where nothing was done).
    """
    P = P.unnormalized()
    scales = block_scales(P)
    if P.noise_ref > 0:  # prepare(normalize_noise=True): always, by the exact real factor (see there)
        rho = P.noise_ref
    else:
        rho = pow2(scales["inputs"]) if scales["inputs"] > threshold and scales["inputs"] > 0 else 1.0
    nu = pow2(scales["output"]) if scales["output"] > threshold and scales["output"] > 0 else 1.0
    if rho == 1.0 and nu == 1.0:
        return P
    return dataclasses.replace(P, B=P.B / rho, D=P.D / rho, L=P.L / nu, rho=rho, nu=nu)


#: Mantissa bits kept by :func:`solver_data` (relative rounding 2⁻³³ ≈ 1.2e-10).
SOLVER_DATA_BITS = 32


def round_mantissa(M: ArrayLike | None, bits: int = SOLVER_DATA_BITS) -> NDArray[np.float64] | None:
    """``M`` rounded to ``bits`` mantissa bits (``None`` stays ``None``): data equal to a few ulps become equal."""
    if M is None:
        return None
    m, e = np.frexp(np.asarray(M, dtype=float))
    return np.ldexp(np.round(m * 2.0**bits) / 2.0**bits, e)


def solver_data(P: Prepared) -> Prepared:
    """The data handed to the solver: ``P`` itself, or with ``noise_ref`` set, ``P`` rounded to 32 mantissa bits.

    The unit-free, noise-normalised data of the same plant written in other
    state units or with B, D × k agree to a few ulps only (real scale
    factors), and the interior-point solvers amplify an ulp into 1e-5 of
    certified γ (measured on Sun et al. (2011)'s chaser: Clarabel
    "optimal" against "optimal_inaccurate", γ 0.3587428 against
    0.3587239). Rounded to :data:`SOLVER_DATA_BITS` bits, such data are
    bitwise the same, so the solver answers the same. Only the solver sees
    the rounded data (a relative change ≤ 1.2e-10 of each entry); the
    certificate is evaluated on ``P`` unrounded and on the original system.
    """
    if not P.noise_ref > 0:
        return P

    rnd = round_mantissa
    return dataclasses.replace(P, A=rnd(P.A), B=rnd(P.B), C=rnd(P.C), D=rnd(P.D), L=rnd(P.L), H=rnd(P.H), E=rnd(P.E))


def lmi20_diagonal(P):
    """Diagonal of the congruence that maps LMI (20) of the original data to that of ``P`` (normalised).

    ``diag(d) M diag(d)`` with ``d = [1/ν (4n), 1/(νρ) (p + q), 1 (l), 1/ν (r)]``
    is (20) of the normalised data at the normalised variables (see
    :func:`normalize`); every entry of d is a power of two, so the product is
    exact in floating point. ``None`` when ``P`` is not normalised.
    """
    if not P.normalized:
        return None
    n, p, q, l = P.A.shape[0], P.B.shape[1], P.D.shape[1], P.L.shape[0]
    r = 0 if P.H is None else P.H.shape[1]
    nu, rho = P.nu, P.rho
    return np.concatenate([np.full(4 * n, 1.0 / nu), np.full(p + q, 1.0 / (nu * rho)), np.ones(l), np.full(r, 1.0 / nu)])
