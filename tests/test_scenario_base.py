"""Issue 23: one Scenario base (hinfnav.sim.scenario) under every paper's Scenario.

Expected values: the definitions n_steps = round(duration_s / dt) and t_k = k dt (closed form), the
papers' documented defaults (sun2011: 0.1 s over 1000 s; shi2018: 0.4 s over 1000 s, window 200-1000 s;
yang2020: h = 0.1 s) and shi2018's earlier name ``window_s`` refused (removed in 0.3).
"""

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.papers import attitude2018, shi2018, sun2011, yang2020
from hinfnav.sim.scenario import Scenario

PAPER_SCENARIOS = (sun2011.Scenario, shi2018.Scenario, attitude2018.Scenario, yang2020.Scenario)


@pytest.mark.parametrize("cls", PAPER_SCENARIOS)
def test_every_paper_scenario_is_a_base_scenario_with_steps_and_time(cls):
    sc = cls() if cls is not yang2020.Scenario else cls(n_steps=50)
    assert isinstance(sc, Scenario)
    assert sc.n_steps == round(sc.duration_s / sc.dt)  # definition
    t = sc.time
    assert t.shape == (sc.n_steps + 1,) and t[0] == 0.0
    np.testing.assert_allclose(np.diff(t), sc.dt, rtol=1e-12)  # t_k = k dt


@pytest.mark.parametrize("cls", PAPER_SCENARIOS)
def test_replace_validates_and_names_an_unknown_field(cls):
    sc = cls() if cls is not yang2020.Scenario else cls(n_steps=50)
    with pytest.raises(InputError, match=r"unknown field 'no_such_field'; the fields are "):
        sc.replace(no_such_field=1.0)


def test_replace_changes_one_setting_and_validates_it_again():
    sc = sun2011.Scenario().replace(duration_s=200.0, rms_window_s=(100.0, 200.0))
    assert sc.n_steps == 2000 and sc.rms_window_s == (100.0, 200.0)  # 200 s at the paper's 0.1 s
    with pytest.raises(InputError, match="rms_window_s must satisfy 0 <= start < end <= duration_s = 200.0"):
        sc.replace(rms_window_s=(150.0, 300.0))
    with pytest.raises(InputError, match="rms_window_s must be a pair"):
        sc.replace(rms_window_s=5.0)


def test_rms_window_is_one_name():
    assert shi2018.Scenario().rms_window_s == (200.0, 1000.0)  # shi2018's documented window
    with pytest.raises(TypeError, match="window_s"):  # its name before issue 23, removed in 0.3
        shi2018.Scenario(window_s=(100.0, 900.0))
    with pytest.raises(InputError, match="unknown field 'window_s'"):
        shi2018.Scenario().replace(window_s=(0.0, 500.0))
    for cls in (sun2011.Scenario, shi2018.Scenario, attitude2018.Scenario):
        sc = cls()
        start, end = sc.rms_window_s
        assert 0 <= start < end <= sc.duration_s


def test_the_adaptive_filters_memory_is_memory_steps():
    # issue 23: ``window`` of the rate-adaptive filters is m, a number of steps, not a (start, end) window
    from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
    from hinfnav.papers.attitude2018.filters import build_aaekf

    sc = AttitudeScenario(orbits=0.25)
    assert build_aaekf(sc).memory_steps == 60  # paper 002's default m (constants.DEFAULT_AA)
    assert build_aaekf(sc, memory_steps=7).memory_steps == 7
    with pytest.raises(TypeError, match="window"):  # its name before issue 23, removed in 0.3
        build_aaekf(sc, window=9)
    with pytest.raises(InputError, match="memory_steps"):
        build_aaekf(sc, memory_steps=0)
