"""Keyword arguments renamed in a release, accepted under their earlier name for one release with a warning.

Issue 23 renames ``window`` wherever it is not a (start, end) time window
(``memory_steps``, ``mean_steps``, ``moving_rms_s``, ``rms_epochs``,
``savgol_length``) and shi2018's ``window_s`` to the one name ``rms_window_s``.
A call written with the earlier name still works until :data:`UNTIL`: the
keyword is mapped to its new name and a :class:`DeprecationWarning` says so.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Mapping
from typing import Any

from .exceptions import InputError

__all__ = ["UNTIL", "renamed_keywords", "translate_keywords"]

#: The release that drops the earlier names.
UNTIL = "0.3"


def translate_keywords(owner: str, renamed: Mapping[str, str], kwargs: Mapping[str, Any], *,
                       stacklevel: int = 3) -> dict[str, Any]:
    """``kwargs`` with every earlier name of ``renamed`` (``{old: new}``) replaced by its new name.

    Parameters
    ----------
    owner : str
        The function or class named in the warning and the error.
    renamed : mapping of str to str
        Earlier keyword → present keyword.
    kwargs : mapping
        The keyword arguments of the call.
    stacklevel : int
        Passed to :func:`warnings.warn` (3: the caller of the function that calls this).

    Returns
    -------
    dict
        The keyword arguments under their present names (same order).

    Raises
    ------
    InputError
        Both the earlier and the present name given.
    """
    out = {}
    for key, value in kwargs.items():
        new = renamed.get(key)
        if new is not None:
            if new in kwargs:
                raise InputError(f"{owner}: give {new!r} only ({key!r} is its deprecated name)")
            warnings.warn(f"{owner}: {key!r} is deprecated, use {new!r} (the earlier name is removed in hinfnav "
                          f"{UNTIL})", DeprecationWarning, stacklevel=stacklevel)
            key = new
        out[key] = value
    return out


def renamed_keywords(**renamed: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator: the function also accepts the earlier keyword names ``old=new``, with a DeprecationWarning.

    Examples
    --------
    >>> @renamed_keywords(window="mean_steps")
    ... def f(x, mean_steps=3):
    ...     return mean_steps
    >>> f(1, mean_steps=5)
    5
    """

    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            return func(*args, **translate_keywords(func.__qualname__, renamed, kwargs))

        wrapper.renamed_keywords = dict(renamed)
        return wrapper

    return decorate
