"""Irregular time: systems discretised per step, time-stamped readings, several sensors fused, a CSV loader.

**The one way** (``estimate_timed``/``smooth_timed`` are in :mod:`hinfnav.estimators.timed`)::

    timed = TimedSystem.from_continuous(A, Qc, state)          # or TimedSystem(lambda dt: ConstantTurn(dt, ...))
    readings = read_timed_csv("log.csv", time="t")              # or TimedReadings(t, y), merge_readings(a, b)
    est = ExtendedKalmanFilter(timed.at(readings.nominal_dt), meas, P0=P0, missing="skip")
    hist = estimate_timed(est, timed, readings, xhat0)          # x̂ and P at every time stamp
    sm = smooth_timed(est, timed, readings, xhat0)              # RTS (or lag=L) on the same stamps

A step from t_k to t_{k+1} uses the system ``timed.at(t_{k+1} − t_k)``: for
``ẋ = A x + G u + w``, ``E[w(t) w(s)ᵀ] = Q_c δ(t − s)``, the exact
discretisation (Van Loan, IEEE TAC 23(3), 1978)

.. math::

    \\exp\\!\\left(\\begin{bmatrix} -A & Q_c \\\\ 0 & A^T \\end{bmatrix} Δt\\right)
    = \\begin{bmatrix} \\cdot & Φ^{-1} Q_d \\\\ 0 & Φ^T \\end{bmatrix},
    \\qquad Φ = e^{AΔt},\\quad Q_d = \\int_0^{Δt} e^{As} Q_c e^{A^Ts} ds      (T1)

and Γ from the zero-order hold (:func:`hinfnav.core.linalg.discretize`).
Any system class that takes its step as an argument is a ``TimedSystem``
through its constructor: the dynamics models of :mod:`hinfnav.systems.dynamics`
(``TimedSystem(lambda dt: ConstantTurn(dt, …))``, a
:class:`~hinfnav.systems.ContinuousDynamics` integrated over each step, a
:class:`~hinfnav.systems.DiscreteDynamics` whose map reads its ``dt``).

**Readings** carry their time stamps t_k (s, strictly increasing); a channel
not read at t_k is NaN (the filters' ``missing="skip"``). Several sensors at
their own rates are one :class:`TimedReadings` by :func:`merge_readings`: the
union of their stamps, their channels side by side, NaN where a sensor did not
read; the filter's measurement model is the stacked one (for linear sensors a
:class:`~hinfnav.systems.LinearMeasurement` with the C's stacked and R block
diagonal). A gap (e.g. 30 s without readings) is one long step, or several
prediction-only steps with :meth:`TimedReadings.with_max_step`.
"""

from __future__ import annotations

import csv
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import as_covariance, discretize
from ..core.validation import as_matrix, as_positive
from .linear import LinearSystem
from .state import StateSpec

__all__ = ["TimedSystem", "TimedReadings", "merge_readings", "read_timed_csv", "van_loan"]


def van_loan(A: ArrayLike, Qc: ArrayLike, dt: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(Φ, Q_d)`` of (T1) for a step of ``dt`` seconds (Van Loan's matrix exponential)."""
    A = as_matrix("A", A)
    n = A.shape[0]
    Qc = as_covariance("Qc", Qc, n, definite=False)
    dt = as_positive("dt", dt)
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -A * dt, Qc * dt, A.T * dt
    E = scipy.linalg.expm(M)
    Phi = E[n:, n:].T
    Qd = Phi @ E[:n, n:]
    return Phi, 0.5 * (Qd + Qd.T)


class TimedSystem:
    """A system discretised per step: ``at(dt)`` gives the system of a step of ``dt`` seconds (cached).

    Parameters
    ----------
    build : callable
        ``build(dt) -> system`` (a :class:`~hinfnav.systems.LinearSystem` or a
        dynamics model with ``n``, ``dt``, ``state``, ``Q``).
    name : str
    """

    def __init__(self, build: Callable[[float], Any], *, name: str = "timed system") -> None:
        if not callable(build):
            raise InputError(f"build must be a callable dt -> system; got {type(build).__name__}")
        self._build, self.name, self._cache = build, str(name), {}

    def at(self, dt: float) -> Any:
        """The system of one step of ``dt`` s (> 0)."""
        dt = as_positive("dt", dt)
        key = float(dt)
        if key not in self._cache:
            system = self._build(key)
            for attr in ("n", "dt", "state", "Q"):
                if not hasattr(system, attr):
                    raise InputError(f"build(dt) must return a hinfnav system (with n, dt, state, Q); got "
                                     f"{type(system).__name__}")
            if len(self._cache) > 100_000:
                self._cache.clear()
            self._cache[key] = system
        return self._cache[key]

    @classmethod
    def from_continuous(cls, A: ArrayLike, Qc: ArrayLike, state: StateSpec, G: ArrayLike | None = None, *,
                        name: str = "continuous linear system") -> TimedSystem:
        """``ẋ = A x + G u + w``, white w of spectral density ``Qc``, discretised exactly per step (T1).

        The step's LinearSystem has ``Phi``, ``Gamma`` (zero-order hold of G;
        one zero column without G), ``B`` with ``B Bᵀ = Q_d``, ``dt``.
        """
        A = as_matrix("A", A)
        n = A.shape[0]
        if A.shape != (n, n):
            raise InputError(f"A must be square; got shape {A.shape}")
        Qc = as_covariance("Qc", Qc, n, definite=False)
        G = np.zeros((n, 1)) if G is None else as_matrix("G", G, (n, None))
        no_input = not np.any(G)

        def build(dt):
            Phi, Qd = van_loan(A, Qc, dt)
            Gamma = np.zeros_like(G) if no_input else discretize(A, G, dt)[1]
            lam, V = np.linalg.eigh(Qd)
            B = V * np.sqrt(np.clip(lam, 0.0, None))
            return LinearSystem(Phi, Gamma, B, dt, state, name=f"{name} (dt = {dt:g} s)")

        return cls(build, name=name)


@dataclass(frozen=True, eq=False)
class TimedReadings:
    """Readings with their time stamps.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Time stamps, s, strictly increasing.
    y : ndarray, shape (runs, N, m)
        Readings (a (N, m) array is one run); NaN marks a channel not read at t_k.
    labels : tuple of str
        Channel names.
    """

    t: np.ndarray
    y: np.ndarray
    labels: tuple = ()

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1 or t.size < 1 or not np.all(np.isfinite(t)):
            raise InputError(f"t must be a 1-D array of finite time stamps (s); got shape {t.shape}")
        if np.any(np.diff(t) <= 0):
            k = int(np.flatnonzero(np.diff(t) <= 0)[0])
            raise InputError(f"t must be strictly increasing; t[{k + 1}] = {t[k + 1]:g} s follows t[{k}] = {t[k]:g} s "
                             "(merge readings at one time stamp into one row)")
        y = np.asarray(self.y, dtype=float)
        if y.ndim == 2:
            y = y[None]
        if y.ndim != 3 or y.shape[1] != t.size:
            raise InputError(f"y must have shape (runs, N, m) or (N, m) with N = {t.size} time stamps; got "
                             f"{np.shape(self.y)}")
        if np.any(np.isinf(y)):
            raise InputError("y must not contain inf (NaN marks a channel not read)")
        labels = tuple(self.labels) or tuple(f"y{i}" for i in range(y.shape[2]))
        if len(labels) != y.shape[2]:
            raise InputError(f"labels must name the {y.shape[2]} channels; got {len(labels)}")
        for key, value in (("t", t), ("y", y)):
            value.setflags(write=False)
            object.__setattr__(self, key, value)
        object.__setattr__(self, "labels", labels)

    @property
    def dt(self) -> NDArray[np.float64]:
        """The steps ``t_{k+1} − t_k``, s, shape (N − 1,)."""
        return np.diff(self.t)

    @property
    def nominal_dt(self) -> float:
        """The median step, s (1 s for a single stamp)."""
        return float(np.median(self.dt)) if self.t.size > 1 else 1.0

    @property
    def runs(self) -> int:
        return self.y.shape[0]

    def with_max_step(self, max_step: float) -> TimedReadings:
        """A copy with reading-free stamps inserted (all channels NaN) so that no step exceeds ``max_step`` s."""
        h = as_positive("max_step", max_step)
        times = [self.t[:1]]
        for a, b in zip(self.t[:-1], self.t[1:]):
            k = int(np.ceil((b - a) / h - 1e-9))
            times.append(a + (b - a) * np.arange(1, k + 1) / k)
        t = np.concatenate(times)
        idx = np.searchsorted(t, self.t)
        y = np.full((self.runs, t.size, self.y.shape[2]), np.nan)
        y[:, idx] = self.y
        return TimedReadings(t, y, self.labels)


def merge_readings(*readings: TimedReadings, tol: float = 0.0) -> TimedReadings:
    """Several sensors' readings as one record: the union of their stamps (those within ``tol`` s merged, at the
    earlier), their channels side by side, NaN where a sensor did not read. The runs must agree."""
    if not readings or not all(isinstance(r, TimedReadings) for r in readings):
        raise InputError("merge_readings takes TimedReadings")
    runs = {r.runs for r in readings}
    if len(runs) != 1:
        raise InputError(f"the readings to merge have different numbers of runs: {sorted(runs)}")
    t_all = np.unique(np.concatenate([r.t for r in readings]))
    if tol > 0:
        keep = np.concatenate([[True], np.diff(t_all) > tol])
        t_all = t_all[keep]
    y = np.full((runs.pop(), t_all.size, sum(r.y.shape[2] for r in readings)), np.nan)
    col = 0
    for r in readings:
        idx = np.searchsorted(t_all, r.t + (tol if tol > 0 else 0.0), side="right") - 1
        if np.any(np.abs(t_all[idx] - r.t) > tol) or np.unique(idx).size != idx.size:
            raise InputError("merge_readings: two stamps of one sensor fall on one merged stamp; reduce tol")
        y[:, idx, col:col + r.y.shape[2]] = r.y
        col += r.y.shape[2]
    return TimedReadings(t_all, y, sum((r.labels for r in readings), ()))


def read_timed_csv(path: str | Path, *, time: str = "t", columns: Sequence[str] | None = None,
                   epoch: str | None = None) -> TimedReadings:
    """Time-stamped readings from a CSV file with a header row.

    Parameters
    ----------
    path : str or Path
    time : str
        The time column: seconds (a number) or ISO 8601 date-times
        (``2010-07-27T00:00:10``), taken relative to ``epoch`` (default the first row).
    columns : sequence of str, optional
        The reading columns (default every other column). An empty cell (or
        ``nan``) is a channel not read at that time.
    epoch : str, optional
        ISO 8601 date-time of t = 0 for date-time stamps.

    Returns
    -------
    TimedReadings
        Rows sorted by time; rows with the same stamp must not repeat.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"path: no file {path}")
    with path.open(newline="") as fh:
        reader = csv.DictReader(fh)
        header = reader.fieldnames or []
        if time not in header:
            raise InputError(f"{path.name}: no time column {time!r}; the columns are {', '.join(header)}")
        cols = [c for c in header if c != time] if columns is None else list(columns)
        missing = [c for c in cols if c not in header]
        if missing:
            raise InputError(f"{path.name}: no column {missing[0]!r}; the columns are {', '.join(header)}")
        stamps, rows = [], []
        for i, row in enumerate(reader, start=2):
            stamps.append(row[time].strip())
            try:
                rows.append([float(row[c]) if row[c] not in (None, "") else np.nan for c in cols])
            except ValueError:
                raise InputError(f"{path.name} line {i}: a reading is not a number") from None
    if not stamps:
        raise InputError(f"{path.name}: no rows")
    try:
        t = np.array([float(s) for s in stamps])
    except ValueError:
        try:
            dt64 = np.array(stamps, dtype="datetime64[ns]")
        except ValueError:
            raise InputError(f"{path.name}: column {time!r} holds neither seconds nor ISO 8601 date-times") from None
        t0 = dt64.min() if epoch is None else np.datetime64(epoch, "ns")
        t = (dt64 - t0).astype("timedelta64[ns]").astype(float) * 1e-9
    order = np.argsort(t, kind="stable")
    return TimedReadings(t[order], np.asarray(rows, dtype=float)[order], tuple(cols))
