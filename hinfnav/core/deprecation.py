"""Earlier argument orders and keyword names, accepted for one release with a DeprecationWarning.

Issue 23 puts ``scenario`` first wherever it is a positional parameter (or
makes it keyword-only where the scenario is optional and follows required
arguments). :func:`accepts_old_order` lets a call written for the earlier
order still work until version 0.3, mapped by name and warned about.

Issue 23 renames ``window`` wherever it is not a (start, end) time window
(``memory_steps``, ``mean_steps``, ``moving_rms_s``, ``rms_epochs``,
``savgol_length``) and shi2018's ``window_s`` to the one name ``rms_window_s``.
A call written with the earlier name still works until :data:`UNTIL`: the
keyword is mapped to its new name and a :class:`DeprecationWarning` says so.
"""

from __future__ import annotations

import functools
import inspect
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from .exceptions import InputError

__all__ = ["UNTIL", "accepts_old_order", "scenario_moved", "scenario_keyword", "renamed_keywords", "translate_keywords"]

#: The release that drops the earlier names.
UNTIL = "0.3"


def accepts_old_order(old_order: Sequence[str], is_new: Callable[[tuple, dict], bool], *,
                      fill: dict[str, Any] | None = None,
                      until: str = UNTIL) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator: a call in the earlier positional order ``old_order`` still works, with a DeprecationWarning.

    Parameters
    ----------
    old_order : sequence of str
        The function's positional parameters in their earlier order.
    is_new : callable
        ``is_new(args, kwargs) -> bool``: whether a call is written for the
        present signature (e.g. its first argument is a scenario).
    fill : dict, optional
        Values of parameters an earlier call could leave out but the present
        signature requires (e.g. ``{"scenario": None}`` when the scenario was
        optional and last).
    until : str
        The version that drops the earlier order (in the warning).

    Returns
    -------
    callable
        The decorator. A call that ``is_new`` refuses has its positional
        arguments bound to ``old_order`` by name (too many is a TypeError, as
        Python reports it; a name given twice too) and is warned about.
    """
    old_order = tuple(old_order)

    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if is_new(args, kwargs):
                return func(*args, **kwargs)
            if len(args) > len(old_order):
                raise TypeError(f"{func.__name__}() takes at most {len(old_order)} positional arguments in its "
                                f"earlier order ({', '.join(old_order)}); got {len(args)}")
            named = dict(zip(old_order, args))
            named.update((k, v) for k, v in (fill or {}).items() if k not in named and k not in kwargs)
            twice = sorted(set(old_order[:len(args)]) & set(kwargs))
            if twice:
                raise TypeError(f"{func.__name__}() got multiple values for argument {twice[0]!r}")
            warnings.warn(
                f"{func.__name__}({', '.join(old_order[:len(args)])}) is the earlier argument order, deprecated and "
                f"removed in hinfnav {until}: the scenario comes first or by keyword "
                f"({func.__name__}({', '.join(inspect.signature(func).parameters)}))",
                DeprecationWarning, stacklevel=2)
            return func(**named, **kwargs)

        return wrapper

    return decorate


def scenario_moved(*old_order: str, was: type | tuple[type, ...] | Callable[[Any], bool],
                   **fill: Any) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator of a function whose scenario moved to the front from its place in ``old_order``.

    Parameters
    ----------
    *old_order : str
        The positional parameters in their earlier order.
    was : type, tuple of types or callable
        What the earlier first argument is (e.g. ``str`` for a registry name,
        ``callable`` for a builder): a call whose first positional argument is
        an instance of it (or for which the predicate holds) and whose second
        is not is in the earlier order. A scenario must never match it; when
        both match (e.g. a scenario wrongly given as a name), the call is read
        in the present order, so the function's own check names the scenario.
    **fill
        As in :func:`accepts_old_order`.
    """
    test = (lambda value: isinstance(value, was)) if isinstance(was, (type, tuple)) else was
    return accepts_old_order(old_order, lambda args, kwargs: not (args and test(args[0]) and not (len(args) > 1 and test(args[1]))),
                             fill=fill)


def scenario_keyword(*old_order: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator of a function whose optional scenario, at its place in ``old_order``, became keyword-only."""
    n = old_order.index("scenario")
    return accepts_old_order(old_order, lambda args, kwargs: len(args) <= n)


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
