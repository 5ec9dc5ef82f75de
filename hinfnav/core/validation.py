"""Input checks shared by the public functions.

Each check raises :class:`hinfnav.exceptions.InputError` naming the parameter
and what is wrong with it, before any numerical work starts.
"""

import numbers
import os
import tempfile
from pathlib import Path

import numpy as np

from .exceptions import InputError

__all__ = ["as_matrix", "as_vector", "as_real", "as_positive", "as_nonnegative", "as_int_at_least", "as_choice", "as_seed",
           "check_keywords", "as_path", "check_new_file"]


def _as_float_array(name, value):
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be an array of real numbers; got {type(value).__name__} ({exc})") from None
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must contain only finite numbers; it has NaN or inf entries")
    return arr


def as_matrix(name, value, shape=None):
    """Return ``value`` as a finite 2-D float array, checking its shape.

    Parameters
    ----------
    name : str
        Parameter name used in the error message.
    value : array_like
        The matrix.
    shape : tuple of (int or None), optional
        Expected shape; ``None`` in a slot accepts any size there.
    """
    arr = _as_float_array(name, value)
    if arr.ndim != 2:
        raise InputError(f"{name} must be a 2-D matrix; got an array with {arr.ndim} dimension(s), shape {arr.shape}")
    if shape is not None:
        for got, want in zip(arr.shape, shape):
            if want is not None and got != want:
                want_txt = "x".join("any" if s is None else str(s) for s in shape)
                raise InputError(f"{name} must have shape {want_txt}; got {arr.shape[0]}x{arr.shape[1]}")
    return arr


def as_vector(name, value, size=None):
    """Return ``value`` as a finite 1-D float array of length ``size``."""
    arr = _as_float_array(name, value)
    if arr.ndim != 1:
        raise InputError(f"{name} must be a 1-D vector; got shape {arr.shape}")
    if size is not None and arr.size != size:
        raise InputError(f"{name} must have {size} entries; got {arr.size}")
    return arr


def _as_real(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{name} must be a real number; got {value!r}")
    value = float(value)
    if not np.isfinite(value):
        raise InputError(f"{name} must be finite; got {value}")
    return value


def as_positive(name, value):
    """Return ``value`` as a finite float > 0."""
    value = _as_real(name, value)
    if value <= 0:
        raise InputError(f"{name} must be > 0; got {value}")
    return value


def as_nonnegative(name, value):
    """Return ``value`` as a finite float >= 0."""
    value = _as_real(name, value)
    if value < 0:
        raise InputError(f"{name} must be >= 0; got {value}")
    return value


def as_real(name, value):
    """Return ``value`` as a finite float."""
    return _as_real(name, value)


def as_int_at_least(name, value, minimum):
    """Return ``value`` as an int >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InputError(f"{name} must be an integer; got {value!r}")
    if value < minimum:
        raise InputError(f"{name} must be >= {minimum}; got {value}")
    return int(value)


def as_choice(name, value, choices):
    """Return ``value`` if it is one of ``choices``, else raise naming the valid ones."""
    if value not in choices:
        raise InputError(f"unknown {name} {value!r}; choose one of: {', '.join(map(str, choices))}")
    return value


def as_seed(name, value):
    """Return ``value`` if it can seed :func:`numpy.random.default_rng`: an int >= 0, a SeedSequence or a Generator."""
    if isinstance(value, (np.random.SeedSequence, np.random.Generator)):
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InputError(f"{name} must be a non-negative integer or a numpy.random.Generator; got {value!r}")
    if value < 0:
        raise InputError(f"{name} must be a non-negative integer; got {value}")
    return value


def check_keywords(what, given, allowed):
    """Raise naming the unknown keywords among ``given`` (a mapping or names) and listing the ``allowed`` ones."""
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        raise InputError(f"unknown {what} {', '.join(map(repr, unknown))}; valid: {', '.join(sorted(allowed)) or 'none'}")


def as_path(name, value):
    """Return ``value`` as a non-empty :class:`pathlib.Path` (a str or path-like)."""
    if isinstance(value, bytes):
        value = value.decode(errors="replace")
    if not isinstance(value, (str, os.PathLike)):
        raise InputError(f"{name} must be a file path (str or pathlib.Path); got {type(value).__name__}")
    if str(value).strip() == "":
        raise InputError(f"{name} must name a file; got an empty path")
    return Path(value)


def check_new_file(name, value, example="result.json"):
    """Return ``value`` as a Path where a file can be written: not empty, not a folder, in an existing folder."""
    path = as_path(name, value)
    if str(path) == ".":
        raise InputError(f"{name} must name a file; got an empty path")
    if path.is_dir():
        raise InputError(f"{name} {path} is a directory; give a file name such as {example}")
    if not path.parent.exists():
        raise InputError(f"{name} {path}: the folder {path.parent} does not exist")
    if not path.parent.is_dir():
        raise InputError(f"{name} {path}: {path.parent} is a file, not a folder")
    try:  # a real probe before any work: a read-only folder or file system is named now, not after a solve
        fd, probe = tempfile.mkstemp(dir=path.parent, prefix=".hinfnav-probe-")
    except OSError as exc:
        raise InputError(f"{name} {path}: cannot write in the folder {path.parent} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
    return path
