"""Provenance of every number the workbook writes: versions, commit, date, seed and runs.

:func:`provenance` returns a JSON-ready dict for ``summary.json``, saved
designs and results tables; figures carry the same in their metadata.
Library versions are read from the installed distributions (no import).
"""

from __future__ import annotations

import datetime
import platform
import subprocess
from importlib import metadata
from pathlib import Path

__all__ = ["provenance", "package_version", "git_commit", "LIBRARIES"]

#: Libraries whose versions are recorded.
LIBRARIES = ("numpy", "scipy", "cvxpy", "control", "filterpy", "matplotlib")


def _source_root() -> Path:
    return Path(__file__).resolve().parents[2]


def package_version() -> str:
    """hinfnav's version: from git in a source checkout, else the installed distribution's.

    In a checkout the version is recomputed from the repository (setuptools-scm: the last tag
    ``vX.Y.Z``, then ``X.Y.(Z+1).devN+g<commit>`` N commits after it, ``.d<date>`` when the tree is
    dirty), so an editable install reports the commit it runs, not the one it was installed at.
    """
    root = _source_root()
    if (root / ".git").exists():
        try:
            from setuptools_scm import get_version  # optional at run time; the build uses it

            return get_version(root=str(root), version_scheme="guess-next-dev", local_scheme="node-and-date")
        except Exception:
            pass
    try:
        return metadata.version("hinfnav")
    except metadata.PackageNotFoundError:  # pragma: no cover - running from a bare source tree
        return "unknown"


def git_commit() -> str | None:
    """The commit of the source tree (with ``+dirty`` if it has uncommitted changes), or None."""
    root = _source_root()
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=5)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, timeout=5)
        return head.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(**extra: object) -> dict:
    """JSON-ready provenance: ``hinfnav``, ``commit``, ``date_utc``, ``python``, library versions, and ``extra``.

    Parameters
    ----------
    **extra
        Added as is (``seed=…``, ``runs=…``, ``command=…``).
    """
    libs = {}
    for name in LIBRARIES:
        try:
            libs[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            libs[name] = None
    out = {
        "hinfnav": package_version(),
        "commit": git_commit(),
        "date_utc": datetime.datetime.now(datetime.UTC).replace(microsecond=0).isoformat(),
        "python": platform.python_version(),
        "libraries": libs,
    }
    out.update(extra)
    return out
