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
"""

import dataclasses

import numpy as np
from tqdm import tqdm

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least, as_nonnegative, as_positive
from ...design.mixed import front_gammas, mixed_front, synthesize_mixed
from .designs import delta_grid, delta_samples, design_for_scenario, design_report_from
from .scenario import Scenario

__all__ = ["mixed_design_for_scenario", "mixed_front_for_scenario", "mixed_design_report",
           "format_mixed_design_report"]


def _setup(scenario, delta_bar, delta_points, options):
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    delta_bar = scenario.delta_bar if delta_bar is None else as_nonnegative("delta_bar", delta_bar)
    delta_points = as_int_at_least("delta_points", delta_points, 2)
    options.setdefault("structure", "diagonal")
    options.setdefault("dt", scenario.dt)
    return scenario, delta_bar, scenario.design_model(delta_bar), delta_samples(delta_bar, delta_points)


def _with_grid(result, delta_bar, delta_points):
    # a nominal design is checked at δ = 0 only; record it so that reports can say so
    return dataclasses.replace(result, delta_bar=float(delta_bar),
                               deltas=np.asarray(delta_grid(delta_bar, delta_points), dtype=float))


def mixed_design_for_scenario(scenario=None, delta_bar=None, gamma=None, *, delta_points=21, **options):
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
    MixedSynthesisResult
    """
    scenario, delta_bar, system, samples = _setup(scenario, delta_bar, delta_points, options)
    res = synthesize_mixed(system.A, system.B, system.C, system.D, system.L, system.H, system.E, gamma=gamma,
                           uncertainty_samples=samples, **options)
    return _with_grid(res, delta_bar, delta_points) if samples is None else res


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
    hinf_result : SynthesisResult, optional
        The H∞ optimum (Corollary 1) at this δ̄; designed here when None.
    progress : bool, optional
        Show a tqdm progress bar.
    **options
        Passed to :func:`hinfnav.design.mixed.mixed_front`.

    Returns
    -------
    MixedFront
        ``points`` certified mixed designs, the unconstrained robust H2 design
        (``h2_result``) and the H∞ optimum (``hinf_result``).
    """
    scenario, delta_bar, system, samples = _setup(scenario, delta_bar, delta_points, options)
    if hinf_result is None:
        hinf_result = design_for_scenario(scenario, delta_bar, delta_points=delta_points)
    gammas = front_gammas(hinf_result.gamma, points, span, first)
    with tqdm(total=len(gammas) + 1, disable=not progress, desc=f"H2/H∞ front, δ̄ = {delta_bar:g}",
              unit="design") as bar:
        front = mixed_front(system.A, system.B, system.C, system.D, system.L, system.H, system.E, gammas=gammas,
                            uncertainty_samples=samples, gamma_star=hinf_result.gamma, hinf_result=hinf_result,
                            progress=lambda _res: bar.update(1), **options)
    if samples is None:
        front = dataclasses.replace(
            front, results=tuple(_with_grid(r, delta_bar, delta_points) for r in front.results),
            h2_result=None if front.h2_result is None else _with_grid(front.h2_result, delta_bar, delta_points))
    return front


def _h2_fields(res):
    return {
        "objective": "h2",
        "gamma_bound": res.gamma_bound,
        "h2_bound": res.h2_bound,
        "h2_lmi": res.h2_lmi,
        "h2_verified": res.h2_verified,
        "lyapunov": res.lyapunov,
    }


def mixed_design_report(delta_bar, gamma=None, solver=None, scenario=None, points=12):
    """JSON-ready summary of a mixed design, or of the front and its knee.

    Parameters
    ----------
    delta_bar : float
    gamma : float or None
        With a γ: one mixed design at that H∞ bound. Without: the front
        (:func:`mixed_front_for_scenario`) and its knee.
    solver : str, optional
        One solver (default: CVXOPT, then Clarabel).
    scenario : Scenario, optional
    points : int, optional
        Points of the front (without ``gamma``).

    Returns
    -------
    tuple of (dict, MixedSynthesisResult)
        The report has the fields of
        :func:`~hinfnav.papers.sun2011.designs.design_report` for the design
        (with a γ) or for the knee's design (without), plus ``objective``
        ("h2"), ``gamma_bound`` (requested γ), ``h2_bound`` (certified ν),
        ``h2_lmi`` (the solver's ν), ``h2_verified`` (largest H2 norm over the
        δ samples) and ``lyapunov``; without γ also ``gamma_star``, ``knee``
        (index), ``knee_gamma``, ``knee_h2_bound``, ``front_total_time_s`` and
        ``front`` (one dict per point, the unconstrained H2 design last, its
        ``gamma_bound`` None). The design is returned with it (for ``--save``).
    """
    opts = {} if solver is None else {"solver": solver}
    if gamma is not None:
        res = mixed_design_for_scenario(scenario, delta_bar, as_positive("gamma", gamma), **opts)
        return {**design_report_from(res), **_h2_fields(res)}, res
    front = mixed_front_for_scenario(scenario, delta_bar, points=points, **opts)
    knee = front.knee
    res = front.results[knee]
    report = {**design_report_from(res), **_h2_fields(res)}
    report.update(gamma_star=front.gamma_star, knee=knee, knee_gamma=res.gamma_bound, knee_h2_bound=res.h2_bound,
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
        lines.append(f"  knee (Kneedle)     : point {report['knee']}, γ = {report['knee_gamma']:.6g} "
                     f"({report['knee_gamma'] / report['gamma_star']:.3g} γ*), ν = {report['knee_h2_bound']:.8g}")
        lines.append(f"  front computed in {report['front_total_time_s']:.1f} s; the design below is the knee's")
    gb = "none (H2 only)" if report["gamma_bound"] is None else f"{report['gamma_bound']:.8g}"
    lines += [
        f"  requested γ        : {gb}",
        f"  certified γ        : {report['gamma']:.8g}   (extended H∞ LMI verified by eigenvalues at the filter)",
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
