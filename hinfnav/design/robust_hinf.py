"""Certified robust H∞ filter synthesis by LMI: Theorem 1 and Corollary 1 of Sun et al. (2011).

:func:`synthesize` solves

    min γ²  subject to LMI (20) in R, S, Ā_F, B̄_F, C̄_F, λ      (Corollary 1)

and rebuilds the filter (12) by (21): ``A_F = S⁻¹Ā_F``, ``B_F = S⁻¹B̄_F``,
``C_F = C̄_F``. The returned filter is *certified*, independently of the
solver's status:

1. LMI (20) is evaluated in float64 at the returned filter
   (``Ā_F = S A_F``, ``B̄_F = S B_F``) and the solver's R, S, λ, and the
   smallest γ making it negative definite is found by a Schur complement and
   confirmed by an eigenvalue test (:func:`hinfnav.analysis.schur_gamma`).
   By Theorem 1 that γ bounds ``‖Ψ‖∞`` for every admissible F (10)–(11).
   This γ is the result's ``gamma``.
2. The H∞ norm of the error system (13)–(15) is computed (SLICOT ab13dd) at
   sampled uncertainties; every sample must be Schur stable with a norm
   ≤ ``gamma``.

The numerics (dropping, balancing, power-of-two scaling) are in
:mod:`hinfnav.lmi.conditioning`; the solver choices in one
:class:`~hinfnav.lmi.SolverOptions`. When the direct minimization of γ² does
not certify, or certifies a γ more than ``rtol`` above the solver's, γ is
bisected with feasibility problems that maximize the margin t in
(20) ≤ −t·I; a problem with no solution for any γ is recognized by the γ-free
part of (20) having no interior point
(:class:`~hinfnav.core.exceptions.InfeasibleLMIError`), confirmed on the
normalised problem (a solver's "infeasible" on the minimization alone is not
trusted: it can be an artefact of badly scaled B, D or L, which the γ-free
part does not contain or has normalised).

Noise and output blocks scaled far from 1 are normalised by powers of two
before solving (:func:`hinfnav.lmi.conditioning.normalize`) and the
certificate is evaluated with the original data. When the certified γ is
more than twice the worst sampled norm the synthesis tries harder (every
interior-point solver with bisection, another scaling, a full Lyapunov
matrix for the filter found) and warns
(:class:`~hinfnav.core.exceptions.LooseBoundWarning`) if the gap remains.

With ``form="observer"`` the filter is constrained to a predictor observer
(``C_F = −L``, ``A_F = A + B_F C``; see :func:`synthesize`); its ``gamma``
is certified with a full Lyapunov matrix for the returned filter.

Nothing here knows about a paper's scenario: the uncertain system comes in as
an :class:`~hinfnav.systems.UncertainSystem`, the uncertainty samples as a
:class:`~hinfnav.design.SampleSet`.
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..analysis.certificates import schur_gamma
from ..analysis.error_system import WorstCase, worst_case_norm
from ..core.exceptions import (
    CertificationError,
    InfeasibleLMIError,
    InputError,
    LooseBoundWarning,
    SolverAccuracyWarning,
)
from ..core.linalg import spectral_radius
from ..core.validation import as_choice, as_int_at_least, as_seed
from ..lmi.blocks import gamma_index, lmi20_matrix
from ..lmi.conditioning import lmi20_diagonal, normalize, prepare
from ..lmi.solve import INFEASIBLE, SolverOptions, solve_lmi
from ..systems.uncertain import UncertainSystem
from .arguments import system_argument
from .explain import infeasibility_hint
from .polytopic import observer_nominal
from .result import SynthesisResult
from .samples import SampleSet, check_plant, check_samples, default_uncertainty_samples
from .tighten import best_candidate as _best
from .tighten import brl_solvers as _brl_solvers
from .tighten import full_lyapunov_gamma, is_loose
from .tighten import key as _key
from .tighten import try_harder as _try_harder

if TYPE_CHECKING:
    from .samples import SampleSet

__all__ = ["FORMS", "synthesize"]

#: Filter structures :func:`synthesize` accepts.
FORMS = ("general", "observer")


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
    """Filter by (21), LMI certificate, sampled norms (internal).

    ``sol`` is in the units of the original data (:func:`solve_lmi` undoes the
    normalisation); the certificate is evaluated with the original B, D, L.
    """
    d, P_rho_nu = lmi20_diagonal(P), P.rho * P.nu  # the congruence of normalize() (None: not normalised)
    P = P.unnormalized()
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
    if d is None:
        gamma_c, info = schur_gamma(M0, gamma_index(n, p, q))
    else:
        # the eigenvalue test on diag(d) M0 diag(d), exact in floating point (powers of two), proves M0 < 0 with
        # a tolerance relative to the normalised scale instead of γ² of the original data
        gamma_c, info = schur_gamma(d[:, None] * M0 * d[None, :], gamma_index(n, p, q))
        gamma_c *= P_rho_nu
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


def synthesize(system: UncertainSystem, *matrices: ArrayLike, structure: str = "full",
               uncertainty_samples: SampleSet | Sequence[ArrayLike | None] | None = None, n_random_samples: int = 4,
               seed: int | np.random.Generator = 0, form: str = "general", options: SolverOptions | None = None,
               solver: str | None = None, **legacy: Any) -> SynthesisResult:
    """Robust H∞ filter for ψ_d (9)–(11) by Corollary 1, certified.

    Parameters
    ----------
    system : UncertainSystem
        The plant ψ_d (9)–(11): ``x(k+1) = (A + H F E) x(k) + B w(k)``,
        ``y = C x + D v``, ``z = L x``, ``FᵀF ≤ I`` (no H, E, or zero ones:
        the nominal H∞ filter). A must be Schur stable for every admissible
        F. Its ``dt`` (s) is the sampling time of the result's
        :meth:`SynthesisResult.statespace`. Deprecated until 0.3: the loose
        matrices ``A, B, C, D, L[, H, E]`` with ``dt=`` (float, or True:
        discrete, unspecified), with a :class:`DeprecationWarning`
        (:func:`hinfnav.design.arguments.system_argument`).
    structure : {"full", "diagonal"}, optional
        Whether F is any contraction or diagonal (as in the paper, Section 4);
        decides how H and E are balanced (see :func:`prepare_uncertainty`)
        and which default samples are checked.
    uncertainty_samples : SampleSet or sequence of array_like, optional
        Contractions F (shape (r, r)) at which the error system is checked;
        default :func:`default_uncertainty_samples`. A :class:`SampleSet`
        also carries a label per sample and, for a family parametrized by one
        scalar, the parameter value behind each sample and its bound
        (returned as ``sample_values`` and ``uncertainty_bound``).
    n_random_samples : int, optional
        Random contractions in the default samples.
    seed : int or numpy.random.Generator, optional
        Seed of the random samples.
    form : {"general", "observer"}, optional
        ``"general"`` (default): LMI (20) as in the paper, any full-order
        filter (12). ``"observer"``: the filter is constrained to a
        predictor observer, ``C_F = −L`` and ``A_F = A + B_F C`` (see Notes);
        any output ``L`` (partial, mixing states; not zero).
    options : SolverOptions, optional
        Every solver choice (solvers and their order, method, margins,
        tolerances, bisection, polishing, state scaling); default
        ``SolverOptions()``.
    solver : str, optional
        Shorthand for ``SolverOptions.only(solver)``: this solver only (not
        together with ``options``).

    Returns
    -------
    SynthesisResult

    Raises
    ------
    InputError
        Mismatched shapes, non-finite entries, bad options (an unknown
        ``form``, or ``L = 0``).
    UnstablePlantError
        ``A + H F E`` is not Schur stable at some sample (no finite γ).
    InfeasibleLMIError
        The γ-free part of LMI (20) (no B, no D; state and output scaled)
        has no interior point for any solver (message carries the status).
        A solver's "infeasible" on the minimization alone is not enough.
    CertificationError
        No solution passed the certification (message says why).

    Warns
    -----
    LooseBoundWarning
        The certified γ is more than twice the worst sampled norm even after
        trying harder (both numbers in the message).
    SolverAccuracyWarning
        SCS is among the solvers (slow and loose on this LMI).

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
    Certification: (20) by eigenvalues at exactly the returned filter, and
    the sampled norms. The level (20) certifies is that of a restricted
    Lyapunov matrix (``diag(R − S, S)`` in the coordinates (x, e)); the
    returned ``gamma`` is that of the filter itself, certified with a full
    Lyapunov matrix (the robust bounded real LMI of Lemmas 1–3 with the
    filter fixed, :func:`hinfnav.design.tighten.full_lyapunov_gamma`), the
    smaller of the two. ``variables["lmi20_gamma"]`` keeps the level of (20)
    and ``lmi_gamma`` the solver's; on Sun et al. (2011)'s model the
    restriction costs 0.03 % (δ̄ = 0.05) to 3 % (δ̄ = 5) in (20), while
    the filters themselves certify within 3e-8 of γ* at δ̄ = 0.05.

    **Scaling.** Noise inputs (B, D, one common factor) and the output (L)
    whose scale exceeds ``options.normalize_above`` are normalised by powers
    of two (:func:`hinfnav.lmi.conditioning.normalize`); the solver's
    variables are scaled back exactly and the certificate is evaluated with
    the original data.

    The derivation only uses ``C_F = −L``: the filter state is always a full
    state estimate ``x̂ = −x_f`` and ``z_f = L x̂``, for any output L (square
    or not, partial or mixing states); only ``L = 0`` is refused (nothing to
    estimate).
    """
    t_start = time.perf_counter()
    system, dt_value = system_argument("synthesize", system, matrices, legacy)
    structure = as_choice("structure", structure, ("full", "diagonal"))
    n_random_samples = as_int_at_least("n_random_samples", n_random_samples, 0)
    seed = as_seed("seed", seed)
    if options is None:
        options = SolverOptions.only(solver)
    elif solver is not None:
        raise InputError("give either solver or options (SolverOptions(solvers=...)), not both")
    elif not isinstance(options, SolverOptions):
        raise InputError(f"options must be a hinfnav.SolverOptions; got {type(options).__name__}")
    method, polish = options.method, options.polish
    if not isinstance(form, str):
        raise InputError(f"form must be a string, one of {', '.join(FORMS)}; got {form!r}")
    form = as_choice("form", form, FORMS)
    solvers = list(options.solvers)
    if system.L.size == 0 or not np.any(system.L):
        raise InputError("L is zero: the estimated signal z = L x is identically 0, so there is nothing to estimate "
                         "(the zero filter is exact); give a nonzero L")
    if system.H is not None and not (np.any(system.H) and np.any(system.E)):
        system = dataclasses.replace(system, H=None, E=None)
    if form == "observer" and system.H is None and not spectral_radius(system.A) < 1.0:
        return observer_nominal(system, dt_value, solvers, t_start)  # needs detectability only (no plant state)
    sample_set = uncertainty_samples if isinstance(uncertainty_samples, SampleSet) else None
    if uncertainty_samples is None:
        samples = default_uncertainty_samples(system, structure, n_random_samples, seed)
    elif sample_set is not None:
        samples = check_samples(list(sample_set.matrices), system, structure)
    else:
        samples = check_samples(list(uncertainty_samples), system, structure)
    checked_samples = samples if system.H is not None else [None]
    labels = None if sample_set is None else sample_set.labels
    check_plant(system, checked_samples, labels)

    state_scaling = options.state_scaling if isinstance(options.state_scaling, str) else np.array(options.state_scaling)
    if "SCS" in solvers:
        warnings.warn(_SCS_WARNING, SolverAccuracyWarning, stacklevel=2)
    P = normalize(prepare(system, structure, state_scaling, form), options.normalize_above)
    run = _Run(options, system, checked_samples, dt_value)
    for slv in solvers:
        # once a solution is certified, the other solvers only polish it (one minimization each)
        how = method if not run.candidates else "minimize"
        run.solver(P, slv, how)
        if run.candidates and not polish:
            break
    gap = _best(run.candidates)[0] if run.candidates else None
    if gap and is_loose(*gap) and gap[0] > 1.01 * min(run.hints, default=0.0):
        # more than 1 % above the solvers' own optimum of (20): the gap may be numerical, so try harder (at the
        # optimum, other solvers and scalings solve the same LMI and the gap is Lemma 2's)
        _try_harder(run, P, system, structure, state_scaling, form)
    if not run.candidates and not run.verdicts and any(st in INFEASIBLE for _, st in run.statuses):
        for slv in solvers:  # method="minimize" met "infeasible": confirm on the γ-free part before saying so
            run.gamma_free(P, slv)
    if run.candidates:
        (gamma_c, sampled), (chk, sol, slv, how) = _best(run.candidates)
        chk.variables.setdefault("lmi20_gamma", gamma_c)
        if form == "observer":
            gamma_full, lyap, lam_full = full_lyapunov_gamma(P, chk.A_F, chk.B_F, chk.C_F, _brl_solvers(solvers))
            run.log.append(f"observer filter, full Lyapunov matrix (robust BRL): certified γ = {gamma_full:.10g} "
                           f"(LMI (20), restricted Lyapunov matrix: {gamma_c:.10g})")
            if sampled <= gamma_full * (1.0 + 1e-9) and gamma_full < gamma_c:
                gamma_c = gamma_full
                chk.variables.update(lyapunov_full=lyap, lam_full=lam_full)
        if is_loose(gamma_c, sampled):
            warnings.warn(
                f"the certified γ = {gamma_c:.6g} is {gamma_c / sampled:.3g} times the worst sampled H∞ norm "
                f"{sampled:.6g} of the returned filter, after trying every interior-point solver with bisection and "
                f"another scaling: the bound is loose (Lemma 2's single multiplier, or an ill-conditioned LMI; see "
                f"the result's attempts)",
                LooseBoundWarning,
                stacklevel=2,
            )
        return SynthesisResult(
            A_F=chk.A_F,
            B_F=chk.B_F,
            C_F=chk.C_F,
            gamma=float(gamma_c),
            lmi_gamma=float(math.sqrt(max(sol.gamma2, 0.0))),
            verified_norm=chk.wc.norm,
            sample_norms=chk.wc.norms,
            worst_sample=chk.wc.index,
            spectral_radius=float(np.max(chk.wc.spectral_radii)),
            solver=slv,
            solve_time_s=run.seconds,
            total_time_s=time.perf_counter() - t_start,
            method=how,
            dt=dt_value,
            variables=chk.variables,
            attempts=tuple(run.log),
            structure=structure,
            samples=tuple(checked_samples),
            uncertainty_bound=None if sample_set is None else sample_set.bound,
            sample_values=None if sample_set is None else sample_set.values,
            form=form,
            sample_labels=() if sample_set is None else sample_set.labels,
            system=system,
        )
    if "infeasible" in run.verdicts and "feasible" not in run.verdicts:
        hint = infeasibility_hint(system.A, system.H, system.E, structure, form)
        raise InfeasibleLMIError(
            "LMI (20) is infeasible: no R, S, λ make the error system quadratically stable for every admissible F, "
            "so Theorem 1 gives no filter for any γ; confirmed on the γ-free part of (20), which contains neither "
            "B nor D, with the state and output normalised (solver status: "
            + "; ".join(f"{slv} {st}" for slv, st in run.statuses)
            + ")."
            + hint
        )
    raise CertificationError(
        "no solution of LMI (20) passed certification (LMI eigenvalue test at the rebuilt filter and H∞ norms of "
        "the error system at the uncertainty samples); last attempts: " + " | ".join(run.log[-5:])
    )


_SCS_WARNING = (
    "SCS is a first-order solver; on LMI (20) it is slow and loose: measured on Sun et al. (2011)'s model at "
    "δ̄ = 0.05 (issue 8), about 80 s and a certified γ of 6.55 against 0.3586 with CLARABEL/CVXOPT (18 times "
    "larger). The result is still certified; prefer CLARABEL or CVXOPT."
)


class _Run:
    """State of one synthesis: candidates, log, statuses, γ-free verdicts, solver time (internal)."""

    def __init__(self, options, system, samples, dt):
        self.options, self.system, self.samples, self.dt = options, system, samples, dt
        self.candidates, self.log, self.statuses, self.verdicts, self.hints = [], [], [], [], []
        self.seconds = 0.0
        self.ran_auto = set()

    def certify(self, P, sol):
        self.seconds += sol.seconds
        if sol.R is None:
            return None
        return _rebuild_and_certify(P, sol, self.system, self.samples, self.dt)

    def solve(self, P, slv, gamma2=None):
        o = self.options
        return solve_lmi(P, slv, o.margin, o.accuracy, gamma2=gamma2)

    def solver(self, P, slv, method):
        """Minimize, then bisect if needed, with one solver (internal)."""
        if method != "minimize":
            self.ran_auto.add((_key(P), slv))
        found = _run_solver(self, P, slv, method)
        self.candidates.extend(found)
        return found

    def gamma_free(self, P, slv):
        """The most interior point of the γ-free part of (20), on P and then normalised: (sol, chk) or None."""
        variants = [P]
        Pn = normalize(P, 0.0)
        if Pn.nu != P.nu:
            variants.append(Pn)  # the γ-free part holds L (and A, C, H, E), not B or D
        for Q in variants:
            sol = self.solve(Q, slv, "free")
            chk = self.certify(Q, sol)
            what = "γ-free feasibility" + (f" (output normalised by {Q.nu:g})" if Q.nu != 1 else "")
            if chk is None or not sol.margin > 0:
                self.log.append(f"{slv} {what}: status {sol.status}, margin {sol.margin:.3g}: no interior point")
                continue
            self.verdicts.append("feasible" if np.isfinite(chk.gamma) else "interior point not certified")
            self.log.append(f"{slv} {what}: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
            return Q, sol, chk
        self.verdicts.append("infeasible")
        self.statuses.append((slv, f"infeasible (status {sol.status}, γ-free part's largest margin {sol.margin:.3g})"))
        return None


def _run_solver(run, P, slv, method):
    """Minimize, then bisect if needed, with one solver; certified candidates (internal)."""
    o = run.options
    rtol, max_bisection = o.rtol, o.max_bisection
    log, statuses = run.log, run.statuses
    cands = []
    lo = 0.0
    if method in ("auto", "minimize"):
        sol = run.solve(P, slv)
        statuses.append((slv, sol.status))
        chk = run.certify(P, sol)
        if chk is None:
            log.append(f"{slv} minimize: status {sol.status}, no solution")
            if method == "minimize":
                return cands
            # an "infeasible" minimization is not trusted: the γ-free part below decides
        else:
            lmi_g = math.sqrt(max(sol.gamma2, 0.0))
            run.hints.append(lmi_g if slv != "SCS" else 0.0)  # the solver's optimum of (20), a hint (SCS: none)
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
                failures = 0
                for step in (1e-4, 1e-3, 1e-2, 1e-1, 1.0):
                    level = lmi_g * (1.0 + step)
                    sol2 = run.solve(P, slv, level**2)
                    chk2 = run.certify(P, sol2)
                    if chk2 is not None and sol2.margin > 0 and chk2.ok:
                        log.append(f"{slv} feasibility at γ = {level:.10g}: margin {sol2.margin:.3g}, certified γ = {chk2.gamma:.10g}")
                        cands.append((chk2, sol2, slv, "bisection"))
                        break
                    log.append(f"{slv} feasibility at γ = {level:.10g}: status {sol2.status}, not certified")
                    failures = failures + 1 if sol2.R is None else 0
                    if failures == 2:
                        break  # the solver gives no solution at all near its own optimum
    # bisection on γ with maximum-margin feasibility problems
    hi = min((c[0].gamma for c in cands), default=None)
    if hi is None:
        # the most interior point of the γ-free part of (20): feasible iff (20) is for some γ
        found = run.gamma_free(P, slv)
        if found is None:
            return cands
        P, sol, chk = found
        if not chk.ok:
            return cands
        sol.gamma2 = chk.gamma**2
        cands.append((chk, sol, slv, "bisection"))
        hi = chk.gamma
    if lo >= hi:
        lo = 0.0  # the solver's γ was no lower bound (it is above a certified level): start from scratch
    failures = 0
    for _ in range(max_bisection):
        if hi - lo <= rtol * hi:
            break
        mid = 0.5 * (lo + hi)
        sol = run.solve(P, slv, mid**2)
        chk = run.certify(P, sol)
        if chk is None or not sol.margin > 0:
            log.append(f"{slv} feasibility at γ = {mid:.10g}: status {sol.status}, margin {sol.margin:.3g}: infeasible")
            lo = mid
            failures = failures + 1 if not np.isfinite(sol.margin) else 0
            if failures == 3:
                log.append(f"{slv} bisection stopped: the solver gave no solution three times in a row")
                break
            continue
        failures = 0
        log.append(f"{slv} feasibility at γ = {mid:.10g}: margin {sol.margin:.3g}, certified γ = {chk.gamma:.10g}: {chk.reason}")
        if chk.ok and chk.gamma < hi:
            cands.append((chk, sol, slv, "bisection"))
            hi = chk.gamma
        if not chk.ok or chk.gamma > mid:
            lo = mid  # the solver's claim of feasibility at this level is not confirmed
    return cands
