"""The base of every scenario: a frozen dataclass of settings with ``replace``, ``n_steps``, ``time`` and one RMS window.

A paper's scenario subclasses :class:`Scenario` as a frozen dataclass that
defines (as fields or properties) the sampling time ``dt`` (s) and the run
length ``duration_s`` (s); it inherits

* :meth:`Scenario.replace` — a validated copy; an unknown field is an
  :class:`~hinfnav.core.exceptions.InputError` naming it and the known ones;
* :attr:`Scenario.n_steps` — the number of sampling intervals
  ``N = round(duration_s / dt)``;
* :attr:`Scenario.time` — the sample times ``t_k = k dt``, ``k = 0 … N`` (s);
* :meth:`Scenario.checked_window` — the validation of the RMS window
  ``rms_window_s = (start, end)`` (s), ``0 ≤ start < end ≤ duration_s``, the one
  name every scenario gives the window of its RMS error statistic.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.exceptions import InputError

__all__ = ["Scenario"]


class Scenario:
    """Base of the scenarios (subclasses are frozen dataclasses defining ``dt`` and ``duration_s``, s)."""

    dt: float
    duration_s: float

    def replace(self, **changes: Any) -> Scenario:
        """A copy with some settings changed, validated again like a new scenario.

        Raises
        ------
        InputError
            A keyword that is not a field of this scenario (the message names it and lists the fields).
        """
        fields = [f.name for f in dataclasses.fields(self) if f.init]
        unknown = [k for k in changes if k not in fields]
        if unknown:
            raise InputError(f"{type(self).__name__}.replace: unknown field {unknown[0]!r}; the fields are "
                             f"{', '.join(fields)}")
        return dataclasses.replace(self, **changes)

    @property
    def n_steps(self) -> int:
        """Number of sampling intervals, ``round(duration_s / dt)``."""
        return int(round(self.duration_s / self.dt))

    @property
    def time(self) -> NDArray[np.float64]:
        """Sample times ``t_k = k dt``, shape (n_steps + 1,), s."""
        return np.arange(self.n_steps + 1) * self.dt

    def checked_window(self, name: str = "rms_window_s") -> tuple[float, float]:
        """The window field ``name`` as a pair of floats (start, end), s, checked against the run.

        Raises
        ------
        InputError
            Not a pair of numbers, or not ``0 <= start < end <= duration_s``.
        """
        value = getattr(self, name)
        try:
            start, end = (float(t) for t in value)
        except (TypeError, ValueError):
            raise InputError(f"{name} must be a pair (start, end) in seconds; got {value!r}") from None
        if not 0 <= start < end <= self.duration_s:
            raise InputError(f"{name} must satisfy 0 <= start < end <= duration_s = {self.duration_s}; "
                             f"got ({start}, {end})")
        return start, end
