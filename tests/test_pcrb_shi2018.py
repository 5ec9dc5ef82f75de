"""The posterior CRB of Shi & Wang's benchmark cells, checked independently (issue 18, "a bound in every cell").

The benchmark once reported the EKF's velocity RMS on Shi's Gaussian cell at 0.977 [0.960, 0.995] of the bound.
These tests pin why that was Monte Carlo error, not a wrong bound: the bound problem is the truth's model
(dynamics, process and sensor noise), ``posterior_crb`` equals a recursion written here from scratch, and the
EKF sits on the bound in steady state (so half of all 50-run cells fall below 1; the spread is in
``benchmarks/shi2018_bound_check.py``).
"""

import numpy as np
import pytest
import scipy.linalg
import scipy.stats

from hinfnav.analysis.pcrb import posterior_crb
from hinfnav.campaign.runner import cell_truth
from hinfnav.estimators.registry import build_estimator
from hinfnav.papers.benchmark import load_papers
from hinfnav.papers.shi2018.campaign import CampaignScenario
from hinfnav.sim.engine import HistorySink, run_monte_carlo
from hinfnav.systems.measurements import wrap_angle


def _cw_matrices(n, dt):
    """Φ and Γ of the Hill/CW equations (x radial, y along-track, z normal), exact hold, by one matrix exponential."""
    A = np.zeros((9, 9))
    A[:3, 3:6] = np.eye(3)
    A[3, 0], A[3, 4], A[4, 3], A[5, 2] = 3 * n**2, 2 * n, -2 * n, -(n**2)
    A[3:6, 6:] = np.eye(3)                      # the held acceleration
    M = scipy.linalg.expm(A * dt)
    return M[:6, :6], M[:6, 6:]


def _fd_jacobian(function, x, h=1e-3):
    """Central differences of the sensor function in the position (m); velocity columns are zero."""
    J = np.zeros((x.shape[0], 3, 6))
    for j in range(3):
        d = np.zeros(6)
        d[j] = h
        diff = function(x + d) - function(x - d)
        diff[:, 1:] = wrap_angle(diff[:, 1:])
        J[:, :, j] = diff / (2 * h)
    return J


def _kalman_form_bound(X, Phi, Q, Lam, function):
    """P(k) = ((Φ P(k−1) Φᵀ + Q)⁻¹ + E[Hᵀ Λ H])⁻¹ from P(0⁻) = 0, the update in Kalman form (Q may be singular)."""
    P, out = np.zeros((6, 6)), []
    for k in range(X.shape[1]):
        if k:
            P = Phi @ P @ Phi.T + Q
        H = _fd_jacobian(function, X[:, k])
        info = np.einsum("rji,jk,rkl->il", H, Lam, H) / X.shape[0]
        mu, V = np.linalg.eigh(info)
        L = np.sqrt(np.clip(mu, 0, None))[:, None] * V.T           # Lᵀ L = E[Hᵀ Λ H]
        P = P - P @ L.T @ np.linalg.solve(L @ P @ L.T + np.eye(6), L @ P)
        out.append(0.5 * (P + P.T))
    return np.array(out)


@pytest.mark.parametrize("maneuver", [False, True])
def test_bound_problem_is_the_truths_model_and_matches_an_independent_recursion(maneuver):
    sc = CampaignScenario()
    prob = sc.bound_problem({"maneuver": maneuver}, "gaussian")
    Phi, Gamma = _cw_matrices(sc.n, sc.dt)
    B = Gamma * sc.sigma_accel
    # expected: the CW matrices by one matrix exponential (closed form); measured 0 difference
    np.testing.assert_allclose(prob["F"], Phi, rtol=0, atol=1e-12)
    np.testing.assert_allclose(prob["Q"], B @ B.T, rtol=0, atol=1e-12 * np.abs(B @ B.T).max())
    # expected: Λ = R⁻¹ for Gaussian noise (closed form)
    np.testing.assert_allclose(prob["Lambda"], np.diag(np.array([sc.sigma_range, sc.sigma_angle, sc.sigma_angle]) ** -2.0),
                               rtol=1e-12)
    assert not np.any(prob["P0"])                                     # the truth starts from x0 itself
    truth = cell_truth(sc, {"maneuver": maneuver}, "gaussian", seed=11, runs=8)
    X = truth.x
    np.testing.assert_array_equal(X[:, 0], np.broadcast_to(sc.x0, (8, 6)))
    # the truth's increments are B w with unit-variance w (the maneuver's impulse is deterministic, added to all
    # runs): residual outside range(B) at rounding, var(w) = 1 within 0.05 (8 × 2500 samples per channel: 1σ 0.01)
    d = X[:, 1:] - X[:, :-1] @ Phi.T - (sc.maneuver_response()[1:] - sc.maneuver_response()[:-1] @ Phi.T
                                          if maneuver else 0.0)
    w = d @ np.linalg.pinv(B).T
    assert np.max(np.abs(d - w @ B.T)) < 1e-9 * np.max(np.abs(d))
    np.testing.assert_allclose(w.reshape(-1, 3).var(axis=0), 1.0, atol=0.05)
    # the readings are h(x(k)) + D v(k), unit-variance v (same tolerance, same sample size)
    v = truth.y - sc.sensor().function(X)
    v[..., 1:] = wrap_angle(v[..., 1:])
    np.testing.assert_allclose((v / np.array([sc.sigma_range, sc.sigma_angle, sc.sigma_angle])).reshape(-1, 3).var(axis=0),
                               1.0, atol=0.05)
    bound = posterior_crb(X, prob["F"], prob["H"], prob["Q"], None, prob["P0"],
                          measurement_information=prob["Lambda"])
    ref = _kalman_form_bound(X, Phi, B @ B.T, prob["Lambda"], sc.sensor().function)
    # expected: the recursion above (own CW matrices, finite-difference Jacobian, Kalman-form update); the
    # central differences are accurate to ~1e-10 m⁻¹ on entries ~3e-4 m⁻¹; measured 3.2e-10 relative. Evaluating
    # H one step early (x(k) for y(k+1)) gives a difference far above the tolerance (checked)
    rel = np.max(np.abs(bound[1:] - ref[1:]), axis=(1, 2)) / np.max(np.abs(ref[1:]), axis=(1, 2))
    assert np.max(rel) < 1e-8, np.max(rel)
    assert not np.any(bound[0])                                       # x(0) known: zero bound at step 0


def test_ekf_sits_on_the_bound_in_steady_state():
    """The bound is tight for the EKF: its own covariance matches the bound after ~200 s, its error within MC error.

    So the expected RMS/bound ratio of a benchmark cell is about 1.00 (1.003 in velocity over 20 000 runs) and a
    50-run cell lies below 1 about as often as above (1.2 % standard deviation; the benchmark's 0.977 was a
    1-in-100 draw): ``python benchmarks/shi2018_bound_check.py``.
    """
    load_papers()
    sc = CampaignScenario()
    runs = 100
    res = run_monte_carlo(sc, {"ekf": build_estimator(sc, "model_ekf")}, sink=HistorySink(sc.xhat0, runs), runs=runs,
                          seed=5, batch_size=runs, keep_covariance="diagonal", maneuver=False)["ekf"]
    prob = sc.bound_problem({"maneuver": False}, "gaussian")
    bound = posterior_crb(res.x, prob["F"], prob["H"], prob["Q"], None, prob["P0"],
                          measurement_information=prob["Lambda"], diagonal_only=True)
    settled = (res.t >= 200) & (res.t <= 700)
    steady = (res.t >= 100) & (res.t <= 1000)                         # the benchmark's window
    z = scipy.stats.norm.ppf(1 - 0.001 / 2)
    for idx in (slice(0, 3), slice(3, 6)):
        # expected: 1, the EKF's covariance on the bound of the same truths; measured 1.0023-1.0031 in position and
        # 1.0007-1.0009 in velocity (seeds 5-7; the excess: the mean of the runs' inverse informations exceeds the
        # inverse of their mean); against a bound from 500 other truths 0.998-1.0003
        assert res.P[:, settled, idx].mean() / bound[settled, idx].mean() == pytest.approx(1.0, abs=6e-3)
        # expected: the bound inside the 99.9 % normal interval of the Monte Carlo mean square over the runs
        # (per-run window means are independent; half-width about 5 % with 100 runs; measured ratio 0.98)
        ms = np.mean((res.xhat - res.x)[:, steady, idx] ** 2, axis=(1, 2))
        half = z * ms.std(ddof=1) / np.sqrt(runs)
        assert abs(ms.mean() - bound[steady, idx].mean()) < half, (ms.mean() / bound[steady, idx].mean(), half / ms.mean())
