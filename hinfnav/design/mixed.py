"""Certified mixed H2/H∞ robust filter synthesis: the filter Sun et al. (2011) name as future work.

:func:`synthesize_mixed` solves, for the uncertain system ψ_d (9)–(11) and the
full-order filter (12),

    minimize ν   subject to   ‖Ψ_F‖₂ ≤ ν  and  ‖Ψ_F‖∞ < γ  for every FᵀF ≤ I,

Ψ_F the error system (13)–(15) from τ = [w; v] to e = z − z_f. ν is a
guaranteed-cost bound on the worst-case H2 norm, i.e. on the stationary RMS
error under unit white noise (summed over the components of e); γ is the H∞
bound of Corollary 1.

Formulation: extended (dilated) LMIs with one slack G, so that the H2 and
H∞ conditions keep separate Lyapunov matrices P₂, P∞ and only G carries the
filter (de Oliveira, Geromel & Bernussou, Int. J. Control 75(9), 2002;
Geromel, Bernussou, Garcia & de Oliveira, SIAM J. Control Optim. 38(5), 2000);
see :mod:`hinfnav.lmi.mixed_blocks` for the LMIs and why the restriction of G
is no loss. The classical common-Lyapunov design (LMI (20) for H∞ with the
H2 conditions on the same P) is available as ``lyapunov="common"``; its
feasible set is contained in the extended one.

Every result is certified independently of the solver's status, at the
filter rebuilt by ``A_F = Z⁻¹Ā_F``, ``B_F = Z⁻¹B̄_F``, ``C_F = C̄_F``:

1. **H∞**: the extended H∞ LMI is evaluated in float64 at the rebuilt
   filter's error system (``GᵀĀ`` formed from it, not from the solver's
   Ā_F) and the solver's G, P∞, λ∞; the smallest γ making it negative
   definite is found by :func:`hinfnav.analysis.schur_gamma` (``gamma``).
   The unconstrained H2 filter's γ is certified by the robust bounded real
   LMI (:func:`hinfnav.lmi.robust_bounded_real_lmi`, itself certified).
2. **H2**: the extended Lyapunov LMI is evaluated the same way with a free
   level κ on its output block; schur_gamma gives the smallest κ, and
   ``ν² = κ · trace(B̄ᵀP₂B̄)`` (``h2_synthesis_bound``). Because the slack G
   still couples H2 and H∞, the returned filter is then analysed alone: the
   robust H2 LMI with its own Lyapunov matrix
   (:func:`hinfnav.lmi.robust_h2.robust_h2_bound`, certified the same way)
   gives ``h2_analysis_bound``; ``h2_bound`` is the smaller of the two.
3. **Samples**: at every uncertainty sample the error system must be Schur
   stable, its H∞ norm (SLICOT) ≤ ``gamma`` and its H2 norm (discrete
   Lyapunov equation) ≤ ``h2_bound``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..analysis.certificates import schur_gamma
from ..analysis.error_system import error_system, error_system_matrices, worst_case_norm
from ..analysis.norms import h2_norm
from ..core.exceptions import CertificationError, InfeasibleLMIError, InputError
from ..core.validation import as_choice, as_int_at_least, as_positive
from ..lmi.blocks import gamma_index
from ..lmi.conditioning import prepare
from ..lmi.mixed_blocks import extended_h2_matrix, robust_extended_hinf_negative, h2_output_index
from ..lmi.mixed_solve import LYAPUNOV, MixedProblem
from ..lmi.robust_brl import robust_bounded_real_lmi
from ..lmi.robust_h2 import robust_h2_bound
from ..lmi.solve import INFEASIBLE, SolverOptions
from ..systems.uncertain import UncertainSystem
from .arguments import system_argument
from .certify_loop import Check, solve_and_certify
from .result import DesignResult
from .samples import SampleSet, check_plant, check_samples, default_uncertainty_samples

__all__ = ["MIXED_SOLVER_OPTIONS", "DesignResult", "MixedFront", "synthesize_mixed", "mixed_front",
           "front_gammas", "knee_index"]

#: Default solver choices of the mixed synthesis: CVXOPT first. On these LMIs Clarabel stops with
#: "AlmostSolved" 1e-4 to 1e-3 (relative) above the optimum of ν (measured on Sun 2011's model),
#: CVXOPT reaches it to ~1e-7; Clarabel remains the fallback.
MIXED_SOLVER_OPTIONS = SolverOptions(solvers=("CVXOPT", "CLARABEL"), polish=False, accuracy=1e-7)


#: What the certificate of a mixed design covers.
COVERS_MIXED = ("every F with FᵀF ≤ I: the H∞ bound for time-varying F(k), the H2 bound ν for constant F (and the "
                "asymptotic RMS of e under unit white noise for a time-varying one)")


def mixed_row(result: DesignResult) -> dict[str, Any]:
    """JSON-ready numbers of a mixed design (no matrices): one row of :meth:`MixedFront.table`."""
    return {
        "gamma_bound": result.gamma_bound,
        "gamma": result.gamma,
        "lmi_gamma": result.lmi_gamma if math.isfinite(result.lmi_gamma) else None,
        "verified_norm": result.verified_norm,
        "h2_bound": result.h2_bound,
        "h2_lmi": result.h2_lmi,
        "h2_synthesis_bound": result.h2_synthesis_bound,
        "h2_analysis_bound": result.h2_analysis_bound,
        "h2_verified": result.h2_verified,
        "lyapunov": result.lyapunov,
        "solver": result.solver,
        "solve_time_s": result.solve_time_s,
        "total_time_s": result.total_time_s,
    }


@dataclass(frozen=True, eq=False)
class MixedFront:
    """Certified mixed designs along γ (the H2/H∞ Pareto front), and the unconstrained H2 design.

    Attributes
    ----------
    gamma_star : float
        Certified H∞ optimum γ* (Corollary 1) the grid starts from.
    results : tuple of DesignResult
        One per γ of the grid, ascending.
    h2_result : DesignResult or None
        The robust H2 filter without H∞ constraint.
    hinf_result : DesignResult or None
        The H∞ optimum (Corollary 1).
    total_time_s : float
    """

    gamma_star: float
    results: tuple
    h2_result: object = None
    hinf_result: object = None
    total_time_s: float = float("nan")

    @property
    def gamma_bounds(self) -> NDArray[np.float64]:
        """Requested γ per point, shape (k,)."""
        return np.array([r.gamma_bound for r in self.results])

    @property
    def gammas(self) -> NDArray[np.float64]:
        """Certified γ per point, shape (k,)."""
        return np.array([r.gamma for r in self.results])

    @property
    def nus(self) -> NDArray[np.float64]:
        """Certified ν per point, shape (k,)."""
        return np.array([r.h2_bound for r in self.results])

    @property
    def synthesis_nus(self) -> NDArray[np.float64]:
        """ν certified at the synthesis LMI's own variables, per point, shape (k,)."""
        return np.array([r.h2_synthesis_bound for r in self.results])

    def monotone(self, rtol: float = 1e-6) -> bool:
        """Whether each point's certified ν is non-increasing along the grid (γ ascending), to ``rtol``."""
        nus = self.nus
        return bool(np.all(nus[1:] <= nus[:-1] * (1.0 + rtol)))

    def pareto(self) -> tuple[NDArray[np.float64], list[DesignResult]]:
        """The Pareto front of the certified designs: at each γ of the grid, the best design certified at ≤ γ.

        Every design (the points and the unconstrained H2 design) is a
        certified filter; one certified at γ_c also meets any bound γ ≥ γ_c.
        So at each grid γ the smallest certified ν among the designs with
        certified γ ≤ γ is achievable: a non-increasing front by construction.

        Returns
        -------
        nus : ndarray, shape (k,)
        designs : list of DesignResult
        """
        pool = list(self.results) + ([self.h2_result] if self.h2_result is not None else [])
        nus, designs = [], []
        for g in self.gamma_bounds:
            best = min((r for r in pool if r.gamma <= g), key=lambda r: r.h2_bound)
            nus.append(best.h2_bound)
            designs.append(best)
        return np.array(nus), designs

    @property
    def knee(self) -> int:
        """Index of the knee of the Pareto front (:func:`knee_index` on :meth:`pareto`)."""
        return knee_index(self.gamma_bounds, self.pareto()[0])

    def table(self) -> list[dict[str, Any]]:
        """One dict per point (:func:`mixed_row`), the H2 point last."""
        rows = [mixed_row(r) for r in self.results]
        if self.h2_result is not None:
            rows.append(mixed_row(self.h2_result))
        return rows


def front_gammas(gamma_star: float, points: int = 12, span: float = 10.0, first: float = 1e-3) -> NDArray[np.float64]:
    """γ grid of a front: ``γ* (1 + s)``, s log-spaced from ``first`` to ``span − 1``.

    Dense near γ* where ν changes fastest; the last point is ``span · γ*``.
    (γ* itself is the infimum of Corollary 1, at the boundary of the LMI's
    feasible set: the first point is ``(1 + first) γ*``.)

    Returns
    -------
    ndarray, shape (points,)
    """
    gamma_star = as_positive("gamma_star", gamma_star)
    points = as_int_at_least("points", points, 2)
    span = as_positive("span", span)
    first = as_positive("first", first)
    if not span - 1.0 > first:
        raise InputError(f"span must exceed 1 + first = {1 + first:g}; got {span:g}")
    return gamma_star * (1.0 + np.logspace(math.log10(first), math.log10(span - 1.0), points))


def knee_index(gammas: ArrayLike, nus: ArrayLike) -> int:
    """Knee of a trade-off curve ν(γ) by the largest distance to its chord (Kneedle).

    In normalized coordinates ``x = (log γ − log γ₀)/(log γ_k − log γ₀)`` and
    ``y = (ν − ν_k)/(ν₀ − ν_k)`` the curve runs from (0, 1) to (1, 0); the
    knee is the point farthest below the chord ``x + y = 1`` (Satopää, Albrecht,
    Irwin & Raghavan, "Finding a 'Kneedle' in a haystack", ICDCS workshops 2011).

    Returns
    -------
    int
        Index into ``gammas`` (0 when the curve is flat).
    """
    g = np.log(np.asarray(gammas, dtype=float))
    v = np.asarray(nus, dtype=float)
    if g.size < 3 or not (v[0] - v[-1] > 0) or not (g[-1] > g[0]):
        return 0
    x = (g - g[0]) / (g[-1] - g[0])
    y = (v - v[-1]) / (v[0] - v[-1])
    return int(np.argmax(1.0 - x - y))


@dataclass
class _Check:
    ok: bool
    reason: str
    gamma: float = float("inf")
    nu: float = float("inf")
    nu_synthesis: float = float("inf")
    nu_analysis: float = float("inf")
    A_F: np.ndarray = None
    B_F: np.ndarray = None
    C_F: np.ndarray = None
    wc: object = None
    h2_norms: np.ndarray = None
    variables: dict = None


class _Designer:
    """Validated data, samples and compiled problems of one uncertain system (internal)."""

    def __init__(self, system, dt, structure, uncertainty_samples, n_random_samples, seed, lyapunov, options, solver):
        self.t_start = time.perf_counter()
        self.dt = dt
        self.structure = as_choice("structure", structure, ("full", "diagonal"))
        self.lyapunov = as_choice("lyapunov", lyapunov, LYAPUNOV)
        n_random_samples = as_int_at_least("n_random_samples", n_random_samples, 0)
        if options is None:
            options = MIXED_SOLVER_OPTIONS if solver is None else SolverOptions.only(solver, accuracy=1e-7)
        elif solver is not None:
            raise InputError("give either solver or options (SolverOptions(solvers=...)), not both")
        elif not isinstance(options, SolverOptions):
            raise InputError(f"options must be a hinfnav.SolverOptions; got {type(options).__name__}")
        self.options = options
        if system.H is not None and not (np.any(system.H) and np.any(system.E)):
            system = dataclasses.replace(system, H=None, E=None)
        sample_set = uncertainty_samples if isinstance(uncertainty_samples, SampleSet) else None
        if uncertainty_samples is None:
            samples = default_uncertainty_samples(system, self.structure, n_random_samples, seed)
        else:
            mats = sample_set.matrices if sample_set is not None else uncertainty_samples
            samples = check_samples(list(mats), system, self.structure)
        self.samples = samples if system.H is not None else [None]
        self.sample_set = sample_set
        check_plant(system, self.samples, None if sample_set is None else sample_set.labels)
        self.system = system
        scaling = options.state_scaling if isinstance(options.state_scaling, str) else np.array(options.state_scaling)
        self.P = prepare(system, self.structure, scaling, "general")
        self._problems = {}
        self.certificate_calls = 0

    def problem(self, hinf):
        if hinf not in self._problems:
            self._problems[hinf] = MixedProblem(self.P, hinf=hinf, lyapunov=self.lyapunov, margin=self.options.margin)
        return self._problems[hinf]

    # -- certification ------------------------------------------------------------

    def certify(self, sol, gamma_req):
        """Rebuild the filter, certify ν (and γ), check the samples (internal)."""
        P = self.P
        n, p = P.B.shape
        q, l = P.D.shape[1], P.L.shape[0]
        condZ = np.linalg.cond(sol.Z)
        if not np.isfinite(condZ) or condZ > 1e14:
            return _Check(False, f"Z is singular to working precision (cond {condZ:.3g}); the filter cannot be rebuilt")
        AFs = np.linalg.solve(sol.Z, sol.Abar_F)
        BFs = np.linalg.solve(sol.Z, sol.Bbar_F)
        CFs = sol.Cbar_F
        if not all(np.all(np.isfinite(M)) for M in (AFs, BFs, CFs)):
            return _Check(False, "the rebuilt filter has non-finite entries")
        Abar, Bbar, Cbar = error_system_matrices(P.A, P.B, P.C, P.D, P.L, AFs, BFs, CFs)
        Gt = np.block([[sol.X, sol.Z], [sol.Y, sol.Z]])
        GH = Ebar = None
        if P.H is not None:
            GH = Gt @ np.vstack([P.H, np.zeros_like(P.H)])
            Ebar = np.hstack([P.E, np.zeros_like(P.E)])
        G, GA, GB = Gt.T, Gt @ Abar, Gt @ Bbar
        M2 = extended_h2_matrix(sol.P2, G, GA, Cbar, GH, Ebar, sol.lam2, 0.0)
        root_kappa, _ = schur_gamma(M2, h2_output_index(n, l))
        kappa = root_kappa**2
        nu2 = kappa * float(np.trace(Bbar.T @ sol.P2 @ Bbar))
        nu = math.sqrt(nu2 * (1.0 + 1e-12)) if np.isfinite(nu2) and nu2 >= 0 else float("inf")
        sig = P.sigma
        A_F = sig[:, None] * AFs / sig[None, :]
        B_F = sig[:, None] * BFs
        C_F = CFs / sig[None, :]
        Hbar = None if P.H is None else np.vstack([P.H, np.zeros_like(P.H)])
        analysis = robust_h2_bound(Abar, Bbar, Cbar, Hbar, Ebar)
        self.certificate_calls += analysis.calls
        nu_c = min(nu, analysis.nu)
        if not np.isfinite(nu_c):
            return _Check(False, "the H2 Lyapunov LMI is not negative definite at the rebuilt filter for any κ",
                          A_F=A_F, B_F=B_F, C_F=C_F)
        if gamma_req is not None:
            M0 = robust_extended_hinf_negative(sol.Pinf, G, GA, GB, Cbar, GH, Ebar, sol.lam_inf, 0.0)
            gamma_c, _ = schur_gamma(M0, gamma_index(n, p, q))
        else:
            gamma_c = robust_bounded_real_lmi(Abar, Bbar, Cbar, Hbar, Ebar, solver="CVXOPT").gamma
            self.certificate_calls += 1
            if not np.isfinite(gamma_c):
                gamma_c = robust_bounded_real_lmi(Abar, Bbar, Cbar, Hbar, Ebar, solver="CLARABEL").gamma
                self.certificate_calls += 1
        Si = 1.0 / sig
        scale2 = np.concatenate([Si, Si])
        variables = {
            "X": Si[:, None] * sol.X * Si[None, :], "Y": Si[:, None] * sol.Y * Si[None, :],
            "Z": Si[:, None] * sol.Z * Si[None, :],
            "P2": scale2[:, None] * sol.P2 * scale2[None, :],
            "Pinf": None if sol.Pinf is None else scale2[:, None] * sol.Pinf * scale2[None, :],
            "lam2": sol.lam2, "lam_inf": sol.lam_inf, "W": sol.W, "kappa": kappa,
            "H": P.H_balanced, "E": P.E_balanced,
        }
        variables["P2_analysis"] = None if analysis.P is None else scale2[:, None] * analysis.P * scale2[None, :]
        variables["lam2_analysis"] = analysis.lam
        chk = _Check(False, "", gamma_c, nu_c, nu, analysis.nu, A_F, B_F, C_F, variables=variables)
        if not np.isfinite(gamma_c):
            chk.reason = "no finite H∞ level certifies the rebuilt filter"
            return chk
        if gamma_req is not None and gamma_c > gamma_req:
            chk.reason = f"certified γ {gamma_c:.10g} exceeds the requested {gamma_req:.10g}"
            return chk
        s = self.system
        wc = worst_case_norm(s, A_F, B_F, C_F, self.samples, dt=1.0)
        chk.wc = wc
        if not wc.stable:
            chk.reason = f"error system not Schur stable at sample {int(np.argmax(wc.spectral_radii))}"
            return chk
        if wc.norm > gamma_c * (1.0 + 1e-9):
            chk.reason = f"sampled H∞ norm {wc.norm:.10g} exceeds the certified γ {gamma_c:.10g}"
            return chk
        h2 = []
        for F in self.samples:
            Ap = s.A if F is None else s.perturbed_A(F)
            h2.append(h2_norm(error_system(Ap, s.B, s.C, s.D, s.L, A_F, B_F, C_F, True)))
        chk.h2_norms = np.array(h2)
        if np.max(chk.h2_norms) > nu_c * (1.0 + 1e-9):
            chk.reason = f"sampled H2 norm {np.max(chk.h2_norms):.10g} exceeds the certified ν {nu_c:.10g}"
            return chk
        chk.ok, chk.reason = True, "certified"
        return chk

    # -- one design -----------------------------------------------------------------

    def design(self, gamma):
        """One certified design at the H∞ bound ``gamma`` (None: the robust H2 filter), through the one certify loop.

        :func:`~hinfnav.design.certify_loop.solve_and_certify` minimises ν with
        each solver (the problem compiled once, γ² a Parameter) and stops at the
        first certified design (unless ``polish``); when rounding leaves a
        solver's certified γ above the request, that solver solves once more at
        ``γ (1 − 10 rtol)`` (the same loop, on that variant).
        """
        t0 = time.perf_counter()
        gamma_req = None if gamma is None else as_positive("gamma", gamma)
        prob = self.problem(gamma_req is not None)
        opts = self.options
        log, exceeded = [], []
        self.certificate_calls = 0  # the robust H2 (and H∞) analysis LMIs the certificate solves

        def variant(level):
            def solve(slv, _level=None):
                sol = prob.solve(None if level is None else level**2, slv, opts.accuracy)
                if not sol.solved:
                    log.append(f"{slv}: status {sol.status}, no solution")
                return sol
            return solve

        def certify(_, sol, level=None):
            chk = self.certify(sol, gamma_req)
            at = "" if level is None else f" at γ = {level:.10g}"
            log.append(f"{sol.solver}{at}: status {sol.status}, solver ν = {math.sqrt(max(sol.nu2, 0.0)):.10g}, "
                       f"certified ν = {chk.nu:.10g}, γ = {chk.gamma:.10g}: {chk.reason}")
            if chk.reason.startswith("certified γ"):
                exceeded.append(sol.solver)
            return Check(chk.ok, chk.nu, chk.reason, chk)  # the level the loop compares is ν

        run = solve_and_certify([("at γ", variant(gamma_req))], list(opts.solvers),
                                lambda v, sol: certify(v, sol, gamma_req), method="minimize", polish=opts.polish,
                                rtol=opts.rtol)
        if gamma_req is not None and exceeded and (opts.polish or not run.candidates):
            inside = gamma_req * (1.0 - 10.0 * opts.rtol)
            solve_and_certify([("just inside γ", variant(inside))], list(exceeded),
                              lambda v, sol: certify(v, sol, inside), method="minimize", polish=opts.polish,
                              rtol=opts.rtol, loop=run)
        statuses = run.statuses
        if not run.candidates:
            what = "γ = " + ("∞ (H2 only)" if gamma_req is None else f"{gamma_req:.10g}")
            if any(st in INFEASIBLE or st.startswith("infeasible") for _, st in statuses):
                raise InfeasibleLMIError(
                    f"the mixed H2/H∞ LMIs are infeasible at {what} (solver status: "
                    + "; ".join(f"{s} {st}" for s, st in statuses)
                    + "); γ must exceed the H∞ optimum γ* of Corollary 1"
                )
            raise CertificationError(f"no solution of the mixed H2/H∞ LMIs at {what} passed certification: "
                                     + " | ".join(log))
        best = run.best()
        return self._result(best.check.data, best.sol, best.solver, gamma_req, run.seconds, tuple(log),
                            time.perf_counter() - t0, run.calls + self.certificate_calls)

    def _result(self, chk, sol, slv, gamma_req, seconds, log, total, calls):
        ss = self.sample_set
        return DesignResult(
            A_F=chk.A_F, B_F=chk.B_F, C_F=chk.C_F,
            gamma=float(chk.gamma), lmi_gamma=float("inf") if gamma_req is None else float(gamma_req),
            verified_norm=chk.wc.norm, sample_norms=chk.wc.norms, worst_sample=chk.wc.index,
            spectral_radius=float(np.max(chk.wc.spectral_radii)), solver=slv, solve_time_s=seconds,
            total_time_s=total, method="h2-minimize", dt=self.dt, witness=chk.variables, attempts=log,
            structure=self.structure, samples=tuple(self.samples),
            uncertainty_bound=None if ss is None else ss.bound, sample_values=None if ss is None else ss.values,
            form="general", sample_labels=() if ss is None else ss.labels,
            h2_bound=float(chk.nu), h2_lmi=float(math.sqrt(max(sol.nu2, 0.0))),
            h2_synthesis_bound=float(chk.nu_synthesis), h2_analysis_bound=float(chk.nu_analysis),
            h2_verified=float(np.max(chk.h2_norms)), h2_sample_norms=chk.h2_norms,
            gamma_bound=None if gamma_req is None else float(gamma_req), lyapunov=self.lyapunov,
            system=self.system, solver_calls=calls, objective="mixed", covers=COVERS_MIXED,
        )


_DOC_PARAMS = """
    system : UncertainSystem
        The plant ψ_d (9)–(11) (no H, E: nominal), A Schur stable for every
        admissible F; its ``dt`` (s) is the result's.
    structure : {"full", "diagonal"}, optional
        Whether F is any contraction or diagonal (balancing, default samples),
        as in :func:`hinfnav.design.synthesize`.
    uncertainty_samples : SampleSet or sequence of array_like, optional
        Contractions F at which the certified bounds are checked.
    n_random_samples, seed : optional
        Random samples of the default set.
    lyapunov : {"extended", "common"}, optional
        Slack-variable (default) or common-Lyapunov formulation.
    options : SolverOptions, optional
        Default :data:`MIXED_SOLVER_OPTIONS` (CVXOPT, then Clarabel; accuracy
        1e-7). The certified γ never exceeds the requested one: if rounding puts
        it above, the LMI is solved once more at ``γ (1 − 10 rtol)``.
    solver : str, optional
        One solver only (not with ``options``).
"""


def synthesize_mixed(system: UncertainSystem, *, gamma: float | None = None, structure: str = "full",
                     uncertainty_samples: SampleSet | Sequence[ArrayLike | None] | None = None, n_random_samples: int = 4,
                     seed: int | np.random.Generator = 0, lyapunov: str = "extended", options: SolverOptions | None = None,
                     solver: str | None = None) -> DesignResult:
    """Robust mixed H2/H∞ filter: minimize the certified worst-case H2 norm ν subject to the H∞ bound γ.

    Parameters
    ----------
    gamma : float or None
        H∞ bound (must exceed γ* of Corollary 1); None: no H∞ constraint
        (the robust H2 filter; its γ is then certified afterwards).
    {params}

    Returns
    -------
    DesignResult
        With ``objective="mixed"``, the certified H2 bound ``h2_bound`` (and
        ``h2_lmi``, ``h2_synthesis_bound``, ``h2_analysis_bound``,
        ``h2_verified``, ``h2_sample_norms``) and the requested ``gamma_bound``.

    Raises
    ------
    InputError
        Bad shapes or options; ``UnstablePlantError`` for a plant that is not
        robustly Schur stable.
    InfeasibleLMIError
        A solver found the LMIs infeasible (γ ≤ γ*) and none gave a certified design.
    CertificationError
        No solution passed the certification.

    Notes
    -----
    At δ̄ = 0 and a γ above the H∞ norm of the Kalman predictor's error
    system the optimum ν is the H2 norm of the optimal one-step predictor,
    ``sqrt(trace(L P Lᵀ))`` with P the stationary predictor covariance (DARE
    with Q = BBᵀ, R = DDᵀ): the filter (12) is a predictor (z_f(k) uses
    y up to k − 1). The test suite checks this to 1e-4.
    """
    system, dt = system_argument("synthesize_mixed", system)
    designer = _Designer(system, dt, structure, uncertainty_samples, n_random_samples, seed, lyapunov, options, solver)
    res = designer.design(gamma)
    return dataclasses.replace(res, total_time_s=time.perf_counter() - designer.t_start)


def mixed_front(system: UncertainSystem, *, gammas: Sequence[float], include_h2: bool = True,
                structure: str = "full", uncertainty_samples: SampleSet | Sequence[ArrayLike | None] | None = None,
                n_random_samples: int = 4, seed: int | np.random.Generator = 0, lyapunov: str = "extended",
                options: SolverOptions | None = None, solver: str | None = None, gamma_star: float | None = None,
                hinf_result: DesignResult | None = None,
                progress: Callable[[DesignResult], object] | None = None) -> MixedFront:
    """Certified mixed designs along a γ grid (one compiled problem, re-solved per γ).

    Parameters
    ----------
    gammas : sequence of float
        H∞ bounds, each above γ* (see :func:`front_gammas`); sorted ascending.
    include_h2 : bool, optional
        Also design the unconstrained robust H2 filter (the end of the front).
    gamma_star : float, optional
        γ* to record (default: the smallest γ of the grid).
    hinf_result : DesignResult, optional
        The H∞ optimum to keep with the front.
    progress : callable, optional
        Called with each result as it is certified.
    {params}

    Returns
    -------
    MixedFront
    """
    g = np.sort(np.array([as_positive("gammas entry", v) for v in np.ravel(gammas)], dtype=float))
    if g.size == 0:
        raise InputError("gammas must contain at least one γ")
    system, dt = system_argument("mixed_front", system)
    designer = _Designer(system, dt, structure, uncertainty_samples, n_random_samples, seed, lyapunov, options, solver)
    results = []
    for gamma in g:
        res = designer.design(float(gamma))
        results.append(res)
        if progress is not None:
            progress(res)
    h2 = designer.design(None) if include_h2 else None
    if h2 is not None and progress is not None:
        progress(h2)
    return MixedFront(
        gamma_star=float(g[0] if gamma_star is None else gamma_star), results=tuple(results), h2_result=h2,
        hinf_result=hinf_result, total_time_s=time.perf_counter() - designer.t_start,
    )


synthesize_mixed.__doc__ = synthesize_mixed.__doc__.replace("{params}", _DOC_PARAMS.strip())
mixed_front.__doc__ = mixed_front.__doc__.replace("{params}", _DOC_PARAMS.strip())
