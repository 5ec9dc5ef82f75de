"""What is estimated: labels, units and groups of a state vector, and its error.

A :class:`StateSpec` is what metrics and plots read instead of slicing
``[:3]``/``[3:]``: the name and unit of each component, named groups of
components (``"position"``, ``"velocity"``, ...), and the definition of the
estimation error (additive here; an attitude state overrides :meth:`error`
with a multiplicative quaternion error).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError

__all__ = ["StateSpec", "chaser_state_spec"]


@dataclass(frozen=True, eq=False)
class StateSpec:
    """Labels, units and groups of a state vector.

    Attributes
    ----------
    labels : tuple of str
        One name per component, e.g. ``("x", "y", "z", "vx", "vy", "vz")``.
    units : tuple of str
        One unit per component, e.g. ``("m", "m", "m", "m/s", "m/s", "m/s")``.
    groups : dict
        Group name → tuple of component indices; every group has one unit.
    axis_names : dict, optional
        Group name → tuple of short names of its components (``("x", "y",
        "z")``), for plot labels; defaults to the component labels.
    """

    labels: tuple
    units: tuple
    groups: dict = field(default_factory=dict)
    axis_names: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("labels", "units"):
            if isinstance(getattr(self, name), str) or not hasattr(getattr(self, name), "__iter__"):
                raise InputError(f"{name} must be a sequence of strings, one per state component; got {getattr(self, name)!r}")
        if not hasattr(self.groups, "items"):
            raise InputError(f"groups must be a dict name -> component indices; got {self.groups!r}")
        if not hasattr(self.axis_names, "get"):
            raise InputError(f"axis_names must be a dict group -> axis names; got {self.axis_names!r}")
        labels, units = tuple(str(s) for s in self.labels), tuple(str(s) for s in self.units)
        if len(labels) != len(units) or not labels:
            raise InputError(f"labels and units must have the same, non-zero length; got {len(labels)} and {len(units)}")
        groups = {}
        for name, idx in dict(self.groups).items():
            try:
                idx = tuple(int(i) for i in idx)
            except (TypeError, ValueError):
                raise InputError(f"group {name!r} must list component indices (integers); got {idx!r}") from None
            if not idx or min(idx) < 0 or max(idx) >= len(labels):
                raise InputError(f"group {name!r} must list component indices in 0..{len(labels) - 1}; got {idx}")
            if len({units[i] for i in idx}) != 1:
                raise InputError(f"group {name!r} mixes units {sorted({units[i] for i in idx})}")
            groups[str(name)] = idx
        axis = {g: tuple(self.axis_names.get(g, tuple(labels[i] for i in idx))) for g, idx in groups.items()}
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "groups", groups)
        object.__setattr__(self, "axis_names", axis)

    @property
    def n(self) -> int:
        """Dimension of the state."""
        return len(self.labels)

    def group_unit(self, group: str) -> str:
        """Unit of a group's components."""
        return self.units[self.indices(group)[0]]

    def indices(self, group: str) -> Sequence[int]:
        """Component indices of a group (an :class:`InputError` names the known groups)."""
        try:
            return self.groups[group]
        except KeyError:
            raise InputError(f"unknown state group {group!r}; this state has {', '.join(self.groups) or 'none'}") from None

    def select(self, values: ArrayLike, group: str) -> NDArray[np.float64]:
        """The components of ``values`` (last axis = state) that belong to ``group``."""
        return np.asarray(values)[..., list(self.indices(group))]

    def error(self, x: ArrayLike, xhat: ArrayLike) -> NDArray[np.float64]:
        """Estimation error ``x − x̂`` (additive), same shape as the inputs."""
        return np.asarray(x) - np.asarray(xhat)


def chaser_state_spec() -> StateSpec:
    """Relative position and velocity in the target's orbital frame (Hill): 6 components."""
    return StateSpec(
        labels=("x", "y", "z", "vx", "vy", "vz"),
        units=("m", "m", "m", "m/s", "m/s", "m/s"),
        groups={"position": (0, 1, 2), "velocity": (3, 4, 5)},
        axis_names={"position": ("x", "y", "z"), "velocity": ("x", "y", "z")},
    )
