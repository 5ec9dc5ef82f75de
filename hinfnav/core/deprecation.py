"""Calls in a function's earlier argument order, accepted for one release with a DeprecationWarning.

Issue 23 puts ``scenario`` first wherever it is a positional parameter (or
makes it keyword-only where the scenario is optional and follows required
arguments). :func:`accepts_old_order` lets a call written for the earlier
order still work until version 0.3, mapped by name and warned about.
"""

from __future__ import annotations

import functools
import inspect
import warnings
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["accepts_old_order"]


def accepts_old_order(old_order: Sequence[str], is_new: Callable[[tuple, dict], bool], *,
                      fill: dict[str, Any] | None = None,
                      until: str = "0.3") -> Callable[[Callable[..., Any]], Callable[..., Any]]:
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

