"""A user's own model checked at the door (issue 36, item 1).

Each case is a mistake a user makes when writing f, h, a Jacobian or a
continuous derivative; the expected outcome is a ModelFunctionError naming the
function (and the step when a filter ran it), never a silent broadcast.
Expected values of the valid cases: the linear map F x with F = [[1, dt], [0, 1]]
(closed form), and the EKF on it equal to the Kalman filter on the same LinearSystem.
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError, ModelFunctionError
from hinfnav.estimators import ExtendedKalmanFilter
from hinfnav.systems import (
    ContinuousDynamics,
    DiscreteDynamics,
    DynamicsModel,
    LinearMeasurement,
    LinearSystem,
    MeasurementModel,
    StateSpec,
)
from hinfnav.systems.dynamics import MAX_SUBSTEPS

DT = 0.5
F = np.array([[1.0, DT], [0.0, 1.0]])
SPEC = StateSpec(labels=("p", "v"), units=("m", "m/s"))
Q = 0.01 * np.eye(2)
SENSOR = LinearMeasurement([[1.0, 0.0]], [[0.5]])


def good_f(x, u, t):
    return x @ F.T


def run(model, runs=3, steps=4, sensor=SENSOR):
    ekf = ExtendedKalmanFilter(model, sensor, P0=np.eye(2))
    y = np.random.default_rng(0).normal(size=(runs, steps, sensor.n_meas))
    return ekf.estimate(y, np.zeros((runs, steps, 0)), np.zeros(2)).xhat


def test_good_model_equals_the_linear_system():
    # reference: the same filter on the LinearSystem (Φ = F), an independent code path
    lin = LinearSystem(F, np.zeros((2, 0)), np.sqrt(0.01) * np.eye(2), DT, SPEC)  # Q = B Bᵀ = 0.01 I
    ref = ExtendedKalmanFilter(lin, SENSOR, P0=np.eye(2))
    y = np.random.default_rng(0).normal(size=(3, 4, 1))
    expected = ref.estimate(y, np.zeros((3, 4, 0)), np.zeros(2)).xhat
    got = run(DiscreteDynamics(good_f, SPEC, DT, Q, jacobian=lambda x, u, t: F))
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("fun, jac, runs, words", [
    (lambda x, u, t: (x @ F.T).T, None, 3, "transposed"),                      # (n, runs)
    (lambda x, u, t: x[:, :1], None, 3, r"shape \(\d+, 1\)"),                       # (runs, 1)
    (good_f, lambda x, u, t: 1.0, 3, "scalar or vector"),                      # scalar Jacobian
    (good_f, lambda x, u, t: np.ones(2), 3, "scalar or vector"),               # vector Jacobian
    (good_f, lambda x, u, t: F.T, 3, "transpose"),                             # transposed Jacobian
    (lambda x, u, t: x @ F.T + np.nan, None, 3, "NaN or inf"),
    (lambda x, u, t: 1 / 0, None, 3, "ZeroDivisionError"),                     # a function that raises
])
def test_wrong_dynamics_functions_are_named(fun, jac, runs, words):
    model = DiscreteDynamics(fun, SPEC, DT, Q, jacobian=jac, name="cart")
    with pytest.raises(ModelFunctionError, match=words) as info:
        run(model, runs=runs)
    assert "dynamics 'cart'" in str(info.value) and "at step 0" in str(info.value)


def test_columns_instead_of_rows_caught_when_the_shapes_agree():
    # F @ x on a (2, 2) batch returns (n, runs) = (2, 2): the first-call probe with one row refuses it
    model = DiscreteDynamics(lambda x, u, t: F @ x, SPEC, DT, Q, name="cart")
    with pytest.raises(ModelFunctionError, match="row by row"):
        model.f(np.array([[1.0, 2.0], [3.0, 4.0]]))


def test_function_that_modifies_its_input_cannot_corrupt_the_filter():
    def inplace(x, u, t):
        x[:, 0] += DT * x[:, 1]
        return x

    got = run(DiscreteDynamics(inplace, SPEC, DT, Q))
    expected = run(DiscreteDynamics(good_f, SPEC, DT, Q))
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)  # a copy is passed: same numbers


def test_raise_names_model_function_and_step():
    calls = []

    def late(x, u, t):
        calls.append(t)
        if t > 1.0:
            raise RuntimeError("table lookup out of range")
        return good_f(x, u, t)

    # the prediction from step 3 (t = 3 dt = 1.5 s) is the first to fail
    with pytest.raises(ModelFunctionError, match=r"at step 3: dynamics 'late': f\(x, u, t\) raised RuntimeError"):
        run(DiscreteDynamics(late, SPEC, DT, Q, name="late", jacobian=lambda x, u, t: F), steps=5)


def test_continuous_derivative_of_wrong_shape_refused():
    model = ContinuousDynamics(lambda x, u, t: x[:, 1:2], SPEC, DT, Q, name="ode")  # (runs, 1)
    with pytest.raises(ModelFunctionError, match=r"derivative a\(x, u, t\) returned shape \(3, 1\)"):
        run(model)
    with pytest.raises(InputError, match="substeps must be <= "):
        ContinuousDynamics(lambda x, u, t: x, SPEC, DT, Q, substeps=MAX_SUBSTEPS + 1)


def test_continuous_jacobian_checked_against_differences():
    a = lambda x, u, t: np.column_stack([x[:, 1], -x[:, 0]])
    A = np.array([[0.0, 1.0], [-1.0, 0.0]])
    ok = ContinuousDynamics(a, SPEC, DT, Q, derivative_jacobian=lambda x, u, t: A)
    np.testing.assert_allclose(ok.jacobian(np.ones((2, 2)))[0], ok.jacobian(np.ones((1, 2)))[0], rtol=1e-14)
    bad = ContinuousDynamics(a, SPEC, DT, Q, derivative_jacobian=lambda x, u, t: A.T)
    with pytest.raises(ModelFunctionError, match=r"entry \[0, 1\]"):
        bad.jacobian(np.ones((2, 2)))


def test_user_subclasses_are_checked():
    class Wrong(DynamicsModel):
        def f(self, x, u=None, t=0.0):
            return x[:, 0]  # (runs,)

    with pytest.raises(ModelFunctionError, match=r"f\(x, u, t\) returned shape \(\d+,\)"):
        run(Wrong(SPEC, DT, Q, name="mine"))

    class Range(MeasurementModel):
        def __init__(self):
            super().__init__(2, [[1.0]], ("r",), ("m",))

        def function(self, x):
            return x[:, :1].copy()

        def jacobian(self, x):
            return np.array([[0.0, 1.0]])  # wrong column

    with pytest.raises(ModelFunctionError, match=r"measurement model Range: jacobian\(x\) disagrees .* entry \[0, 0\]"):
        run(DiscreteDynamics(good_f, SPEC, DT, Q), sensor=Range())


def test_noise_matrices_checked_whenever_set():
    ekf = ExtendedKalmanFilter(DiscreteDynamics(good_f, SPEC, DT, Q), SENSOR, P0=np.eye(2))
    ekf.Q = 0.02 * np.eye(2)  # a valid new value is kept
    np.testing.assert_array_equal(ekf.Q, 0.02 * np.eye(2))
    for name, bad, words in [("Q", -np.eye(2), "semidefinite"), ("R", [[0.0]], "positive definite"),
                             ("P0", np.ones((3, 3)), "shape 2x2"), ("Q", [[1.0, np.nan], [0, 1]], "finite")]:
        with pytest.raises(InputError, match=f"ExtendedKalmanFilter.{name}.*{words}"):
            setattr(ekf, name, bad)
