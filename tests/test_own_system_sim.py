"""A dynamics model of one's own through the simulation: its truth drawn at the Q the filters assume.

``DynamicsModel.step(x, u, w, t) = f(x, u, t) + G w`` with G Gᵀ = Q, so that
:func:`hinfnav.sim.simulate_truth` and the Monte Carlo engine simulate a user's
model (here the constant-turn target of the README's "Your own system") with
any of the package's noise models. Expected values: G Gᵀ = Q (closed form, to
rounding); the EKF's NEES and NIS, averaged over runs and steps, inside their
95 % χ² bounds (Bar-Shalom, Li & Kirubarajan 2001, §5.4), which a noise drawn
at another covariance would leave.
"""

import numpy as np

from hinfnav.estimators import ExtendedKalmanFilter
from hinfnav.metrics import consistency
from hinfnav.sim import HistorySink, TruthModel, run_monte_carlo, simulate_truth
from hinfnav.systems import ConstantTurn, RangeBearing

MODEL = ConstantTurn(dt=1.0, sigma_accel=0.05, sigma_turn_rate=1e-3)
SENSOR = RangeBearing(MODEL.n, sigma_range=5.0, sigma_bearing=0.01)
X0 = np.array([-1500.0, 400.0, 0.0, -15.0, 0.03])
P0 = np.diag([50.0, 50.0, 5.0, 5.0, 0.02]) ** 2


class Target:
    """A scenario of one's own: ``truth_model()`` and ``xhat0``."""

    xhat0 = X0

    def truth_model(self):
        return TruthModel(system=MODEL, measurement=SENSOR, x0=X0, n_steps=120)


def test_noise_gain_is_a_square_root_of_q():
    G = MODEL.noise_gain
    np.testing.assert_allclose(G @ G.T, MODEL.Q, rtol=0, atol=1e-12 * np.abs(MODEL.Q).max())
    assert MODEL.n_noise == MODEL.n


def test_step_is_the_map_plus_the_scaled_draw():
    x = np.tile(X0, (3, 1))
    w = np.random.default_rng(0).standard_normal((3, MODEL.n))
    np.testing.assert_array_equal(MODEL.step(x, None, w), MODEL.f(x) + w @ MODEL.noise_gain.T)
    np.testing.assert_array_equal(MODEL.step(x), MODEL.f(x))


def test_own_dynamics_simulated_and_the_ekf_consistent_on_it():
    truth = simulate_truth(Target().truth_model(), runs=2, seed=1)
    assert truth.x.shape == (2, 121, MODEL.n) and np.all(np.isfinite(truth.y))
    ekf = ExtendedKalmanFilter(MODEL, SENSOR, P0=P0)
    res = run_monte_carlo(Target(), {"ekf": ekf}, sink=HistorySink(X0, 50), runs=50, seed=3, batch_size=20,
                          diagnostics=("innovation", "innovation_covariance"))["ekf"]
    _, info = consistency(res)
    whole = info["windows"]["all"]
    lo, hi = info["nees_bounds"]
    assert lo <= whole["nees"] <= hi, (whole["nees"], info["nees_bounds"])  # measured 4.77 in [4.16, 5.91]
    lo, hi = info["nis_bounds"]
    assert lo <= whole["nis"] <= hi, (whole["nis"], info["nis_bounds"])  # measured 1.94 in [1.48, 2.59]
