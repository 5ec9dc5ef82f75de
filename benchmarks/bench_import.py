"""Benchmark: import time of each layer, in fresh interpreters.

Run: ``python benchmarks/bench_import.py [--repeat 5] [--layers estimators sim]``. For every layer of
the import-linter layers contract (``pyproject.toml``, bottom first) it starts ``--repeat`` fresh
Python processes and measures, with ``time.perf_counter`` inside each, ``import hinfnav.<layer>``
(the package) and then the whole layer (every submodule and every exported name, the cost of its
first real use). Prints the medians and the heavy libraries (cvxpy, python-control, matplotlib,
pandas, Dask) each loads; asserts nothing (``tests/test_import_time.py`` holds the budget: under
1 s, none of cvxpy, python-control, matplotlib, for ``hinfnav.estimators`` and ``hinfnav.sim``).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("cvxpy", "control", "matplotlib", "pandas", "dask")

PROBE = """
import importlib, json, pkgutil, sys, time
start = time.perf_counter()
package = importlib.import_module({module!r})
package_s = time.perf_counter() - start
light = sorted({{m.split(".")[0] for m in sys.modules}} & set({heavy!r}))
for info in pkgutil.walk_packages(getattr(package, "__path__", []), package.__name__ + "."):
    importlib.import_module(info.name)
for name in getattr(package, "__all__", ()):
    getattr(package, name)
whole_s = time.perf_counter() - start
whole = sorted({{m.split(".")[0] for m in sys.modules}} & set({heavy!r}))
print(json.dumps({{"package_s": package_s, "whole_s": whole_s, "package_heavy": light, "whole_heavy": whole}}))
"""


def layers():
    """The layers of the import-linter contract, bottom first."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    contract = next(c for c in config["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    return [name.removeprefix("hinfnav.") for name in reversed(contract["layers"])]


def probe(module):
    """One fresh interpreter: the times (s) and the heavy libraries loaded."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
           "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, "-c", PROBE.format(module=module, heavy=HEAVY)], cwd=ROOT, env=env,
                          capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="fresh processes per layer (default 5)")
    parser.add_argument("--layers", nargs="+", default=None, help="layers to measure (default: all, bottom first)")
    args = parser.parse_args(argv)
    names = args.layers or layers()
    print(f"median over {args.repeat} fresh processes (python {sys.version.split()[0]})")
    print(f"{'layer':<12}{'import (s)':>11}{'whole (s)':>11}  {'heavy on import':<28}heavy with the whole layer")
    for layer in names:
        runs = [probe(f"hinfnav.{layer}") for _ in range(args.repeat)]
        package_s = statistics.median(r["package_s"] for r in runs)
        whole_s = statistics.median(r["whole_s"] for r in runs)
        light = ", ".join(runs[0]["package_heavy"]) or "-"
        whole = ", ".join(runs[0]["whole_heavy"]) or "-"
        print(f"{layer:<12}{package_s:>11.3f}{whole_s:>11.3f}  {light:<28}{whole}")


if __name__ == "__main__":
    main()
