"""The closed loop of Section 3: plant, sensors, Algorithm 3, ADRC (or PID), actuators, vectorized over runs.

At each t_k (h = 0.1 s), with the default ``timing="posterior"``:

1. the sensors read ``Y_k = C_o X_o,k + d_k`` (5) and the accelerometers
   ``a_k = (K_trans r_k + D_trans ṙ_k)/m_tm + (F_Csc,k−1 + w_F,k−1 + F_Dsc(t_k))/m_sc + d_a,k``
   (11) just before the new command (the actuator still holds u_{k−1}),
   clipped to ±6e-6 m/s² (14);
2. Algorithm 3 updates with (Y_k, a_k), told the input u_{k−1} the reading contains;
3. the controller computes u_k from the filtered estimate X̂_k and the
   attitude command; u_k is clipped to ±ρ and held over [t_k, t_{k+1});
4. Algorithm 3 predicts with u_k, and the plant moves by the exact ZOH
   discretization of (4) with ``u_k + w_k + f(t_k)`` held.

With ``timing="prior"`` (13) is read literally — the accelerometer reading of
t_k contains the command u_k — so u_k is computed first, from the prior
estimate X̂⁻_k, and the compensation of the disturbance lags one step.

Alongside, without acting on the loop, the standalone estimators of Figs 5-7
run on the same readings: Algorithm 1 and Algorithm 2 in its three variants
L1 (truncated-normal update), L2 (ideal: fed the unclipped readings, never
clipped) and L3 (skips clipped readings), batched into one array. Their timing
is the fused filter's: the update is told the input the reading contains
(u_{k−1}, or u_k with ``timing="prior"``), the prediction the input the plant
moves with (u_k). (Before issue 22 L1/L2/L3 also predicted with u_{k−1}.)

Randomness: run r draws from the r-th child of ``numpy.random.default_rng(seed)``,
in blocks of ``BLOCK`` steps, w (9) then d (9) then d_a (3) per block: the same
seed gives the same numbers whatever the number of runs.

The steps themselves are the package's one stepped loop,
:func:`hinfnav.sim.stepped.run_stepped`; this module gives it the loop's hooks:
the plant with its sensors and the block noise draw (``_Plant``: (4), (5),
(11), (14)), Algorithm 3 per group of rows with equal readings
(``_FusedGroups``), the stacked ADRC law with the attitude command
(``_Law``: (44)-(46)) and the standalone estimators as a passive observer
(``_Passive``).
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ...core.exceptions import InputError
from ...control.adrc import DragFreeADRC
from ...core.validation import as_choice, as_int_at_least
from ...sim.stepped import SteppedPlant, run_stepped
from ...sim.truth import child_rngs
from .constants import ACCELEROMETER_RANGE, D_TRANS, K_TRANS, M_SC, M_TM
from .filters import build_alg1, build_alg2, build_fused
from .model import MEASURED_INDICES, disturbance
from .scenario import CONTROLLERS, check_scenario

__all__ = ["LoopResult", "run_closed_loop", "run_closed_loops", "residual_acceleration", "Alg2Bank", "BLOCK", "PASSIVE"]

#: Steps per block of noise drawn at once.
BLOCK = 10_000
#: The standalone estimators run alongside the loop (Figs 5-7).
PASSIVE = ("alg1", "L1", "L2", "L3")


@dataclass(frozen=True, eq=False)
class LoopResult:
    """Histories of one closed-loop simulation (SI units).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s.
    x : ndarray, shape (runs, n, 18)
        Plant state ``[φ_sc, φ̇_sc, r, ṙ, φ_rel, φ̇_rel]``.
    f : ndarray, shape (n, 9)
        True disturbances ``[T_Dsc, F_Dsc, T_Dtm]``.
    u : ndarray, shape (runs, n, 9)
        Applied (clipped) inputs.
    drive : ndarray, shape (runs, n, 9)
        What acts on the plant, ``u + w + f``.
    acc : ndarray, shape (runs, n, 3)
        Accelerometer readings before the range (14) is applied.
    xhat : ndarray, shape (runs, n, 27)
        Algorithm 3's filtered estimate.
    passive : dict
        ``alg1``, ``L1``, ``L2``, ``L3`` → filtered estimates of the drag-free
        block ``[r (3), ṙ (3), F_Dsc (3)]``, shape (runs, n_passive, 9).
    reference : ndarray, shape (n, 3)
        Attitude command, rad.
    settings : dict
    """

    t: np.ndarray
    x: np.ndarray
    f: np.ndarray
    u: np.ndarray
    drive: np.ndarray
    acc: np.ndarray
    xhat: np.ndarray
    passive: dict = field(default_factory=dict)
    reference: np.ndarray = None
    settings: dict = field(default_factory=dict)

    @property
    def runs(self):
        return self.x.shape[0]

    @property
    def acc_clipped(self):
        """The readings the filters receive, clipped to the range (14)."""
        return np.clip(self.acc, *ACCELEROMETER_RANGE)

    @property
    def saturated(self):
        """Which readings sat at a bound, (runs, n, 3)."""
        lo, up = ACCELEROMETER_RANGE
        return (self.acc <= lo) | (self.acc >= up)

    @property
    def w(self):
        """Input noise, (runs, n, 9)."""
        return self.drive - self.u - self.f

    def true_extended(self):
        """The true extended state (27) at each step, from x and f."""
        X = np.empty(self.x.shape[:2] + (27,))
        X[..., 0:6] = self.x[..., 0:6]
        X[..., 6:9] = self.f[:, 0:3]
        X[..., 9:15] = self.x[..., 6:12]
        X[..., 15:18] = self.f[:, 3:6]
        X[..., 18:24] = self.x[..., 12:18]
        X[..., 24:27] = self.f[:, 6:9]
        return X

    def dragfree_truth(self):
        """True ``[r, ṙ, F_Dsc]`` (runs, n, 9), the block the drag-free estimators report."""
        return np.concatenate([self.x[..., 6:12], np.broadcast_to(self.f[:, 3:6], self.x.shape[:2] + (3,))], axis=-1)


def residual_acceleration(result, reading="test_mass"):
    """The translational residual acceleration of Fig 12, m/s², shape (runs, n, 3).

    Parameters
    ----------
    result : LoopResult
    reading : {"test_mass", "relative", "accelerometer"}
        ``test_mass``: the non-conservative acceleration on the test mass, the
        coupling ``−(K_trans r + D_trans ṙ)/m_tm``; ``relative``: the true
        relative acceleration ``r̈`` of (2) (what the accelerometer senses,
        sign aside); ``accelerometer``: the unclipped reading, noise included.
    """
    as_choice("residual reading", reading, ("test_mass", "relative", "accelerometer"))
    r, v = result.x[..., 6:9], result.x[..., 9:12]
    coupling = -(r @ K_TRANS.T + v @ D_TRANS.T) / M_TM
    if reading == "test_mass":
        return coupling
    if reading == "accelerometer":
        return result.acc
    return coupling - result.drive[..., 3:6] / M_SC


class Alg2Bank:
    """L1, L2, L3 stacked as rows of one Algorithm 2 array (runs × 3 variants).

    Parameters
    ----------
    alg : SaturatedExtendedStateFilter
        The Algorithm 2 whose kernels are used (``build_alg2(scenario)``; another θ or prediction for
        :func:`hinfnav.papers.yang2020.studies.theta_readings_study`).
    runs : int
    """

    def __init__(self, alg, runs):
        self.alg = alg
        self.runs = runs
        self.X = np.zeros((3 * runs, 3, 3))
        self.P = np.broadcast_to(self.alg.P0, (3 * runs, 3, 3, 3)).copy()
        self.skip = np.repeat([False, False, True], runs)  # rows: L1 (runs), L2 (runs), L3 (runs)
        self.ideal = np.repeat([False, True, False], runs)

    def step(self, acc_raw, acc_clipped, u_read, u_next):
        """Update with the readings (runs, 3), which contain the input ``u_read`` (runs, 3), N; then predict
        over the hold of ``u_next`` (runs, 3), N, the input the plant moves with. Returns the filtered
        ``[r, ṙ, F_Dsc]`` of L1, L2, L3, shape (3, runs, 9)."""
        y = np.concatenate([acc_clipped, acc_raw, acc_clipped])
        sat = self.alg.flags(y) & ~self.ideal[:, None]
        X, P, _, _, _ = self.alg.kernel_update(self.X, self.P, y, np.concatenate([u_read] * 3), sat=sat,
                                               skip=self.skip)
        self.X, self.P = self.alg.kernel_predict(X, P, np.concatenate([u_next] * 3))
        return self.alg.to_full(X).reshape(3, self.runs, 9)


class _Plant(SteppedPlant):
    """The plant (4) and its sensors (5), (11), (14) on ``nv × runs`` rows: the plant hooks of the stepped loop.

    Noise: per run, blocks of :data:`BLOCK` steps, w (9) then d (9) then d_a (3), from the run's generator;
    the rows of every variant share their run's draws, scaled by their own standard deviations ``sd``.
    """

    def __init__(self, sc, nv, runs, rngs, sd, F, same_f):
        m = sc.model
        self.x0, self.nv, self.rngs, self.sd, self.F, self.same_f = sc.x0, nv, rngs, sd, F, same_f
        self.rows, self.n1, self.n_input = nv * runs, sc.n_steps + 1, 9
        self.prior = sc.timing == "prior"
        self.PhiT, self.GamT, self.CaT = m.Phi.T, m.Gamma.T, m.accel_C.T
        self.lo, self.up = ACCELEROMETER_RANGE
        self.drive = np.empty((self.rows, self.n1, 9))  # u + w + f
        self.acc = np.empty((self.rows, self.n1, 3))  # unclipped readings
        self.w_prev = np.zeros((self.rows, 9))  # input noise of the hold interval that ends at t_k

    def start(self):
        return np.broadcast_to(self.x0, (self.rows, 18)).copy()

    def draw(self, k):
        nb = min(BLOCK, self.n1 - k)
        blocks = [[rng.standard_normal((nb, p)) for p in (9, 9, 3)] for rng in self.rngs]
        self.W, self.Dn, self.Da = (np.tile(np.stack([b[i] for b in blocks]), (self.nv, 1, 1)) * sd
                                    for i, sd in enumerate(self.sd))
        self.k0 = k
        return k + nb

    def measure(self, k, x, u_read):
        """Y_k (5) and the clipped a_k (11), (14) as one reading (rows, 12); a_k contains ``u_read`` and its noise."""
        j = k - self.k0
        fk = self.fk = self.F[k] if self.same_f else self.F[:, k]
        wk = self.wk = self.W[:, j]
        w_read = wk if self.prior else self.w_prev
        Y = self.Y = x[:, MEASURED_INDICES] + self.Dn[:, j]
        a_raw = self.a_raw = x @ self.CaT + (u_read[:, 3:6] + w_read[:, 3:6] + fk[..., 3:6]) * (1.0 / M_SC) + self.Da[:, j]
        a_c = self.a_c = np.clip(a_raw, self.lo, self.up)
        return np.concatenate([Y, a_c], axis=1)

    def record(self, k, x, u):
        g = self.g = u + self.wk + self.fk
        self.drive[:, k], self.acc[:, k] = g, self.a_raw

    def step(self, k, x, u):
        self.w_prev = self.wk
        return x @ self.PhiT + self.g @ self.GamT


class _FusedGroups:
    """Algorithm 3 per group of rows with equal readings (:data:`FILTER_FIELDS`): the estimator stage.

    ``groups``: lists ``[rows slice, fused filter, its state, first steady step, x̂0]``, updated in place.
    """

    n_state = 27

    def __init__(self, groups, rows):
        self.groups, self.one = groups, len(groups) == 1
        self.xhat = np.empty((rows, 27))

    def start(self, rows):
        for grp in self.groups:
            grp[2] = grp[1].start(grp[4], None, grp[0].stop - grp[0].start)

    def update(self, k, y, u_read):
        # the filters' unchecked steps: the loop's readings and inputs are float arrays of the right shapes,
        # their finiteness checked once after the loop (:func:`run_closed_loops`), as ``Estimator.estimate`` does
        one = self.one
        for grp in self.groups:
            sl, fused, fs = grp[0], grp[1], grp[2]
            fs = fused.feed_input_unchecked(fs, u_read if one else u_read[sl])
            fs, out = fused.update_unchecked(fs, y if one else y[sl])
            grp[2] = fs
            if one:
                xhat = out.xhat
            else:
                self.xhat[sl] = out.xhat
            if grp[3] is None and fs.extra["steady"] is not None:
                grp[3] = k
        return xhat if one else self.xhat

    def prior(self):
        return self.groups[0][2].x if self.one else np.concatenate([grp[2].x for grp in self.groups])

    def predict(self, k, u):
        one = self.one
        for grp in self.groups:
            grp[2] = grp[1].predict_unchecked(grp[2], u if one else u[grp[0]])


class _Law:
    """The stacked ADRC laws with the attitude command (a stateful law); counts the steps each variant clipped."""

    def __init__(self, law, ref, nv):
        self.law, self.ref, self.nv = law, ref, nv
        self.clipped = np.zeros(nv, dtype=int)

    def start(self, rows):
        return self.law.start(rows)

    def step(self, k, xhat, cs):
        u, ucmd, cs = self.law(xhat, self.ref[k], cs)
        if self.nv == 1:
            self.clipped[0] += bool(np.any(u != ucmd))
        else:
            self.clipped += np.any((u != ucmd).reshape(self.nv, -1), axis=1)
        return u, cs


class _Passive:
    """Algorithm 1 and L1, L2, L3 (:class:`Alg2Bank`) on the readings of rows ``prow`` over the first ``n`` steps.

    A passive observer: fed the plant's last readings, told the input the reading contains and the one the plant
    moves with; ``h`` holds the filtered ``[r, ṙ, F_Dsc]`` (prow.size, n, 9) of each of :data:`PASSIVE`.
    """

    def __init__(self, plant, sc, prow, n):
        self.plant, self.prow, self.n = plant, prow, n
        self.all = prow.size == plant.rows
        self.h = {name: np.empty((prow.size, n, 9)) for name in PASSIVE}
        self.a1 = build_alg1(sc, steady_tol=sc.steady_tol)
        self.s1 = self.a1.start(sc.xhat0, None, prow.size)
        self.bank = Alg2Bank(build_alg2(sc, mode="truncated"), prow.size)

    def observe(self, k, y, u_read, u):
        if k >= self.n:
            return
        p, h, prow = self.plant, self.h, self.prow
        Yp, up_, ur, ar, ac = ((p.Y, u, u_read, p.a_raw, p.a_c) if self.all else
                               (p.Y[prow], u[prow], u_read[prow], p.a_raw[prow], p.a_c[prow]))
        self.s1, o1 = self.a1.update_unchecked(self.s1, Yp)  # unchecked, as in :class:`_FusedGroups`
        h["alg1"][:, k] = o1.xhat[:, 9:18]
        self.s1 = self.a1.predict_unchecked(self.s1, up_)
        h["L1"][:, k], h["L2"][:, k], h["L3"][:, k] = self.bank.step(ar, ac, ur[:, 3:6], up_[:, 3:6])


def run_closed_loop(scenario, *, controller="adrc", runs=1, seed=0, passive=True, passive_steps=100_000,
                    progress=False):
    """Simulate the closed loop of Section 3 (see the module docstring).

    Parameters
    ----------
    scenario : Scenario
        Length, readings, ``steady_tol`` (gains frozen once converged).
    controller : {"adrc", "adrc_pid", "pid", "dragfree_off"}
    runs : int
    seed : int or numpy.random.Generator
    passive : bool
        Also run the standalone estimators of Figs 5-7 (Algorithm 1, L1, L2, L3).
    passive_steps : int
        Over the first ``passive_steps`` samples only (their cost is a third of the loop's).
    progress : bool

    Returns
    -------
    LoopResult
    """
    return run_closed_loops([(scenario, controller)], runs=runs, seed=seed, passive=passive,
                            passive_steps=passive_steps, progress=progress)[0]


#: Scenario fields that only the controller (``integral``) or the post-processing (``residual``) reads: loops that
#: differ only in these (and in the controller) share the plant, the noise and the estimator and are batched.
CONTROLLER_FIELDS = ("integral", "residual")
#: Scenario fields that change the noise levels, the disturbance or the estimator (not the plant's matrices nor the
#: loop's timing): loops that differ in these are batched too, each group of equal readings with its own estimator.
FILTER_FIELDS = ("noise", "omega_d", "fused_covariance")


def _check_variants(variants):
    """The scenarios and controllers of ``variants``, checked to share everything but the controller."""
    if isinstance(variants, (str, bytes)) or not hasattr(variants, "__iter__"):
        raise InputError("variants must be a sequence of (scenario, controller) pairs")
    variants = list(variants)
    if not variants:
        raise InputError("variants must hold at least one (scenario, controller) pair")
    out = []
    for i, pair in enumerate(variants):
        if not isinstance(pair, tuple) or len(pair) != 2:
            raise InputError(f"variants[{i}] must be a (scenario, controller) pair; got {pair!r}")
        sc = check_scenario(pair[0])
        out.append((sc, as_choice("controller", pair[1], CONTROLLERS)))
    first = out[0][0]
    blank = {key: getattr(first, key) for key in CONTROLLER_FIELDS + FILTER_FIELDS}
    for i, (sc, _) in enumerate(out[1:], 1):
        if replace(sc, **blank) != first:
            raise InputError(f"variants[{i}]'s scenario differs from variants[0]'s beyond "
                             f"{CONTROLLER_FIELDS + FILTER_FIELDS}: only loops on the same plant and timing are batched")
    return out


def run_closed_loops(variants, *, runs=1, seed=0, passive=True, passive_steps=100_000, progress=False):
    """Several closed loops of Section 3 on the same plant and noise, stepped together as rows of one batch.

    Each variant ``(scenario, controller)`` is one loop of :func:`run_closed_loop`; the scenarios may differ only
    in :data:`CONTROLLER_FIELDS`. Row ``v * runs + r`` is run r of variant v and draws from the r-th child of the
    seed in the order of the module docstring, so every variant's numbers equal those of its own
    :func:`run_closed_loop` (round-off aside: the rows share the matrix products) whatever the other variants:
    common random numbers, and the per-step Python work is paid once for all the loops.

    Parameters
    ----------
    variants : sequence of (Scenario, str)
        The loops: scenario and controller (``CONTROLLERS``).
    runs : int
        Monte Carlo runs of every variant.
    seed : int or numpy.random.Generator
    passive : bool or sequence of bool
        Run the standalone estimators alongside (all variants, or per variant).
    passive_steps : int
    progress : bool

    Returns
    -------
    list of LoopResult
        One per variant, in order.
    """
    given = _check_variants(variants)
    nv = len(given)
    runs = as_int_at_least("runs", runs, 1)
    flags = [bool(passive)] * nv if np.ndim(passive) == 0 else [bool(p) for p in passive]
    if len(flags) != nv:
        raise InputError(f"passive must be one bool or {nv} (one per variant); got {len(flags)}")
    if isinstance(seed, np.random.Generator):
        seed = int(seed.integers(2**63))
    # rows grouped by estimator (FILTER_FIELDS): each group a contiguous slice with its own Algorithm 3
    keys = [tuple(getattr(sc, f) for f in FILTER_FIELDS) for sc, _ in given]
    group_keys = list(dict.fromkeys(keys))
    order = sorted(range(nv), key=lambda v: group_keys.index(keys[v]))
    pairs, flags = [given[v] for v in order], [flags[v] for v in order]
    if any(fl and keys[v] != keys[order[0]] for v, fl in zip(order, flags)):
        raise InputError("the standalone estimators (passive) run on the variants of the first variant's readings only")
    rngs = child_rngs(seed, runs)
    sc = pairs[0][0]
    n1 = sc.n_steps + 1
    rows = nv * runs
    t = np.arange(n1) * sc.dt
    ref = sc.attitude_reference(n1)
    law = _Law(DragFreeADRC.stacked([s.controller(kind) for s, kind in pairs], runs), ref, nv)  # one call for every row
    slices = [slice(v * runs, (v + 1) * runs) for v in range(nv)]
    groups = []  # [rows slice, fused filter, its state, first steady step, x̂0]
    for key in group_keys:
        vs = [v for v in range(nv) if keys[order[v]] == key]
        g_sc = pairs[vs[0]][0]
        groups.append([slice(vs[0] * runs, (vs[-1] + 1) * runs), build_fused(g_sc, steady_tol=g_sc.steady_tol), None,
                       None, g_sc.xhat0])
    if len(groups) == 1:  # per-step standard deviations of w, d, d_a
        sd = (sc.input_std, sc.sensor_std, sc.accel_std)
    else:
        sd = tuple(np.repeat(np.stack([getattr(s, name) for s, _ in pairs]), runs, axis=0)[:, None]
                   for name in ("input_std", "sensor_std", "accel_std"))
    fs_v = [disturbance(t, s.w_d) for s, _ in pairs]
    same_f = all(s.w_d == sc.w_d for s, _ in pairs)
    F = fs_v[0] if same_f else np.repeat(np.stack(fs_v), runs, axis=0)  # (n1, 9) or (rows, n1, 9)
    plant = _Plant(sc, nv, runs, rngs, sd, F, same_f)
    n_passive = min(n1, as_int_at_least("passive_steps", passive_steps, 0)) if any(flags) else 0
    observers = ()
    if n_passive:
        prow = np.concatenate([np.arange(rows)[sl] for sl, fl in zip(slices, flags) if fl])
        observers = (_Passive(plant, sc, prow, n_passive),)
    hist = run_stepped(plant, _FusedGroups(groups, rows), law, observers=observers, prior=sc.timing == "prior",
                       progress=progress, desc=f"closed loop ({', '.join(p[1] for p in pairs)})")
    if not (np.isfinite(hist.x).all() and np.isfinite(hist.xhat).all() and np.isfinite(plant.acc).all()):
        raise InputError("the closed loop diverged to non-finite states, estimates or readings")
    pas = observers[0].h if n_passive else {}
    results = [None] * nv
    first = 0
    for v, ((s, kind), sl) in enumerate(zip(pairs, slices)):
        grp = next(g for g in groups if g[0].start <= sl.start < g[0].stop)
        settings = dict(s.readings, controller=kind, runs=runs, seed=seed, n_steps=s.n_steps, dt=s.dt, w_d=s.w_d,
                        steady_tol=s.steady_tol, fused_steady_from_step=grp[3],
                        clipped_input_steps=int(law.clipped[v]), theta_alg1=float(grp[1].alg1.theta),
                        theta_alg2=grp[1].alg2.theta.tolist())
        if flags[v] and n_passive:
            pv = {name: h[first:first + runs] for name, h in pas.items()}
            first += runs
        else:
            pv = {}
        results[order[v]] = LoopResult(t=t, x=hist.x[sl], f=fs_v[v], u=hist.u[sl], drive=plant.drive[sl],
                                       acc=plant.acc[sl], xhat=hist.xhat[sl], passive=pv, reference=ref, settings=settings)
    return results
