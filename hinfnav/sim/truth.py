"""Open-loop truth: a system driven by noise, an optional feedback on the true state, measured.

::

    x(k+1) = Φ x(k) + Γ u(k) + B w(k),    u(k) = K x(k) (or none)       (a LinearSystem)
    x(k+1) = step(x(k), u(k), w(k), t_k), u(k) = controller(x(k)) (or 0) (a nonlinear system)
    y(k)   = h(x(k)) + D v(k)

w and v are unit-variance noise sequences from :mod:`hinfnav.noise`. A
feedback on the *true* state does not depend on any estimator, so one truth
can feed several estimators.

Randomness: run ``r`` draws its noise from the ``r``-th child of
``numpy.random.default_rng(seed).spawn(runs)``, w first then v, whole
histories at once. The same seed gives the same numbers, whatever the batch
size.

**Dispersed initial states.** A :class:`TruthModel` with ``x0_covariance``
P₀ draws each run's initial state ``x_r(0) = x₀ + L z_r``, ``L Lᵀ = P₀``,
``z_r ~ N(0, I)``, from its own stream (:func:`dispersion_rngs`: the r-th
child of a SeedSequence tagged apart from the noise streams), so that the
noise of a run is the same with or without dispersion and the draws do not
depend on the batch size or the workers. With ``x₀`` the filters' x̂₀ and
P₀ their initial covariance, the initial error is N(0, P₀) as the filters
assume, and the NEES of the first steps is a consistency measure too. Without
``x0_covariance`` every run starts at the same x₀ (the papers' printed
initial states).
"""

from __future__ import annotations

import inspect
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..core.exceptions import InputError
from ..core.linalg import as_covariance
from ..core.protocols import ScenarioProtocol
from ..core.validation import as_int_at_least, as_vector
from ..noise import ColoredNoise, make_noise

if TYPE_CHECKING:
    from ..noise import NoiseModel


__all__ = ["TruthModel", "Truth", "child_rngs", "dispersion_rngs", "noise_models", "draw_noise", "simulate_truth", "scenario_truth_model"]


@dataclass(frozen=True, eq=False)
class TruthModel:
    """Everything that defines a truth simulation (what a scenario hands to :mod:`hinfnav.sim`).

    Attributes
    ----------
    system : LinearSystem
        The true dynamics (Φ, Γ, B, dt, state spec).
    measurement : MeasurementModel
        What is measured.
    x0 : ndarray, shape (n,)
        Initial true state.
    n_steps : int
        Number of sampling intervals (histories have n_steps + 1 samples).
    controller : LinearFeedback or None
        Feedback on the true state (None: zero input).
    settings : dict
        The scenario's conditions, normalized (recorded in results).
    x0_covariance : ndarray, shape (n, n), or None
        P₀ of dispersed initial states: each run starts at x₀ + L z_r
        (module docstring); None: every run at x₀.
    """

    system: object
    measurement: object
    x0: np.ndarray
    n_steps: int
    controller: object = None
    settings: dict = field(default_factory=dict)
    x0_covariance: np.ndarray = None

    def __post_init__(self):
        if not all(hasattr(self.system, a) for a in ("n", "dt")):
            raise InputError(f"system must be a hinfnav system such as LinearSystem; got {type(self.system).__name__}")
        if not all(hasattr(self.measurement, a) for a in ("n_state", "n_meas", "measure")):
            raise InputError(f"measurement must be a hinfnav MeasurementModel; got {type(self.measurement).__name__}")
        object.__setattr__(self, "x0", as_vector("x0", self.x0, self.system.n))
        object.__setattr__(self, "n_steps", as_int_at_least("n_steps", self.n_steps, 1))
        if self.measurement.n_state != self.system.n:
            raise InputError(f"the measurement acts on {self.measurement.n_state} states, the system has {self.system.n}")
        if self.x0_covariance is not None:
            spec = getattr(self.system, "state", None)
            if spec is not None and getattr(spec, "n", self.system.n) != self.system.n:
                raise InputError("x0_covariance: this system's state has its own error coordinates (a quaternion); "
                                 "dispersed initial states are drawn for additive states only")
            P0 = as_covariance("x0_covariance", self.x0_covariance, self.system.n, definite=False)
            P0.setflags(write=False)
            object.__setattr__(self, "x0_covariance", P0)

    def initial_states(self, seed: int | np.random.SeedSequence | np.random.Generator, runs: int,
                       first_run: int = 0) -> NDArray[np.float64]:
        """Initial true states of runs ``first_run …`` (runs, n): x₀ each, or x₀ + L z_r when dispersed."""
        runs = as_int_at_least("runs", runs, 1)
        if self.x0_covariance is None:
            return np.broadcast_to(self.x0, (runs, self.x0.size)).copy()
        lam, V = np.linalg.eigh(self.x0_covariance)
        L = V * np.sqrt(np.clip(lam, 0.0, None))  # L Lᵀ = P₀ (semidefinite allowed)
        z = np.stack([rng.standard_normal(self.x0.size) for rng in dispersion_rngs(seed, runs, first_run)])
        return self.x0 + z @ L.T

    @property
    def time(self) -> NDArray[np.float64]:
        """Sample times ``t_k = k dt``, s."""
        return np.arange(self.n_steps + 1) * self.system.dt


@dataclass(frozen=True, eq=False)
class Truth:
    """Time histories of the true motion.

    Attributes
    ----------
    t : ndarray, shape (n_samples,)
        Time, s.
    x : ndarray, shape (runs, n_samples, n)
        True state.
    u : ndarray, shape (runs, n_samples, m_u)
        Input applied over [t_k, t_k+1).
    y : ndarray, shape (runs, n_samples, m)
        Measurements.
    settings : dict
    state : StateSpec
    measurement : MeasurementModel
        What produced ``y`` (estimators are checked against it).
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    y: np.ndarray
    settings: dict = field(default_factory=dict)
    state: object = None
    measurement: object = None


def scenario_truth_model(scenario: Any, conditions: dict[str, Any]) -> TruthModel:
    """``scenario.truth_model(**conditions)``, after checking that ``scenario`` is one
    (:class:`~hinfnav.core.protocols.ScenarioProtocol`) and knows every condition.

    Raises :class:`InputError` naming an unknown condition (e.g. a misspelt
    ``maneuvre=``) and the ones the scenario takes, instead of a TypeError.
    """
    if not isinstance(scenario, ScenarioProtocol):
        raise InputError(f"scenario must offer truth_model(**conditions) and xhat0 (hinfnav.ScenarioProtocol; such as a "
                         f"paper's Scenario, hinfnav.papers.<key>.Scenario); got {type(scenario).__name__}")
    build = scenario.truth_model
    try:
        params = inspect.signature(build).parameters.values()
    except (TypeError, ValueError):  # pragma: no cover - builtins without a signature
        params = None
    if params is not None and not any(p.kind is p.VAR_KEYWORD for p in params):
        names = [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
        unknown = sorted(set(conditions) - set(names))
        if unknown:
            raise InputError(f"unknown condition {', '.join(map(repr, unknown))} for {type(scenario).__name__}; "
                             f"its conditions are: {', '.join(names) or 'none'}")
    return build(**conditions)


def child_rngs(seed: int | np.random.SeedSequence | np.random.Generator, runs: int, first: int = 0) -> list[np.random.Generator]:
    """The independent generators of runs ``first … first + runs − 1`` from ``seed`` (an int ≥ 0, a SeedSequence
    or a Generator).

    Run r's generator is the r-th child of ``numpy.random.default_rng(seed)``
    (``Generator.spawn``); from an int or a SeedSequence it is built directly
    (``SeedSequence(entropy, spawn_key=(…, r))``, what ``spawn`` builds), so that a
    batch of late runs neither builds the generators of the runs before it
    (time and memory that would grow with the runs) nor depends on what was
    spawned from the SeedSequence before. A Generator is spawned from (its children
    ``first …`` of this call).
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer, np.random.SeedSequence, np.random.Generator)):
        raise InputError(f"seed must be a non-negative integer or a numpy.random.Generator; got {seed!r}")
    if isinstance(seed, (int, np.integer)) and seed < 0:
        raise InputError(f"seed must be a non-negative integer; got {seed}")
    first = as_int_at_least("first", first, 0)
    if isinstance(seed, np.random.Generator):
        return seed.spawn(first + runs)[first:]
    parent = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(int(seed))
    return [np.random.Generator(np.random.PCG64(np.random.SeedSequence(
        parent.entropy, spawn_key=tuple(parent.spawn_key) + (r,), pool_size=parent.pool_size)))
        for r in range(first, first + runs)]


#: Spawn-key tag of the dispersion streams: run r's initial state is drawn from child (TAG, r) of the seed.
DISPERSION_TAG = 0x7FFFFFFF


def dispersion_rngs(seed: int | np.random.SeedSequence | np.random.Generator, runs: int,
                    first: int = 0) -> list[np.random.Generator]:
    """The generators of the initial-state draws of runs ``first …``: apart from the noise streams of :func:`child_rngs`.

    Run r's generator is built from ``SeedSequence(entropy, spawn_key=key + (DISPERSION_TAG, r))`` of the seed's
    SeedSequence (a Generator's own), so it neither consumes nor shifts the noise of any run.
    """
    if isinstance(seed, np.random.Generator):
        seq = seed.bit_generator.seed_seq
        if not isinstance(seq, np.random.SeedSequence):
            raise InputError("seed: a Generator without a SeedSequence cannot seed dispersed initial states; give an int")
    else:
        child_rngs(seed, 1)  # checks the seed
        seq = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(int(seed))
    tagged = np.random.SeedSequence(seq.entropy, spawn_key=tuple(seq.spawn_key) + (DISPERSION_TAG,),
                                    pool_size=seq.pool_size)
    return child_rngs(tagged, runs, first)


def _noise_at(noise, dt, name):
    """A noise model for a system sampled at ``dt``: colored noise is built at that T, or refused at another."""
    if isinstance(noise, str) and noise == "colored" and dt is not None:
        return make_noise("colored", dt=dt)
    model = make_noise(noise)
    if dt is not None and isinstance(model, ColoredNoise) and abs(model.dt - dt) > 1e-12 * dt:
        raise InputError(f"{name}: colored noise built for dt = {model.dt:g} s cannot drive a system sampled at "
                         f"dt = {dt:g} s (its correlation time would be wrong); use ColoredNoise(dt={dt:g}, ...)")
    return model


def noise_models(noise: str | NoiseModel, measurement_noise: str | NoiseModel | None = None,
                 dt: float | None = None) -> tuple[NoiseModel, NoiseModel]:
    """The process- and measurement-noise models (the second defaults to the first).

    With ``dt`` (the system's sampling time, s), colored noise given by name is
    built at that T, and a colored-noise model built for another T is refused.
    """
    w_model = _noise_at(noise, dt, "noise")
    v_model = w_model if measurement_noise is None else _noise_at(measurement_noise, dt, "measurement_noise")
    return w_model, v_model


def draw_noise(w_model: NoiseModel, v_model: NoiseModel, rngs: Sequence[np.random.Generator], n_samples: int,
               p: int, q: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """w (runs, n_samples, p) and v (runs, n_samples, q), each run from its own generator, w first."""
    runs = len(rngs)
    w = np.empty((runs, n_samples, p))
    v = np.empty((runs, n_samples, q))
    for r, rng in enumerate(rngs):
        w[r] = w_model.sample(rng, (n_samples, p))
        v[r] = v_model.sample(rng, (n_samples, q))
    return w, v


def simulate_truth(model: TruthModel, *, noise: str | NoiseModel = "gaussian", measurement_noise: str | NoiseModel | None = None,
                   runs: int = 1, seed: int | np.random.SeedSequence | np.random.Generator = 0, first_run: int = 0) -> Truth:
    """Simulate the true motion and the measurements of a :class:`TruthModel`.

    Parameters
    ----------
    model : TruthModel
    noise : str or NoiseModel
        Process noise w (and measurement noise v unless ``measurement_noise``
        is given); a name from :data:`hinfnav.noise.NOISE_NAMES`.
    measurement_noise : str or NoiseModel, optional
    runs : int
        Number of Monte Carlo runs, ≥ 1.
    seed : int or numpy.random.Generator
    first_run : int
        Index of the first run among the seed's children (to simulate one
        batch of a larger Monte Carlo set).

    Returns
    -------
    Truth
    """
    if not isinstance(model, TruthModel):
        raise InputError(f"model must be a hinfnav TruthModel; got {type(model).__name__}")
    runs = as_int_at_least("runs", runs, 1)
    first_run = as_int_at_least("first_run", first_run, 0)
    system, meas = model.system, model.measurement
    ctrl = model.controller
    if ctrl is not None and getattr(ctrl, "source", "truth") != "truth":
        raise InputError("simulate_truth takes feedback on the true state only; use simulate_closed_loop for u = K x̂")
    linear = callable(getattr(system, "transition_matrix", None)) and (ctrl is None or hasattr(ctrl, "K"))
    if not linear and not callable(getattr(system, "step", None)):
        raise InputError(f"model.system must be a LinearSystem or offer step(x, u, w, t); got {type(system).__name__}")
    w_model, v_model = noise_models(noise, measurement_noise, system.dt)
    n1 = model.n_steps + 1
    rngs = child_rngs(seed, runs, first_run)
    w, v = draw_noise(w_model, v_model, rngs, n1, system.n_noise, meas.n_noise)
    x = np.empty((runs, n1, system.n))
    x[:, 0] = model.initial_states(seed, runs, first_run)
    if linear:
        K = None if ctrl is None else ctrl.K
        AclT = system.transition_matrix(K).T
        drive = w @ system.B.T
        for k in range(n1 - 1):
            x[:, k + 1] = x[:, k] @ AclT + drive[:, k]
        u = x @ K.T if K is not None else np.zeros((runs, n1, system.n_input))
    else:  # x(k+1) = step(x(k), u(k), w(k), t_k), u(k) = controller(x(k)) (or 0)
        u = np.zeros((runs, n1, system.n_input))
        t = model.time
        for k in range(n1):
            if ctrl is not None:
                u[:, k] = ctrl(x[:, k])
            if k < n1 - 1:
                x[:, k + 1] = system.step(x[:, k], u[:, k], w[:, k], t[k])
    y = meas.measure(x, v)
    settings = dict(model.settings)
    settings.update(
        noise=w_model.name,
        measurement_noise=v_model.name,
        runs=runs,
        seed=seed if isinstance(seed, (int, np.integer)) else repr(seed),
    )
    return Truth(t=model.time, x=x, u=u, y=y, settings=settings, state=system.state, measurement=meas)
