"""Steady-state a-priori H-infinity filter (Simon 2006, ch. 11): Kalman limit, scalar closed form, bounds."""

import numpy as np
import pytest
import scipy.linalg

from hinfnav.analysis.hinf_riccati import max_admissible_theta, steady_state_hinf
from hinfnav.core.exceptions import InputError


def random_system(seed, n=4, m=2, rho=1.05, q_rank=None):
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(n, n))
    F *= rho / np.abs(np.linalg.eigvals(F)).max()
    H = rng.normal(size=(m, n))
    A = rng.normal(size=(n, q_rank or n))
    Q = 0.1 * A @ A.T
    B = rng.normal(size=(m, m))
    R = B @ B.T + 0.5 * np.eye(m)
    return F, H, Q, R


@pytest.mark.parametrize(
    "seed, n, m, rho, q_rank", [(1, 4, 2, 1.05, None), (2, 3, 1, 0.8, None), (3, 5, 3, 1.2, 2), (4, 2, 2, 0.5, 1)]
)
def test_theta_zero_is_the_kalman_predictor(seed, n, m, rho, q_rank):
    # Source: scipy's DARE solver. The predictor Riccati equation
    # P = F P F^T - F P H^T (H P H^T + R)^-1 H P F^T + Q is solve_discrete_are(F^T, H^T, Q, R).
    F, H, Q, R = random_system(seed, n, m, rho, q_rank)
    P, K = steady_state_hinf(F, H, Q, R, 0.0)
    P_ref = scipy.linalg.solve_discrete_are(F.T, H.T, Q, R)
    np.testing.assert_allclose(P, P_ref, rtol=1e-9, atol=1e-9 * np.abs(P_ref).max())
    # The filter is x_{k+1} = F x_k + F K (y_k - H x_k), so K is the a-priori
    # Kalman gain without the leading F.
    K_ref = P_ref @ H.T @ np.linalg.inv(H @ P_ref @ H.T + R)
    np.testing.assert_allclose(K, K_ref, rtol=1e-9, atol=1e-9 * np.abs(K_ref).max())


def scalar_closed_form(F, H, Q, R, theta, s_bar):
    # Scalar steady state. With a = H^2/R - theta*s_bar the recursion is
    #   P' = F^2 P / (1 - theta s_bar P + (H^2/R) P) + Q = F^2 P / (1 + a P) + Q.
    # A fixed point satisfies P (1 + a P) = F^2 P + Q (1 + a P), i.e. the quadratic
    #   a P^2 + b P - Q = 0,   b = 1 - F^2 - a Q.
    # The root reached from P_0 = Q (the positive root if a > 0, the smaller
    # positive root if a < 0, Q / (1 - F^2) if a = 0) is, in rationalised form,
    #   P = 2 Q / (b + sqrt(b^2 + 4 a Q)),
    # and the gain is K = P / (1 + a P) * H / R.
    # Largest theta: for |F| < 1 the two roots merge (b^2 + 4 a Q = 0) when
    # sqrt(-a Q) = 1 - |F|, i.e. theta_max = (H^2/R + (1 - |F|)^2 / Q) / s_bar,
    # where 1/P + a = |F| (1 - |F|) / Q > 0 still holds; for |F| >= 1 the
    # positive root needs a > 0, so theta_max = H^2 / (R s_bar) (P -> inf there).
    a = H * H / R - theta * s_bar
    b = 1.0 - F * F - a * Q
    P = 2.0 * Q / (b + np.sqrt(b * b + 4.0 * a * Q))
    K = P / (1.0 + a * P) * H / R
    theta_max = (H * H / R + (1 - abs(F)) ** 2 / Q) / s_bar if abs(F) < 1 else H * H / (R * s_bar)
    return P, K, theta_max


SCALARS = [  # F, H, Q, R, S (s_bar = L^2 S with L = 1 unless given)
    (0.9, 1.0, 0.5, 2.0, 1.0),
    (1.2, 0.7, 0.3, 0.5, 2.0),
    (-0.5, 2.0, 1.0, 1.0, 0.5),
    (1.0, 1.0, 1.0, 1.0, 1.0),
]


@pytest.mark.parametrize("F, H, Q, R, S", SCALARS)
@pytest.mark.parametrize("fraction", [0.0, 0.3, 0.9, 0.999])
def test_scalar_closed_form(F, H, Q, R, S, fraction):
    theta_max = scalar_closed_form(F, H, Q, R, 0.0, S)[2]
    theta = fraction * theta_max
    P_ref, K_ref, _ = scalar_closed_form(F, H, Q, R, theta, S)
    P, K = steady_state_hinf([[F]], [[H]], [[Q]], [[R]], theta, S=[[S]])
    assert P.shape == (1, 1) and K.shape == (1, 1)
    assert P[0, 0] == pytest.approx(P_ref, rel=1e-10)
    assert K[0, 0] == pytest.approx(K_ref, rel=1e-10)


def test_scalar_weighting_through_L_and_S():
    # s_bar = L^T S L = 3^2 * 0.5 = 4.5
    P_ref, K_ref, _ = scalar_closed_form(0.9, 1.0, 0.5, 2.0, 0.1, 4.5)
    P, K = steady_state_hinf([[0.9]], [[1.0]], [[0.5]], [[2.0]], 0.1, L=[[3.0]], S=[[0.5]])
    assert P[0, 0] == pytest.approx(P_ref, rel=1e-10) and K[0, 0] == pytest.approx(K_ref, rel=1e-10)


@pytest.mark.parametrize("F, H, Q, R, S", SCALARS)
def test_scalar_max_admissible_theta(F, H, Q, R, S):
    theta_ref = scalar_closed_form(F, H, Q, R, 0.0, S)[2]
    theta_max = max_admissible_theta([[F]], [[H]], [[Q]], [[R]], S=[[S]], rtol=1e-6)
    assert theta_max <= theta_ref * (1 + 1e-12)
    assert theta_max == pytest.approx(theta_ref, rel=1e-5)


def test_positive_theta_matches_dare_with_indefinite_augmented_R():
    # Source: scipy's DARE solver. G = H^T R^-1 H - theta L^T S L equals
    # Ha^T Ra^-1 Ha with Ha = [H; sqrt(theta) S^(1/2) L], Ra = blockdiag(R, -I), so by
    # the matrix inversion lemma F (P^-1 + G)^-1 F^T + Q is the DARE map of (F^T, Ha^T, Q, Ra).
    F, H, Q, R = random_system(1)
    n = F.shape[0]
    L = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 1.0, 0.0]])
    S = np.array([[2.0, 0.3], [0.3, 1.0]])
    theta_max = max_admissible_theta(F, H, Q, R, L=L, S=S)
    for theta in (0.3 * theta_max, 0.9 * theta_max):
        P, K = steady_state_hinf(F, H, Q, R, theta, L=L, S=S)
        Ha = np.vstack([H, np.sqrt(theta) * np.real(scipy.linalg.sqrtm(S)) @ L])
        Ra = scipy.linalg.block_diag(R, -np.eye(2))
        P_ref = scipy.linalg.solve_discrete_are(F.T, Ha.T, Q, Ra)
        np.testing.assert_allclose(P, P_ref, rtol=1e-9, atol=1e-9 * np.abs(P_ref).max())
        # Existence condition at the solution, and the gain by its defining formula.
        Sbar = L.T @ S @ L
        W = H.T @ np.linalg.solve(R, H)
        assert np.linalg.eigvalsh(np.linalg.inv(P) - theta * Sbar + W).min() > 0
        K_ref = P @ np.linalg.inv(np.eye(n) - theta * Sbar @ P + W @ P) @ H.T @ np.linalg.inv(R)
        np.testing.assert_allclose(K, K_ref, rtol=1e-9, atol=1e-9 * np.abs(K_ref).max())


def test_theta_above_bound_raises_naming_theta_and_the_bound():
    F, H, Q, R = random_system(1)
    theta_max = max_admissible_theta(F, H, Q, R)
    steady_state_hinf(F, H, Q, R, 0.999 * theta_max)  # admissible just below
    for theta in (1.01 * theta_max, 2.0 * theta_max, 100.0 * theta_max):
        with pytest.raises(InputError, match="theta") as err:
            steady_state_hinf(F, H, Q, R, theta)
        assert "largest admissible theta" in str(err.value)
        bound = float(str(err.value).split("largest admissible theta is about ")[1].split(";")[0])
        assert bound == pytest.approx(theta_max, rel=1e-5)


def test_scalar_theta_above_closed_form_bound_raises():
    theta_ref = scalar_closed_form(0.9, 1.0, 0.5, 2.0, 0.0, 1.0)[2]
    with pytest.raises(InputError, match="theta"):
        steady_state_hinf([[0.9]], [[1.0]], [[0.5]], [[2.0]], 1.001 * theta_ref)


def test_undetectable_system_fails_at_theta_zero():
    F = np.diag([1.5, 0.5])
    H = np.array([[0.0, 1.0]])  # the unstable mode is not observed
    with pytest.raises(InputError, match="theta = 0"):
        steady_state_hinf(F, H, np.eye(2), [[1.0]], 0.0)
    with pytest.raises(InputError, match="detectable"):
        max_admissible_theta(F, H, np.eye(2), [[1.0]])


def test_zero_weight_admits_every_theta():
    F, H, Q, R = random_system(2, 3, 1, 0.8)
    assert max_admissible_theta(F, H, Q, R, L=np.zeros((1, 3))) == np.inf


@pytest.mark.parametrize(
    "change, name",
    [
        ({"F": np.ones((2, 3))}, "F"),
        ({"H": np.ones((1, 3))}, "H"),
        ({"Q": np.array([[1.0, 0.5], [0.0, 1.0]])}, "Q"),
        ({"Q": -np.eye(2)}, "Q"),
        ({"R": [[0.0]]}, "R"),
        ({"R": [[np.nan]]}, "R"),
        ({"theta": -0.1}, "theta"),
        ({"theta": np.inf}, "theta"),
        ({"L": np.ones((1, 3))}, "L"),
        ({"S": np.eye(3)}, "S"),
        ({"S": -np.eye(2)}, "S"),
    ],
)
def test_bad_inputs_raise_input_error_naming_the_parameter(change, name):
    args = {"F": 0.9 * np.eye(2), "H": [[1.0, 0.0]], "Q": np.eye(2), "R": [[1.0]], "theta": 0.1}
    args.update(change)
    with pytest.raises(InputError, match=rf"\b{name}\b"):
        steady_state_hinf(**args)
