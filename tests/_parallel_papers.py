"""Two stand-in papers for tests/test_reproduce_parallel.py (stdlib only, so that a spawned worker starts fast).

Each writes ``summary.json`` into its folder and returns its summary: numbers drawn from ``random.Random(seed)``
(so the same seed gives the same numbers in any process), the process id and the BLAS threads it ran on.
"""

import json
import os
import random
import time


def _blas_threads():
    from threadpoolctl import threadpool_info

    return sorted({lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"})


def _paper(key, out_dir, seed, runs, fail, slow):
    print(f"{key}: start")
    print(f"{key}: half a line ", end="")
    print("and the rest")
    if slow == key:
        time.sleep(60.0)
    if fail == key:
        raise ValueError(f"{key} failed on purpose")
    summary = {"key": key, "numbers": [random.Random(seed * 1000 + i).random() for i in range(runs)]}
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(summary, f)
    print(f"{key}: done")
    return dict(summary, pid=os.getpid(), blas_threads=_blas_threads())


def paper_a(out_dir, *, seed=0, runs=3, progress=True, fail=None, slow=None):
    """A stand-in paper ``a`` (``fail="a"``: raises; ``slow="a"``: sleeps a minute first)."""
    return _paper("a", out_dir, seed, runs, fail, slow)


def paper_b(out_dir, *, seed=0, runs=3, progress=True, fail=None, slow=None):
    """A stand-in paper ``b`` (as ``a``)."""
    return _paper("b", out_dir, seed + 1, runs, fail, slow)
