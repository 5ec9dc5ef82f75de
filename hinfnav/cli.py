"""Command line: ``python -m hinfnav {simulate,design,reproduce,campaign} ...``.

Run ``python -m hinfnav COMMAND --help`` for each command's options. The
parser imports nothing heavy: the choices of ``--filter``, ``--noise``,
``--solver`` and ``--paper`` are read from the package's own registries and
lists (:class:`RegistryChoices`) the first time they are needed (a value to
check, or a command's ``--help``), and each command imports the layers it
needs when it runs, so ``python -m hinfnav --help`` starts fast.
"""

import argparse
import importlib
import math
import os
import sys
from collections.abc import Callable, Sequence

from .core.exceptions import HinfnavError, InputError
from .io.outputs import check_output_dir, dumps_strict
from .core.validation import check_new_file

__all__ = ["main", "simulate_report", "format_simulate_report", "FILTER_CHOICES",
           "NOISE_CHOICES", "SOLVER_CHOICES", "PAPER_CHOICES", "MAX_RUNS"]


class RegistryChoices(Sequence):
    """The choices of an option, read from the package when first used (a sequence of names).

    Parameters
    ----------
    load : callable
        ``load() -> sequence of str``, called once, on the first membership
        test, iteration or length (argparse checks a value by ``in`` and
        lists the choices in ``--help`` and its errors by iterating).
    what : str
        What the names are (for ``repr``).
    """

    def __init__(self, load: Callable[[], Sequence[str]], what: str):
        self._load, self._what, self._names = load, what, None

    def _items(self):
        if self._names is None:
            self._names = tuple(self._load())
        return self._names

    def __getitem__(self, index):
        return self._items()[index]

    def __len__(self):
        return len(self._items())

    def __contains__(self, value):
        return value in self._items()

    def __iter__(self):
        return iter(self._items())

    def __repr__(self):
        return f"RegistryChoices({self._what}: {', '.join(self._items())})"


def _attribute(module, name):
    """``load`` of a :class:`RegistryChoices`: attribute ``name`` of ``module`` (imported then)."""
    return lambda: getattr(importlib.import_module(module), name)


def _lazy(action, choices):
    """Give ``action`` its :class:`RegistryChoices` after ``add_argument``.

    ``add_argument`` formats the option once to check it, which would read the
    registry while the parser is built (and ``python -m hinfnav --help`` would
    import every layer); set afterwards, the choices are read only to check a
    value or to print that command's ``--help``.
    """
    action.choices = choices
    return action


def _sun2011_estimators():
    from .estimators.registry import registered_estimators
    from .papers.sun2011.scenario import Scenario

    return registered_estimators(Scenario())


def _paper_keys():
    from .papers import PAPERS, SELECTIONS

    return tuple(SELECTIONS) + tuple(PAPERS)


#: ``simulate --filter`` choices: every registered estimator that fits Sun 2011's scenario.
FILTER_CHOICES = RegistryChoices(_sun2011_estimators, "estimators registered for Sun 2011's scenario")
#: ``--noise`` choices: hinfnav.noise.NOISE_NAMES.
NOISE_CHOICES = RegistryChoices(_attribute("hinfnav.noise", "NOISE_NAMES"), "noise models")
#: ``design --solver`` choices: hinfnav.lmi.solve.SOLVERS.
SOLVER_CHOICES = RegistryChoices(_attribute("hinfnav.lmi.solve", "SOLVERS"), "SDP solvers")
#: Largest ``--runs`` (= hinfnav.papers.sun2011.report.MAX_RUNS), checked before anything heavy is imported.
MAX_RUNS = 1_000_000
#: ``reproduce --paper`` choices: the selections and keys of hinfnav.papers.
PAPER_CHOICES = RegistryChoices(_paper_keys, "paper selections and keys")


def simulate_report(*args, **kwargs):
    """See :func:`hinfnav.papers.sun2011.report.simulate_report`."""
    from .papers.sun2011.report import simulate_report as _report

    return _report(*args, **kwargs)


def format_simulate_report(rep):
    """See :func:`hinfnav.papers.sun2011.report.format_simulate_report`."""
    from .papers.sun2011.report import format_simulate_report as _fmt

    return _fmt(rep)


def _cmd_simulate(args):
    import hinfnav.papers  # noqa: F401 - registers every paper's estimators (hbf, recursive_hinf, ...)

    if args.design is not None and not args.design.strip():
        raise InputError("--design must name a design file (from 'design --save FILE'); got an empty path")
    rep = simulate_report(args.filter, maneuver=not args.no_maneuver, delta=args.delta, noise=args.noise,
                          seed=args.seed, runs=args.runs, discretization=args.discretization,
                          progress=not args.json and args.runs > 1, design=args.design, verbatim=args.verbatim)
    print(dumps_strict(rep, indent=2) if args.json else format_simulate_report(rep))


#: design options given on the command line only for the built-in scenario, with their defaults (issue 36: an
#: option that does not apply is refused, not ignored)
_DESIGN_DEFAULTS = {"delta_bar": 0.05, "points": 12, "form": "general", "objective": "hinf"}
_FLAG = {"delta_bar": "--delta-bar", "points": "--points", "form": "--form", "objective": "--objective",
         "solver": "--solver", "lyapunov": "--lyapunov", "gamma": "--gamma", "save": "--save",
         "time_limit": "--time-limit"}


def _check_design_options(args):
    """Refuse the design options that do not apply to what was asked, then fill in the defaults."""
    given = {k for k in _FLAG if getattr(args, k, None) is not None}
    if args.recertify is not None:
        bad = given
        why = "--recertify re-checks a saved design file alone"
    elif args.system is not None:
        bad = given & {"delta_bar", "points", "gamma"}
        why = "with --system the file states its own uncertainty (its [uncertainty] table) and design"
    else:
        bad = set()
    if bad:
        raise InputError(f"{', '.join(sorted(_FLAG[k] for k in bad))} does not apply here: {why}")
    for key, value in _DESIGN_DEFAULTS.items():
        if getattr(args, key) is None:
            setattr(args, key, value)


def _cmd_design(args):
    _check_design_options(args)
    if args.save is not None:  # before the heavy imports and the solver: an empty path, a folder, a missing folder
        check_new_file("--save", args.save, example="design.json")
    if args.recertify is not None or args.system is not None:
        return _cmd_design_own(args)
    if args.lyapunov is not None:
        raise InputError("--lyapunov applies to --system only")
    from .papers.sun2011.designs import design_for_scenario, design_report_from, format_design_report, save_design

    if getattr(args, "objective", "hinf") == "h2":
        return _cmd_design_h2(args, save_design)
    if getattr(args, "gamma", None) is not None:
        raise InputError("--gamma applies to --objective h2 (Corollary 1 minimizes gamma itself)")
    with _design_watch(args, 6, 1, "common"):  # Sun et al. (2011)'s chaser: 6 states, norm-bounded
        result = design_for_scenario(None, args.delta_bar, solver=args.solver, form=args.form)
    rep = design_report_from(result)
    if args.save:
        rep["saved_to"] = str(save_design(result, args.save))
    print(dumps_strict(rep, indent=2) if args.json else format_design_report(rep))


def _design_watch(args, n, vertices, lyapunov):
    """The design's estimated time, progress bar and SCS budget (issue 36 item 5; hinfnav.design.cost)."""
    from .design.cost import DESIGN_LIMIT_S, design_progress, estimate_design_seconds

    limit = DESIGN_LIMIT_S if args.time_limit is None else args.time_limit
    if not limit > 0:
        raise InputError(f"--time-limit must be a number of seconds > 0; got {args.time_limit!r}")
    est = estimate_design_seconds(n, vertices, lyapunov, args.solver)
    return design_progress(est, progress=not args.json, limit_s=limit,
                           what=f"design ({n} states{f', {vertices} vertices' if vertices > 1 else ''})")


def _cmd_design_own(args):
    """``design --system FILE`` (a system of one's own) or ``design --recertify FILE`` (issue 19)."""
    from .design import design_from_system_file, recertify
    from .design.io import save_design

    if args.recertify is not None:
        if args.system is not None or args.save is not None:
            raise InputError("--recertify takes a design file alone (no --system, no --save)")
        rep = recertify(args.recertify)
        print(dumps_strict(rep, indent=2) if args.json else "\n".join(
            [f"design file {rep['path']}: {'RECERTIFIED' if rep['ok'] else 'NOT RECERTIFIED'}",
             f"  stored gamma {rep['gamma']:.10g}; LMI witness re-evaluated in float64: {rep['lmi_gamma_recomputed']:.10g}",
             f"  worst sampled H-infinity norm {rep['sampled_worst_norm']:.10g} over {rep['n_samples']} samples",
             f"  covers: {rep['covers']}"] + [f"  refused: {r}" for r in rep["reasons"]]))
        if not rep["ok"]:
            from .core.exceptions import CertificationError

            raise CertificationError(f"design file {rep['path']} is not recertified: " + "; ".join(rep["reasons"]))
        return
    if args.gamma is not None:
        raise InputError("--gamma applies to --objective h2 of the built-in scenario only")
    if args.save:
        from .systems.files import read_system_file

        if read_system_file(args.system).dt == 0:
            raise InputError("--save: a continuous-time design (dt = 0) cannot be saved yet: the design-file format "
                             "and --recertify carry discrete-time certificates only (drop --save; the design is "
                             "certified when it is printed)")
    from .design.cost import system_size
    from .systems.files import read_system_file

    n, vertices, lyap = system_size(read_system_file(args.system), args.lyapunov, args.form)
    with _design_watch(args, n, vertices, lyap):
        result, rep = design_from_system_file(args.system, lyapunov=args.lyapunov, form=args.form,
                                              objective=args.objective, solver=args.solver)
    if args.save:
        rep["saved_to"] = str(save_design(result, result.system, args.save, options={"system_file": args.system}))
    print(dumps_strict(rep, indent=2) if args.json else "\n".join(
        [f"certified {'H2 bound' if rep['objective'] == 'h2' else 'gamma'} {rep['gamma']:.10g} (solver "
         f"{rep['lmi_gamma']:.10g}), worst sampled norm "
         f"{rep['verified_worst_norm']:.10g} over {rep['n_samples']} samples",
         f"  Lyapunov: {rep['lyapunov']}, form: {rep['form']}; covers {rep['covers']}"]
        + ([f"  saved to {rep['saved_to']}"] if args.save else [])))


def _cmd_design_h2(args, save_design):
    """``design --objective h2``: a mixed H2/H∞ design at ``--gamma``, or the front and its knee (issue 12)."""
    from .papers.sun2011.mixed_designs import format_mixed_design_report, mixed_design_report

    if args.form != "general":
        raise InputError("--objective h2 designs general-form filters only; leave out --form observer")
    if args.points < 2:
        raise InputError(f"--points must be >= 2; got {args.points}")
    with _design_watch(args, 6, 1 if args.gamma is not None else args.points + 1, "common"):  # one design per point
        rep, result = mixed_design_report(None, args.delta_bar, gamma=args.gamma, solver=args.solver,
                                          points=args.points)
    if args.save:
        rep["saved_to"] = str(save_design(result, args.save))
    print(dumps_strict(rep, indent=2) if args.json else format_mixed_design_report(rep))


def _cmd_reproduce(args):
    check_output_dir(args.out, "--out")  # before the heavy imports (reproduce checks it again, atomically)
    from .papers import reproduce

    reproduce(args.paper, args.out, seed=args.seed, runs=args.runs, notebooks=args.notebooks, progress=True,
              jobs=args.jobs)


def _cmd_campaign(args):
    """``campaign SPEC --out DIR``: run a campaign (issue 13) on a LocalCluster or the cluster at --scheduler."""
    from .campaign import run_campaign
    from .papers.benchmark import load_papers

    load_papers()  # every paper's scenarios and estimators, so that SPEC may name any of them
    table = run_campaign(args.spec, client=args.scheduler, out_dir=args.out, progress=True, workers=args.workers,
                         limits=dict(args.limit))
    info = table.attrs
    print(f"{len(info['cells'])} cells ({info['computed']} computed, {info['reused']} reused); "
          f"table: {info['out_dir']}/results.csv")
    for cell_id, message in info["errors"].items():
        print(f"error: cell {cell_id}: {message}", file=sys.stderr)
    if info["errors"]:  # the spec was checked whole before any work: these failed while running
        raise HinfnavError(f"{len(info['errors'])} cells failed while running (see above); the finished cells are "
                           "kept, and running the command again computes only the failed ones (which helps only if "
                           "the failure was transient, e.g. a lost worker)")


def _limit(text):
    """``--limit NAME=VALUE`` → ``(NAME, VALUE)``; argparse reports a malformed one."""
    name, sep, value = text.partition("=")
    try:
        number = float(value)
    except ValueError:
        number = float("nan")
    if not sep or not name.strip() or not (math.isfinite(number) and number > 0):
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE with a number VALUE > 0 (e.g. runs=10000000); got {text!r}")
    return name.strip(), int(number) if number.is_integer() else number


class _VersionAction(argparse.Action):
    """``--version``: the package version (computed only when asked: from git in a checkout)."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from .io.provenance import package_version

        print(f"hinfnav {package_version()}")
        parser.exit()


def _parser():
    p = argparse.ArgumentParser(
        prog="python -m hinfnav",
        description="hinfnav: robust navigation filtering of spacecraft, reproduced and extended "
                    "(base: Sun et al. 2011, robust H-infinity filtering for a chaser satellite).",
    )
    p.add_argument("--version", action=_VersionAction, help="print hinfnav's version and exit")
    p.add_argument("--backend", default=None, choices=("auto", "numpy", "numba"),
                   help="how the filters run: their compiled kernel where one exists (auto, the default), the NumPy "
                        "reference, or the kernel only (numba); sets HINFNAV_BACKEND for every worker")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    s = sub.add_parser("simulate", help="simulate the paper's scenario with one filter and print its errors")
    _lazy(s.add_argument("--filter", default="published", help="estimator (default: published)"), FILTER_CHOICES)
    s.add_argument("--design", metavar="FILE", default=None,
                   help="run a filter saved by 'design --save FILE' instead of --filter (refused if made for another "
                        "system, e.g. another T)")
    s.add_argument("--verbatim", action="store_true",
                   help="with --design: run (12) exactly, assuming u = Kx (default: told the applied thrust)")
    s.add_argument("--no-maneuver", action="store_true", help="free motion, u = 0 (default: maneuver, u = Kx)")
    s.add_argument("--delta", type=float, default=0.0, help="true orbital-rate error delta, omega = omega0(1+delta) (default 0)")
    _lazy(s.add_argument("--noise", default="gaussian", help="noise model of w and v (default gaussian)"), NOISE_CHOICES)
    s.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    s.add_argument("--runs", type=int, default=1, help="Monte Carlo runs (default 1; memory does not grow with runs)")
    s.add_argument("--discretization", default="exact", choices=("exact", "euler"), help="truth discretization (default exact)")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(func=_cmd_simulate)

    d = sub.add_parser("design", help="design a robust H-infinity filter by LMI (Corollary 1) and certify it")
    d.add_argument("--delta-bar", type=float, default=None, help="uncertainty bound delta_bar >= 0 of the built-in "
                   "scenario (default 0.05; not with --system, whose file states its own)")
    _lazy(d.add_argument("--solver", default=None, type=str.upper,
                         help="SDP solver (default: CVXOPT, then CLARABEL if CVXOPT certifies nothing; SCS is slow and "
                              "loose, with a warning)"), SOLVER_CHOICES)
    d.add_argument("--form", default=None, choices=("general", "observer"),
                   help="filter structure: general (the paper's LMI (20), default) or observer "
                        "(extension: error independent of the trajectory)")
    d.add_argument("--save", metavar="FILE", default=None,
                   help="write the certified filter, the system it was designed for and provenance to FILE (JSON)")
    d.add_argument("--objective", default=None, choices=("hinf", "h2"),
                   help="hinf: Corollary 1, min gamma (default); h2: mixed H2/H-infinity, min the certified H2 bound "
                        "subject to --gamma (without --gamma: the front gamma* .. 10 gamma* and its knee)")
    d.add_argument("--gamma", type=float, default=None,
                   help="with --objective h2: the H-infinity bound (above gamma* of Corollary 1)")
    d.add_argument("--points", type=int, default=None, help="with --objective h2 and no --gamma: front points (default 12)")
    d.add_argument("--system", metavar="SYS.toml", default=None,
                   help="design for your own system from a TOML file (dt, [nominal] A B C D L, optional "
                        "[uncertainty] norm-bounded H E or polytope vertices) instead of the built-in scenario")
    d.add_argument("--lyapunov", default=None, choices=("common", "parameter-dependent"),
                   help="with --system: one Lyapunov matrix (time-varying uncertainty) or one per vertex "
                        "(constant uncertainty; default for a polytope)")
    d.add_argument("--recertify", metavar="FILE", default=None,
                   help="re-check a saved design file in float64 without a solver (LMI witness and sampled norms)")
    d.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="refuse a design whose estimated time exceeds SECONDS (default 3600; the estimate and a "
                        "progress bar are shown for designs above a few seconds)")
    d.add_argument("--json", action="store_true", help="print one JSON object")
    d.set_defaults(func=_cmd_design)

    r = sub.add_parser("reproduce", help="regenerate a paper's tables and figures into a folder (Table 1, Figs 2-7)")
    _lazy(r.add_argument("--paper", default="papers",
                         help="which paper (default: papers = the four papers; all adds the cross-paper benchmark; "
                              "sun2011 writes into --out itself, the others into --out/<paper>/)"), PAPER_CHOICES)
    r.add_argument("--out", default="results", help="output folder (default: results/)")
    r.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    r.add_argument("--runs", type=int, default=None,
                   help="Monte Carlo runs per case (default: each paper's own, e.g. 100 for sun2011)")
    r.add_argument("--notebooks", action="store_true", help="also execute the notebooks into the folder")
    r.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="worker processes running the papers side by side, longest first (default: one per core; "
                        "1: one after another in this process); the numbers do not depend on it")
    r.set_defaults(func=_cmd_reproduce)

    c = sub.add_parser("campaign", help="run a campaign (a grid of estimators x scenarios x noises x runs, TOML) on Dask")
    c.add_argument("spec", metavar="SPEC", help="campaign file (TOML; see hinfnav.campaign.spec)")
    c.add_argument("--out", required=True, metavar="DIR",
                   help="campaign folder: finished cells are written there and reused on the next run (resume)")
    c.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of a running Dask scheduler (tcp://host:8786); default: a LocalCluster on this "
                        "machine; 'serial': in this process")
    c.add_argument("--workers", type=int, default=None, metavar="N",
                   help="worker processes of the LocalCluster (default: one per core)")
    c.add_argument("--limit", action="append", default=[], type=_limit, metavar="NAME=VALUE",
                   help="raise a stated maximum checked before any work (runs, cells, steps, batch_bytes; see "
                        "hinfnav.campaign.spec.LIMITS), e.g. --limit runs=10000000; repeatable")
    c.set_defaults(func=_cmd_campaign)
    return p


def main(argv=None):
    """Entry point; returns the exit status (0 ok, 2 bad input, 1 other failure)."""
    parser = _parser()
    args = parser.parse_args(argv)
    if getattr(args, "runs", None) is not None and args.runs < 1:
        parser.error(f"--runs must be >= 1; got {args.runs}")
    if getattr(args, "runs", None) is not None and args.runs > MAX_RUNS:
        parser.error(f"--runs must be at most {MAX_RUNS}; got {args.runs}")
    if getattr(args, "delta_bar", None) is not None and not (math.isfinite(args.delta_bar) and args.delta_bar >= 0):
        parser.error(f"--delta-bar must be a finite number >= 0; got {args.delta_bar}")
    if hasattr(args, "delta") and not math.isfinite(args.delta):
        parser.error(f"--delta must be finite; got {args.delta}")
    if getattr(args, "seed", 0) < 0:
        parser.error(f"--seed must be >= 0; got {args.seed}")
    if getattr(args, "workers", None) is not None and (args.workers < 1 or args.scheduler is not None):
        parser.error(f"--workers must be >= 1 and applies to the LocalCluster only (not with --scheduler); got {args.workers}")
    if getattr(args, "jobs", None) is not None and args.jobs < 1:
        parser.error(f"--jobs must be >= 1; got {args.jobs}")
    if getattr(args, "verbatim", False) and args.design is None:
        parser.error("--verbatim applies to --design only")
    old_backend = os.environ.get("HINFNAV_BACKEND")
    if args.backend is not None:
        os.environ["HINFNAV_BACKEND"] = args.backend  # read by every estimate (compiled.default_backend), workers too
    try:
        args.func(args)
    except HinfnavError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, ValueError) else 1
    except KeyboardInterrupt:
        # one line, no traceback: the writers publish a folder or file only when complete (atomic), so an
        # interrupted run leaves no partial output behind
        print("interrupted (Ctrl-C): stopped; nothing half-written is left (a campaign keeps its finished cells: run it again to resume)", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # output piped into e.g. `head`, which closed early: not an error of ours
        sys.stdout = open(os.devnull, "w")
    except OSError as exc:
        # a file system refusal the checks could not foresee (permissions, a full disk): say it, no traceback
        print(f"error: {exc}", file=sys.stderr)
        return 1
    finally:
        if old_backend is None:
            os.environ.pop("HINFNAV_BACKEND", None)
        else:
            os.environ["HINFNAV_BACKEND"] = old_backend
    return 0
