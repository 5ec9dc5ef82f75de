"""Huber measurement update: Kalman limit, exact Huber minimiser, batching, input errors."""

import dataclasses

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators.huber import HuberUpdate, huber_update


def random_problem(seed, n=4, m=6):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    P = A @ A.T + 0.5 * np.eye(n)
    B = rng.normal(size=(m, m))
    R = B @ B.T + 0.2 * np.eye(m)
    H = rng.normal(size=(m, n))
    x_true = rng.normal(size=n)
    x_prior = x_true + np.linalg.cholesky(P) @ rng.normal(size=n)
    z = H @ x_true + np.linalg.cholesky(R) @ rng.normal(size=m)
    return x_prior, P, z, H, R


def whitened_regression(x_prior, P, z, H, R):
    """M = S^-1 [H; I], y = S^-1 [z; x_prior] with S = blockdiag(chol R, chol P), by explicit inverses."""
    Ri = np.linalg.inv(np.linalg.cholesky(R))
    Pi = np.linalg.inv(np.linalg.cholesky(P))
    return np.vstack([Ri @ H, Pi]), np.concatenate([Ri @ z, Pi @ x_prior])


def test_equals_kalman_update_when_residuals_are_small():
    # Source: closed form. With every whitened residual <= gamma the Huber
    # cost is the least-squares cost, whose minimiser is the Kalman update.
    rng = np.random.default_rng(7)
    n, m = 4, 3
    A = rng.normal(size=(n, n))
    P = A @ A.T + n * np.eye(n)
    B = rng.normal(size=(m, m))
    R = B @ B.T + np.eye(m)
    H = rng.normal(size=(m, n))
    x_prior = rng.normal(size=n)
    z = H @ x_prior + 0.05 * rng.normal(size=m)

    out = huber_update(x_prior, P, z, H, R)

    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    x_kf = x_prior + K @ (z - H @ x_prior)
    P_kf = (np.eye(n) - K @ H) @ P
    np.testing.assert_allclose(out.x, x_kf, rtol=1e-12, atol=1e-12 * np.abs(x_kf).max())
    np.testing.assert_allclose(out.P, P_kf, rtol=1e-12, atol=1e-12 * np.abs(P_kf).max())
    assert np.all(out.weights == 1.0)
    assert out.converged is True and out.iterations == 1
    M, y = whitened_regression(x_prior, P, z, H, R)
    assert np.abs(M @ out.x - y).max() <= 1.345  # the premise of the test holds


@pytest.mark.parametrize(
    "seed, n, m, outliers",
    [(0, 3, 6, [20.0, -15.0]), (1, 4, 8, [50.0]), (2, 2, 5, [10.0, 10.0, -8.0]), (3, 6, 12, [30.0, -30.0, 5.0])],
)
def test_equals_exact_huber_minimiser_with_outliers(seed, n, m, outliers):
    # Source: independent computation, the convex program solved by cvxpy.
    # cvxpy.huber(r, g) = r^2 (|r| <= g), 2 g |r| - g^2 (otherwise) is twice the
    # textbook rho, so it has the same minimiser.
    cp = pytest.importorskip("cvxpy")
    x_prior, P, z, H, R = random_problem(seed, n, m)
    z[: len(outliers)] += np.asarray(outliers)
    gamma = 1.345
    M, y = whitened_regression(x_prior, P, z, H, R)
    xv = cp.Variable(n)
    prob = cp.Problem(cp.Minimize(cp.sum(cp.huber(M @ xv - y, gamma))))
    prob.solve(solver="CLARABEL", tol_gap_abs=1e-14, tol_gap_rel=1e-14, tol_feas=1e-14, tol_ktratio=1e-12, max_iter=500)
    assert prob.status == "optimal"

    out = huber_update(x_prior, P, z, H, R, gamma=gamma)

    assert out.converged
    scale = max(1.0, np.abs(xv.value).max())
    np.testing.assert_allclose(out.x, xv.value, rtol=0, atol=1e-8 * scale)
    zeta = M @ out.x - y
    assert np.any(np.abs(zeta) > gamma)  # the outliers are down-weighted
    # Weights and covariance at the solution, recomputed from their definitions.
    psi = np.where(np.abs(zeta) <= gamma, 1.0, gamma / np.abs(zeta))
    np.testing.assert_allclose(out.weights, psi, rtol=1e-12)
    np.testing.assert_allclose(out.P, np.linalg.inv(M.T @ (psi[:, None] * M)), rtol=1e-9, atol=1e-12)


def test_batched_equals_loop_over_runs():
    runs, n, m = 5, 3, 5
    problems = [random_problem(10 + r, n, m) for r in range(runs)]
    x_prior = np.stack([p[0] for p in problems])
    P = np.stack([p[1] for p in problems])
    z = np.stack([p[2] for p in problems])
    z[1, 0] += 40.0  # some runs with outliers, some without
    z[3, :2] -= 25.0
    H = np.stack([p[3] for p in problems])
    R = problems[0][4]  # shared, broadcast over the runs

    out = huber_update(x_prior, P, z, H, R)

    assert out.x.shape == (runs, n) and out.P.shape == (runs, n, n)
    assert out.weights.shape == (runs, m + n)
    assert out.iterations.shape == (runs,) and out.converged.shape == (runs,)
    for r in range(runs):
        one = huber_update(x_prior[r], P[r], z[r], H[r], R)
        np.testing.assert_allclose(out.x[r], one.x, rtol=1e-14, atol=1e-14 * np.abs(one.x).max())
        np.testing.assert_allclose(out.P[r], one.P, rtol=1e-14, atol=1e-14 * np.abs(one.P).max())
        np.testing.assert_allclose(out.weights[r], one.weights, rtol=1e-14)
        assert out.iterations[r] == one.iterations and out.converged[r] == one.converged


def test_weights_in_unit_interval_and_result_frozen():
    x_prior, P, z, H, R = random_problem(4, 4, 8)
    z[:3] += [100.0, -60.0, 30.0]
    out = huber_update(x_prior, P, z, H, R, gamma=1.0)
    assert isinstance(out, HuberUpdate)
    assert np.all(out.weights > 0) and np.all(out.weights <= 1)
    assert np.any(out.weights < 1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        out.x = None


def test_output_shapes_follow_unbatched_input():
    x_prior, P, z, H, R = random_problem(5, 3, 2)
    out = huber_update(x_prior, P, z, H, R)
    assert out.x.shape == (3,) and out.P.shape == (3, 3) and out.weights.shape == (5,)
    assert isinstance(out.iterations, int) and isinstance(out.converged, bool)


def _bad_inputs():
    x_prior, P, z, H, R = random_problem(6, 3, 2)
    not_pd = P.copy()
    not_pd[0, 0] = -1.0
    asym = R.copy()
    asym[0, 1] += 1.0
    nan_x = x_prior.copy()
    nan_x[1] = np.nan
    good = {"x_prior": x_prior, "P_prior": P, "z": z, "H": H, "R": R}
    return [
        ({**good, "P_prior": not_pd}, {}, "P_prior"),
        ({**good, "R": asym}, {}, "R"),
        ({**good, "R": np.zeros((2, 2))}, {}, "R"),
        ({**good, "z": np.ones(3)}, {}, "H"),  # z sets m = 3, so H (2x3) is the mismatch
        ({**good, "H": np.ones((2, 4))}, {}, "H"),
        ({**good, "x_prior": nan_x}, {}, "x_prior"),
        ({**good, "x_prior": np.ones((2, 2, 3))}, {}, "x_prior"),
        ({**good, "x_prior": np.ones((4, 3)), "z": np.ones((5, 2))}, {}, "z"),
        (good, {"gamma": 0.0}, "gamma"),
        (good, {"tol": -1.0}, "tol"),
        (good, {"max_iter": 0}, "max_iter"),
    ]


@pytest.mark.parametrize("args, options, name", _bad_inputs())
def test_bad_inputs_raise_input_error_naming_the_parameter(args, options, name):
    with pytest.raises(InputError, match=rf"\b{name}\b"):
        huber_update(args["x_prior"], args["P_prior"], args["z"], args["H"], args["R"], **options)


def test_measurement_space_equals_the_whole_regression_solver():
    # Independent computation: hinfnav.estimators.huber_regression.minimise on the whole whitened
    # regression (n + m rows), from the same Kalman start, with explicit inverses of the Cholesky factors.
    # Large outliers push prior rows beyond gamma, so both of huber_update's paths are taken.
    from hinfnav.estimators.huber_regression import covariance, huber_weights, minimise, normal_matrix

    rng = np.random.default_rng(7)
    runs, n, m, gamma = 300, 6, 3, 1.0
    A = rng.normal(size=(runs, n, n))
    P = A @ np.swapaxes(A, -1, -2) + 0.1 * np.eye(n)
    H = rng.normal(size=(m, n))
    R = np.diag([1.0, 2.0, 0.5])
    x_prior = rng.normal(size=(runs, n))
    z = rng.normal(size=(runs, m)) * rng.choice([0.5, 3.0, 30.0], size=(runs, 1))
    out = huber_update(x_prior, P, z, H, R, gamma=gamma)

    LRi = np.linalg.inv(np.linalg.cholesky(R))
    LPi = np.linalg.inv(np.linalg.cholesky(P))
    M = np.concatenate([np.broadcast_to(LRi @ H, (runs, m, n)), LPi], axis=1)
    y = np.concatenate([z @ LRi.T, (LPi @ x_prior[..., None])[..., 0]], axis=1)
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    x0 = x_prior + ((z - x_prior @ H.T)[:, None, :] @ np.swapaxes(K, -1, -2))[:, 0]
    x, _, conv = minimise(M, y, x0, gamma, 1e-12, 200)
    w = huber_weights((M @ x[..., None])[..., 0] - y, gamma)
    assert conv.all() and out.converged.all()
    prior_out = np.mean(np.any(out.weights[:, m:] < 1, axis=1))
    assert 0.05 < prior_out < 0.95  # runs on both paths (measurement space; whole regression)
    # the same unique minimiser, to the solvers' tolerance (whitened residual steps of 1e-10)
    np.testing.assert_allclose(out.x, x, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(out.weights, w, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(out.P, covariance(normal_matrix(M, w)), rtol=1e-7, atol=1e-10)
