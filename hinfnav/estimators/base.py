"""The estimator step contract, shared by every estimator of the workbook.

An estimator is built on a system (:class:`hinfnav.systems.LinearSystem` or
another object with ``n``, ``dt``, ``state`` …) and a measurement model
(:class:`hinfnav.systems.MeasurementModel`). It runs in two ways:

**Per step**, so that it can sit inside a control loop::

    state = est.start(xhat0, P0, runs=R)        # x̂(0|−1) = xhat0
    for k in range(n_samples):
        state, out = est.update(state, y[:, k])  # out.xhat: estimate at t_k
        u_k = controller(out.xhat)               # may use the estimate
        state = est.predict(state, u_k)          # to t_{k+1}

``update`` consumes the measurement y_k at t_k and returns the estimate the
filter reports at t_k (filtered x̂(k|k), or predicted x̂(k|k−1) for a
predictor such as the LTI filter (12)), its covariance if it carries one and
diagnostics (innovation, weights, fading factors …). ``predict`` takes the
input u_k held over [t_k, t_{k+1}) (ignored unless ``uses_input``).
:meth:`Estimator.step` does both.

**In batch** over (runs, n_samples) histories: :meth:`Estimator.estimate`
loops over the steps with all runs at once; a subclass may override it with a
faster path that gives the same numbers (tested by the contract suite).

The public ``start``/``update``/``predict`` trust nothing: they check the call
order (``FilterState.phase``), the shapes and finiteness of ``xhat0``, ``P0``,
y and u, and name the parameter and the step in an
:class:`~hinfnav.core.exceptions.InputError`; then they call the hooks
``_start``/``_update``/``_predict`` that each estimator implements. The batch
``estimate`` checks its arrays once and calls the hooks directly.
``missing="skip"`` (a constructor option of every filter, or the
:attr:`Estimator.missing` property) lets a NaN channel mark a missing reading.

Variants override one hook: the Huber filter the correction, a strong-tracking
filter the covariance prediction, an augmented filter the system it is built
on, a saturated-measurement filter the update when a channel is clipped.

**Filters of the Kalman core are composed, not subclassed** (:mod:`hinfnav.estimators.strategies`): a filter
of :class:`~hinfnav.estimators.kalman.KalmanCore` is its *moment rule* (:mod:`hinfnav.estimators.moments`:
linearised, or the sigma-point :class:`~hinfnav.estimators.sigma_point.SigmaPointRule`), which gives the
prediction and the moments of the predicted reading (ȳ, S, P_xy), plus *strategies* that act on those moments
whatever the rule: a correction (``"huber"``, ``"correntropy"``) and a prior fading (``"strong_tracking"``). The one scheme:
``build_estimator(scenario, name, correction=..., fading=...)`` composes strategies onto the registered filter
``name``, and :func:`~hinfnav.estimators.registry.register_composition` names a combination
(``huber_ukf`` = ``ukf`` + ``correction="huber"``; ``stukf`` = ``ukf`` + ``fading="strong_tracking"``). A
composed filter keeps its class (and its checks), runs on the NumPy path, and reports its strategies in
``est.strategies``. The named classes of the linearised rule (``HuberFilter``, ``StrongTrackingEKF`` …) remain
as configurations with compiled kernels; on the EKF a composition gives their numbers bitwise.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import FilterDivergedError, InputError, ModelFunctionError
from ..core.linalg import as_covariance
from ..core.validation import as_choice, as_int_at_least
from .compiled import run_compiled, select_backend
from .inputs import KNOWN_DIAGNOSTICS, READING_LIMIT, initial_estimates
from .inputs import check_reading_size as _check_reading_size

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["FilterState", "StepOutput", "EstimateHistory", "Estimator", "check_estimator_inputs", "fill_missing", "history_keys",
           "store_diagnostics", "READING_LIMIT", "KNOWN_DIAGNOSTICS", "available_channels", "initial_estimates"]

#: What an estimator does with a NaN channel of a reading: refuse it, or skip it (see :class:`Estimator`).
MISSING = ("refuse", "skip")
#: The values of :attr:`Estimator.nonfinite`.
NONFINITE_POLICIES = ("raise", "flag")


def available_channels(y):
    """Mask of the finite channels of a reading ``y`` (runs, m), or None when every channel is there."""
    ok = ~np.isnan(y)
    return None if ok.all() else ok


def fill_missing(measurement, y, x, yhat, mask):
    """A reading with its missing channels replaced by the predicted ones, and the mask to apply.

    ``yhat`` is the predicted output ``h(x̂⁻)``. A converted measurement (one with a ``sensor`` whose
    readings it converts, e.g. range and angles to a position) has no meaning with part of a reading:
    a run missing any channel misses the whole reading, which is replaced by the sensor's prediction.
    """
    if mask is None:
        return y, None
    sensor = getattr(measurement, "sensor", None)
    if sensor is None or not hasattr(measurement, "convert"):
        return np.where(mask, y, yhat), mask
    whole = np.broadcast_to(mask.all(axis=1, keepdims=True), mask.shape)
    return np.where(whole, y, sensor.function(x)), whole


@dataclass
class FilterState:
    """What an estimator carries from one step to the next (all runs at once).

    Attributes
    ----------
    x : ndarray, shape (runs, n_x)
        The estimator's internal state (the prior estimate before ``update``).
    P : ndarray, shape (runs, n, n) or (n, n) or None
        Covariance; a 2-D array is shared by every run (data-independent gains).
    k : int
        Index of the next measurement.
    extra : dict
        Anything else a filter keeps (last measurement, posterior, windows).
    phase : {"prior", "posterior"}
        "prior" after ``start``/``predict`` (the next call must be
        ``update``), "posterior" after ``update`` (the next must be ``predict``).
    """

    x: np.ndarray
    P: np.ndarray = None
    k: int = 0
    extra: dict = field(default_factory=dict)
    phase: str = "prior"

    @property
    def runs(self) -> int:
        return self.x.shape[0]


@dataclass(frozen=True, eq=False)
class StepOutput:
    """What ``update`` reports at t_k.

    Attributes
    ----------
    xhat : ndarray, shape (runs, n)
    P : ndarray, shape (runs, n, n) or (n, n) or None
    diagnostics : dict
        Name → array with leading dimension runs (``innovation`` …).
    """

    xhat: np.ndarray
    P: np.ndarray = None
    diagnostics: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class EstimateHistory:
    """Estimate histories of a batch of runs.

    Attributes
    ----------
    xhat : ndarray, shape (runs, n_samples, n)
        Estimate at each t_k.
    P : ndarray, shape (runs, n_samples, n, n), or None
        Covariance the filter believes in (None for filters without one).
    state : StateSpec or None
        Labels, units and groups of the estimated state.
    diagnostics : dict
        Name → array (runs, n_samples, ...), when asked for.
    """

    xhat: np.ndarray
    P: np.ndarray = None
    state: object = None
    diagnostics: dict = field(default_factory=dict)

    @property
    def labels(self) -> tuple[str, ...] | None:
        """State labels (from the system)."""
        return None if self.state is None else self.state.labels

    @property
    def units(self) -> tuple[str, ...] | None:
        """State units (from the system)."""
        return None if self.state is None else self.state.units


def history_keys(keep_covariance, diagnostics):
    """Check the history options of :meth:`Estimator.estimate`; the diagnostics to keep (None: all)."""
    if keep_covariance not in (True, False, "diagonal"):
        raise InputError(f"keep_covariance must be True, False or 'diagonal'; got {keep_covariance!r}")
    if diagnostics is True:
        return None
    if diagnostics is False or diagnostics is None:
        return set()
    if isinstance(diagnostics, str):
        return {diagnostics}
    try:
        return set(diagnostics)
    except TypeError:
        raise InputError(f"diagnostics must be True, False or names of diagnostics; got {diagnostics!r}") from None


def store_diagnostics(diag: dict[str, np.ndarray], step: Mapping[str, Any], keys: set[str] | None, k: int, runs: int,
                      n_samples: int) -> None:
    """Write the diagnostics ``step`` of step ``k`` into the histories ``diag`` (name -> (runs, n_samples, ...)), in place.

    Only the names in ``keys`` are kept (None: all, as :func:`history_keys` returns); a
    history is allocated at its first value, with that value's trailing shape and dtype.
    """
    for key, val in step.items():
        if keys is None or key in keys:
            val = np.asarray(val)
            if key not in diag:
                diag[key] = np.empty((runs, n_samples) + val.shape[1:], dtype=val.dtype)
            diag[key][:, k] = val


def check_estimator_inputs(y: ArrayLike, u: ArrayLike | None, xhat0: ArrayLike, n_state: int, n_meas: int | None = None,
                           n_input: int | None = None, missing: str = "refuse") -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64]]:
    """Validate the arguments of :meth:`Estimator.estimate`; return float arrays.

    With ``missing="skip"`` a NaN in y marks a missing channel (inf is still refused).
    """
    y = np.asarray(y, dtype=float)
    if y.ndim != 3:
        raise InputError(f"y must have shape (runs, n_samples, n_meas); got {y.shape}")
    if n_meas is not None and y.shape[2] != n_meas:
        raise InputError(f"y must have {n_meas} measurement channels; got {y.shape[2]}")
    if missing == "skip":
        if np.any(np.isinf(y)):
            raise InputError("y (the measurements) must not contain inf (NaN marks a missing channel with missing='skip')")
    elif not np.all(np.isfinite(y)):
        raise InputError("y (the measurements) must contain only finite numbers; it has NaN or inf entries "
                         "(a filter built with missing='skip' skips NaN channels)")
    _check_reading_size(y, "y (the measurements)")
    u = np.asarray(u, dtype=float)
    if u.ndim != 3 or u.shape[:2] != y.shape[:2]:
        raise InputError(f"u must have shape (runs, n_samples, n_input) matching y {y.shape[:2]}; got {u.shape}")
    if n_input is not None and u.shape[2] != n_input:
        raise InputError(f"u must have {n_input} input channels; got {u.shape[2]}")
    if not np.all(np.isfinite(u)):
        raise InputError("u (the inputs) must contain only finite numbers; it has NaN or inf entries")
    xhat0 = initial_estimates(xhat0, n_state, y.shape[0])
    return y, u, xhat0


class Estimator:
    """Base class of the estimators (see the module docstring).

    Parameters
    ----------
    system : LinearSystem (or compatible)
        Gives ``n``, ``n_input``, ``dt`` and ``state`` (labels, units, error).
    measurement : MeasurementModel
        Gives ``n_meas``, h, its Jacobian and R.
    name : str

    Attributes
    ----------
    uses_input : bool
        Whether ``predict`` uses the input u.
    vectorized : bool
        Whether one call of :meth:`estimate` processes all runs at once
        (True for every estimator on the step contract).
    """

    name = "estimator"
    uses_input = False
    vectorized = True
    #: the noise matrices checked whenever they are set again after construction (name → must be definite)
    checked_covariances = {"Q": False, "R": True, "P0": True}
    #: The non-finite policy (:meth:`_check_finite`): ``"raise"`` (default) raises :class:`FilterDivergedError` at
    #: the step where an estimate or covariance stops being finite; ``"flag"`` carries the NaN/inf on in the runs
    #: it reached, so that a Monte Carlo campaign counts those runs as diverged (``nonfinite_runs``, status
    #: ``"diverged"``) and keeps the others. Both backends behave the same (the compiled path hands a non-finite
    #: batch back to the NumPy loop, which applies the policy at its step).
    nonfinite = "raise"

    def __setattr__(self, name: str, value: Any) -> None:
        """Q, R and P0 set after construction are checked as the constructor checks them (issue 36).

        A new value must be a finite symmetric matrix of the size the filter was built with, positive
        semidefinite (Q) or definite (R, P0); a per-run or per-step stack (3-D) keeps its shape.
        """
        if name == "nonfinite" and value not in NONFINITE_POLICIES:
            raise InputError(f"{type(self).__name__}.nonfinite must be one of {', '.join(map(repr, NONFINITE_POLICIES))}; "
                             f"got {value!r}")
        old = self.__dict__.get(name) if name in self.checked_covariances else None
        if old is not None and value is not None:
            old_arr = np.asarray(old)
            if old_arr.ndim == 2:
                value = as_covariance(f"{type(self).__name__}.{name}", value, old_arr.shape[0],
                                      definite=self.checked_covariances[name])
            else:
                arr = np.asarray(value, dtype=float)
                if arr.shape != old_arr.shape or not np.isfinite(arr).all():
                    raise InputError(f"{type(self).__name__}.{name} must be a finite array of shape {old_arr.shape}; "
                                     f"got shape {arr.shape}")
        object.__setattr__(self, name, value)
    #: The compiled kernel a class declares in its own body (one of
    #: :data:`hinfnav.estimators.compiled.KERNELS`), None: the NumPy path only.
    compiled_kernel = None

    def __init__(self, system: LinearSystem | DynamicsModel, measurement: MeasurementModel, *, name: str | None = None,
                 missing: str = "refuse") -> None:
        for attr in ("n", "dt", "state"):
            if not hasattr(system, attr):
                raise InputError(f"system must be a hinfnav system (with n, dt, state); got {type(system).__name__}")
        if not hasattr(measurement, "n_meas"):
            raise InputError(f"measurement must be a hinfnav MeasurementModel; got {type(measurement).__name__}")
        if measurement.n_state != system.n:
            raise InputError(f"measurement acts on {measurement.n_state} states but the system has {system.n}")
        self.system = system
        self.measurement = measurement
        if name is not None:
            self.name = str(name)
        self.missing = missing

    @property
    def missing(self) -> str:
        """Policy for NaN channels of a reading: "refuse" (an InputError) or "skip" (see :meth:`update`)."""
        return self._missing

    @missing.setter
    def missing(self, value: str) -> None:
        self._missing = as_choice("missing", value, MISSING)

    # -- dimensions ---------------------------------------------------------

    @property
    def n_state(self) -> int:
        """Dimension of the estimated state."""
        return self.system.n

    @property
    def n_input(self) -> int:
        """Number of input channels the estimator accepts."""
        return getattr(self.system, "n_input", 0)

    @property
    def dt(self) -> float:
        """Sampling time, s."""
        return self.system.dt

    # -- the step contract: checked public calls ------------------------------

    def start(self, xhat0: ArrayLike, P0: ArrayLike | None = None, runs: int = 1) -> FilterState:
        """Initial filter state for ``runs`` runs, with prior estimate ``xhat0`` (shape (n,), or (runs, n): one per run).

        ``P0`` (a finite square matrix; its size is the filter's covariance
        dimension) overrides the filter's default. Raises InputError naming
        ``xhat0``, ``P0`` or ``runs``.
        """
        runs = as_int_at_least("runs", runs, 1)
        xhat0 = initial_estimates(xhat0, self.n_state, runs)
        if P0 is not None:
            P0 = np.asarray(P0, dtype=float)
            if P0.ndim != 2 or P0.shape[0] != P0.shape[1]:
                raise InputError(f"P0 must be a square matrix; got shape {P0.shape}")
            if not np.all(np.isfinite(P0)):
                raise InputError("P0 must contain only finite numbers; it has NaN or inf entries")
        if xhat0.ndim == 2:  # one prior per run: each row's internal state by the filter's own _start
            state = self._start(xhat0[0], P0, runs)
            state.x = np.concatenate([self._start(row, P0, 1).x for row in xhat0])
            return self._phase(state, None, "prior")
        return self._phase(self._start(xhat0, P0, runs), None, "prior")

    def update(self, state: FilterState, y: ArrayLike) -> tuple[FilterState, StepOutput]:
        """Consume y_k (shape (runs, n_meas)); return ``(state, StepOutput)``.

        Checks the call order (after ``start`` or ``predict``), the shape of
        y and its finiteness: with ``missing="skip"`` a NaN channel is not
        used at this step, a reading with every channel NaN skips the update.
        """
        self._check_order(state, "update", "prior")
        k, runs, m = state.k, state.x.shape[0], self.measurement.n_meas
        try:
            y = np.asarray(y, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"filter {self.name!r}: y at step {k} must be an array of real numbers") from None
        if y.shape != (runs, m):
            raise InputError(f"filter {self.name!r}: y at step {k} must have shape (runs, n_meas) = ({runs}, {m}); "
                             f"got {y.shape}")
        if self._missing == "skip":
            if np.isinf(y).any():
                raise InputError(f"filter {self.name!r}: y at step {k} has inf entries (NaN marks a missing channel)")
        elif not np.isfinite(y).all():
            raise InputError(f"filter {self.name!r}: y at step {k} must contain only finite numbers; it has NaN or "
                             "inf entries (build the filter with missing='skip' to skip NaN channels)")
        _check_reading_size(y, f"filter {self.name!r}: y at step {k}")
        try:
            new, out = self._update(state, y)
        except ModelFunctionError as exc:
            raise exc.at_step(k) from exc.__cause__
        self._check_finite(out, k)
        return self._phase(new, state, "posterior"), out

    def predict(self, state: FilterState, u: ArrayLike | None = None) -> FilterState:
        """Propagate to t_{k+1} with the input u_k (shape (runs, n_input)); return the state.

        Checks the call order (after ``update``) and u: required when the
        filter ``uses_input``; when given, of shape (runs, ·) and finite.
        """
        self._check_order(state, "predict", "posterior")
        u = self._check_step_input(state, u, "predict")
        try:
            new = self._predict(state, u)
        except ModelFunctionError as exc:
            raise exc.at_step(state.k) from exc.__cause__
        return self._phase(new, state, "prior")

    def step(self, state: FilterState, y: ArrayLike, u: ArrayLike | None = None) -> tuple[FilterState, StepOutput]:
        """``update`` with y_k, then ``predict`` with u_k; returns ``(state, StepOutput)``."""
        state, out = self.update(state, y)
        return self.predict(state, u), out

    def _check_order(self, state, call, phase):
        if not isinstance(state, FilterState):
            raise InputError(f"filter {self.name!r}: {call} needs the FilterState returned by start (call order: "
                             f"start, then update and predict alternately); got {type(state).__name__}")
        if state.phase != phase:
            wanted = "update" if state.phase == "prior" else "predict"
            raise InputError(f"filter {self.name!r}: wrong call order at step {state.k}: {call} after "
                             f"{'update' if state.phase == 'posterior' else 'start or predict'}; call {wanted} first "
                             "(order: start, then update and predict alternately)")

    def _check_step_input(self, state, u, call):
        """u of a step: None (allowed unless the filter uses it) or a finite (runs, n_input) array."""
        k, runs = state.k, state.x.shape[0]
        if u is None:
            if self.uses_input:
                raise InputError(f"filter {self.name!r} uses the applied input: {call} at step {k} needs u")
            return None
        try:
            u = np.asarray(u, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"filter {self.name!r}: u at step {k} must be an array of real numbers") from None
        n_in = self.n_input if self.uses_input else None
        if u.ndim != 2 or u.shape[0] != runs or (n_in is not None and u.shape[1] != n_in):
            want = f"({runs}, {n_in})" if n_in is not None else f"({runs}, n_input)"
            raise InputError(f"filter {self.name!r}: u at step {k} must have shape {want}; got {u.shape}")
        if not np.isfinite(u).all():
            raise InputError(f"filter {self.name!r}: u at step {k} must contain only finite numbers; it has NaN or "
                             "inf entries")
        return u

    def _check_feed_input(self, state, u):
        """The input a reading contains (``feed_input`` of a filter whose readings hold ``D u``): checked as
        ``predict`` checks u, between ``start``/``predict`` and ``update``."""
        self._check_order(state, "feed_input", "prior")
        return self._check_step_input(state, u, "feed_input")

    # -- unchecked steps: for inner loops that check their arrays once (as ``estimate`` does) ---------

    def update_unchecked(self, state: FilterState, y: NDArray[np.float64]) -> tuple[FilterState, StepOutput]:
        """:meth:`update` without its checks, for an inner loop that checked its readings once.

        ``y`` must be a finite float (runs, n_meas) array (NaN channels only with ``missing="skip"``);
        nothing is checked and the call order is not tracked (the returned state's ``phase`` is not
        maintained: keep calling the unchecked methods on it). The numbers are bitwise those of
        :meth:`update`.
        """
        return self._update(state, y)

    def predict_unchecked(self, state: FilterState, u: NDArray[np.float64] | None) -> FilterState:
        """:meth:`predict` without its checks: ``u`` a finite float (runs, n_input) array, or None when the
        filter does not use its input (see :meth:`update_unchecked`)."""
        return self._predict(state, u)

    def _check_finite(self, out, k):
        """The non-finite policy (:attr:`nonfinite`): by default an estimate or covariance with NaN or inf raises
        :class:`FilterDivergedError`; with ``nonfinite = "flag"`` it is carried on.

        Every path does this at the step where it happens (the compiled one by handing a non-finite batch back
        to this loop), so the NumPy and numba backends refuse the same inputs. A skipped reading leaves the
        prior, which is finite; NaN marks nothing else in an estimate.
        """
        if self.nonfinite == "flag":
            return
        if not np.isfinite(out.xhat).all() or (out.P is not None and not np.isfinite(out.P).all()):
            what = "estimate" if not np.isfinite(out.xhat).all() else "covariance"
            raise FilterDivergedError(f"filter {self.name!r} diverged at step {k}: its {what} is not finite (NaN or "
                                      "inf; readings or a model too large for double precision, or an unstable "
                                      "filter)")

    @staticmethod
    def _phase(new, old, phase):
        """``new`` marked with ``phase`` (a copy when a hook handed back the state it was given)."""
        if new is old:
            new = FilterState(x=new.x, P=new.P, k=new.k, extra=dict(new.extra))
        new.phase = phase
        return new

    # -- the step contract: hooks of the subclasses (inputs already checked) ---

    def _start(self, xhat0, P0, runs):
        """Initial filter state (``xhat0`` a finite (n,) vector, ``P0`` None or a finite square matrix)."""
        raise NotImplementedError

    def _update(self, state, y):
        """Consume a checked y_k (runs, n_meas); return ``(state, StepOutput)``."""
        raise NotImplementedError

    def _predict(self, state, u):
        """Propagate with a checked u_k (runs, n_input) or None; return the state."""
        raise NotImplementedError

    # -- batch --------------------------------------------------------------

    def estimate(self, y: ArrayLike, u: ArrayLike | None, xhat0: ArrayLike, P0: ArrayLike | None = None, *,
                 keep_covariance: bool | str = True, diagnostics: bool | Iterable[str] = False,
                 backend: str | None = None) -> EstimateHistory:
        """Estimate the state histories of a batch of runs.

        Parameters
        ----------
        y : array_like, shape (runs, n_samples, n_meas)
            Measurements y(k) at t_k.
        u : array_like, shape (runs, n_samples, n_input)
            Inputs applied over [t_k, t_{k+1}).
        xhat0 : array_like, shape (n,) or (runs, n)
            Prior estimate of x(0), one for every run or one per run (the
            NumPy path: a compiled kernel takes one).
        P0 : array_like, shape (n, n), optional
            Initial covariance (filters that carry one; their default otherwise).
        keep_covariance : bool or "diagonal"
            Return the covariance history (True), its diagonal only (the
            variances, shape (runs, n_samples, n): a long run's economy), or
            none (False).
        diagnostics : bool or iterable of str
            Return the diagnostics histories: all (True), none (False), or
            those named.
        backend : {"auto", "numpy", "numba"}, optional
            The kernel where one exists (the default, unless the environment
            variable ``HINFNAV_BACKEND`` says otherwise), the NumPy step loop
            (the reference), or a compiled kernel (an InputError if none
            fits); see :mod:`hinfnav.estimators.compiled` and its
            :func:`~hinfnav.estimators.compiled.why_numpy`.

        Returns
        -------
        EstimateHistory
        """
        keys = history_keys(keep_covariance, diagnostics)
        y, u, xhat0 = check_estimator_inputs(y, u, xhat0, self.n_state, self.measurement.n_meas,
                                             self.n_input if self.uses_input else None, self.missing)
        if getattr(self, "gate", None) is not None and backend != "numpy":  # a gate runs on the NumPy path only
            if backend == "numba":
                raise InputError(f"backend='numba' is not available for filter {self.name!r}: its gate runs on the "
                                 "NumPy path only; use backend='numpy' or 'auto'")
            backend = "numpy"
        if xhat0.ndim == 2:  # one prior per run: the NumPy step loop
            if backend == "numba":
                raise InputError("backend='numba' takes one xhat0 (n,) for every run; use backend='numpy' (or "
                                 "'auto') with one initial estimate per run")
        elif select_backend(self, backend, keys) == "numba":
            xhat, P_hist, diag = run_compiled(self, y, u, xhat0, P0, keep_covariance, keys)
            if xhat is not None and np.isfinite(xhat).all() and (P_hist is None or np.isfinite(P_hist).all()):
                # else a factorisation failed or a number is not finite: the NumPy path raises at its step
                return EstimateHistory(xhat=xhat, P=P_hist, state=self.system.state, diagnostics=diag)
        core = 1 if keep_covariance == "diagonal" else 2
        runs, n1, _ = y.shape
        state = self.start(xhat0, P0, runs)  # checked once; the loop calls the hooks
        xhat = np.empty((runs, n1, self.n_state))
        P_hist, shared, diag = None, False, {}
        produced = set()
        k = 0
        try:
            for k in range(n1):
                state, out = self._update(state, y[:, k])
                self._check_finite(out, k)
                xhat[:, k] = out.xhat
                if keep_covariance and out.P is not None:
                    P = np.diagonal(out.P, axis1=-2, axis2=-1) if core == 1 else out.P
                    if P_hist is None:
                        # a covariance shared by every run (one array, or broadcast with stride 0) is stored once
                        shared = P.ndim == core or P.strides[0] == 0
                        P_hist = np.empty(((n1,) if shared else (runs, n1)) + P.shape[P.ndim - core:])
                    if shared and not (P.ndim == core or P.strides[0] == 0):
                        # a skipped channel in some runs only: the covariance becomes per run from here on
                        P_hist, shared = np.broadcast_to(P_hist, (runs,) + P_hist.shape).copy(), False
                    if shared:
                        P_hist[k] = P if P.ndim == core else P[0]
                    else:
                        P_hist[:, k] = P
                store_diagnostics(diag, out.diagnostics, keys, k, runs, n1)
                if keys:
                    produced.update(out.diagnostics)
                if k < n1 - 1:
                    state = self._predict(state, u[:, k])
        except ModelFunctionError as exc:
            raise exc.at_step(k) from exc.__cause__
        unknown = keys - produced - set(KNOWN_DIAGNOSTICS) if keys else set()
        if unknown:  # a name asked for that this filter never reports: refused, not ignored
            raise InputError(f"unknown diagnostic {', '.join(map(repr, sorted(unknown)))} for filter "
                             f"{self.name!r}; it reports: {', '.join(sorted(produced)) or 'none'}")
        if shared:
            P_hist.setflags(write=False)
            P_hist = np.broadcast_to(P_hist, (runs,) + P_hist.shape)
        return EstimateHistory(xhat=xhat, P=P_hist, state=self.system.state, diagnostics=diag)

    def __repr__(self):
        return f"<{type(self).__name__} {self.name!r} uses_input={self.uses_input}>"
