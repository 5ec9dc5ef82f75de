"""The system argument of the synthesis functions, and the loose-matrix form they accepted before.

:func:`~hinfnav.design.synthesize`, :func:`~hinfnav.design.synthesize_mixed`
and :func:`~hinfnav.design.mixed_front` take the uncertain system ψ_d (9)–(11)
as one :class:`~hinfnav.systems.UncertainSystem`, whose sampling time is the
design's. Until version 0.3 they also accept the seven loose matrices
``A, B, C, D, L[, H, E]`` and ``dt=`` (the earlier signature), with a
:class:`DeprecationWarning`.
"""

from __future__ import annotations

import warnings
from typing import Any

from ..core.exceptions import InputError
from ..core.validation import as_positive
from ..systems.uncertain import UncertainSystem

__all__ = ["system_argument"]

_LOOSE = ("A", "B", "C", "D", "L", "H", "E")


def system_argument(func: str, system: Any, matrices: tuple, legacy: dict[str, Any]
                    ) -> tuple[UncertainSystem, float | bool]:
    """The system a synthesis designs for, and the sampling time of its result.

    Parameters
    ----------
    func : str
        Name of the calling function (for the messages).
    system : UncertainSystem or array_like
        The system, or (deprecated) its state matrix A.
    matrices : tuple
        Further positional arguments: none with a system; ``B, C, D, L[, H, E]``
        after a loose A (deprecated).
    legacy : dict
        Keywords other than the function's own: none with a system; ``H``,
        ``E`` and ``dt`` (float > 0 s, or True: discrete, unspecified) with
        loose matrices (deprecated).

    Returns
    -------
    (UncertainSystem, float or True)
        The system (dt 1.0 when the loose form gave ``dt=True``) and the
        result's sampling time (``system.dt``, or True).

    Raises
    ------
    InputError
        Matrices, ``H``, ``E`` or ``dt`` given together with a system.
    TypeError
        An unknown keyword, or too many positional arguments (as Python
        reports a wrong call).
    """
    if isinstance(system, UncertainSystem) and matrices:
        raise InputError(f"{func}: give the UncertainSystem alone; {len(matrices)} more positional "
                         "argument(s) were given (the loose matrices go into the UncertainSystem)")
    unknown = sorted(set(legacy) - {"H", "E", "dt"})
    if unknown:
        raise TypeError(f"{func}() got an unexpected keyword argument {unknown[0]!r}")
    if isinstance(system, UncertainSystem):
        if legacy:
            what = ", ".join(sorted(legacy))
            hint = (" (the sampling time is the system's: dataclasses.replace(system, dt=...))" if "dt" in legacy
                    else " (the uncertainty is the system's H and E)" if {"H", "E"} & set(legacy) else "")
            raise InputError(f"{func}: unexpected keyword argument(s) {what} with an UncertainSystem{hint}")
        return system, system.dt
    if len(matrices) > 6:
        raise TypeError(f"{func}() takes an UncertainSystem (or, deprecated, at most 7 matrices A … E); "
                        f"got {1 + len(matrices)} positional arguments")
    if len(matrices) < 4:
        raise InputError(f"{func}: system must be a hinfnav UncertainSystem; got {type(system).__name__}"
                         + (" with too few matrices for the deprecated form A, B, C, D, L[, H, E]" if matrices else ""))
    given = dict(zip(_LOOSE, (system, *matrices)))
    for key in ("H", "E"):
        if key in legacy:
            if key in given:
                raise TypeError(f"{func}() got multiple values for argument {key!r}")
            given[key] = legacy[key]
    dt = legacy.get("dt", True)
    dt_value = True if dt is True else as_positive("dt", dt)
    warnings.warn(
        f"{func}(A, B, C, D, L, H, E, dt=...) is deprecated and will be removed in hinfnav 0.3: pass the system as "
        f"one object, {func}(hinfnav.UncertainSystem(A, B, C, D, L, H, E, dt=T), ...)",
        DeprecationWarning, stacklevel=3)
    system = UncertainSystem(given["A"], given["B"], given["C"], given["D"], given["L"], given.get("H"),
                             given.get("E"), dt=1.0 if dt_value is True else dt_value)
    return system, dt_value
