"""Issue 30, item 4: the route from a continuous parameter family to a discrete filter at a chosen rate.

References: the exact ZOH written here with scipy.signal.cont2discrete (independent of hinfnav's discretize), and the
worst case over a dense stiffness grid of the sampled family, each norm by SLICOT (python-control linfnorm).
"""

import control
import numpy as np
import pytest
from scipy.signal import cont2discrete

from hinfnav.core.exceptions import InputError
from hinfnav.design.discretised import design_discrete_at_rate, zoh_plant

DT = 0.1
B, C, D, L = np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]), np.array([[0.1]]), np.array([[1.0, 0.0]])


def _msd(k):
    """Mass-spring-damper, m = 1 kg, c = 0.4 N s/m, stiffness k (N/m); y = q + 0.1 v, z = q."""
    return np.array([[0.0, 1.0], [-k, -0.4]]), B, C, D, L


def _error_norm(res, k):
    Ad, Bd, *_ = cont2discrete((_msd(k)[0], B, C, np.zeros((1, 1))), DT, method="zoh")
    Ab = np.block([[Ad, np.zeros((2, res.A_F.shape[0]))], [res.B_F @ C, res.A_F]])
    Bb = np.block([[Bd, np.zeros((2, 1))], [np.zeros((res.A_F.shape[0], 1)), res.B_F @ D]])
    return control.linfnorm(control.ss(Ab, Bb, np.hstack([L, -res.C_F]), 0, DT))[0]


def test_zoh_plant_matches_scipy():
    A, Bd, *_ = zoh_plant(_msd, DT)(k=1.1)
    Ar, Br, *_ = cont2discrete((_msd(1.1)[0], B, C, np.zeros((1, 1))), DT, method="zoh")
    assert np.allclose(A, Ar, atol=1e-13) and np.allclose(Bd, Br, atol=1e-13)  # same exact ZOH, round-off


def test_discrete_filter_at_rate_for_a_continuous_stiffness_family():
    out = design_discrete_at_rate(_msd, {"k": (0.8, 1.2)}, DT)
    res = out.result
    assert out.polytope.n_vertices == 2 and out.polytope.dt == DT
    # the ZOH is not affine in k: the corners' hull misses the family by more than round-off, but little (measured
    # 2.3e-7 absolute, 5.9e-6 of the spread of the two vertices; bound 1e-3), and cells shrink it (4 cells: 1.4e-8)
    assert 1e-9 < out.coverage.relative < 1e-3
    assert "vertex spread" in out.covers and "w held constant" in out.covers
    finer = design_discrete_at_rate(_msd, {"k": (0.8, 1.2)}, DT, splits={"k": 4})
    assert finer.coverage.max_distance < out.coverage.max_distance / 4  # ~quadratic in the cell width
    # the certificate covers the hull; the sampled family (41 stiffnesses, exact ZOH by scipy) is checked here: its
    # worst error norm is below the certified γ (1e-9 relative), and within 5 % of it (the vertex LMI's conservatism)
    worst = max(_error_norm(res, k) for k in np.linspace(0.8, 1.2, 41))
    assert worst <= res.gamma * (1 + 1e-9) and res.gamma <= 1.05 * worst


def test_bad_plant_is_refused_naming_it():
    with pytest.raises(InputError, match="plant_c"):
        zoh_plant(lambda k: (1.0, 2.0), DT)(k=1.0)
    with pytest.raises(InputError, match="dt"):
        design_discrete_at_rate(_msd, {"k": (0.8, 1.2)}, 0.0)
