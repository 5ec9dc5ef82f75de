"""Store (or check) the papers' verdict status of a full ``reproduce`` run: ``hinfnav/papers/status_seed0.json``.

Usage::

    python -m hinfnav reproduce --out results          # seed 0, default runs
    python benchmarks/status_snapshot.py results        # rewrite the stored status from results/<key>/summary.json
    python benchmarks/status_snapshot.py results --check  # exit 1 if the stored status differs

The status is recomputed from each ``summary.json`` by :func:`hinfnav.papers.verdicts.paper_status`
(and compared with the ``status`` field the run wrote). ``tests/test_verdicts.py`` checks the README's
status table and the notebooks' verdict statements against the stored file.
"""

import argparse
import json
import sys
from pathlib import Path

from hinfnav.papers.verdicts import STATUS_FILE, paper_status

KEYS = ("shi2018", "attitude2018", "yang2020")


def collect(results):
    out = {}
    for key in KEYS:
        path = Path(results) / key / "summary.json"
        if not path.is_file():
            raise SystemExit(f"{path} is missing: run python -m hinfnav reproduce --paper {key} --out {results}")
        summary = json.loads(path.read_text(encoding="utf-8"))
        status = paper_status(key, summary)
        if "status" in summary and summary["status"] != status:
            raise SystemExit(f"{path}: its status field disagrees with its own claims")
        out[key] = status
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="a reproduce --out folder with <key>/summary.json")
    ap.add_argument("--check", action="store_true", help="compare with the stored status instead of writing it")
    args = ap.parse_args(argv)
    new = collect(args.results)
    if args.check:
        old = json.loads(STATUS_FILE.read_text(encoding="utf-8"))
        bad = [k for k in KEYS if old.get(k) != new[k]]
        for k in bad:
            print(f"{k}: stored {old.get(k, {}).get('line')!r}\n{' ' * len(k)}  run    {new[k]['line']!r}")
        return 1 if bad else 0
    STATUS_FILE.write_text(json.dumps(new, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {STATUS_FILE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
