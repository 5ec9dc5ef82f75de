"""The ADRC laws (44)-(46), Han's fal, the PID comparison and actuator saturation (hinfnav.control.adrc).

Expected values: fal's closed form, the laws computed a second way (as one
linear gain on the extended state, Scenario.linear_feedback_gain), and the
spectral radius of the linearized discrete loops (the evidence for reading
the printed integral terms as off).
"""

import numpy as np
import pytest
import scipy.linalg

import hinfnav as hn
from hinfnav.control.adrc import DragFreeADRC, NonlinearPID, fal, saturate
from hinfnav.papers.yang2020 import Scenario
from hinfnav.papers.yang2020.constants import FAL_DELTA, M_SC, NLPID_GAINS

SC = Scenario(n_steps=10)


def test_fal_closed_form():
    # fal(e, 0.5, 0.01) = e / 0.01^0.5 = 10 e inside |e| <= 0.01, sign(e) |e|^0.5 outside (Han)
    np.testing.assert_allclose(fal([0.0, 0.005, -0.005, 0.01, 0.04, -0.09]), [0, 0.05, -0.05, 0.1, 0.2, -0.3],
                               rtol=1e-15)
    assert fal(0.01 + 1e-12) == pytest.approx(0.1, rel=1e-9)  # continuous at |e| = δ
    assert fal(2.0, 1.0, 0.3) == 2.0  # α = 1 is linear
    with pytest.raises(hn.InputError, match="alpha"):
        fal(1.0, 1.5)
    with pytest.raises(hn.InputError, match="delta"):
        fal(1.0, 0.5, 0.0)


@pytest.mark.parametrize("integral, scale", [("printed", 1.0), ("dt", 0.1), ("off", 0.0)])
def test_nlpid_integral_readings(integral, scale):
    pid = NonlinearPID(1.0, 2.0, 0.0, integral=integral, dt=0.1, linear=True)
    e_i = np.zeros(1)
    for _ in range(5):
        u0, e_i = pid(np.array([1e-3]), np.array([0.0]), e_i)
    # e_i = Σ_{j<=k} e_p,j (printed), h Σ (dt), unused (off)
    assert e_i[0] == pytest.approx(scale * 5e-3, rel=1e-12)
    assert u0[0] == pytest.approx(1e-3 + (2.0 * scale * 5e-3 if integral != "off" else 0.0), rel=1e-12)
    with pytest.raises(hn.InputError, match="integral reading"):
        NonlinearPID(1, 0, 1, integral="forever")


def test_laws_44_to_46_in_fal_linear_zone_equal_the_linear_gain():
    # with the estimate equal to the truth, errors below δ and no integral, (44)-(46) are the gain K X
    law = SC.controller("adrc")
    rng = np.random.default_rng(0)
    X = rng.uniform(-1, 1, (4, 27)) * np.r_[[1e-3] * 3, [1e-5] * 3, [1e-2] * 3, [1e-4] * 3, [1e-6] * 3, [1e-2] * 3,
                                             [1e-3] * 3, [1e-5] * 3, [1e-9] * 3]
    u, u_cmd, _ = law(X, np.zeros(3), law.start(4))
    np.testing.assert_allclose(u_cmd, X @ SC.linear_feedback_gain().T, rtol=1e-12, atol=1e-18)
    np.testing.assert_array_equal(u, saturate(u_cmd, 0.03))


def test_compensation_cancels_the_estimated_disturbance():
    # (45) and (44): F_Csc and T_Csc contain -F̂_Dsc, -T̂_Dsc; the PID law does not compensate
    X = np.zeros((1, 27))
    X[0, 15:18] = [-0.012, -0.01, -0.02]
    X[0, 6:9] = [-0.005, 0.001, 0.002]
    u, _, _ = SC.controller("adrc")(X, np.zeros(3), np.zeros((1, 9)))
    np.testing.assert_allclose(u[0, 3:6], [0.012, 0.01, 0.02], rtol=1e-15)
    np.testing.assert_allclose(u[0, 0:3], [0.005, -0.001, -0.002], rtol=1e-15)
    up, _, _ = SC.controller("pid")(X, np.zeros(3), np.zeros((1, 9)))
    assert np.all(up[0, 3:6] == 0)
    X[0, 9], X[0, 12] = 1e-3, 2e-4
    up, _, _ = SC.controller("pid")(X, np.zeros(3), np.zeros((1, 9)))
    assert up[0, 3] == pytest.approx(5.55e-3 + 9 * 2e-4, rel=1e-12)  # F = -(K_P e_p + K_D e_d), e = 0 - x̂
    uo, _, _ = SC.controller("dragfree_off")(X, np.zeros(3), np.zeros((1, 9)))
    assert np.all(uo[0, 3:6] == 0)


def test_attitude_command_and_saturation():
    law = SC.controller("adrc")
    u, u_cmd, _ = law(np.zeros((1, 27)), np.array([0.01, 0.02, 0.03]), law.start(1))
    # e_p = command; fal(0.02) = √0.02 outside δ; T_Csc = I_sc T_Csc0 (44)
    T0 = 0.001 * fal(np.array([0.01, 0.02, 0.03]))
    np.testing.assert_allclose(u_cmd[0, 0:3], SC.controller().I_sc @ T0, rtol=1e-12)
    assert np.all(np.abs(u) <= 0.03) and np.any(np.abs(u_cmd) > 0.03)
    with pytest.raises(hn.InputError, match="xhat"):
        law(np.zeros((1, 18)), np.zeros(3), law.start(1))
    with pytest.raises(hn.InputError, match="attitude"):
        DragFreeADRC(I_sc=np.eye(3), I_tm=np.eye(3), m_sc=1.0, m_tm=1.0, K_trans=np.eye(3), D_trans=np.eye(3),
                     K_rot=np.eye(3), D_rot=np.eye(3), attitude=None, dragfree=law.dragfree, relative=law.relative,
                     bound=1.0)


def _loop_radius(kp, ki, kd, gain, integral_scale, h=0.1):
    """Spectral radius of a double integrator ẍ = gain·u₀ under u₀ = 10(k_p e_p + k_i e_i + k_d e_d), ZOH h.

    fal's linear zone (slope δ^{α−1} = 10); e_p = −x, e_d = −ẋ, e_i(k) = e_i(k−1) + s e_p(k).
    """
    Ad = np.array([[1.0, h], [0.0, 1.0]])
    Bd = np.array([h * h / 2, h]) * gain
    s = 10.0  # fal slope inside δ
    # state z = [x, v, e_i(k-1)]; u0 = s(kp(-x) + ki(e_i + c(-x)) + kd(-v))
    c = integral_scale
    K = s * np.array([-kp - ki * c, -kd, ki])
    A = np.zeros((3, 3))
    A[:2, :2] = Ad + np.outer(Bd, K[:2])
    A[:2, 2] = Bd * K[2]
    A[2] = [-c, 0.0, 1.0]
    if ki == 0:  # no integral term: e_i is not part of the loop
        A = A[:2, :2]
    return max(abs(np.linalg.eigvals(A)))


@pytest.mark.parametrize("loop, gain", [("attitude", 1.0), ("dragfree", 1.0 / M_SC)])
def test_printed_integral_terms_destabilize_the_loops(loop, gain):
    # the reason the default reading switches the NLPID integrals off: in fal's linear zone the printed
    # e_i (a sum over steps) gives a spectral radius > 1; without it the loop is stable (Routh, continuous:
    # attitude 0.1*0.01 < 0.01, drag-free 19*5 < 1050*1)
    assert FAL_DELTA == 0.01
    kp, ki, kd = NLPID_GAINS[loop]
    assert _loop_radius(kp, ki, kd, gain, 1.0) > 1.0
    assert _loop_radius(kp, 0.0, kd, gain, 0.0) < 1.0
    # h Σ: the attitude loop sits on the margin (0.1*0.01 = 0.001 exactly), the drag-free loop grows slowly
    assert _loop_radius(kp, ki, kd, gain, 0.1) > 1.0 - 1e-6


def test_pid_comparison_loop_is_stable():
    # F = -(5.55 e_p + 9 e_d) through 1/m_sc: stable, lightly damped (the Fig 9 baseline)
    Ad = scipy.linalg.expm(np.array([[0, 1], [-5.55 / M_SC, -9 / M_SC]]) * 0.1)
    assert max(abs(np.linalg.eigvals(Ad))) < 1.0
