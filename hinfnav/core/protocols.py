"""The written protocols: what the simulation, the campaigns and the filters look up on your objects.

A protocol (PEP 544, :class:`typing.Protocol`) names the members an object
must have; nothing needs to inherit from it. Each one here is
``@runtime_checkable``, so ``isinstance(obj, ScenarioProtocol)`` tells
whether ``obj`` has those members (their presence only: Python does not check
signatures or units; those are documented below, and the code that uses them
checks shapes and raises :class:`~hinfnav.core.exceptions.InputError`).

* :class:`ScenarioProtocol`: what :func:`hinfnav.sim.simulate` and a campaign cell
  read (each paper's ``Scenario`` and campaign scenario);
* :class:`OwnTruthScenario`, :class:`CampaignTruthScenario`: a scenario that makes its
  own truth (the Monte Carlo engine and a campaign cell call these before ``truth_model``);
* :class:`TruthModelProtocol`: what :func:`hinfnav.sim.simulate_truth` reads
  (:class:`hinfnav.sim.TruthModel`);
* :class:`DynamicsProtocol`, :class:`MeasurementProtocol`: the system and the sensor
  (``LinearSystem``, ``DynamicsModel``; ``MeasurementModel``);
* :class:`EstimatorHooks`: the hooks behind :class:`hinfnav.estimators.Estimator`'s checked
  ``start``/``update``/``predict`` and ``estimate``;
* :class:`DesignResultProtocol`: a certified filter design (``hinfnav.design.DesignResult``).

A scenario of your own needs only the two members of :class:`ScenarioProtocol`
(``truth_model(**conditions)`` returning a :class:`hinfnav.sim.TruthModel`,
and ``xhat0``); register its factory with
:func:`hinfnav.campaign.registry.register_scenario` to run it in a campaign.
The optional members (``P0``, ``offers``, ``kalman_model``,
``estimator_from_design``) are listed in :class:`ScenarioProtocol`'s notes;
the two optional truth hooks are protocols of their own
(:class:`OwnTruthScenario`, :class:`CampaignTruthScenario`) because the
engine dispatches on them.

This module imports only :mod:`typing` (and numpy for the annotations), so any
layer may use it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["ScenarioProtocol", "OwnTruthScenario", "CampaignTruthScenario", "TruthModelProtocol",
           "DynamicsProtocol", "MeasurementProtocol", "EstimatorHooks", "DesignResultProtocol"]


@runtime_checkable
class ScenarioProtocol(Protocol):
    """A scenario: the truth of a Monte Carlo run, and where the filters start.

    Attributes
    ----------
    xhat0 : ndarray, shape (n_stored,)
        The filters' initial estimate x̂(0|−1), in the units of the state spec
        of the truth model's system (e.g. m and m/s).

    Notes
    -----
    Optional members, looked up when present:

    ``P0`` : ndarray, shape (n, n)
        The filters' initial error covariance (units² of the state).
    ``offers`` : :class:`hinfnav.estimators.registry.Offers`
        What estimators built by name may rely on (the models, the error form).
    ``kalman_model()``
        The model the generic filters (``model_ekf``, ``model_ukf``, ``model_hbf``,
        ``model_stekf``) are built on: a dict with ``system``, ``measurement``,
        ``P0`` (state units²) and ``uses_input`` (with ``offers.models`` holding ``"kalman"``).
    ``estimator_from_design(design)``
        The estimator of a :class:`DesignResultProtocol` (the LTI filter (12)
        for Sun et al. 2011), so that :func:`hinfnav.sim.simulate` takes a design.
    """

    xhat0: NDArray[np.float64]

    def truth_model(self, **conditions: Any) -> TruthModelProtocol:
        """The truth model under ``conditions`` (keyword arguments; their names are the scenario's
        conditions, :func:`hinfnav.campaign.registry.condition_parameters`)."""
        ...


@runtime_checkable
class OwnTruthScenario(Protocol):
    """The optional hook of a scenario that simulates its own truth (a manoeuvre, a plant the generic
    simulation cannot make): the Monte Carlo engine calls it instead of ``truth_model``.

    A hook protocol: ``isinstance(s, OwnTruthScenario)`` checks this member alone (a scenario is
    one that also satisfies :class:`ScenarioProtocol`).
    """

    def simulate_truth(self, *, noise: Any = "gaussian", measurement_noise: Any = None, runs: int = 1,
                       seed: int | np.random.SeedSequence = 0, first_run: int = 0, **conditions: Any) -> Any:
        """The :class:`hinfnav.sim.truth.Truth` of runs ``first_run … first_run + runs − 1``.

        Run r must draw from the r-th child of ``numpy.random.default_rng(seed)``
        (:func:`hinfnav.sim.truth.child_rngs`), so that batches give the same numbers.
        """
        ...


@runtime_checkable
class CampaignTruthScenario(Protocol):
    """The optional hook of a campaign scenario whose truth takes the campaign's noise per channel or an
    impulse: a campaign cell and the Monte Carlo engine call it first (a hook protocol, as
    :class:`OwnTruthScenario`)."""

    def campaign_truth(self, conditions: Mapping[str, Any], noise: Any,
                       rngs: Sequence[np.random.Generator]) -> Any:
        """The :class:`hinfnav.sim.truth.Truth` of one run per generator of ``rngs`` (in order)."""
        ...


@runtime_checkable
class DynamicsProtocol(Protocol):
    """A discrete-time system, linear or not.

    Attributes
    ----------
    n : int
        State dimension.
    n_noise : int
        Number of unit-variance process-noise channels w.
    n_input : int
        Number of input channels u (0 without input).
    dt : float
        Sampling time, s.
    state : StateSpec
        Labels, units and the state error (``state.error(x, xhat)``).

    Notes
    -----
    The truth simulation uses ``transition_matrix(K)`` and ``B`` when the system
    has them (a :class:`hinfnav.systems.LinearSystem`: x(k+1) = Φ x + Γ u + B w),
    and otherwise ``step(x, u, w, t)``, with ``x`` (runs, n) and ``w`` (runs, n_noise).
    """

    n: int
    n_noise: int
    n_input: int
    dt: float
    state: Any


@runtime_checkable
class MeasurementProtocol(Protocol):
    """A measurement ``y = h(x) + D v`` (v unit-variance, D sets the units and levels).

    Attributes
    ----------
    n_state : int
        Dimension of the state it reads.
    n_meas : int
        Number of channels m.
    n_noise : int
        Number of unit-variance noise channels v.
    R : ndarray, shape (m, m)
        Noise covariance D Dᵀ, in the channels' units² (e.g. m² and rad²).
    """

    n_state: int
    n_meas: int
    n_noise: int
    R: NDArray[np.float64]

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        """h(x) for ``x`` (..., n): the noise-free reading (..., m)."""
        ...

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """∂h/∂x at ``x`` (..., n): shape (..., m, n)."""
        ...

    def residual(self, y: ArrayLike, yhat: ArrayLike) -> NDArray[np.float64]:
        """y − ŷ (an angle channel wrapped to (−π, π])."""
        ...

    def measure(self, x: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """The reading h(x) + D v of states ``x`` (..., n) with unit-variance noise ``v`` (..., n_noise)."""
        ...


@runtime_checkable
class TruthModelProtocol(Protocol):
    """Everything a truth simulation needs (what ``scenario.truth_model(**conditions)`` returns).

    Attributes
    ----------
    system : DynamicsProtocol
        The true dynamics.
    measurement : MeasurementProtocol
        What is measured (``measurement.n_state == system.n``).
    x0 : ndarray, shape (n,)
        Initial true state, in the state's units.
    n_steps : int
        Number of sampling intervals (histories have ``n_steps + 1`` samples, ``time`` s apart by ``dt``).
    controller : object or None
        Feedback on the true state (None: zero input).
    settings : dict
        The conditions, recorded in results.
    """

    system: Any
    measurement: Any
    x0: NDArray[np.float64]
    n_steps: int
    controller: Any
    settings: dict


@runtime_checkable
class EstimatorHooks(Protocol):
    """The step contract's hooks (:mod:`hinfnav.estimators.base`): what a new estimator implements.

    The public ``start``/``update``/``predict`` of
    :class:`hinfnav.estimators.Estimator` check the call order, shapes and
    finiteness, then call these with checked arrays; the batch ``estimate``
    calls them directly. A variant overrides one hook.

    Attributes
    ----------
    name : str
    uses_input : bool
        Whether ``_predict`` uses u.
    system : DynamicsProtocol
    measurement : MeasurementProtocol
    """

    name: str
    uses_input: bool
    system: Any
    measurement: Any

    def _start(self, xhat0: NDArray[np.float64], P0: NDArray[np.float64] | None, runs: int) -> Any:
        """The initial FilterState: ``xhat0`` a finite (n,) vector, ``P0`` None (the filter's default) or
        a finite square matrix (state units²), for ``runs`` runs."""
        ...

    def _update(self, state: Any, y: NDArray[np.float64]) -> tuple[Any, Any]:
        """Consume y_k, shape (runs, n_meas) (NaN channels when ``missing="skip"``); return
        ``(state, StepOutput)``: the estimate the filter reports at t_k, its covariance, diagnostics."""
        ...

    def _predict(self, state: Any, u: NDArray[np.float64] | None) -> Any:
        """Propagate to t_{k+1} with u_k, shape (runs, n_input), held over [t_k, t_{k+1}) (or None)."""
        ...


@runtime_checkable
class DesignResultProtocol(Protocol):
    """A certified filter design: the filter (12) ``x_f(k+1) = A_F x_f + B_F y``, ``z_f = C_F x_f``.

    Attributes
    ----------
    A_F : ndarray, shape (n_f, n_f)
    B_F : ndarray, shape (n_f, m)
    C_F : ndarray, shape (l, n_f)
    gamma : float
        Certified level of the error system's norm (units of z per unit of the noise).
    verified_norm : float
        Largest sampled norm of the error system (a lower bound of the worst case).
    dt : float or True
        Sampling time, s (True: discrete, unspecified).
    """

    A_F: NDArray[np.float64]
    B_F: NDArray[np.float64]
    C_F: NDArray[np.float64]
    gamma: float
    verified_norm: float
    dt: Any
