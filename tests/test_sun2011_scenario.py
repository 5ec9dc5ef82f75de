"""The paper's scenario and the published filter (Section 4)."""

import numpy as np
import pytest
import scipy.linalg

from hinfnav import InputError
from hinfnav.papers.sun2011 import Scenario, infer_sampling_time, published_filter
from hinfnav.core import spectral_radius
from hinfnav.sim import TruthModel
from hinfnav.systems import LinearMeasurement, LinearSystem, measurement_matrix


def test_sampling_time_inferred_from_published_filter(scenario):
    # A_F[:3, 3:] = T·I and A_F[:3, :3] − B_F[:3] = I for an observer-form filter of (6) (see docstring)
    T, residual = infer_sampling_time()
    assert T == pytest.approx(0.1, abs=1e-12)
    assert residual < 1e-12  # exact in the printed digits
    assert scenario.dt == pytest.approx(T)


def test_sampling_time_inference_recovers_a_known_T():
    # build an observer-form filter with T = 0.25 s and read T back
    s = Scenario(dt=0.25)
    A = s.design_model().A
    C = measurement_matrix()
    G = np.vstack([1.5 * np.eye(3), 5.0 * np.eye(3)])
    A_F = A - G @ C
    T, residual = infer_sampling_time(A_F, -G)
    assert T == pytest.approx(0.25, abs=1e-12)
    assert residual < 1e-12


def test_published_filter_is_stable_and_estimates_minus_its_state():
    pub = published_filter()
    # eigenvalues computed from the printed A_F: largest modulus 0.3834
    assert spectral_radius(pub.A_F) == pytest.approx(0.3834, abs=5e-4)
    # C_F is printed as 1e-6·[...] with -1e6 on the diagonal: C_F = -I to 7.3e-5 (entry 6,6: -999927e-6)
    assert np.max(np.abs(pub.C_F + np.eye(6))) < 7.4e-5


def test_published_filter_is_close_to_a_predictor_observer_of_the_closed_loop(scenario):
    # structure consistency: with x̂ = C_F x_f the filter reads x̂⁺ = Â x̂ + G y with
    # Â ≈ A − G C, A = I + T(A₁+G₀K); printed digits agree to 3.5e-4
    s = scenario
    pub = published_filter()
    A = s.design_model().A
    Ci = np.linalg.inv(pub.C_F)
    Ahat = pub.C_F @ pub.A_F @ Ci
    G = pub.C_F @ pub.B_F
    assert np.max(np.abs(Ahat - (A - G @ measurement_matrix()))) < 3.5e-4


def test_scenario_defaults_are_the_papers(scenario):
    # Section 4 of the paper
    s = scenario
    assert s.omega0 == 7.2722e-5 and s.mass == 1000.0
    np.testing.assert_array_equal(s.x0, [600, 550, 1040, 0.02, -0.08, 0.03])
    np.testing.assert_array_equal(s.xhat0, [630, 520, 1000, 0, 0, 0])
    np.testing.assert_array_equal(np.diag(s.B), [0.05] * 3 + [0.001] * 3)
    np.testing.assert_array_equal(np.diag(s.D), [0.1] * 3)
    assert s.K[0, 0] == -2.2541 and s.K[2, 5] == -24.2818
    assert s.n_steps == 10000 and s.time[-1] == pytest.approx(1000.0)
    # the scenario is immutable
    with pytest.raises(ValueError):
        s.K[0, 0] = 1.0


def test_24h_orbit_rate(scenario):
    # ω₀ = 2π / 86400 s (a 24 h orbit; the paper prints 7.2722e-5 rad/s)
    assert scenario.omega0 == pytest.approx(2 * np.pi / 86400, rel=1e-4)


def test_thrust_decays_in_the_first_500_s(scenario):
    # continuous closed-loop poles of A₁ + G₀K: slowest real part about -0.0096 1/s,
    # so the thrust falls below 5 % of its start in about 500 s (the paper's Fig 6 text)
    s = scenario
    A1, G0 = s.continuous_matrices()
    ev = np.linalg.eigvals(A1 + G0 @ s.K)
    assert ev.real.max() == pytest.approx(-0.0096, abs=5e-4)
    x500 = scipy.linalg.expm((A1 + G0 @ s.K) * 500) @ s.x0
    assert np.linalg.norm(s.K @ x500) < 0.05 * np.linalg.norm(s.K @ s.x0)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"dt": 0.0}, "dt must be > 0"),
        ({"delta_bar": -0.1}, "delta_bar must be >= 0"),
        ({"K": np.ones((2, 6))}, "K must have shape 3x6"),
        ({"x0": [1, 2, 3]}, "x0 must have 6 entries"),
        ({"xhat0": [np.nan] * 6}, "xhat0 must contain only finite"),
        ({"rms_window_s": (500, 100)}, "rms_window_s must satisfy"),
        ({"mass": -1}, "mass must be > 0"),
    ],
)
def test_scenario_bad_input(kwargs, message):
    with pytest.raises(InputError, match=message):
        Scenario(**kwargs)


def test_truth_matrices_reject_nonphysical_delta(scenario):
    with pytest.raises(InputError, match="delta must be > -1"):
        scenario.truth_matrices(-1.5)
    with pytest.raises(InputError, match="delta must be > -1"):
        scenario.truth_model(delta=-1.5)


def test_generic_objects_are_the_scenarios_matrices(scenario):
    # system(), measurement, controller() and truth_model() hand the generic layers exactly the
    # matrices of truth_matrices(), (8) and (3)
    s = scenario
    for delta, disc in ((0.0, "exact"), (0.3, "euler")):
        Phi, Gamma = s.truth_matrices(delta, disc)
        sysm = s.system(delta, disc)
        assert isinstance(sysm, LinearSystem)
        np.testing.assert_array_equal(sysm.Phi, Phi)
        np.testing.assert_array_equal(sysm.Gamma, Gamma)
        np.testing.assert_array_equal(sysm.B, s.B)
        assert sysm.dt == s.dt
        loop = s.system(delta, disc, closed_loop=True)
        np.testing.assert_array_equal(loop.Phi, Phi + Gamma @ s.K)
        assert loop.n_input == 0
    assert isinstance(s.measurement, LinearMeasurement)
    np.testing.assert_array_equal(s.measurement.C, measurement_matrix())
    np.testing.assert_array_equal(s.measurement.D, s.D)
    np.testing.assert_array_equal(s.controller().K, s.K)
    assert s.controller(maneuver=False) is None
    model = s.truth_model(maneuver=True, delta=0.2, discretization="euler")
    assert isinstance(model, TruthModel)
    np.testing.assert_array_equal(model.system.Phi, s.truth_matrices(0.2, "euler")[0])
    np.testing.assert_array_equal(model.x0, s.x0)
    assert model.n_steps == s.n_steps and model.controller.source == "truth"
    np.testing.assert_allclose(model.time, s.time, rtol=0, atol=0)
    assert model.settings == {"maneuver": True, "delta": 0.2, "discretization": "euler"}
    assert s.truth_model(maneuver=False).controller is None
    with pytest.raises(InputError, match="maneuver must be True or False"):
        s.truth_model(maneuver="yes")
    with pytest.raises(InputError, match="unknown discretization 'rk4'"):
        s.truth_model(discretization="rk4")
