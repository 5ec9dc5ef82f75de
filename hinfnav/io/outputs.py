"""Output folders written whole or not at all, and never by two processes at once.

:func:`atomic_output_dir` checks the target before any work (an empty path, a
file, a folder under a file, a folder that cannot be written, a folder holding
files hinfnav did not write → a clear :class:`InputError`), takes an OS-level lock
beside it (:func:`output_lock`: a second process writing into the same folder
is refused), hands out a
temporary folder beside the target, and only when the work has finished
replaces the target by it in two renames. An interrupted run leaves the
previous complete folder untouched (and a ``.tmp`` folder that the next run
removes); no file ever mixes two runs.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import filelock
import numpy as np

from ..core.exceptions import InputError

__all__ = ["dumps_strict", "MARKER", "check_output_dir", "atomic_output_dir", "output_lock", "lock_path", "to_json", "atomic_write_text",
           "write_json"]

#: File that marks a folder as written by hinfnav (so it may be replaced).
MARKER = ".hinfnav-output"
#: Seconds a new run waits for the lock of an output folder before refusing (covers a holder that is just
#: releasing it; a run in progress holds it for its whole length).
_LOCK_WAIT_S = 0.5


def check_output_dir(path: str | os.PathLike | None, name: str = "out") -> Path:
    """Validate an output folder before any work; return it as an absolute :class:`Path`."""
    if path is None or str(path).strip() == "":
        raise InputError(f"{name} must name a folder; got an empty path")
    target = Path(path).expanduser().absolute()
    if target.exists() and not target.is_dir():
        raise InputError(f"{name} {target} is a file, not a folder")
    parent = target.parent
    for anc in [target] + list(target.parents):
        if anc.exists():
            if not anc.is_dir():
                raise InputError(f"{name} {target} lies under {anc}, which is a file")
            break
    probe = parent
    while not probe.exists():
        probe = probe.parent
    check_writable_folder(probe, f"{name} {target}")
    if target.is_dir() and any(target.iterdir()) and not (target / MARKER).exists():
        raise InputError(
            f"{name} {target} already holds files that hinfnav did not write; refusing to replace it "
            "(choose an empty or new folder)"
        )
    return target


def check_writable_folder(folder: str | os.PathLike, what: str) -> None:
    """Raise an InputError naming the real cause unless a file can be created in ``folder`` now.

    A real probe (a file created and removed), not :func:`os.access`: that says yes to root on a read-only
    file system and cannot see a full disk's inode table or a mount that refuses writes.
    """
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".hinfnav-probe-")
    except OSError as exc:
        raise InputError(f"{what}: cannot write in {folder} ({exc.strerror or exc})") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)


def lock_path(target: str | os.PathLike) -> Path:
    """The lock file of the output folder ``target``: ``.<name>.lock`` beside it."""
    target = Path(target)
    return target.parent / f".{target.name}.lock"


@contextlib.contextmanager
def output_lock(target: str | os.PathLike, name: str = "out") -> Iterator[None]:
    """Context manager: hold the OS-level lock of the output folder ``target`` (another holder → InputError).

    The lock is an advisory ``flock``/``LockFileEx`` lock taken through :mod:`filelock` on
    ``.<name>.lock`` beside the folder: the operating system releases it when the holder exits, however it
    exits (even SIGKILL), so a stale lock cannot exist and no process ever deletes another's lock. The file
    is removed while the lock is still held (a process that opened it meanwhile sees an unlinked file and
    tries again, which ``filelock`` does), so a finished run leaves nothing beside its folder.
    """
    lock_file = lock_path(target)
    try:
        lock_file.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{name} {target}: cannot create the folder {lock_file.parent} ({exc.strerror or exc})") from None
    check_writable_folder(lock_file.parent, f"{name} {target}")  # else filelock would wait and say "another process"
    lock = filelock.FileLock(lock_file, timeout=_LOCK_WAIT_S, is_singleton=False)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise InputError(f"{name}: another process is writing into {target} (it holds the lock {lock_file}); "
                         "wait for it to finish or choose another folder") from None
    try:
        yield lock_file
    finally:
        with contextlib.suppress(OSError):
            lock_file.unlink()
        lock.release()


@contextlib.contextmanager
def atomic_output_dir(path: str | os.PathLike, *, keep: Iterable[str] = (), name: str = "out") -> Iterator[Path]:
    """Context manager: yield a temporary folder that replaces ``path`` when the block succeeds.

    Parameters
    ----------
    path : str or Path
        The target folder.
    keep : sequence of str
        Entries of the existing target to carry over into the new one (e.g.
        the sub-folders of other papers when only one paper is redone).
    name : str
        Parameter name used in error messages.
    """
    target = check_output_dir(path, name)
    with output_lock(target, name):
        tmp = target.parent / f".{target.name}.tmp"
        try:
            shutil.rmtree(tmp, ignore_errors=True)
            tmp.mkdir(parents=True)
            (tmp / MARKER).write_text("written by hinfnav; this folder is replaced whole by the next run\n")
            yield tmp
            for entry in keep:
                src = target / entry
                if src.exists() and not (tmp / entry).exists():
                    shutil.copytree(src, tmp / entry) if src.is_dir() else shutil.copy2(src, tmp / entry)
            old = target.parent / f".{target.name}.old"
            shutil.rmtree(old, ignore_errors=True)
            if target.exists():
                target.rename(old)
            tmp.rename(target)
            shutil.rmtree(old, ignore_errors=True)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


def to_json(obj: Any, *, strict: bool = False) -> Any:
    """A JSON-ready copy of ``obj``: numpy arrays and scalars become lists and Python numbers.

    ``strict=True`` also turns NaN and infinities into None (null), which
    strict JSON requires (Python's ``json`` writes them as ``NaN``/``Infinity``).
    """
    if isinstance(obj, dict):
        return {str(k): to_json(v, strict=strict) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_json(v, strict=strict) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_json(obj.tolist(), strict=strict)
    if isinstance(obj, (np.floating, np.integer, np.bool_)):
        obj = obj.item()
    if strict and isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def atomic_write_text(path: str | os.PathLike, text: str, encoding: str = "utf-8", newline: str | None = None) -> Path:
    """Write ``text`` to ``path`` through a temporary file beside it and :func:`os.replace` (never half a file).

    ``newline=""`` writes the line ends as they are in ``text`` (what :mod:`csv` needs); the default
    translates ``"\\n"`` to the platform's line end, like :meth:`pathlib.Path.write_text`.
    """
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        tmp.write_text(text, encoding=encoding, newline=newline)
        os.replace(tmp, path)
    except BaseException as exc:  # a full disk, a read-only folder, Ctrl-C: no temporary file left behind
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError):
            raise OSError(exc.errno, f"cannot write {path}: {exc.strerror or exc}") from None
        raise
    return path


def dumps_strict(obj: Any, **kwargs: Any) -> str:
    """``json.dumps`` of ``to_json(obj, strict=True)``: strict JSON, NaN and infinities as null (issue 36)."""
    return json.dumps(to_json(obj, strict=True), allow_nan=False, **kwargs)


def write_json(path: str | os.PathLike, obj: Any, *, strict: bool = True) -> Any:
    """Write ``to_json(obj, strict=strict)`` to ``path`` atomically (indented, newline at the end); return it.

    Strict JSON by default (NaN and infinities as null, which every JSON reader accepts); ``strict=False``
    keeps Python's ``NaN``/``Infinity`` tokens, for a reader that needs them.
    """
    data = to_json(obj, strict=strict)
    atomic_write_text(path, json.dumps(data, indent=2, allow_nan=not strict) + "\n")
    return data
