"""Mixed H2/H∞ robust designs on Sun et al. (2011)'s scenario: the filter the paper names as future work.

The paper ends by proposing to improve its accuracy "by considering the H∞ and
H2 performance indices of the filtering error system together". Here the
generic certified synthesis :func:`hinfnav.design.mixed.synthesize_mixed` is
handed the scenario's closed-loop uncertain model ψ_d at δ̄, its diagonal F_Δa
and the δ grid of :func:`~hinfnav.papers.sun2011.designs.delta_grid`, exactly
as :func:`~hinfnav.papers.sun2011.designs.design_for_scenario` does for
Corollary 1; the front runs from the H∞ optimum γ* to 10 γ* and ends with the
robust H2 filter without H∞ bound. ``python -m hinfnav design --objective h2``
prints :func:`mixed_design_report`.

Every row of the front is certified the same way (issue 22): the synthesis
certifies a mixed point's γ at its own LMI variables (the slack G shared with
the H2 condition), the robust H2 filter's γ by the robust bounded real LMI of
the filter alone (Lemmas 1–3), which is tighter. So each row also gets the
latter (:func:`analysis_gamma`) and keeps the smaller of its certificates,
just as ν is the smaller of the synthesis and analysis certificates; and the
knee (:func:`certified_knee`) is chosen among the rows no other row beats on
both certified γ and ν. Before, the knee at δ̄ = 0.05 (γ 0.410, ν 0.140773) was
beaten on both by the H2 row (γ 0.393, ν 0.140733).
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

import numpy as np
from tqdm import tqdm

from ...analysis.error_system import error_system_matrices
from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_positive
from ...design.mixed import front_gammas, knee_index, mixed_front, synthesize_mixed
from ...lmi.conditioning import prepare_uncertainty
from ...lmi.robust_brl import robust_bounded_real_lmi
from .designs import delta_grid, delta_samples, design_for_scenario, design_report_from, with_grid
from .scenario import Scenario

if TYPE_CHECKING:
    from ...design.mixed import DesignResult

__all__ = ["mixed_design_for_scenario", "mixed_front_for_scenario", "mixed_design_report",
           "format_mixed_design_report", "certified_knee"]


def _setup(scenario, delta_bar, delta_points, options):
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    delta_points = as_int_at_least("delta_points", delta_points, 2)
    system = scenario.design_model(delta_bar)  # checks δ̄ (once, where H and E are built)
    delta_bar = float(scenario.delta_bar if delta_bar is None else delta_bar)
    if "dt" in options:
        system = dataclasses.replace(system, dt=options.pop("dt"))
    options.setdefault("structure", "diagonal")
    return scenario, delta_bar, system, delta_samples(delta_bar, delta_points)


def _with_grid(result, delta_bar, delta_points):
    # a nominal design is checked at δ = 0 only; record it so that reports can say so
    return with_grid(result, delta_bar, delta_grid(delta_bar, delta_points))


def mixed_design_for_scenario(scenario: Scenario | None = None, delta_bar: float | None = None,
                              gamma: float | None = None, *, delta_points: int = 21,
                              **options: Any) -> DesignResult:
    """Mixed H2/H∞ robust filter for a scenario's closed-loop model at δ̄.

    Minimizes the certified worst-case H2 norm ν of the error system (13)
    (from τ = [w; v] to e) subject to the H∞ bound γ, for every admissible
    F_Δa of (10)–(11).

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    delta_bar : float, optional
        Default ``scenario.delta_bar``.
    gamma : float or None
        H∞ bound (above γ*(δ̄) of Corollary 1); None: the robust H2 filter.
    delta_points : int, optional
        Points of the δ grid the bounds are checked on.
    **options
        Passed to :func:`hinfnav.design.mixed.synthesize_mixed` (``solver``,
        ``lyapunov``, ``options`` ...).

    Returns
    -------
    DesignResult
        Its ``gamma`` the smaller of the synthesis and :func:`analysis_gamma` certificates.
    """
    scenario, delta_bar, system, samples = _setup(scenario, delta_bar, delta_points, options)
    res = synthesize_mixed(system, gamma=gamma, uncertainty_samples=samples, **options)
    res = _with_grid(res, delta_bar, delta_points) if samples is None else res
    return _recertified(system, res)  # γ certified as every row of a front (certify_front)


def analysis_gamma(system, result):
    """Certified worst-case H∞ bound of a filter alone: the robust bounded real LMI (Lemmas 1–3, (17)).

    The certificate the synthesis gives the unconstrained H2 filter
    (:func:`hinfnav.lmi.robust_bounded_real_lmi`, Clarabel and CVXOPT, the
    smaller γ certified by eigenvalues), here for any filter of ``system``
    (the design model ψ_d at δ̄, F_Δa diagonal).

    Returns
    -------
    float
        γ (units of e per unit τ); ``inf`` when no solver certifies one.
    """
    Abar, Bbar, Cbar = error_system_matrices(system.A, system.B, system.C, system.D, system.L,
                                             result.A_F, result.B_F, result.C_F)
    Hbar = Ebar = None
    if system.H is not None:
        H_b, E_b, _ = prepare_uncertainty(system.H, system.E, "diagonal")
        if H_b.shape[1]:
            Hbar, Ebar = np.vstack([H_b, np.zeros_like(H_b)]), np.hstack([E_b, np.zeros_like(E_b)])
    return float(robust_bounded_real_lmi(Abar, Bbar, Cbar, Hbar, Ebar).gamma)


def certify_front(front, system):
    """The front with every row's γ certified the same way: the smaller of its own and :func:`analysis_gamma`.

    Both are valid certificates of the same filter, so the smaller is too;
    the H2 row's own γ already is the analysis one.

    Returns
    -------
    MixedFront
    """
    return dataclasses.replace(front, results=tuple(_recertified(system, r) for r in front.results),
                               h2_result=None if front.h2_result is None else _recertified(system, front.h2_result))


def _recertified(system, res):
    """``res`` with γ the smaller of its own and the analysis certificate; its own kept in
    ``witness["gamma_synthesis"]`` (the level its returned LMI variables certify)."""
    g = analysis_gamma(system, res)
    if not g < res.gamma:
        return res
    return dataclasses.replace(res, gamma=g, witness=dict(res.witness or {}, gamma_synthesis=float(res.gamma)))


def certified_knee(front):
    """Knee of the front chosen on certified numbers: an index into ``front.table()`` (the H2 row last).

    The rows (points and the robust H2 filter) are reduced to those that no
    other row beats on both certified γ and certified ν (sorted by γ, each
    with a smaller ν than every row of smaller γ); :func:`hinfnav.design.mixed.knee_index`
    (Kneedle on log γ) picks the knee among them.

    Returns
    -------
    int
    """
    rows = list(front.results) + ([front.h2_result] if front.h2_result is not None else [])
    gam = np.array([r.gamma for r in rows], dtype=float)
    nu = np.array([r.h2_bound for r in rows], dtype=float)
    kept, best = [], np.inf
    for i in np.lexsort((nu, gam)):
        if nu[i] < best:
            kept.append(int(i))
            best = nu[i]
    return kept[knee_index(gam[kept], nu[kept])]


def mixed_front_for_scenario(scenario=None, delta_bar=None, *, points=12, span=10.0, first=1e-3, delta_points=21,
                             hinf_result=None, progress=False, **options):
    """The certified H2/H∞ Pareto front of a scenario at δ̄.

    Parameters
    ----------
    scenario : Scenario, optional
    delta_bar : float, optional
    points, span, first : optional
        The γ grid :func:`hinfnav.design.mixed.front_gammas`:
        ``γ*(1 + s)``, s log-spaced from ``first`` to ``span − 1``.
    delta_points : int, optional
    hinf_result : DesignResult, optional
        The H∞ optimum (Corollary 1) at this δ̄; designed here when None.
    progress : bool, optional
        Show a tqdm progress bar.
    **options
        Passed to :func:`hinfnav.design.mixed.mixed_front`.

    Returns
    -------
    MixedFront
        ``points`` certified mixed designs, the unconstrained robust H2 design
        (``h2_result``) and the H∞ optimum (``hinf_result``); every row's
        γ certified the same way (:func:`certify_front`).
    """
    scenario, delta_bar, system, samples = _setup(scenario, delta_bar, delta_points, options)
    if hinf_result is None:
        hinf_result = design_for_scenario(scenario, delta_bar, delta_points=delta_points)
    gammas = front_gammas(hinf_result.gamma, points, span, first)
    with tqdm(total=len(gammas) + 1, disable=not progress, desc=f"H2/H∞ front, δ̄ = {delta_bar:g}",
              unit="design") as bar:
        front = mixed_front(system, gammas=gammas, uncertainty_samples=samples, gamma_star=hinf_result.gamma, hinf_result=hinf_result,
                            progress=lambda _res: bar.update(1), **options)
    if samples is None:
        front = dataclasses.replace(
            front, results=tuple(_with_grid(r, delta_bar, delta_points) for r in front.results),
            h2_result=None if front.h2_result is None else _with_grid(front.h2_result, delta_bar, delta_points))
    return certify_front(front, system)


def _h2_fields(res):
    return {
        "objective": "h2",
        "gamma_bound": res.gamma_bound,
        "h2_bound": res.h2_bound,
        "h2_lmi": res.h2_lmi,
        "h2_verified": res.h2_verified,
        "lyapunov": res.lyapunov,
    }


def mixed_design_report(scenario=None, delta_bar=None, gamma=None, solver=None, points=12):
    """JSON-ready summary of a mixed design, or of the front and its knee.

    Parameters
    ----------
    scenario : Scenario, optional
        Default: the paper's.
    delta_bar : float, optional
        Default ``scenario.delta_bar``.
    gamma : float or None
        With a γ: one mixed design at that H∞ bound. Without: the front
        (:func:`mixed_front_for_scenario`) and its knee.
    solver : str, optional
        One solver (default: CVXOPT, then Clarabel).
    points : int, optional
        Points of the front (without ``gamma``).

    Returns
    -------
    tuple of (dict, DesignResult)
        The report has the fields of
        :func:`~hinfnav.papers.sun2011.designs.design_report` for the design
        (with a γ) or for the knee's design (without), plus ``objective``
        ("h2"), ``gamma_bound`` (requested γ), ``h2_bound`` (certified ν),
        ``h2_lmi`` (the solver's ν), ``h2_verified`` (largest H2 norm over the
        δ samples) and ``lyapunov``; without γ also ``gamma_star``, ``knee``
        (index into ``front``, :func:`certified_knee`), ``knee_gamma`` (its
        certified γ), ``knee_gamma_bound`` (its requested γ, None for the H2
        row), ``knee_h2_bound``, ``front_total_time_s`` and
        ``front`` (one dict per point, the unconstrained H2 design last, its
        ``gamma_bound`` None). The design is returned with it (for ``--save``).
    """
    opts = {} if solver is None else {"solver": solver}
    if gamma is not None:
        res = mixed_design_for_scenario(scenario, delta_bar, as_positive("gamma", gamma), **opts)
        return {**design_report_from(res), **_h2_fields(res)}, res
    front = mixed_front_for_scenario(scenario, delta_bar, points=points, **opts)
    knee = certified_knee(front)
    res = (list(front.results) + [front.h2_result])[knee]
    report = {**design_report_from(res), **_h2_fields(res)}
    report.update(gamma_star=front.gamma_star, knee=knee, knee_gamma=res.gamma, knee_gamma_bound=res.gamma_bound,
                  knee_h2_bound=res.h2_bound,
                  front_total_time_s=front.total_time_s, front=front.table())
    return report, res


def format_mixed_design_report(report):
    """Readable text version of :func:`mixed_design_report`'s dict."""
    lines = [
        f"Mixed H2/H∞ robust filter (the extension Sun et al. 2011 propose), δ̄ = {report['delta_bar']:g}",
        f"  Lyapunov matrices  : {report['lyapunov']} (one slack G: de Oliveira, Geromel & Bernussou 2002)",
    ]
    if "front" in report:
        lines.append(f"  H∞ optimum γ*      : {report['gamma_star']:.8g}   (Corollary 1)")
        lines.append(f"  {'γ bound':>14} {'certified γ':>12} {'certified ν':>12} {'solver ν':>12} {'sampled ν':>12}")
        for row in report["front"]:
            gb = "none (H2)" if row["gamma_bound"] is None else f"{row['gamma_bound']:.6g}"
            lines.append(f"  {gb:>14} {row['gamma']:12.6g} {row['h2_bound']:12.8g} {row['h2_lmi']:12.8g} "
                         f"{row['h2_verified']:12.8g}")
        lines.append(f"  knee (Kneedle)     : row {report['knee']}, among the rows no row beats on both certified γ and ν")
        lines.append(f"                       certified γ = {report['knee_gamma']:.6g} "
                     f"({report['knee_gamma'] / report['gamma_star']:.3g} γ*), ν = {report['knee_h2_bound']:.8g}")
        lines.append(f"  front computed in {report['front_total_time_s']:.1f} s; the design below is the knee's")
    gb = "none (H2 only)" if report["gamma_bound"] is None else f"{report['gamma_bound']:.8g}"
    lines += [
        f"  requested γ        : {gb}",
        f"  certified γ        : {report['gamma']:.8g}   (smaller of the extended H∞ LMI and the robust BRL of the filter "
        "alone, each verified by eigenvalues)",
        f"  certified ν        : {report['h2_bound']:.8g}   (extended H2 LMI verified by eigenvalues at the filter)",
        f"  solver ν           : {report['h2_lmi']:.8g}   ({report['solver']})",
        f"  worst sampled ‖Ψ‖₂ : {report['h2_verified']:.8g}   (Lyapunov equation, {len(report['deltas_checked'])} δ)",
        f"  worst sampled ‖Ψ‖∞ : {report['verified_norm']:.8g}   at δ = {report['worst_delta']:.6g} (slycot ab13dd)",
        f"  solve time         : {report['solve_time_s']:.3f} s   (total with certification "
        f"{report['total_time_s']:.3f} s)",
    ]
    for name in ("A_F", "B_F", "C_F"):
        lines.append(f"  {name} =")
        lines += ["    " + " ".join(f"{v: .5e}" for v in row) for row in np.asarray(report[name], dtype=float)]
    return "\n".join(lines)
