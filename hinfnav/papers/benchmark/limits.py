"""The bound of one benchmark cell: the Riccati limit of a linear-Gaussian cell, the posterior CRB of the others.

:func:`cell_bound` gives every cell its bound (below, the Riccati limit of Sun 2011's cells).

For Sun et al. (2011)'s chaser with the true orbital-rate error δ the truth
is ``x(k+1) = A x(k) + B w(k)``, ``y(k) = C x(k) + D v(k)`` with
``A = Φ(δ) + Γ(δ) K`` with maneuver (the closed loop (3)) and ``A = Φ(δ)``
without, exact zero-order hold at T, ``C = [I 0]`` of (8). The steady-state
Kalman filter of that model — which knows δ, the law u = K x and the noise
covariances ``Q = B Bᵀ``, ``R = D Dᵀ`` — has the smallest error covariance any
*linear* estimator can have for white noise of those covariances; its
per-axis standard deviations, as an RMS over x, y, z, are the denominators of
the benchmark's ratios. At δ = 0 this is :func:`hinfnav.papers.sun2011.kalman_limit`
(tested equal).

What the limit does and does not bound (said beside the table):

* every noise of the benchmark has unit variance, so ``Q`` and ``R`` are the
  same for all four, and so is this limit; for white Gaussian noise no
  estimator can beat it, for white non-Gaussian noise (mixture, Student-t) a
  nonlinear estimator (the Huber filter) may, and for coloured noise (not
  white) a filter that models the colour may;
* with maneuver, a filter told the applied thrust u(k) as an exogenous input
  has the error dynamics of Φ, not Φ + ΓK: its own limit is the
  no-maneuver one (velocity 0.0224 against 0.0135–0.0139 m/s), so its
  velocity ratio cannot go below about 1.6;
* the LTI filters (12) are one-step predictors (their estimate at t_k uses y
  up to k − 1): their bound is the predicted limit (``*_predicted``), about
  1.28 times the filtered one in position.
"""

import numpy as np

from ...analysis.pcrb import posterior_crb
from ...analysis.riccati import steady_state_kalman
from ...campaign.runner import cell_truth
from ...core.exceptions import InputError
from ...systems.hill import measurement_matrix
from ..sun2011.scenario import Scenario

__all__ = ["cell_kalman_limit", "cell_bound"]


def cell_kalman_limit(scenario, *, maneuver, delta=0.0, discretization="exact"):
    """Steady-state Kalman error of one benchmark cell's true model, RMS over x, y, z.

    Parameters
    ----------
    scenario : hinfnav.papers.sun2011.Scenario
    maneuver : bool
        Truth with u = K x (3) or u = 0.
    delta : float
        True orbital-rate error δ of (4), > −1.
    discretization : {"exact", "euler"}

    Returns
    -------
    dict
        ``pos_m``, ``vel_mps`` (filtered: uses y(k)) and ``pos_m_predicted``,
        ``vel_mps_predicted`` (uses y up to k − 1), each the RMS over the three
        axes of the per-axis standard deviation (m, m/s), and ``pos_axes_m``,
        ``vel_axes_mps`` (filtered, per axis).
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a hinfnav Sun 2011 Scenario; got {type(scenario).__name__}")
    if not isinstance(maneuver, (bool, np.bool_)):
        raise InputError(f"maneuver must be True or False; got {maneuver!r}")
    Phi, Gamma = scenario.truth_matrices(delta, discretization)
    A = Phi + Gamma @ scenario.K if maneuver else Phi
    P, Pf, _ = steady_state_kalman(A, measurement_matrix(), scenario.B @ scenario.B.T, scenario.D @ scenario.D.T)
    sf, sp = np.sqrt(np.diag(Pf)), np.sqrt(np.diag(P))
    rms = lambda s: float(np.sqrt(np.mean(s ** 2)))
    return {"pos_m": rms(sf[:3]), "vel_mps": rms(sf[3:]), "pos_m_predicted": rms(sp[:3]),
            "vel_mps_predicted": rms(sp[3:]), "pos_axes_m": sf[:3].tolist(), "vel_axes_mps": sf[3:].tolist()}


def _group_rms(diag, groups, quantities, mask=None):
    """RMS over a group's components (and the masked steps) of a bound's diagonal ``(…, n)``."""
    d = diag if mask is None else diag[mask]
    return {q: float(np.sqrt(np.mean(d[..., list(groups[q])]))) for q in quantities}


def cell_bound(scenario, conditions, noise, windows, quantities, *, runs=20, seed=0):
    """The bound of one benchmark cell, per window and quantity: the RMS error no estimator can beat.

    * Sun 2011's chaser: :func:`cell_kalman_limit` (the steady-state Riccati limit of the cell's true model);
    * any other scenario, from its ``bound_problem(conditions, noise)``: the posterior Cramér–Rao bound (:func:`hinfnav.analysis.pcrb.posterior_crb`, Tichavský,
      Muravchik & Nehorai 1998), its expectations a Monte Carlo mean over ``runs`` truths of the cell
      (:func:`hinfnav.campaign.runner.cell_truth`, seeded by ``seed``, independent of the cells' draws).

    Each value is ``√(mean over the window's samples and the group's components of the bound's diagonal)``:
    the quantity a pooled RMS error is compared with.

    Returns
    -------
    dict
        ``{"kind": "riccati" | "pcrb", "windows": {window: {quantity: bound}}}``. With linear dynamics and
        measurements the posterior CRB is the Kalman covariance recursion (from the bound's P₀), the same on
        every run (tested equal to the Riccati limit once converged).
    """
    if isinstance(scenario, Scenario):
        lim = cell_kalman_limit(scenario, maneuver=bool(conditions.get("maneuver", False)),
                                delta=float(conditions.get("delta", 0.0)))
        value = {"position": lim["pos_m"], "velocity": lim["vel_mps"]}
        return {"kind": "riccati", "windows": {w: {q: value[q] for q in quantities} for w in windows}}
    prob = scenario.bound_problem(conditions, noise)
    truth = cell_truth(scenario, conditions, noise, seed=seed, runs=runs)
    groups = prob.get("groups") or truth.state.groups
    states = prob["states"](truth.x)
    diag = posterior_crb(states, prob["F"], prob["H"], prob["Q"], None, prob["P0"],
                         measurement_information=prob["Lambda"], diagonal_only=True)
    out = {}
    for w, (a, b) in windows.items():
        mask = (truth.t >= a - 1e-9) & (truth.t <= b + 1e-9)
        out[w] = _group_rms(diag, groups, quantities, mask)
    return {"kind": "pcrb", "windows": out}
