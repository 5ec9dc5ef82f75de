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
    """hinfnav's version: the installed distribution's (``importlib.metadata.version("hinfnav")``).

    The number is set in ``pyproject.toml`` (setuptools-scm: ``fallback_version`` with the
    ``only-version`` scheme, so a checkout without tags installs as that release, e.g. ``0.3.0``);
    the commit an output was made at is recorded beside it (:func:`git_commit`), so the version
    carries no commit suffix. ``"unknown"`` when hinfnav runs from a source tree that was never
    installed.
    """
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
