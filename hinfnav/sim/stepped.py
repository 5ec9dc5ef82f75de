"""The one stepped closed loop: plant, estimator(s), controller and passive observers advanced together.

:func:`run_stepped` owns the per-step loop of every closed loop of the
package (the engine's :func:`~hinfnav.sim.engine.closed_loop_batch`, and any
loop a paper builds from its own hooks). For k = 0 … n1 − 1, all rows (runs,
or runs of several variants) at once::

    if k is where the noise drawn so far ends:  plant.draw(k)              (noise-draw hook)
    prior timing:      u_k = control(x̂⁻_k)  and the reading contains u_k
    y_k  = plant.measure(k, x_k, u_read)      u_read: u_{k−1} (zeros at k = 0), or u_k with prior timing
    x̂_k  = estimator.update(k, y_k, u_read)
    posterior timing:  u_k = control(x̂_k)   (or control(x_k) for a law whose ``source`` is "truth")
    record x_k, u_k, x̂_k;  plant.record(k, x_k, u_k)
    observer.observe(k, y_k, u_read, u_k) for each passive observer (fed the readings, not acting)
    k < n1 − 1:  estimator.predict(k, u_k);  x_{k+1} = plant.step(k, x_k, u_k)

The hooks are objects the caller passes:

* the *plant* (:class:`SteppedPlant`): ``rows``, ``n1``, ``n_input``,
  ``start()`` → x_0 (rows, n), ``draw(k)`` → the first step the noise it has
  now drawn does not cover (the default, for noise given as whole histories
  drawn by :func:`~hinfnav.sim.truth.draw_noise`: ``n1``; a plant may draw per
  run in blocks instead), ``measure``, ``step`` and ``record`` (its own
  histories: the readings, the drive…);
* the *estimator stage*: ``start(rows)``, ``update(k, y, u_read)`` → x̂_k
  (rows, n_est), ``predict(k, u)``, ``prior()`` → x̂⁻_k (prior timing only) and
  ``n_state`` (:class:`EstimatorStage` runs one :class:`~hinfnav.estimators.Estimator`);
* the *controller*: a callable ``u = law(z)``, or a stateful law with
  ``start(rows)`` → its state and ``step(k, z, state)`` → ``(u, state)``;
  ``z`` is x̂ (or x when the law's ``source`` is ``"truth"``);
* *observers* with ``observe(k, y, u_read, u)``.

The driver adds a handful of Python calls per step to what the hooks compute,
and passes the hooks' arrays on unchanged (no copy, no reshaping), so a loop
written with hooks gives the numbers of the same operations written inline.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from tqdm import tqdm

from ..core.exceptions import InputError
from ..estimators.base import history_keys, store_diagnostics
from ..io.progress import bar_disabled

__all__ = ["SteppedHistory", "SteppedPlant", "ModelPlant", "EstimatorStage", "run_stepped"]


@dataclass(frozen=True, eq=False)
class SteppedHistory:
    """What :func:`run_stepped` records: state, applied input and estimate at each step.

    Attributes
    ----------
    x : ndarray, shape (rows, n1, n)
    u : ndarray, shape (rows, n1, n_input)
    xhat : ndarray, shape (rows, n1, n_est)
    """

    x: np.ndarray
    u: np.ndarray
    xhat: np.ndarray


class SteppedPlant:
    """The plant hooks of :func:`run_stepped` (a base: ``start``, ``measure`` and ``step`` are the subclass's).

    Attributes
    ----------
    rows, n1, n_input : int
        Rows stepped together, steps (samples) and inputs.
    """

    rows: int
    n1: int
    n_input: int

    def start(self) -> np.ndarray:
        """The initial state x_0, shape (rows, n)."""
        raise NotImplementedError

    def draw(self, k: int) -> int:
        """Draw the noise from step ``k`` on; return the first step it does not cover.

        Default: the noise was given whole (histories of
        :func:`~hinfnav.sim.truth.draw_noise`), nothing to draw.
        """
        return self.n1

    def measure(self, k: int, x: np.ndarray, u_read: np.ndarray) -> np.ndarray:
        """The reading y_k of the state ``x`` (rows, n), which may contain the input ``u_read`` (and its noise)."""
        raise NotImplementedError

    def record(self, k: int, x: np.ndarray, u: np.ndarray) -> None:
        """Keep what the plant records at step ``k`` beyond x, u and x̂ (nothing by default)."""

    def step(self, k: int, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """x_{k+1} from x_k and the input u_k held over [t_k, t_{k+1}) (and the noise of step k)."""
        raise NotImplementedError


class ModelPlant(SteppedPlant):
    """A :class:`~hinfnav.sim.truth.TruthModel`'s plant driven by noise histories ``w`` (rows, n1, p), ``v`` (rows, n1, q).

    The plant moves by its system's ``step(x, u, w, t)`` when it has one
    (nonlinear dynamics), else by ``propagate(x, u, w)``; the readings are kept
    in ``y`` (rows, n1, n_meas).
    """

    def __init__(self, model: Any, w: np.ndarray, v: np.ndarray, x0: np.ndarray | None = None) -> None:
        self.model, self.w, self.v = model, w, v
        self.x0 = model.x0 if x0 is None else np.asarray(x0, dtype=float)  # (n,) or one per row (rows, n)
        self.system, self.meas = model.system, model.measurement
        self.rows, self.n1 = w.shape[:2]
        self.n_input = self.system.n_input
        self.t = model.time
        self.y = np.empty((self.rows, self.n1, self.meas.n_meas))
        step = getattr(self.system, "step", None)
        self._step = step if callable(step) else None

    def start(self) -> np.ndarray:
        x = np.empty((self.rows, self.system.n))
        x[:] = self.x0
        return x

    def measure(self, k: int, x: np.ndarray, u_read: np.ndarray) -> np.ndarray:
        self.y[:, k] = self.meas.measure(x, self.v[:, k])
        return self.y[:, k]

    def step(self, k: int, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if self._step is not None:
            return self._step(x, u, self.w[:, k], self.t[k])
        return self.system.propagate(x, u, self.w[:, k])


class EstimatorStage:
    """One :class:`~hinfnav.estimators.Estimator` as the estimator stage of :func:`run_stepped`.

    Parameters
    ----------
    estimator : Estimator
    xhat0 : ndarray, shape (n,)
        Initial (prior) estimate.
    P0 : array_like, optional
    keep_covariance : bool or "diagonal"
        Keep the covariance reported at each step in ``P`` (rows, n1, n, n) or its diagonal (rows, n1, n).
    diagnostics : bool or sequence of str
        Keep the estimator's diagnostics in ``diagnostics`` (name → (rows, n1, …)).
    n1 : int
        Steps, for the histories.
    """

    def __init__(self, estimator: Any, xhat0: np.ndarray, P0: Any = None, *, keep_covariance: bool | str = False,
                 diagnostics: bool | Sequence[str] = False, n1: int) -> None:
        self.estimator, self.xhat0, self.P0 = estimator, xhat0, P0
        self.keep_covariance, self.keys, self.n1 = keep_covariance, history_keys(keep_covariance, diagnostics), n1
        self.n_state = int(np.shape(xhat0)[-1])
        self.P, self.diagnostics = None, {}

    def start(self, rows: int) -> None:
        self.rows = rows
        self.state = self.estimator.start(self.xhat0, self.P0, rows)

    def update(self, k: int, y: np.ndarray, u_read: np.ndarray) -> np.ndarray:
        self.state, out = self.estimator.update(self.state, y)
        kc = self.keep_covariance
        if kc and out.P is not None:
            P = np.diagonal(out.P, axis1=-2, axis2=-1) if kc == "diagonal" else out.P
            if self.P is None:
                self.P = np.empty((self.rows, self.n1) + P.shape[-(1 if kc == "diagonal" else 2):])
            self.P[:, k] = P
        store_diagnostics(self.diagnostics, out.diagnostics, self.keys, k, self.rows, self.n1)
        return out.xhat

    def prior(self) -> np.ndarray:
        return self.state.x

    def predict(self, k: int, u: np.ndarray) -> None:
        self.state = self.estimator.predict(self.state, u)


def run_stepped(plant: SteppedPlant, estimator: Any, controller: Any, *, observers: Sequence[Any] = (),
                prior: bool = False, progress: bool = False, desc: str = "closed loop") -> SteppedHistory:
    """Step a closed loop through its hooks (the order of the module docstring).

    Parameters
    ----------
    plant : SteppedPlant
        ``rows``, ``n1``, ``n_input``, ``start``, ``draw``, ``measure``, ``record``, ``step``.
    estimator : estimator stage
        ``n_state``, ``start(rows)``, ``update(k, y, u_read)`` → x̂_k, ``predict(k, u)``, ``prior()``.
    controller : callable or stateful law
        ``u = controller(z)``, or ``start(rows)`` / ``step(k, z, state)`` → ``(u, state)``;
        ``z`` = x̂_k, or x_k when ``controller.source == "truth"``; u of shape (rows, n_input).
    observers : sequence
        Passive observers: ``observe(k, y, u_read, u)`` after the record (they do not act on the loop).
    prior : bool
        Prior timing: u_k from the prior estimate x̂⁻_k, before the reading, which then contains u_k.
    progress : bool
    desc : str
        Label of the progress bar.

    Returns
    -------
    SteppedHistory
    """
    rows, n1, n_in = int(plant.rows), int(plant.n1), int(plant.n_input)
    stateful = callable(getattr(controller, "start", None)) and callable(getattr(controller, "step", None))
    if not stateful and not callable(controller):
        raise InputError(f"controller must be a callable law or have start/step; got {type(controller).__name__}")
    on_truth = getattr(controller, "source", "estimate") == "truth"
    x = plant.start()
    estimator.start(rows)
    cs = controller.start(rows) if stateful else None
    x_h = np.empty((rows, n1) + x.shape[1:])
    u_h = np.empty((rows, n1, n_in))
    xhat_h = np.empty((rows, n1, int(estimator.n_state)))
    observers = tuple(observers)
    u_read = np.zeros((rows, n_in))  # the input held before t_0
    drawn, last = 0, n1 - 1
    for k in tqdm(range(n1), disable=bar_disabled(progress), desc=desc, unit="step", mininterval=1.0, leave=False):
        if k == drawn:
            drawn = plant.draw(k)
        if prior:
            z = x if on_truth else estimator.prior()
            u, cs = controller.step(k, z, cs) if stateful else (controller(z), None)
            u_read = u
        y = plant.measure(k, x, u_read)
        xhat = estimator.update(k, y, u_read)
        if not prior:
            z = x if on_truth else xhat
            u, cs = controller.step(k, z, cs) if stateful else (controller(z), None)
        if k == 0 and np.shape(u) != (rows, n_in):
            raise InputError(f"controller must return inputs of shape ({rows}, {n_in}); got {np.shape(u)}")
        x_h[:, k], u_h[:, k], xhat_h[:, k] = x, u, xhat
        plant.record(k, x, u)
        for obs in observers:
            obs.observe(k, y, u_read, u)
        if k < last:
            estimator.predict(k, u)
            x = plant.step(k, x, u)
        u_read = u
    return SteppedHistory(x=x_h, u=u_h, xhat=xhat_h)
