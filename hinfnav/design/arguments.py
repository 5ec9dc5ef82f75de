"""The system argument of the synthesis functions.

:func:`~hinfnav.design.synthesize`, :func:`~hinfnav.design.synthesize_mixed`
and :func:`~hinfnav.design.mixed_front` take the uncertain system ψ_d (9)–(11)
as one :class:`~hinfnav.systems.UncertainSystem`, whose sampling time is the
design's.
"""

from __future__ import annotations

from typing import Any

from ..core.exceptions import InputError
from ..systems.uncertain import UncertainSystem

__all__ = ["system_argument"]


def system_argument(func: str, system: Any) -> tuple[UncertainSystem, float]:
    """The system a synthesis designs for, and the sampling time of its result (``system.dt``, s).

    Raises
    ------
    InputError
        ``system`` is not an :class:`~hinfnav.systems.UncertainSystem` (the
        matrices ``A, B, C, D, L, H, E`` go into one:
        ``UncertainSystem(A, B, C, D, L, H, E, dt=T)``).
    """
    if not isinstance(system, UncertainSystem):
        raise InputError(f"{func}: system must be a hinfnav UncertainSystem (UncertainSystem(A, B, C, D, L, H, E, "
                         f"dt=T)); got {type(system).__name__}")
    return system, system.dt
