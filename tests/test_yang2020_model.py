"""Yang et al. (2020): Table 2 transcribed, the readings, and the model (1)-(8), (10)-(13).

Expected values are the paper's printed numbers (Table 2 and Section 3), closed
forms derived from them (stated in each comment), or an independent
computation (matrix exponential by scipy).
"""

import numpy as np
import pytest
import scipy.linalg

import hinfnav as hn
from hinfnav.papers.yang2020 import TABLE2, Scenario, disturbance, drag_free_model, increment_bounds, noise_std, omega_d
from hinfnav.papers.yang2020 import constants as c


def test_table2_as_printed():
    # Table 2 of the paper, value by value
    assert c.M_TM == 1.0 and c.M_SC == 1050.0
    np.testing.assert_array_equal(c.I_TM, 0.2667e-3 * np.eye(3))
    np.testing.assert_array_equal(c.I_SC, [[200, 1, 2], [1, 2700, 1], [2, 1, 2650]])
    np.testing.assert_array_equal(c.K_TRANS, 1e-6 * np.array([[1, 0.039, 0.039], [0.039, 1, 0.039], [0.039, 0.039, 1]]))
    np.testing.assert_array_equal(c.D_TRANS, 1.4e-11 * np.eye(3))
    np.testing.assert_array_equal(c.K_ROT, 1e-9 * np.array([[1, 10, 10], [10, 1, 10], [10, 10, 1]]))
    np.testing.assert_array_equal(c.D_ROT, 1.4e-11 * np.eye(3))
    assert (c.DISTURBANCE_MEAN, c.DISTURBANCE_AMPLITUDE, c.OMEGA_D_PRINTED) == (-12.8e-3, 7.7e-3, 1.2e-3)
    np.testing.assert_allclose(c.DISTURBANCE_PHASES, [0, 2 * np.pi / 3, 4 * np.pi / 3], rtol=0, atol=0)
    assert TABLE2["omega_d"]["printed_unit"] == "Hz" and TABLE2["T_Dtm"]["value"] == 0.0


def test_section3_constants_as_printed():
    # the simulation paragraph and the controller gains of Section 3
    assert c.H == 0.1
    np.testing.assert_array_equal(c.INPUT_NOISE_DENSITY, [1e-8, 1e-8, 1e-15])
    assert (c.SENSOR_NOISE_DENSITY, c.ACCELEROMETER_NOISE_DENSITY) == (1e-8, 1e-12)
    assert c.ACCELEROMETER_RANGE == (-6e-6, 6e-6) and c.ACTUATOR_BOUND == 0.03 and c.P0_DIAGONAL == 0.01
    assert c.NLPID_GAINS == {"attitude": (0.001, 0.0001, 0.01), "dragfree": (0.5, 0.01, 1.9),
                             "relative_attitude": (0.0001, 0.0, 0.0021)}
    assert (c.FAL_ALPHA, c.FAL_DELTA, c.PID_GAINS) == (0.5, 0.01, (5.55, 0.0, 9.0))
    np.testing.assert_array_equal(c.STEP_COMMAND, [0.01, 0.02, 0.03])
    assert (c.STEP_ON, c.STEP_OFF, c.REQUIREMENT_ASD, c.REQUIREMENT_BAND_HZ) == (100_000, 200_000, 3e-14, (1e-3, 30e-3))


def test_every_reading_has_a_reason_and_a_default():
    assert set(c.READINGS) == set(c.READING_REASONS)
    sc = Scenario(n_steps=10)
    assert all(sc.readings[k] == v[0] for k, v in c.READINGS.items())


def test_disturbance_and_its_derived_span():
    # REFERENCE.md: F_Dsc/m_sc spans about -1.95e-5 ... -4.86e-6 m/s^2; omega_d read in Hz gives an 833 s period
    w = omega_d("hz")
    assert w == pytest.approx(2 * np.pi * 1.2e-3, rel=1e-15) and 2 * np.pi / w == pytest.approx(833.33, rel=1e-4)
    assert omega_d("rad_s") == 1.2e-3
    t = np.linspace(0, 2 * np.pi / w, 10001)
    F = disturbance(t, w)[:, 3:6] / c.M_SC
    assert F.min() == pytest.approx(-20.5e-3 / 1050, rel=1e-6) and F.max() == pytest.approx(-5.1e-3 / 1050, rel=1e-6)
    np.testing.assert_allclose([-1.952e-5, -4.857e-6], [F.min(), F.max()], rtol=1e-3)
    assert np.all(disturbance(t, w)[:, 6:] == 0) and np.array_equal(disturbance(t, w)[:, :3], disturbance(t, w)[:, 3:6])
    # the t restored in components 2 and 3: they vary, a third of a period apart
    np.testing.assert_allclose(disturbance(np.array([0.0]), w)[0, 1], -12.8e-3 + 7.7e-3 * np.sin(2 * np.pi / 3))


def test_increment_bounds_and_noise_conversion():
    w = omega_d()
    # q_i = (max |df/dt| h)^2 = (7.7e-3 w_d 0.1)^2 for T_Dsc and F_Dsc, 0 for T_Dtm (Section 3)
    np.testing.assert_allclose(increment_bounds(w), [(7.7e-3 * w * 0.1) ** 2] * 6 + [0.0] * 3, rtol=1e-15)
    # one-sided: sigma^2 = ASD^2 / (2 h); two-sided: ASD^2 / h; per sample: the number itself
    assert noise_std(1e-8, 0.1, "one_sided") == pytest.approx(1e-8 * np.sqrt(5), rel=1e-15)
    assert noise_std(1e-8, 0.1, "two_sided") == pytest.approx(1e-8 * np.sqrt(10), rel=1e-15)
    assert noise_std(1e-8, 0.1, "per_sample") == 1e-8
    with pytest.raises(hn.InputError, match="noise reading"):
        noise_std(1e-8, 0.1, "double")


def test_model_structure_of_eq_4():
    m = drag_free_model()
    Z, I3 = np.zeros((3, 3)), np.eye(3)
    np.testing.assert_array_equal(m.A_o[0:3, 3:6], I3)
    np.testing.assert_array_equal(m.A_o[9:12, 6:9], -c.K_TRANS / c.M_TM)
    np.testing.assert_array_equal(m.A_o[15:18, 12:15], np.linalg.inv(c.I_TM) @ c.K_ROT)  # + as printed in (3)
    np.testing.assert_array_equal(m.B_o[3:6, 0:3], np.linalg.inv(c.I_SC))
    np.testing.assert_array_equal(m.B_o[9:12, 3:6], -I3 / c.M_SC)
    np.testing.assert_array_equal(m.B_o[15:18], np.hstack([-np.linalg.inv(c.I_SC), Z, np.linalg.inv(c.I_TM)]))
    assert drag_free_model(k_rot_sign="restoring").A_o[15, 12] == -m.A_o[15, 12]
    # K_rot is indefinite (eigenvalues 21e-9, -9e-9, -9e-9): +K_rot leaves a mode growing at sqrt(21e-9 / I_tm)
    np.testing.assert_allclose(np.linalg.eigvalsh(c.K_ROT), [-9e-9, -9e-9, 21e-9], rtol=1e-12)
    assert m.info["max_unstable_rate_1_s"] == pytest.approx(np.sqrt(21e-9 / 0.2667e-3), rel=1e-3)


def test_extended_discrete_model_eqs_6_to_8():
    m = drag_free_model()
    # independent: expm of the 27-state extended A of (6), in the paper's order
    A = np.zeros((27, 27))
    B = np.zeros((27, 9))
    o = np.r_[0:6, 9:15, 18:24]  # plant states in the extended order
    f = np.r_[6:9, 15:18, 24:27]  # disturbances
    A[np.ix_(o, o)] = m.A_o
    A[np.ix_(o, f)] = m.B_o
    B[o] = m.B_o
    E = scipy.linalg.expm(np.block([[A, B], [np.zeros((9, 36))]]) * 0.1)
    np.testing.assert_allclose(m.A_d, E[:27, :27], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(m.B_d, E[:27, 27:], rtol=1e-9, atol=1e-12 * np.abs(m.B_d).max())
    np.testing.assert_array_equal(m.B_e[f], np.eye(9))
    assert np.count_nonzero(m.B_e) == 9
    np.testing.assert_array_equal(m.C_d[:, [0, 1, 2, 9, 10, 11, 18, 19, 20]], np.eye(9))
    # observable (Assumption 1)
    O = np.vstack([m.C_d @ np.linalg.matrix_power(m.A_d, k) for k in range(27)])
    assert np.linalg.matrix_rank(O) == 27


def test_per_axis_model_eqs_10_to_13():
    m = drag_free_model()
    for a in range(3):
        k, d = c.K_TRANS[a, a] / c.M_TM, c.D_TRANS[a, a] / c.M_TM
        Ac = np.array([[0, 1, 0], [-k, -d, -1 / c.M_SC], [0, 0, 0]])
        np.testing.assert_allclose(m.axis_A_d[a], scipy.linalg.expm(Ac * 0.1), rtol=1e-12, atol=1e-18)
        np.testing.assert_array_equal(m.axis_C[a], [k, d, 1 / c.M_SC])  # (11): a = K r/m + D v/m + (u+w+f)/m_sc
    assert np.all(m.axis_D == 1 / c.M_SC)


def test_scenario_rejects_unknown_readings():
    with pytest.raises(hn.InputError, match="omega_d reading"):
        Scenario(omega_d="khz")
    with pytest.raises(hn.InputError, match="integral reading"):
        Scenario(integral="sometimes")
    with pytest.raises(hn.InputError, match="n_steps"):
        Scenario(n_steps=0)
