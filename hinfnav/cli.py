"""Command line: ``python -m hinfnav {simulate,design,reproduce} ...``.

Run ``python -m hinfnav COMMAND --help`` for each command's options. The
parser imports nothing heavy: each command imports the layers it needs when it
runs, so ``--help`` starts fast. The choices below are literals for that reason;
``tests/test_cli.py`` checks that they equal the package's own lists.
"""

import argparse
import json
import math
import os
import sys

from .core.exceptions import HinfnavError

__all__ = ["main", "simulate_report", "format_simulate_report", "FILTER_CHOICES", "NOISE_CHOICES", "SOLVER_CHOICES",
           "PAPER_CHOICES"]

#: ``simulate --filter`` choices (= hinfnav.papers.sun2011.FILTER_NAMES).
FILTER_CHOICES = ("published", "published_closed_loop", "designed", "designed_closed_loop", "designed_observer",
                  "designed_observer_closed_loop", "ekf", "ekf_known_input")
#: ``--noise`` choices (= hinfnav.noise.NOISE_NAMES).
NOISE_CHOICES = ("gaussian", "colored", "mixture", "uniform", "laplace", "student_t")
#: ``design --solver`` choices (= hinfnav.lmi.SOLVERS).
SOLVER_CHOICES = ("CLARABEL", "CVXOPT", "SCS")
#: ``reproduce --paper`` choices (= "all" and the keys of hinfnav.papers.PAPERS).
PAPER_CHOICES = ("all", "sun2011")

_SCS_WARNING = (
    "warning: SCS is a first-order solver; on this LMI it is slow and loose (measured at delta_bar = 0.05: about "
    "80 s and a certified gamma of 6.55 against 0.3586 with CLARABEL/CVXOPT). The result is still certified."
)


def simulate_report(*args, **kwargs):
    """See :func:`hinfnav.papers.sun2011.report.simulate_report`."""
    from .papers.sun2011.report import simulate_report as _report

    return _report(*args, **kwargs)


def format_simulate_report(rep):
    """See :func:`hinfnav.papers.sun2011.report.format_simulate_report`."""
    from .papers.sun2011.report import format_simulate_report as _fmt

    return _fmt(rep)


def _cmd_simulate(args):
    rep = simulate_report(args.filter, maneuver=not args.no_maneuver, delta=args.delta, noise=args.noise,
                          seed=args.seed, runs=args.runs, discretization=args.discretization,
                          progress=not args.json and args.runs > 1, design=args.design, verbatim=args.verbatim)
    print(json.dumps(rep, indent=2) if args.json else format_simulate_report(rep))


def _cmd_design(args):
    from .papers.sun2011.designs import design_for_scenario, design_report_from, format_design_report, save_design

    if args.solver == "SCS":
        print(_SCS_WARNING, file=sys.stderr)
    result = design_for_scenario(None, args.delta_bar, solver=args.solver, form=args.form)
    rep = design_report_from(result)
    if args.save:
        rep["saved_to"] = str(save_design(result, args.save))
    print(json.dumps(rep, indent=2) if args.json else format_design_report(rep))


def _cmd_reproduce(args):
    from .papers import reproduce

    reproduce(args.paper, args.out, seed=args.seed, runs=args.runs, notebooks=args.notebooks, progress=True)


def _parser():
    p = argparse.ArgumentParser(
        prog="python -m hinfnav",
        description="hinfnav: robust navigation filtering of spacecraft, reproduced and extended "
                    "(base: Sun et al. 2011, robust H-infinity filtering for a chaser satellite).",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    s = sub.add_parser("simulate", help="simulate the paper's scenario with one filter and print its errors")
    s.add_argument("--filter", default="published", choices=FILTER_CHOICES, help="estimator (default: published)")
    s.add_argument("--design", metavar="FILE", default=None,
                   help="run a filter saved by 'design --save FILE' instead of --filter (refused if made for another "
                        "system, e.g. another T)")
    s.add_argument("--verbatim", action="store_true",
                   help="with --design: run (12) exactly, assuming u = Kx (default: told the applied thrust)")
    s.add_argument("--no-maneuver", action="store_true", help="free motion, u = 0 (default: maneuver, u = Kx)")
    s.add_argument("--delta", type=float, default=0.0, help="true orbital-rate error delta, omega = omega0(1+delta) (default 0)")
    s.add_argument("--noise", default="gaussian", choices=NOISE_CHOICES, help="noise model of w and v (default gaussian)")
    s.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    s.add_argument("--runs", type=int, default=1, help="Monte Carlo runs (default 1; memory does not grow with runs)")
    s.add_argument("--discretization", default="exact", choices=("exact", "euler"), help="truth discretization (default exact)")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(func=_cmd_simulate)

    d = sub.add_parser("design", help="design a robust H-infinity filter by LMI (Corollary 1) and certify it")
    d.add_argument("--delta-bar", type=float, default=0.05, help="uncertainty bound delta_bar >= 0 (default 0.05)")
    d.add_argument("--solver", default=None, type=str.upper, choices=SOLVER_CHOICES,
                   help="SDP solver (default: CLARABEL, polished by CVXOPT; SCS is slow and loose, with a warning)")
    d.add_argument("--form", default="general", choices=("general", "observer"),
                   help="filter structure: general (the paper's LMI (20), default) or observer "
                        "(extension: error independent of the trajectory)")
    d.add_argument("--save", metavar="FILE", default=None,
                   help="write the certified filter, the system it was designed for and provenance to FILE (JSON)")
    d.add_argument("--json", action="store_true", help="print one JSON object")
    d.set_defaults(func=_cmd_design)

    r = sub.add_parser("reproduce", help="regenerate a paper's tables and figures into a folder (Table 1, Figs 2-7)")
    r.add_argument("--paper", default="all", choices=PAPER_CHOICES,
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
    if hasattr(args, "runs") and args.runs < 1:
        parser.error(f"--runs must be >= 1; got {args.runs}")
    if hasattr(args, "delta_bar") and not (math.isfinite(args.delta_bar) and args.delta_bar >= 0):
        parser.error(f"--delta-bar must be a finite number >= 0; got {args.delta_bar}")
    if hasattr(args, "delta") and not math.isfinite(args.delta):
        parser.error(f"--delta must be finite; got {args.delta}")
    if getattr(args, "seed", 0) < 0:
        parser.error(f"--seed must be >= 0; got {args.seed}")
    if getattr(args, "verbatim", False) and args.design is None:
        parser.error("--verbatim applies to --design only")
    try:
        args.func(args)
    except HinfnavError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, ValueError) else 1
    except BrokenPipeError:
        # output piped into e.g. `head`, which closed early: not an error of ours
        sys.stdout = open(os.devnull, "w")
    return 0
