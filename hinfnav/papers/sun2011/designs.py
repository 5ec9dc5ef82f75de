"""Sun et al. (2011)'s robust H∞ designs: the δ grid, Corollary 1 at a δ̄, the γ*(δ̄) sweep,
the design report of ``python -m hinfnav design``, and the published filter against the optimum.

The generic synthesis (:func:`hinfnav.design.synthesize`) knows nothing of
this scenario; here the scenario's uncertain model, its diagonal F_Δa and the
δ grid it is certified on are handed to it as a
:class:`~hinfnav.design.SampleSet`.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import control
import numpy as np
import scipy.optimize
from numpy.typing import NDArray
from tqdm import tqdm

from ...analysis.error_system import error_system, worst_case_norm
from ...analysis.norms import channel_norms, hinf_norm
from ...analysis.observer import observer_form
from ...core.exceptions import InputError, UnstablePlantError
from ...core.linalg import spectral_radius
from ...io.progress import bar_disabled
from ...io.provenance import provenance
from ...core.validation import as_int_at_least, as_nonnegative, check_keywords
from ...design import io as design_io
from ...design.result import DesignResult
from ...design.robust_hinf import synthesize
from ...design.samples import SampleSet
from ...lmi.conditioning import prepare_uncertainty
from ...lmi.robust_brl import robust_bounded_real_lmi
from ...systems.hill import uncertainty_F
from .constants import DEFAULT_DELTA_BARS, published_filter
from .scenario import Scenario

__all__ = [
    "delta_grid",
    "delta_samples",
    "design_for_scenario",
    "GammaSweep",
    "gamma_sweep",
    "design_report",
    "design_report_from",
    "format_design_report",
    "compare_with_published",
    "save_design",
    "load_design",
    "small_gain_bounds",
    "small_gain_crossing",
]




#: Options of :func:`design_for_scenario` passed on to :func:`synthesize` (the δ grid sets the samples).
_SYNTHESIS_OPTIONS = ("dt", "structure", "n_random_samples", "seed", "form", "options", "solver")


def delta_grid(delta_bar, points=21):
    """δ values checked for a design: ``points`` evenly spaced in [−δ̄, δ̄].

    An odd ``points`` includes δ = 0; the vertices ±δ̄ are always included.

    Returns
    -------
    ndarray, shape (points,) (``[0.]`` when δ̄ = 0)
    """
    return _grid(as_nonnegative("delta_bar", delta_bar), as_int_at_least("points", points, 2))


def _grid(delta_bar, points):
    """:func:`delta_grid` of a checked δ̄ and number of points (internal)."""
    if delta_bar == 0:
        return np.zeros(1)
    grid = np.linspace(-delta_bar, delta_bar, points)
    return np.unique(np.concatenate([grid, [0.0]]))


def delta_samples(delta_bar, points=21):
    """The δ grid of :func:`delta_grid` as a :class:`~hinfnav.design.SampleSet` of F_Δa(δ) (None when δ̄ = 0)."""
    return _samples(as_nonnegative("delta_bar", delta_bar), as_int_at_least("points", points, 2))


def _samples(delta_bar, points):
    """:func:`delta_samples` of a checked δ̄ and number of points (internal)."""
    if delta_bar == 0:
        return None
    deltas = _grid(delta_bar, points)
    return SampleSet(
        matrices=tuple(uncertainty_F(d, delta_bar) for d in deltas),
        labels=tuple(f"δ = {d:.6g}" for d in deltas),
        values=deltas,
        bound=delta_bar,
    )


def design_for_scenario(scenario: Scenario | None = None, delta_bar: float | None = None, *, delta_points: int = 21,
                        **options: Any) -> DesignResult:
    """Design the robust filter for a scenario's closed-loop model at δ̄.

    Builds ψ_d from ``scenario.design_model(delta_bar)`` (A = I + T(A₁ + G₀K),
    H = T·H_a, E = E_a of Section 4), treats F as diagonal (the paper's
    F_Δa) and certifies on the δ grid :func:`delta_grid` (vertices ±δ̄ and 0
    included), with F(δ) from :func:`hinfnav.systems.hill.uncertainty_F`.

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    delta_bar : float, optional
        Default ``scenario.delta_bar``; checked where the system is built
        (:func:`hinfnav.systems.hill.uncertainty_structure`).
    delta_points : int, optional
        Points of the δ grid.
    **options
        Passed to :func:`synthesize` (``solver``, ``method``, ``form``, ...);
        ``dt`` (s) replaces the design model's sampling time in the result.

    Returns
    -------
    DesignResult
        With ``uncertainty_bound`` = δ̄ and ``sample_values`` = the δ grid,
        ``dt = scenario.dt``.
    """
    scenario = _scenario(scenario)
    delta_points = as_int_at_least("delta_points", delta_points, 2)
    check_keywords("design option", options, _SYNTHESIS_OPTIONS)
    system = scenario.design_model(delta_bar)  # checks δ̄ (once, where H and E are built)
    delta_bar = float(scenario.delta_bar if delta_bar is None else delta_bar)
    if "dt" in options:
        system = dataclasses.replace(system, dt=options.pop("dt"))
    samples = _samples(delta_bar, delta_points)
    options.setdefault("structure", "diagonal")
    try:
        result = synthesize(system, uncertainty_samples=samples, **options)
    except UnstablePlantError as exc:
        if delta_bar > 0 and spectral_radius(system.A) < 1.0:  # stable at δ = 0: it is δ̄ that is too large
            raise UnstablePlantError(f"delta_bar = {delta_bar:g} is too large for this scenario: {exc}") from None
        raise
    if samples is None:
        # a nominal design is checked at δ = 0 only; record it so reports can say so
        result = with_grid(result, delta_bar, _grid(delta_bar, delta_points))
    return result


def with_grid(result, delta_bar, deltas):
    """``result`` with the δ̄ and δ grid of a nominal design recorded (it is checked at δ = 0 only)."""
    return dataclasses.replace(result, uncertainty_bound=float(delta_bar), sample_values=np.asarray(deltas, dtype=float))


@dataclass(frozen=True, eq=False)
class GammaSweep:
    """Certified designs across δ̄ (the curve γ*(δ̄)).

    Attributes
    ----------
    delta_bars : ndarray, shape (k,)
    results : tuple of DesignResult
    """

    delta_bars: np.ndarray
    results: tuple

    @property
    def gammas(self) -> NDArray[np.float64]:
        """Certified γ per δ̄, shape (k,)."""
        return np.array([r.gamma for r in self.results])

    @property
    def lmi_gammas(self) -> NDArray[np.float64]:
        """Solver γ per δ̄, shape (k,)."""
        return np.array([r.lmi_gamma for r in self.results])

    @property
    def verified_norms(self) -> NDArray[np.float64]:
        """Worst sampled norm per δ̄, shape (k,)."""
        return np.array([r.verified_norm for r in self.results])

    @property
    def solve_times(self) -> NDArray[np.float64]:
        """Solver wall time per δ̄, s, shape (k,)."""
        return np.array([r.solve_time_s for r in self.results])

    @property
    def nondecreasing(self) -> bool:
        """Whether the certified γ*(δ̄) is non-decreasing (δ̄ sorted ascending)."""
        order = np.argsort(self.delta_bars)
        return bool(np.all(np.diff(self.gammas[order]) >= 0))

    def table(self) -> list[dict[str, Any]]:
        """Rows ``(δ̄, γ, lmi_γ, verified norm, worst δ, solver, method, time)`` as dicts."""
        return [
            {
                "delta_bar": float(d),
                "gamma": r.gamma,
                "lmi_gamma": r.lmi_gamma,
                "verified_norm": r.verified_norm,
                "worst_delta": r.worst_value,
                "solver": r.solver,
                "method": r.method,
                "solve_time_s": r.solve_time_s,
            }
            for d, r in zip(self.delta_bars, self.results)
        ]


def gamma_sweep(scenario: Scenario | None = None, delta_bars: Sequence[float] = DEFAULT_DELTA_BARS,
                progress: bool = False, **options: Any) -> GammaSweep:
    """Certified designs for several δ̄ (Corollary 1 at each).

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    delta_bars : sequence of float, optional
        Default :data:`DEFAULT_DELTA_BARS` (0 … 5).
    progress : bool, optional
        Show a tqdm progress bar.
    **options
        Passed to :func:`design_for_scenario` (``form="observer"`` for the
        observer-form curve).

    Returns
    -------
    GammaSweep
    """
    if isinstance(delta_bars, str) or not hasattr(delta_bars, "__iter__"):
        raise InputError(f"delta_bars must be a sequence of bounds >= 0; got {delta_bars!r}")
    dbs = np.array([as_nonnegative("delta_bars entry", d) for d in delta_bars], dtype=float)
    if dbs.size == 0:
        raise InputError("delta_bars must hold at least one uncertainty bound")
    results = []
    for d in tqdm(dbs, disable=bar_disabled(progress), desc="γ*(δ̄)", unit="design"):
        results.append(design_for_scenario(scenario, d, **options))
    return GammaSweep(dbs, tuple(results))


def design_report(scenario: Scenario | None = None, delta_bar: float | None = None, solver: str | None = None,
                  form: str = "general") -> dict[str, Any]:
    """JSON-ready summary of one certified design (for ``python -m hinfnav design``).

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    delta_bar : float, optional
        Uncertainty bound δ̄ ≥ 0; default ``scenario.delta_bar``.
    solver : str, optional
        ``"CLARABEL"``, ``"CVXOPT"`` or ``"SCS"`` (default: CVXOPT, Clarabel fallback).
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
    return design_report_from(design_for_scenario(scenario, delta_bar, solver=solver, form=form))


def design_report_from(res):
    """The JSON-ready report of :func:`design_report` for a design already made (with provenance)."""
    return {
        "delta_bar": float(res.uncertainty_bound),
        "form": res.form,
        "gamma": res.gamma,
        "lmi_gamma": res.lmi_gamma,
        "lmi20_gamma": float(res.witness.get("lmi20_gamma", res.gamma)),
        "verified_norm": res.verified_norm,
        "worst_delta": res.worst_value,
        "spectral_radius": res.spectral_radius,
        "solver": res.solver,
        "method": res.method,
        "solve_time_s": res.solve_time_s,
        "total_time_s": res.total_time_s,
        "dt": float(res.dt),
        "A_F": res.A_F.tolist(),
        "B_F": res.B_F.tolist(),
        "C_F": res.C_F.tolist(),
        "deltas_checked": [float(d) for d in res.sample_values],
        "attempts": list(res.attempts),
        "provenance": provenance(),
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
        f"  certified γ        : {report['gamma']:.8g}   "
        + ("(full Lyapunov matrix for the returned filter, robust bounded real LMI)"
           if report.get("lmi20_gamma", report["gamma"]) > report["gamma"]
           else "(LMI (20) verified by eigenvalues at the returned filter)"),
        f"  solver γ           : {report['lmi_gamma']:.8g}   ({report['solver']}, {report['method']})",
    ] + ([f"  LMI (20) level     : {report['lmi20_gamma']:.8g}   (restricted Lyapunov matrix diag(R − S, S))"]
         if form == "observer" and "lmi20_gamma" in report else []) + [
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


def compare_with_published(scenario: Scenario | None = None, solver: str | None = None, delta_points: int = 21,
                           design: DesignResult | None = None) -> dict[str, Any]:
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
    design : DesignResult, optional
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
        ``excess_percent``; ``deltas``; ``design`` (the DesignResult).
    """
    scenario = _scenario(scenario)
    if design is not None and not isinstance(design, DesignResult):
        raise InputError(f"design must be a hinfnav DesignResult (from design_for_scenario); got {type(design).__name__}")
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




def _scenario(scenario):
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    return scenario


def _is_scenario_design(result):
    """Whether a result was made by :func:`design_for_scenario` (its system is the paper's design model)."""
    own = result.system
    if getattr(result, "uncertainty_bound", None) is None or not hasattr(own, "A"):
        return False
    ref = Scenario().design_model(float(result.uncertainty_bound))
    return own.A.shape == ref.A.shape and np.allclose(own.A, ref.A) and np.allclose(own.B, ref.B)


def save_design(result: DesignResult, path: str | os.PathLike[str], *,
                scenario: Scenario | None = None) -> Path:
    """Save a design made for ``scenario`` (default the paper's) as a JSON design file.

    The file holds the filter, its certificate, the uncertain system ψ_d of
    the scenario at the design's δ̄ (with its fingerprint and T), the design
    options and provenance (:mod:`hinfnav.design.io`). Returns the path.
    """
    own = getattr(result, "system", None)
    if scenario is None and own is not None and not _is_scenario_design(result):
        # a design of another system (not from design_for_scenario): saved with its own system
        return design_io.save_design(result, own, path, options={"form": result.form})
    if not isinstance(result, DesignResult):
        raise InputError(f"result must be a hinfnav DesignResult (from design_for_scenario); got {type(result).__name__}")
    scenario = _scenario(scenario)
    design_io.check_design_path(path)
    delta_bar = 0.0 if result.uncertainty_bound is None else float(result.uncertainty_bound)
    system = scenario.design_model(delta_bar)
    options = {"delta_bar": delta_bar, "form": result.form, "structure": result.structure, "solver": result.solver}
    extra = {"paper": "sun2011", "scenario": {"dt_s": scenario.dt, "omega0": scenario.omega0, "mass": scenario.mass}}
    return design_io.save_design(result, system, path, options=options, extra=extra)


def load_design(path: str | os.PathLike[str], *, scenario: Scenario | None = None) -> DesignResult:
    """Load a design file and check it was made for ``scenario`` (default the paper's).

    Raises
    ------
    InputError
        If the file is not a design, was edited, or was designed for another
        system (another T, B, D, K, …): the message names what differs.
    """
    result, system, d = design_io.load_design(path)
    if scenario is None and (d.get("extra") or {}).get("paper") != "sun2011":
        return result  # a design of another system: checked against its own fingerprint only
    scenario = _scenario(scenario)
    if result.uncertainty != "norm-bounded":
        raise InputError(f"design file {path} was made for another system (a polytope of "
                         f"{getattr(system, 'n_vertices', '?')} vertices), not for the scenario: design again for it")
    delta_bar = 0.0 if result.uncertainty_bound is None else float(result.uncertainty_bound)
    design_io.check_design_system(system, system.dt, scenario.design_model(delta_bar), scenario.dt,
                                  what="the scenario")
    return result


def small_gain_bounds(scenario, delta_bars):
    """The small-gain number ``‖E(zI − A)⁻¹H‖∞`` of the design model across δ̄.

    With one multiplier λ (Lemma 2), the γ-free part of LMI (20) asks the
    plant ``A + H F E`` to be quadratically stable for every F the factors
    admit; for F any contraction (``structure="full"``) that holds iff
    ``‖E(zI − A)⁻¹H‖∞ < 1`` (bounded real lemma for ``(A, H√λ⁻¹, E√λ)``,
    small-gain theorem), whatever the filter. Computed (SLICOT ab13dd) for
    the factors as printed (``H = T·H_a``, ``E = E_a``; a common balancing
    scalar does not change the number) and for the channel-balanced ones
    the synthesis uses with a diagonal F, ``diag(s)⁻¹ E (zI − A)⁻¹ H diag(s)``
    (:func:`hinfnav.lmi.conditioning.prepare_uncertainty`).

    Parameters
    ----------
    scenario : Scenario or None
        None: the paper's.
    delta_bars : sequence of float
        Uncertainty bounds δ̄ > 0.

    Returns
    -------
    dict
        ``delta_bars``, ``printed``, ``balanced`` (ndarrays, dimensionless).
    """
    scenario = _scenario(scenario)
    dbs = np.array([as_nonnegative("delta_bars entry", d) for d in delta_bars], dtype=float)
    if np.any(dbs == 0):
        raise InputError("delta_bars entries must be > 0 (δ̄ = 0 has no uncertainty, no small-gain number)")
    out = {"delta_bars": dbs, "printed": [], "balanced": []}
    for d in dbs:
        s = scenario.design_model(d)
        for key, structure in (("printed", "full"), ("balanced", "diagonal")):
            H, E, _ = prepare_uncertainty(s.H, s.E, structure)
            sys_ = control.ss(s.A, H, E, np.zeros((E.shape[0], H.shape[1])), scenario.dt)
            out[key].append(hinf_norm(sys_))
    out["printed"], out["balanced"] = np.array(out["printed"]), np.array(out["balanced"])
    return out


def small_gain_crossing(scenario=None, bracket=(0.5, 5.0)):
    """The δ̄ at which the printed factors' small-gain number reaches 1 (LMI (20) with them turns infeasible).

    Root of ``small_gain_bounds(None, [δ̄])["printed"] − 1`` by Brent's method in
    ``bracket`` (to 1e-6 in δ̄).
    """
    f = lambda d: small_gain_bounds(scenario, [d])["printed"][0] - 1.0
    return float(scipy.optimize.brentq(f, *bracket, xtol=1e-6))
