"""The model mismatch, measured on the real day (issue 20, item 2).

* :func:`propagation_errors` — start from the true relative state at many epochs and propagate it with
  the Hill/CW model of paper 000 (exact zero-order-hold discretisation of (2) at the chief's mean rate
  ω₀), with the nonlinear two-body model of both spacecraft and with two-body + J2 (RK4, 5 s steps,
  :mod:`.dynamics`); compare with the truth after 1/10, 1/4 and one orbit.
* :func:`one_step_mismatch` — the mismatch of one 10 s step of the Hill model,
  ``e_k = x_{k+1} − Φ(ω₀) x_k``, and the orbital-rate uncertainty ``ω = ω₀(1 + δ)`` that explains it:
  per step the least-squares δ_k, the global minimiser of
  ``f_k(δ) = ‖W (x_{k+1} − Φ(ω₀(1+δ)) x_k)‖²`` (the position components weighted by 1 m and the
  velocity components by 1 m/s / ω₀ so both count in metres), solved to convergence by
  :func:`delta_minima`: every local minimum in |δ| ≤ :data:`DELTA_SPAN` is found on a grid and refined
  by bisection on f_k′ (all minima are reported; about a quarter of the steps have two). **Sign
  convention:** ω₀ > 0 is GRACE-B's mean orbital rate, δ > 0 a faster rate, δ < −1 a reversed (negative)
  rate, which no orbit has: the minimiser restricted to a positive rate (δ > −1) is reported beside the
  unrestricted one. (Up to 0.2 a 3-step Gauss–Newton from δ = 0 was reported; it had not converged.)
  Two bounds:

  - ``delta_bar_fit = max_k |δ_k|``: every step's best-fitting δ lies in [−δ̄, δ̄] (the family then
    leaves a residual, reported);
  - ``delta_bar_norm = max_k ‖e_k‖ / ‖∂Φ/∂δ x_k‖``: the norm-bounded cover, the smallest δ̄ whose
    first-order perturbation ``δ ∂Φ/∂δ x_k`` is as large as the mismatch at every step (the direction is
    not matched: this is the size argument behind the norm-bounded model (10)–(11)).
"""

import numpy as np

from ...core.validation import as_int_at_least
from .constants import DT_S, HORIZONS
from .dataset import hill_basis, inertial_to_hill
from .dynamics import MODELS, pair, rk4

__all__ = ["hill_transition", "propagation_errors", "one_step_mismatch", "delta_minima", "SUBSTEPS", "DELTA_SPAN",
           ]

#: The per-step δ search covers |δ| ≤ this (Φ is periodic in ω dt: far beyond, aliases of the same minima recur).
DELTA_SPAN = 4.0
#: Grid step of the search for local minima before each is refined (0.01 missed one shallow second minimum of
#: the day, a bump of 0.4 m² at δ = −1.29 on step 4299; 0.0025 and 0.001 find the same 2449 steps with two).
DELTA_GRID_STEP = 0.0025

#: RK4 sub-steps per 10 s data interval (5 s steps: the integration error on the relative state over one
#: orbit is below 1 mm, checked in the tests against 2.5 s steps).
SUBSTEPS = 2


def hill_transition(omega, dt=DT_S):
    """``Φ(ω) = exp(A₀(ω) dt)`` of the Hill model (2) in closed form (the Clohessy–Wiltshire transition),
    batched over an array ``omega`` (…, 6, 6); equal to the matrix exponential (tested)."""
    n = np.asarray(omega, float)
    s, c, nt = np.sin(n * dt), np.cos(n * dt), n * dt
    P = np.zeros(n.shape + (6, 6))
    P[..., 0, 0], P[..., 0, 3], P[..., 0, 4] = 4 - 3 * c, s / n, 2 * (1 - c) / n
    P[..., 1, 0], P[..., 1, 1], P[..., 1, 3], P[..., 1, 4] = 6 * (s - nt), 1.0, -2 * (1 - c) / n, (4 * s - 3 * nt) / n
    P[..., 2, 2], P[..., 2, 5] = c, s / n
    P[..., 3, 0], P[..., 3, 3], P[..., 3, 4] = 3 * n * s, c, 2 * s
    P[..., 4, 0], P[..., 4, 3], P[..., 4, 4] = -6 * n * (1 - c), -2 * s, 4 * c - 3
    P[..., 5, 2], P[..., 5, 5] = -n * s, c
    return P


def _hill_path(x0, Phi, n):
    out = np.empty((n + 1,) + x0.shape)
    out[0] = x0
    for j in range(n):
        out[j + 1] = out[j] @ Phi.T
    return out


def _nonlinear_path(data, starts, n, model, substeps):
    f = pair(MODELS[model])
    X = np.concatenate([data.rB[starts], data.vB[starts], data.rA[starts], data.vA[starts]], axis=-1)
    out = np.empty((n + 1, len(starts), 6))
    out[0] = data.truth[starts]
    for j in range(n):
        X = rk4(f, X, data.t[0] + j * DT_S, DT_S / substeps, substeps)
        out[j + 1] = inertial_to_hill(X[:, :3], X[:, 3:6], X[:, 6:9], X[:, 9:12])
    return out


def propagation_errors(data, *, start_every=180, horizons=None, substeps=SUBSTEPS):
    """Errors of the three models propagating the true relative state, by horizon.

    Parameters
    ----------
    data : GraceData
    start_every : int
        Steps between start epochs (180 steps = 30 min).
    horizons : dict, optional
        Name → fraction of an orbit (default :data:`.constants.HORIZONS`).
    substeps : int
        RK4 steps per 10 s.

    Returns
    -------
    dict
        ``horizons_s``, ``starts`` (count), ``models`` → horizon → RMS and max over starts of the
        position error norm (m), velocity error norm (m/s), and the per-axis position RMS (m);
        ``growth`` → model → the RMS position error over starts at every step up to one orbit (m),
        with ``growth_t_s``.
    """
    start_every = as_int_at_least("start_every", start_every, 1)
    horizons = dict(HORIZONS if horizons is None else horizons)
    period = data.period_s
    steps = {k: int(round(v * period / DT_S)) for k, v in horizons.items()}
    n = max(steps.values())
    starts = np.arange(0, data.t.size - n, start_every)
    truth = np.stack([data.truth[starts + j] for j in range(n + 1)])
    paths = {"hill_cw": _hill_path(data.truth[starts], hill_transition(data.orbital_rate), n)}
    for model in MODELS:
        paths[model] = _nonlinear_path(data, starts, n, model, substeps)
    out = {"omega0_rad_s": data.orbital_rate, "period_s": period, "starts": int(starts.size),
           "start_every_s": start_every * DT_S, "horizons_s": {k: v * DT_S for k, v in steps.items()},
           "models": {}, "growth_t_s": np.arange(n + 1) * DT_S, "growth": {}}
    for name, path in paths.items():
        err = path - truth
        pos = np.linalg.norm(err[..., :3], axis=-1)
        vel = np.linalg.norm(err[..., 3:], axis=-1)
        out["growth"][name] = np.sqrt(np.mean(pos**2, axis=1))
        out["models"][name] = {
            h: {"position_rms_m": float(np.sqrt(np.mean(pos[j] ** 2))), "position_max_m": float(pos[j].max()),
                "velocity_rms_m_s": float(np.sqrt(np.mean(vel[j] ** 2))),
                "position_rms_per_axis_m": np.sqrt(np.mean(err[j, :, :3] ** 2, axis=0)).tolist()}
            for h, j in steps.items()}
    return out


def _objective_and_slope(delta, x, x1, w0, W, dt, h=1e-6):
    """f(δ) = ‖W (x1 − Φ(ω₀(1+δ)) x)‖² and f′(δ) (∂Φ/∂δ by a central difference of step h), per row."""
    r = (x1 - np.einsum("kij,kj->ki", hill_transition(w0 * (1 + delta), dt), x)) * W
    dP = (hill_transition(w0 * (1 + delta + h), dt) - hill_transition(w0 * (1 + delta - h), dt)) / (2 * h)
    J = np.einsum("kij,kj->ki", dP, x) * W
    return np.sum(r * r, axis=1), -2.0 * np.sum(r * J, axis=1)


def delta_minima(x, x1, omega0, *, dt=DT_S, weights=None, span=DELTA_SPAN, step=DELTA_GRID_STEP, chunk=128):
    """Every local minimum of f_k(δ) = ‖W (x1_k − Φ(ω₀(1+δ)) x_k)‖² in |δ| ≤ ``span``, per step k.

    The grid δ_i = −span + (i + ½) step (it never hits δ = −1, where ω = 0) finds each local minimum
    (f_{i−1} ≥ f_i ≤ f_{i+1}); bisection on f′ over [δ_{i−1}, δ_{i+1}] refines it to machine precision
    (60 halvings of 2·step).

    Parameters
    ----------
    x, x1 : ndarray, shape (n, 6)
        States at k and k+1 (m, m/s).
    omega0 : float
        ω₀, rad/s (> 0).
    weights : ndarray, shape (6,), optional
        W (default 1 for positions, 1/ω₀ for velocities).

    Returns
    -------
    dict
        ``minima`` (n, j) the local minimisers sorted by f (NaN-padded), ``values`` (n, j) f at them,
        ``count`` (n,) the number of local minima, ``best`` (n,) the global minimiser,
        ``best_positive_rate`` (n,) the best local minimiser with δ > −1 (NaN if none).
    """
    x, x1 = np.asarray(x, float), np.asarray(x1, float)
    W = np.array([1, 1, 1, 1 / omega0, 1 / omega0, 1 / omega0]) if weights is None else np.asarray(weights, float)
    grid = -span + (np.arange(int(round(2 * span / step))) + 0.5) * step
    G = grid.size
    # Φ_gᵀ side by side, (6, G·6): one matrix product gives Φ_g x_k for every grid point and step
    M = np.ascontiguousarray(np.swapaxes(hill_transition(omega0 * (1 + grid), dt), 1, 2).transpose(1, 0, 2)
                             .reshape(6, G * 6))
    rows, cols = [], []
    for a in range(0, x.shape[0], chunk):
        xs, x1s = x[a:a + chunk], x1[a:a + chunk]
        r = x1s[:, None, :] - (xs @ M).reshape(-1, G, 6)
        r *= W
        r *= r
        f = r.sum(axis=2).T  # (grid, k)
        loc = (f[1:-1] <= f[:-2]) & (f[1:-1] <= f[2:])
        i, k = np.nonzero(loc)
        rows.append(k + a)
        cols.append(i + 1)
    k = np.concatenate(rows)
    i = np.concatenate(cols)
    lo, hi = grid[i - 1], grid[i + 1]
    for _ in range(60):  # bisection on f' (negative left of the minimum, positive right)
        mid = 0.5 * (lo + hi)
        _, g = _objective_and_slope(mid, x[k], x1[k], omega0, W, dt)
        lo, hi = np.where(g < 0, mid, lo), np.where(g < 0, hi, mid)
    d = 0.5 * (lo + hi)
    fv, _ = _objective_and_slope(d, x[k], x1[k], omega0, W, dt)
    n = x.shape[0]
    count = np.bincount(k, minlength=n)
    j = max(1, int(count.max()) if count.size else 1)
    minima, values = np.full((n, j), np.nan), np.full((n, j), np.nan)
    order = np.lexsort((fv, k))
    k, d, fv = k[order], d[order], fv[order]
    slot = np.arange(k.size) - np.searchsorted(k, k)
    minima[k, slot], values[k, slot] = d, fv
    pos = np.where(minima > -1, values, np.inf)
    best_pos = np.where(np.isfinite(pos).any(axis=1), minima[np.arange(n), np.argmin(pos, axis=1)], np.nan)
    return {"minima": minima, "values": values, "count": count, "best": minima[:, 0], "best_positive_rate": best_pos}


def _delta_stats(delta):
    a = np.abs(delta)
    return {"mean": float(np.mean(delta)), "max_abs": float(a.max()), "p95_abs": float(np.quantile(a, 0.95))}


def one_step_mismatch(data, *, h=1e-4):
    """The Hill model's one-step mismatch and the orbital-rate uncertainty δ that covers it (module notes).

    Returns
    -------
    dict
        ``e`` (n−1, 6) the mismatch; ``delta`` (n−1,) the per-step least-squares δ_k; RMS and max of the
        mismatch (position m, velocity m/s), of the residual left at δ_k, ``delta_bar_fit``,
        ``delta_bar_fit_p95``, ``delta_bar_norm``, and the second moment ``Q_mismatch`` (6, 6) of e
        (m², m²/s²), what a Kalman filter's Q must hold to be consistent with it.
    """
    w0 = data.orbital_rate
    x, x1 = data.truth[:-1], data.truth[1:]
    W = np.array([1, 1, 1, 1 / w0, 1 / w0, 1 / w0])
    e = x1 - x @ hill_transition(w0).T
    fit = delta_minima(x, x1, w0, weights=W)
    delta = fit["best"]
    resid = x1 - np.einsum("kij,kj->ki", hill_transition(w0 * (1 + delta)), x)
    J0 = np.einsum("ij,kj->ki", (hill_transition(w0 * (1 + h)) - hill_transition(w0 * (1 - h))) / (2 * h), x) * W
    ratio = np.linalg.norm(e * W, axis=1) / np.linalg.norm(J0, axis=1)

    def stats(a, sl):
        nrm = np.linalg.norm(a[:, sl], axis=1)
        return {"rms": float(np.sqrt(np.mean(nrm**2))), "max": float(nrm.max())}

    return {
        "omega0_rad_s": w0, "e": e, "delta": delta, "delta_minima": fit["minima"],
        "mismatch_position_m": stats(e, slice(0, 3)), "mismatch_velocity_m_s": stats(e, slice(3, 6)),
        "residual_at_best_delta_position_m": stats(resid, slice(0, 3)),
        "residual_at_best_delta_velocity_m_s": stats(resid, slice(3, 6)),
        "delta_mean": float(delta.mean()), "delta_bar_fit": float(np.abs(delta).max()),
        "delta_bar_fit_p95": float(np.quantile(np.abs(delta), 0.95)),
        "delta_bar_norm": float(ratio.max()), "delta_bar_norm_p95": float(np.quantile(ratio, 0.95)),
        "delta_fit": {"convention": "omega = omega0 (1 + delta), omega0 > 0 GRACE-B's mean rate; delta < -1 is a "
                                    "reversed (negative) rate; least squares with positions in m and velocities "
                                    "/omega0, every local minimum in |delta| <= " + f"{DELTA_SPAN:g} solved to convergence",
                      "steps": int(delta.size), "steps_with_two_or_more_minima": int(np.sum(fit["count"] >= 2)),
                      "steps_with_reversed_rate_best": int(np.sum(delta < -1)),
                      "best": _delta_stats(delta),
                      "positive_rate": _delta_stats(fit["best_positive_rate"]),
                      "steps_without_positive_rate_minimum": int(np.sum(np.isnan(fit["best_positive_rate"])))},
        "Q_mismatch": e.T @ e / e.shape[0],
    }


def chief_rate_range(data):
    """Min and max over the day of GRACE-B's instantaneous Hill rate ``|h|/|r|²`` relative to ω₀ (a δ seen directly)."""
    w = hill_basis(data.rB, data.vB)[1]
    return float(w.min() / data.orbital_rate - 1), float(w.max() / data.orbital_rate - 1)
