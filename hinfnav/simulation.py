"""Truth simulation of the chaser and Monte Carlo runs of an estimator.

The truth follows the Hill model with the true orbital rate ω₀(1+δ),
discretized exactly (zero-order hold) unless Euler is asked for::

    x(k+1) = Φ(δ) x(k) + Γ(δ) u(k) + B w(k)
    y(k)   = C x(k) + D v(k)
    u(k)   = K x(k)   (orbit maneuver, (3))   or   0   (no maneuver)

w and v are unit-variance noise sequences from :mod:`hinfnav.noise`. The
feedback uses the true state (the paper's u = Kx), so the truth does not
depend on the estimator and one truth can feed several estimators.

Randomness: run ``r`` draws its noise from the ``r``-th child of
``numpy.random.default_rng(seed).spawn(runs)``, w first then v. The same
seed gives the same numbers, whatever the batch size.
"""

from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from .estimators import EstimateHistory, Estimator
from .exceptions import InputError
from .models import measurement_matrix
from .noise import NoiseModel, make_noise
from .scenario import Scenario
from .validation import as_choice, as_int_at_least, as_real

__all__ = ["Truth", "SimulationResult", "simulate_truth", "simulate", "run_estimator"]


@dataclass(frozen=True, eq=False)
class Truth:
    """Time histories of the true motion.

    Attributes
    ----------
    t : ndarray, shape (n_steps + 1,)
        Time, s.
    x : ndarray, shape (runs, n_steps + 1, 6)
        True relative state, m and m/s.
    u : ndarray, shape (runs, n_steps + 1, 3)
        Thrust applied over [t_k, t_k+1), N.
    y : ndarray, shape (runs, n_steps + 1, 3)
        Measured relative position, m.
    settings : dict
        maneuver, delta, noise, runs, seed, discretization.
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    y: np.ndarray
    settings: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Truth plus one estimator's output.

    Attributes
    ----------
    t : ndarray, shape (n_steps + 1,)
    x, xhat : ndarray, shape (runs, n_steps + 1, 6)
    u : ndarray, shape (runs, n_steps + 1, 3)
    y : ndarray, shape (runs, n_steps + 1, 3)
    P : ndarray, shape (runs, n_steps + 1, 6, 6), or None
    settings : dict
        The truth's settings plus ``filter``.
    """

    t: np.ndarray
    x: np.ndarray
    xhat: np.ndarray
    u: np.ndarray
    y: np.ndarray
    P: np.ndarray = None
    settings: dict = field(default_factory=dict)

    @property
    def error(self):
        """Estimation error ``x − x̂``, shape (runs, n_steps + 1, 6)."""
        return self.x - self.xhat

    @property
    def runs(self):
        """Number of Monte Carlo runs."""
        return self.x.shape[0]


def _child_rngs(seed, runs):
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer, np.random.SeedSequence, np.random.Generator)):
        raise InputError(f"seed must be a non-negative integer or a numpy.random.Generator; got {seed!r}")
    if isinstance(seed, (int, np.integer)) and seed < 0:
        raise InputError(f"seed must be a non-negative integer; got {seed}")
    return np.random.default_rng(seed).spawn(runs)


def _noise_settings(noise, measurement_noise):
    w_model = make_noise(noise)
    v_model = w_model if measurement_noise is None else make_noise(measurement_noise)
    return w_model, v_model


def simulate_truth(
    scenario=None,
    *,
    maneuver=True,
    delta=0.0,
    noise="gaussian",
    measurement_noise=None,
    runs=1,
    seed=0,
    discretization="exact",
    first_run=0,
):
    """Simulate the true relative motion and the measurements.

    Parameters
    ----------
    scenario : Scenario, optional
        Defaults to the paper's.
    maneuver : bool
        True: u = K x (3). False: u = 0 (free Hill motion).
    delta : float
        True orbital-rate error δ of (4), > −1; not bound by δ̄.
    noise : str or NoiseModel
        Process noise w (and measurement noise v unless ``measurement_noise``
        is given); a name from :data:`hinfnav.noise.NOISE_NAMES`.
    measurement_noise : str or NoiseModel, optional
    runs : int
        Number of Monte Carlo runs, ≥ 1.
    seed : int or numpy.random.Generator
    discretization : {"exact", "euler"}
    first_run : int
        Index of the first run among the seed's children (used to simulate
        a batch of a larger Monte Carlo run).

    Returns
    -------
    Truth
    """
    scenario = Scenario() if scenario is None else scenario
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav.Scenario; got {type(scenario).__name__}")
    runs = as_int_at_least("runs", runs, 1)
    first_run = as_int_at_least("first_run", first_run, 0)
    delta = as_real("delta", delta)
    as_choice("discretization", discretization, ("exact", "euler"))
    if not isinstance(maneuver, (bool, np.bool_)):
        raise InputError(f"maneuver must be True or False; got {maneuver!r}")
    w_model, v_model = _noise_settings(noise, measurement_noise)
    Phi, Gamma = scenario.truth_matrices(delta, discretization)
    K = scenario.K if maneuver else np.zeros_like(scenario.K)
    Acl = Phi + Gamma @ K
    B, D, C = scenario.B, scenario.D, measurement_matrix()
    n1 = scenario.n_steps + 1
    rngs = _child_rngs(seed, first_run + runs)[first_run:]
    w = np.empty((runs, n1, B.shape[1]))
    v = np.empty((runs, n1, D.shape[1]))
    for r, rng in enumerate(rngs):
        w[r] = w_model.sample(rng, (n1, B.shape[1]))
        v[r] = v_model.sample(rng, (n1, D.shape[1]))
    x = np.empty((runs, n1, 6))
    x[:, 0] = scenario.x0
    drive = w @ B.T
    AclT = Acl.T
    for k in range(n1 - 1):
        x[:, k + 1] = x[:, k] @ AclT + drive[:, k]
    u = x @ K.T
    y = x @ C.T + v @ D.T
    settings = {
        "maneuver": bool(maneuver),
        "delta": delta,
        "noise": w_model.name,
        "measurement_noise": v_model.name,
        "runs": runs,
        "seed": seed if isinstance(seed, (int, np.integer)) else repr(seed),
        "discretization": discretization,
    }
    return Truth(t=scenario.time, x=x, u=u, y=y, settings=settings)


def run_estimator(estimator, truth, xhat0, *, progress=False, desc=None):
    """Run an estimator on a simulated truth.

    Vectorized estimators get all runs at once; the others run by run, with
    a progress bar when ``progress`` is true.

    Returns
    -------
    SimulationResult
    """
    if not isinstance(estimator, Estimator):
        raise InputError(f"estimator must be a hinfnav Estimator; got {type(estimator).__name__}")
    runs = truth.x.shape[0]
    if estimator.vectorized:
        hist = estimator.estimate(truth.y, truth.u, xhat0)
        xhat, P = hist.xhat, hist.P
    else:
        xhat = np.empty_like(truth.x)
        P = None
        for r in tqdm(range(runs), disable=not progress or runs == 1, desc=desc or estimator.name, unit="run", leave=False):
            hist = estimator.estimate(truth.y[r : r + 1], truth.u[r : r + 1], xhat0)
            xhat[r] = hist.xhat[0]
            if hist.P is not None:
                if P is None:
                    P = np.empty((runs,) + hist.P.shape[1:])
                P[r] = hist.P[0]
    if not isinstance(hist, EstimateHistory) or xhat.shape != truth.x.shape:
        raise InputError(f"estimator {estimator.name!r} returned estimates of shape {np.shape(xhat)}; expected {truth.x.shape}")
    settings = dict(truth.settings, filter=estimator.name)
    return SimulationResult(t=truth.t, x=truth.x, xhat=xhat, u=truth.u, y=truth.y, P=P, settings=settings)


def _concat_covariances(Ps, runs):
    """Join per-batch covariance histories; keep a shared (data-independent) one as a view.

    Filters whose covariance does not depend on the data (the EKF with the linear
    position measurement) return it broadcast over the runs (stride 0); copying
    it per run would cost ~290 MB per 100 runs of 10 001 samples.
    """
    if Ps[0] is None:
        return None
    shared = all(P.strides[0] == 0 for P in Ps) and all(np.array_equal(P[0], Ps[0][0]) for P in Ps[1:])
    if shared:
        return np.broadcast_to(Ps[0][0], (runs,) + Ps[0].shape[1:])
    return np.concatenate(Ps)


def simulate(
    scenario=None,
    estimator=None,
    *,
    maneuver=True,
    delta=0.0,
    noise="gaussian",
    measurement_noise=None,
    runs=1,
    seed=0,
    discretization="exact",
    batch_size=100,
    progress=False,
):
    """Simulate the truth and run an estimator on it, over Monte Carlo runs.

    Parameters
    ----------
    scenario : Scenario, optional
        Defaults to the paper's.
    estimator : Estimator or str
        An estimator, or a name understood by
        :func:`hinfnav.filters.make_estimator` (``"published"``, ...).
    maneuver, delta, noise, measurement_noise, runs, seed, discretization
        As in :func:`simulate_truth`.
    batch_size : int
        Runs simulated together (memory: about 1 MB per run at the paper's
        10 001 samples); the numbers do not depend on it.
    progress : bool
        Show a tqdm progress bar over the runs.

    Returns
    -------
    SimulationResult
        Histories of all runs.
    """
    from .filters import make_estimator  # local: filters imports this module's users

    scenario = Scenario() if scenario is None else scenario
    if estimator is None:
        raise InputError("estimator must be given (an Estimator or a filter name such as 'published')")
    if isinstance(estimator, str):
        estimator = make_estimator(estimator, scenario)
    runs = as_int_at_least("runs", runs, 1)
    batch_size = as_int_at_least("batch_size", batch_size, 1)
    if isinstance(seed, np.random.Generator):
        # one draw fixes the whole Monte Carlo run, so batches agree
        seed = int(seed.integers(2**63))
    parts = []
    with tqdm(total=runs, disable=not progress, desc=f"{estimator.name}", unit="run") as bar:
        for start in range(0, runs, batch_size):
            n = min(batch_size, runs - start)
            truth = simulate_truth(
                scenario,
                maneuver=maneuver,
                delta=delta,
                noise=noise,
                measurement_noise=measurement_noise,
                runs=n,
                seed=seed,
                discretization=discretization,
                first_run=start,
            )
            parts.append(run_estimator(estimator, truth, scenario.xhat0))
            bar.update(n)
    if len(parts) == 1:
        res = parts[0]
        res.settings["runs"] = runs
        return res
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
    P = _concat_covariances([p.P for p in parts], runs)
    settings = dict(parts[0].settings, runs=runs)
    return SimulationResult(t=parts[0].t, x=cat("x"), xhat=cat("xhat"), u=cat("u"), y=cat("y"), P=P, settings=settings)
