"""A χ² innovation gate for every filter of the Kalman core, that reports what it rejects and cannot lock out.

A gate tests each reading before the correction, on the innovation
``ν = y − h(x̂⁻)`` and its covariance ``S = H P⁻ Hᵀ + R`` (the missing channels
removed first):

* ``per="reading"``: the whole reading is rejected when the Mahalanobis distance
  ``d² = νᵀ S⁻¹ ν`` exceeds ``χ²_{m'}(probability)`` (m' the channels it has);
* ``per="channel"``: channel j is rejected when ``ν_j² / S_jj > χ²_1(probability)``
  (the others are kept).

A rejected channel is removed from the update exactly as a missing one is
(:func:`~hinfnav.estimators.correction.drop_missing`): the correction then uses
the channels kept, and a reading with none left leaves the prior as the estimate.

**Recovery** (so that a run of rejections cannot lock the filter out). Rejecting
every reading is what a filter whose prior has drifted away from the truth does
for good: its P stops growing fast enough to admit the readings again. A run
whose last ``after`` readings were all rejected entirely (every channel it had)
recovers at the next reading:

* ``recovery="inflate"`` (default): the prior covariance is multiplied by
  ``inflation`` before the test, at that reading and every further one while the
  rejections go on (P grows geometrically, ``inflation^j``, on top of its own
  prediction), so the gate widens until the reading passes; the inflated P is the
  one the correction uses, so the filter re-converges on the readings it accepts;
* ``recovery="reacquire"``: the reading is accepted without a test (re-acquisition
  on the sensor) and the count starts again;
* ``recovery=None``: no recovery (a filter may lock out: for comparisons).

The count of consecutive rejected readings is carried in ``FilterState.extra``
(``gate_count``). Diagnostics at every step (leading dimension runs):
``gate_rejected`` (runs, m) bool — the channels rejected at this reading;
``gate_distance`` (runs,) — d² of the reading (its available channels, after any
inflation); ``gate_recovery`` (runs,) bool — recovery acted; ``gate_count`` (runs,)
— consecutive fully rejected readings after this one. :func:`gate_report` turns a
history's diagnostics into the count, the steps and the channels.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.stats import chi2

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_int_at_least, as_positive
from .correction import drop_missing

__all__ = ["ChiSquareGate", "GateOption", "gate_report", "gated"]

#: Recovery policies (see the module docstring).
RECOVERIES = ("inflate", "reacquire", None)


@dataclass(frozen=True)
class ChiSquareGate:
    """χ² innovation gate (see the module docstring).

    Parameters
    ----------
    probability : float
        The gate's probability: a reading consistent with the filter is rejected with
        probability ``1 − probability`` (in (0, 1); default 0.999).
    per : {"reading", "channel"}
    recovery : {"inflate", "reacquire", None}
    after : int
        Consecutive fully rejected readings before recovery acts (≥ 1).
    inflation : float
        Factor on P⁻ per recovering reading with ``recovery="inflate"`` (> 1).
    """

    probability: float = 0.999
    per: str = "reading"
    recovery: str | None = "inflate"
    after: int = 5
    inflation: float = 4.0

    def __post_init__(self):
        p = as_positive("probability", self.probability)
        if p >= 1.0:
            raise InputError(f"probability must be in (0, 1); got {self.probability!r}")
        as_choice("per", self.per, ("reading", "channel"))
        if self.recovery not in RECOVERIES:
            raise InputError(f"recovery must be one of 'inflate', 'reacquire' or None; got {self.recovery!r}")
        as_int_at_least("after", self.after, 1)
        if as_positive("inflation", self.inflation) <= 1.0:
            raise InputError(f"inflation must be > 1; got {self.inflation!r}")

    def threshold(self, dof: NDArray[np.int_]) -> NDArray[np.float64]:
        """``χ²_dof(probability)`` (inf where dof is 0: nothing to reject)."""
        dof = np.asarray(dof)
        return np.where(dof > 0, chi2.ppf(self.probability, np.maximum(dof, 1)), np.inf)

    def inflate(self, P: NDArray[np.float64], count: NDArray[np.int_] | None) -> NDArray[np.float64]:
        """The prior covariance of the runs recovering by inflation (``count ≥ after``) times :attr:`inflation`."""
        if self.recovery != "inflate" or count is None:
            return P
        recovering = np.asarray(count) >= self.after
        if not recovering.any():
            return P
        factor = np.where(recovering, self.inflation, 1.0)
        return np.broadcast_to(P, (factor.size,) + P.shape[-2:]) * factor[:, None, None]

    def decide(self, S: NDArray[np.float64], innovation: NDArray[np.float64], avail: NDArray[np.bool_],
               count: NDArray[np.int_] | None) -> tuple[NDArray[np.bool_], dict, NDArray[np.int_]]:
        """``(rejected, diagnostics, new count)`` of one reading per run.

        ``S`` (runs, m, m) and ``innovation`` (runs, m) with the missing channels already removed
        (innovation 0, unit diagonal in S), ``avail`` (runs, m) the channels the reading has.
        """
        runs, m = innovation.shape
        count = np.zeros(runs, dtype=int) if count is None else np.asarray(count)
        recovering = count >= self.after
        S = np.broadcast_to(S, (runs, m, m))
        d2 = np.einsum("ri,ri->r", innovation, np.linalg.solve(S, innovation[..., None])[..., 0])
        if self.per == "reading":
            rejected = avail & (d2 > self.threshold(avail.sum(axis=1)))[:, None]
        else:
            z2 = innovation**2 / np.diagonal(S, axis1=-2, axis2=-1)
            rejected = avail & (z2 > self.threshold(np.ones(m, dtype=int)))
        if self.recovery == "reacquire":
            rejected = rejected & ~recovering[:, None]
        has = avail.any(axis=1)
        lost = has & ~(avail & ~rejected).any(axis=1)  # every channel the reading had was rejected
        new_count = np.where(lost, count + 1, np.where(has, 0, count))
        diag = {"gate_rejected": rejected, "gate_distance": d2,
                "gate_recovery": recovering if self.recovery is not None else np.zeros(runs, dtype=bool),
                "gate_count": new_count}
        return rejected, diag, new_count

    def screen(self, P: NDArray[np.float64], H: NDArray[np.float64], R: NDArray[np.float64],
               innovation: NDArray[np.float64], mask: NDArray[np.bool_] | None,
               count: NDArray[np.int_] | None) -> tuple[NDArray[np.float64], NDArray[np.bool_] | None, dict, dict]:
        """Test one reading of every run of a Kalman-type filter; return ``(P⁻, mask, diagnostics, extra)``.

        ``P`` (runs, n, n) the prior (inflated on the recovering runs), ``mask`` the
        channels to use ((runs, m); None: all), the diagnostics of the module
        docstring and ``{"gate_count": …}`` to carry.
        """
        runs, m = innovation.shape
        avail = np.ones((runs, m), dtype=bool) if mask is None else np.asarray(mask, dtype=bool)
        P = self.inflate(P, count)
        Pg, Hg, Rg, nu = drop_missing(P, H, R, innovation, None if mask is None else avail)
        S = Hg @ Pg @ np.swapaxes(Hg, -1, -2) + Rg
        rejected, diag, new_count = self.decide(S, nu, avail, count)
        keep = avail & ~rejected
        new_mask = None if (mask is None and keep.all()) else keep
        return P, new_mask, diag, {"gate_count": new_count}


class GateOption:
    """Mixin: the ``gate`` option of a filter (a :class:`ChiSquareGate`, the dict of its parameters, or None)."""

    _gate = None

    @property
    def gate(self) -> ChiSquareGate | None:
        """The χ² innovation gate every reading passes before the correction (None: no gate).

        A :class:`~hinfnav.estimators.gate.ChiSquareGate`: rejected channels are removed from the
        update as missing ones are, its recovery policy keeps a run of rejections from locking the
        filter out, and each step reports ``gate_rejected`` … (see :mod:`hinfnav.estimators.gate`).
        A gated filter carries one covariance per run and runs on the NumPy path.
        """
        return self._gate

    @gate.setter
    def gate(self, value: ChiSquareGate | dict | None) -> None:
        if isinstance(value, dict):  # the gate's parameters (a campaign cell's options are JSON)
            value = ChiSquareGate(**value)
        if value is not None and not isinstance(value, ChiSquareGate):
            raise InputError(f"gate must be a hinfnav ChiSquareGate, the dict of its parameters or None; got "
                             f"{type(value).__name__}")
        self._gate = value


def gated(estimator: Any, gate: ChiSquareGate | None = None, **options: Any) -> Any:
    """A copy of a Kalman-core ``estimator`` with ``gate`` (default ``ChiSquareGate(**options)``)."""
    if not hasattr(type(estimator), "gate"):
        raise InputError(f"estimator {type(estimator).__name__} takes no gate (the Kalman core's filters and the "
                         "sigma-point filter do)")
    new = copy.copy(estimator)
    new.gate = ChiSquareGate(**options) if gate is None else gate
    return new


def gate_report(diagnostics: Mapping[str, Any], dt: float | None = None) -> dict[str, Any]:
    """What a gate rejected, from a history's diagnostics (``estimate(..., diagnostics=True)``).

    Returns
    -------
    dict
        ``rejected_channels`` (total channel readings rejected), ``rejected_readings``
        (readings with at least one channel rejected), ``per_run`` (runs,) counts of
        rejected readings, ``per_channel`` (m,) counts of rejected channel readings,
        ``steps`` the sorted step indices with a rejection in any run (``times`` in s
        with ``dt``), ``recoveries`` (readings at which recovery acted) and
        ``longest_run`` the longest stretch of consecutive fully rejected readings.
    """
    if "gate_rejected" not in diagnostics:
        raise InputError("diagnostics has no 'gate_rejected': run a gated filter with diagnostics=True")
    rej = np.asarray(diagnostics["gate_rejected"], dtype=bool)  # (runs, n_samples, m)
    any_rej = rej.any(axis=2)
    steps = np.flatnonzero(any_rej.any(axis=0))
    out = {"rejected_channels": int(rej.sum()), "rejected_readings": int(any_rej.sum()),
           "per_run": any_rej.sum(axis=1), "per_channel": rej.sum(axis=(0, 1)), "steps": steps,
           "recoveries": int(np.asarray(diagnostics.get("gate_recovery", np.zeros(1, bool))).sum()),
           "longest_run": int(np.asarray(diagnostics.get("gate_count", np.zeros(1, int))).max())}
    if dt is not None:
        out["times"] = steps * float(dt)
    return out
