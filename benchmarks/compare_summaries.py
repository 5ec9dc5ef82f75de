"""Compare two ``summary.json`` files number by number.

Usage::

    python benchmarks/compare_summaries.py OLD/summary.json NEW/summary.json [--rtol 1e-9]

Prints every numeric leaf whose relative difference exceeds ``rtol`` (and keys
present in one file only), then the largest relative difference; exits 1 if
anything differs. Used to check that a refactoring leaves every reproduced
number of ``python -m hinfnav reproduce --seed 0`` unchanged (issue 7: 1e-9).
Fields that record time or provenance (``*_time_s``, ``timing_s``, ``elapsed_s``, ``provenance``) are skipped;
fields only in NEW are listed as added (a later version may add fields), fields
only in OLD count as differences.
"""

import argparse
import json
import math
import sys

SKIP = ("time_s", "timing_s", "elapsed_s", "provenance", "generated")


def leaves(obj, prefix=""):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from leaves(v, f"{prefix}/{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from leaves(v, f"{prefix}[{i}]")
    else:
        yield prefix, obj


def compare(old, new, rtol):
    a, b = dict(leaves(old)), dict(leaves(new))
    problems, worst, added = [], 0.0, []
    for key in sorted(set(a) | set(b)):
        if any(s in key for s in SKIP):
            continue
        if key not in a:
            added.append(key)
            continue
        if key not in b:
            problems.append(f"{key}: only in old")
            continue
        x, y = a[key], b[key]
        if isinstance(x, (int, float)) and isinstance(y, (int, float)) and not isinstance(x, bool):
            if math.isnan(x) and math.isnan(y):
                continue
            rel = abs(x - y) / max(abs(x), abs(y), 1e-300)
            worst = max(worst, rel)
            if rel > rtol:
                problems.append(f"{key}: {x!r} vs {y!r} (relative {rel:.3g})")
        elif x != y:
            problems.append(f"{key}: {x!r} vs {y!r}")
    return problems, worst, len(a), added


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("--rtol", type=float, default=1e-9)
    args = p.parse_args(argv)
    with open(args.old) as fh:
        old = json.load(fh)
    with open(args.new) as fh:
        new = json.load(fh)
    problems, worst, n, added = compare(old, new, args.rtol)
    for line in problems:
        print(line)
    print(f"{n} leaves compared; largest relative difference {worst:.3g}; {len(problems)} differ beyond {args.rtol:g}; "
          f"{len(added)} fields added")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
