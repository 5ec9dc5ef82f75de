"""I/O layer: what the workbook writes to disk, and how it reports progress.

Output folders written whole or not at all under an OS-level lock
(:mod:`~hinfnav.io.outputs`), the provenance that goes with every number written
(:mod:`~hinfnav.io.provenance`) and the progress-bar policy
(:mod:`~hinfnav.io.progress`). It sits above the numerical layers (core,
systems, noise, analysis, lmi), which never write a file, and below the first
layer that does (design, which saves designs).

Names are loaded lazily (PEP 562, :mod:`hinfnav.core.lazy`): ``import hinfnav``
reads its version from here without loading filelock or numpy.
"""

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .outputs import (MARKER, atomic_output_dir, atomic_write_text, check_output_dir, lock_path, output_lock, to_json,
                          write_json)
    from .progress import bar_disabled
    from .provenance import LIBRARIES, git_commit, package_version, provenance

__all__ = [
    "MARKER",
    "atomic_output_dir",
    "check_output_dir",
    "lock_path",
    "output_lock",
    "to_json",
    "atomic_write_text",
    "write_json",
    "bar_disabled",
    "LIBRARIES",
    "git_commit",
    "package_version",
    "provenance",
]

__getattr__, __dir__ = lazy_exports(__name__)
