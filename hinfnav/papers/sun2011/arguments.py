"""The earlier argument orders of Sun et al. (2011)'s functions, accepted until 0.3 (issue 23).

The scenario comes first wherever it is a positional parameter, and is
keyword-only where it is optional and follows required arguments
(``save_design``, ``load_design``); a call in the earlier order still works,
with a :class:`DeprecationWarning` (:func:`hinfnav.core.deprecation.accepts_old_order`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ...core.deprecation import accepts_old_order, scenario_keyword
from .scenario import Scenario

__all__ = ["scenario_first", "scenario_keyword"]


def _leads(args, kwargs):
    """Whether a call is in the present order: no positional argument, or a scenario (or None for the paper's) first."""
    if not args or isinstance(args[0], Scenario):
        return True
    return args[0] is None and not (len(args) > 1 and isinstance(args[1], Scenario))


def scenario_first(*old_order: str, **fill: Any) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator of a function whose scenario moved to the front from its place in ``old_order``."""
    return accepts_old_order(old_order, _leads, fill=fill)
