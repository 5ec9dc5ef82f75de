"""Shi 2018 with a two-body + J2 truth (issue 35 item 3): the truth is built as stated, the filters unchanged.

Expected values: identities (the high-fidelity truth of a seed is the CW truth of the same draws plus the
noise-free difference of the two models; it starts at the scenario's x₀), the RK4 integration checked against
half the step (the step-size error is far below the model difference), and the CW closed form for the size of
the difference: over 200 s the CW and two-body + J2 relative motions of a 3 km formation differ by centimetres
to metres, not kilometres.
"""

import numpy as np

from hinfnav.papers.shi2018 import Scenario
from hinfnav.papers.shi2018.highfidelity import HighFidelityScenario, high_fidelity, relative_trajectory

SHORT = Scenario(duration_s=200.0, rms_window_s=(0.0, 200.0), maneuver_time_s=100.0)


def test_trajectory_starts_at_x0_and_is_converged_in_the_step():
    hf = relative_trajectory(SHORT)
    np.testing.assert_allclose(hf[0], SHORT.x0, rtol=0, atol=1e-9)  # Hill -> inertial -> Hill round trip
    half = relative_trajectory(SHORT, substeps=2)
    diff = hf - SHORT.nominal_trajectory()
    assert np.abs(half - hf)[:, :3].max() < 1e-6  # RK4 at 0.4 s: micrometres
    assert 1e-3 < np.abs(diff[:, :3]).max() < 5.0  # the model mismatch: millimetres to metres in 200 s
    assert np.abs(diff[:, :3]).max() > 1e3 * np.abs(half - hf)[:, :3].max()


def test_high_fidelity_truth_is_the_cw_truth_plus_the_model_difference():
    sc = high_fidelity(SHORT)
    assert isinstance(sc, HighFidelityScenario) and sc.sigma_range == SHORT.sigma_range and sc.inclination_deg == 45.0
    hf, cw = sc.simulate_truth(runs=3, seed=5), SHORT.simulate_truth(runs=3, seed=5)
    np.testing.assert_allclose(hf.x - cw.x, np.broadcast_to(sc.nominal_high_fidelity() - SHORT.nominal_trajectory(),
                                                            hf.x.shape), rtol=0, atol=1e-9)
    # the readings are re-taken from the new truth with the same noise: equal where the states are equal
    assert np.allclose(hf.y[:, 0], cw.y[:, 0], rtol=0, atol=1e-9)
    assert not np.allclose(hf.y[:, -1], cw.y[:, -1], rtol=0, atol=1e-9)
