"""Command line: ``python -m hinfnav {simulate,design,reproduce} ...``.

Run ``python -m hinfnav COMMAND --help`` for each command's options. The
commands import the heavy layers (cvxpy, python-control, matplotlib) only
when they run.
"""

import argparse
import json
import os
import sys

import numpy as np

from .core.exceptions import HinfnavError

__all__ = ["main", "simulate_report", "format_simulate_report"]


def simulate_report(filter="published", *, maneuver=True, delta=0.0, noise="gaussian", seed=0, runs=1,
                    discretization="exact", scenario=None, progress=False):
    """Simulate the paper's scenario with one filter and summarize the errors.

    Returns
    -------
    dict
        JSON-ready: ``filter``, ``maneuver``, ``delta``, ``noise``, ``runs``,
        ``seed``, ``window_s``, ``rms_pos_m`` (x, y, z), ``rms_vel_mps``
        (x, y, z), ``max_pos_m``, ``max_vel_mps``, and over runs
        ``mc_mean_pos_m`` etc. (per-run RMS averaged, with a 95 % interval).
    """
    from .metrics import max_error, monte_carlo_summary, rms_error
    from .papers.sun2011 import Scenario, make_estimator
    from .sim import simulate

    scenario = Scenario() if scenario is None else scenario
    est = make_estimator(filter, scenario)
    res = simulate(scenario, est, maneuver=maneuver, delta=delta, noise=noise, runs=runs, seed=seed,
                   discretization=discretization, progress=progress)
    win = scenario.rms_window_s
    st = res.state
    pos, vel = (st.select(rms_error(res.error, res.t, win), g) for g in ("position", "velocity"))
    mx = max_error(res.error, res.t, win)
    mc = monte_carlo_summary(res.error, res.t, win)
    r = lambda a: [float(v) for v in np.asarray(a)]  # noqa: E731
    P, V = st.indices("position"), st.indices("velocity")
    return {
        "filter": filter,
        "maneuver": bool(maneuver),
        "delta": float(delta),
        "noise": res.settings["noise"],
        "runs": int(runs),
        "seed": int(seed),
        "discretization": discretization,
        "dt_s": scenario.dt,
        "duration_s": scenario.duration_s,
        "window_s": list(win),
        "rms_pos_m": r(pos),
        "rms_vel_mps": r(vel),
        "max_pos_m": r(mx[list(P)]),
        "max_vel_mps": r(mx[list(V)]),
        "mc_mean_pos_m": r(mc.mean[list(P)]),
        "mc_mean_vel_mps": r(mc.mean[list(V)]),
        "mc_ci95_pos_m": [r(mc.ci95[0, list(P)]), r(mc.ci95[1, list(P)])],
        "mc_ci95_vel_mps": [r(mc.ci95[0, list(V)]), r(mc.ci95[1, list(V)])],
        "error_measure": "per-axis RMS of x - xhat over window_s, pooled over runs",
    }


def format_simulate_report(rep):
    """A readable table of :func:`simulate_report`'s output."""
    lines = [
        f"filter {rep['filter']}  maneuver {'yes' if rep['maneuver'] else 'no'}  delta {rep['delta']:g}  "
        f"noise {rep['noise']}  runs {rep['runs']}  seed {rep['seed']}",
        f"per-axis RMS error over t = {rep['window_s'][0]:g} .. {rep['window_s'][1]:g} s (T = {rep['dt_s']:g} s)",
        "",
        f"{'':16}{'x':>10}{'y':>10}{'z':>10}",
    ]
    for label, key in (("position (m)", "rms_pos_m"), ("velocity (m/s)", "rms_vel_mps"),
                       ("max |pos| (m)", "max_pos_m"), ("max |vel| (m/s)", "max_vel_mps")):
        lines.append(f"{label:16}" + "".join(f"{v:10.4f}" for v in rep[key]))
    return "\n".join(lines)


def _cmd_simulate(args):
    rep = simulate_report(args.filter, maneuver=not args.no_maneuver, delta=args.delta, noise=args.noise,
                          seed=args.seed, runs=args.runs, discretization=args.discretization,
                          progress=not args.json and args.runs > 1)
    print(json.dumps(rep, indent=2) if args.json else format_simulate_report(rep))


def _cmd_design(args):
    from .papers.sun2011.designs import design_report, format_design_report

    rep = design_report(args.delta_bar, solver=args.solver, form=args.form)
    print(json.dumps(rep, indent=2) if args.json else format_design_report(rep))


def _cmd_reproduce(args):
    from .papers import reproduce

    reproduce(args.paper, args.out, seed=args.seed, runs=args.runs, notebooks=args.notebooks, progress=True)


def _parser():
    from .lmi.solve import SOLVERS
    from .noise import NOISE_NAMES
    from .papers import PAPERS
    from .papers.sun2011.filters import FILTER_NAMES

    p = argparse.ArgumentParser(
        prog="python -m hinfnav",
        description="hinfnav: robust H-infinity relative navigation of a chaser satellite (Sun et al. 2011), reproduced.",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    s = sub.add_parser("simulate", help="simulate the paper's scenario with one filter and print its errors")
    s.add_argument("--filter", default="published", choices=FILTER_NAMES, help="estimator (default: published)")
    s.add_argument("--no-maneuver", action="store_true", help="free motion, u = 0 (default: maneuver, u = Kx)")
    s.add_argument("--delta", type=float, default=0.0, help="true orbital-rate error delta, omega = omega0(1+delta) (default 0)")
    s.add_argument("--noise", default="gaussian", choices=NOISE_NAMES, help="noise model of w and v (default gaussian)")
    s.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    s.add_argument("--runs", type=int, default=1, help="Monte Carlo runs (default 1)")
    s.add_argument("--discretization", default="exact", choices=("exact", "euler"), help="truth discretization (default exact)")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(func=_cmd_simulate)

    d = sub.add_parser("design", help="design a robust H-infinity filter by LMI (Corollary 1) and certify it")
    d.add_argument("--delta-bar", type=float, default=0.05, help="uncertainty bound delta_bar >= 0 (default 0.05)")
    d.add_argument("--solver", default=None, type=str.upper, choices=SOLVERS,
                   help="SDP solver (default: CLARABEL, polished by CVXOPT; SCS works but is very slow)")
    d.add_argument("--form", default="general", choices=("general", "observer"),
                   help="filter structure: general (the paper's LMI (20), default) or observer "
                        "(extension: error independent of the trajectory)")
    d.add_argument("--json", action="store_true", help="print one JSON object")
    d.set_defaults(func=_cmd_design)

    r = sub.add_parser("reproduce", help="regenerate a paper's tables and figures into a folder (Table 1, Figs 2-7)")
    r.add_argument("--paper", default="all", choices=("all",) + tuple(PAPERS),
                   help="which paper (default: all; sun2011 writes into --out itself)")
    r.add_argument("--out", default="results", help="output folder (default: results/)")
    r.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    r.add_argument("--runs", type=int, default=100, help="Monte Carlo runs per case (default 100)")
    r.add_argument("--notebooks", action="store_true", help="also execute the notebooks into the folder")
    r.set_defaults(func=_cmd_reproduce)
    return p


def main(argv=None):
    """Entry point; returns the exit status (0 ok, 2 bad input, 1 other failure)."""
    parser = _parser()
    args = parser.parse_args(argv)
    for name in ("runs",):
        if hasattr(args, name) and getattr(args, name) < 1:
            parser.error(f"--{name} must be >= 1; got {getattr(args, name)}")
    if getattr(args, "delta_bar", 0) < 0:
        parser.error(f"--delta-bar must be >= 0; got {args.delta_bar}")
    if hasattr(args, "delta") and not np.isfinite(args.delta):
        parser.error(f"--delta must be finite; got {args.delta}")
    if getattr(args, "seed", 0) < 0:
        parser.error(f"--seed must be >= 0; got {args.seed}")
    try:
        args.func(args)
    except HinfnavError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, ValueError) else 1
    except BrokenPipeError:
        # output piped into e.g. `head`, which closed early: not an error of ours
        sys.stdout = open(os.devnull, "w")
    return 0
