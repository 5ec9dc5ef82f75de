"""Huang et al. (2017)'s benchmark, reduced runs: the Student-t filter below Huber's filter, Monte Carlo-significant.

The set-up (hinfnav.papers.benchmark.huang2017, from the paper's §V) is checked first against a closed form: the
Kalman filter told the mixtures' true covariances has the steady-state position RMS sqrt(tr P_pos) of its Riccati
equation (scipy's DARE, computed here), the pooled ARMSE over 100 steps within 8 % of it (transient and sampling).
Then the claim: the Student-t filter's position ARMSE is below Huber's, the run-by-run (paired) difference's 95 %
interval excluding 0 (the paper; an independent port in issue 33 gives 17.35 m against 18.66 m at 1000 runs;
measured here at 100 runs: 15.08 m against 18.85 m, paired difference -4.15 m [-5.43, -2.87]; at 1000 runs
17.52 m against 18.75 m, -3.18 m [-3.78, -2.58], the KFTCM 26.33 m).
"""

import numpy as np
import scipy.linalg

from hinfnav.papers.benchmark.huang2017 import SETUP, huang_comparison, huang_system, huang_truth


def test_kf_with_true_covariances_matches_its_riccati_limit():
    system, meas = huang_system()
    Q_true = (0.95 + 0.05 * 100) * system.Q
    R_true = (0.9 + 0.1 * 100) * meas.R
    H = meas.H
    P = scipy.linalg.solve_discrete_are(system.Phi.T, H.T, Q_true, R_true)  # prior covariance
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R_true)
    steady = np.sqrt(np.trace((P - K @ H @ P)[:2, :2]))  # 26.38 m
    table = huang_comparison(runs=100, names=["kf_true_cov"], reference="kf_true_cov").set_index("filter")
    np.testing.assert_allclose(table.loc["kf_true_cov", "armse_m"], steady, rtol=0.08)


def test_student_t_below_huber_with_a_paired_interval_excluding_zero():
    table = huang_comparison(runs=100, names=["hbf", "stkf"], reference="hbf").set_index("filter")
    st = table.loc["stkf"]
    assert st.armse_m < table.loc["hbf", "armse_m"]
    assert st.vs_hbf_m_high < 0.0, (st.vs_hbf_m, st.vs_hbf_m_low, st.vs_hbf_m_high)


def test_record_does_not_depend_on_the_number_of_runs():
    # each run draws from its own child seed: the first 3 runs of a 5-run record are the 3-run record (identity)
    x3, y3 = huang_truth(3, 20, seed=4)
    x5, y5 = huang_truth(5, 20, seed=4)
    np.testing.assert_array_equal(y3, y5[:3])
    np.testing.assert_array_equal(x3, x5[:3])
    assert SETUP["p_measurement"] == 0.9 and SETUP["scale_measurement"] == 100.0  # the paper's outlier model
