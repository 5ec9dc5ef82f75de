"""Benchmark: peak memory and time of Monte Carlo, streaming statistics against full histories.

Run: ``python benchmarks/bench_memory.py [--runs 200 1000 5000]``. Each case runs in
a child process (``python -m hinfnav simulate ... --json`` for the streaming path,
``hinfnav.simulate`` for histories) and its peak resident memory is read from
``resource.getrusage(RUSAGE_CHILDREN)``. Prints times and peaks; asserts nothing.
Also prints the start-up time of ``python -m hinfnav --help`` (target < 0.5 s).
"""

import argparse
import resource
import subprocess
import sys
import time

HISTORIES = (
    "import sys, hinfnav as hn; from hinfnav.papers import sun2011; r = hn.simulate(sun2011.Scenario(), 'published', runs=int(sys.argv[1]), seed=0); "
    "print(r.x.nbytes + r.xhat.nbytes + r.u.nbytes + r.y.nbytes)"
)


def _child(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        return wall, None, proc.stderr.strip().splitlines()[-1] if proc.stderr else f"exit {proc.returncode}"
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss  # KiB, the largest child so far
    return wall, peak if peak > before else None, ""


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, nargs="+", default=[200, 1000, 5000])
    p.add_argument("--histories-up-to", type=int, default=1000, help="largest runs for the histories path (default 1000)")
    args = p.parse_args(argv)
    t = min(_child([sys.executable, "-m", "hinfnav", "--help"])[0] for _ in range(3))
    print(f"python -m hinfnav --help: {t:.2f} s (best of 3)")
    print(f"{'runs':>6}  {'path':<28}{'time (s)':>10}{'peak RSS (MiB)':>16}")
    # children run in increasing size so that the running maximum of ru_maxrss is each child's own peak
    for runs in sorted(args.runs):
        cmd = [sys.executable, "-m", "hinfnav", "simulate", "--filter", "published", "--runs", str(runs), "--json"]
        wall, peak, err = _child(cmd)
        print(f"{runs:6d}  {'simulate --json (streaming)':<28}{wall:10.1f}{(peak or 0) / 1024:16.0f} {err}")
    for runs in sorted(r for r in args.runs if r <= args.histories_up_to):
        wall, peak, err = _child([sys.executable, "-c", HISTORIES, str(runs)])
        print(f"{runs:6d}  {'hinfnav.simulate (histories)':<28}{wall:10.1f}{(peak or 0) / 1024:16.0f} {err}")
    print("(a peak of 0 means it did not exceed an earlier child's: ru_maxrss is a running maximum)")


if __name__ == "__main__":
    main()
