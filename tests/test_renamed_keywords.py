"""Issue 23: ``window`` renamed where it is not a (start, end) time window; the earlier names warn and work.

Every renamed keyword still works for one release (until hinfnav 0.3) with a DeprecationWarning and gives
what the new name gives; both names together are an InputError. The expected values are the results of
the same call under the new name (an independent call), and for the K-band noise the Savitzky–Golay
window that the summary records.
"""

import inspect
import types
import warnings

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.core.deprecation import UNTIL, renamed_keywords, translate_keywords
from hinfnav.papers.attitude2018.chaser import build_augmented_thrust, plot_chaser
from hinfnav.papers.attitude2018.figures import fig_fading
from hinfnav.papers.attitude2018.filters import build_aaekf
from hinfnav.papers.grace2010.figures import errors_figure
from hinfnav.papers.grace2010.measurements import kband_noise
from hinfnav.papers.sun2011 import Scenario as ChaserScenario

#: Every keyword issue 23 renamed in a function: function → {earlier name: present name}.
RENAMED = {
    plot_chaser: {"window_s": "moving_rms_s"},
    build_aaekf: {"window": "memory_steps"},
    build_augmented_thrust: {"window": "memory_steps"},
    fig_fading: {"window": "mean_steps"},
    errors_figure: {"window": "rms_epochs"},
    kband_noise: {"window": "savgol_length"},
}


def test_translate_maps_the_earlier_name_with_a_warning_and_refuses_both():
    with pytest.warns(DeprecationWarning, match=rf"f: 'window' is deprecated, use 'mean_steps' .*hinfnav {UNTIL}"):
        assert translate_keywords("f", {"window": "mean_steps"}, {"a": 1, "window": 5}) == {"a": 1, "mean_steps": 5}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the present names: no warning
        assert translate_keywords("f", {"window": "mean_steps"}, {"mean_steps": 5}) == {"mean_steps": 5}
    with pytest.raises(InputError, match="f: give 'mean_steps' only"):
        translate_keywords("f", {"window": "mean_steps"}, {"window": 5, "mean_steps": 6})


def test_the_decorated_function_warns_at_the_callers_line():
    @renamed_keywords(window="mean_steps")
    def f(x, mean_steps=3):
        return x * mean_steps

    assert f(2) == 6 and f(2, mean_steps=4) == 8
    with pytest.warns(DeprecationWarning) as record:
        assert f(2, window=4) == 8
    assert record[0].filename == __file__  # points at this call, not at the decorator


@pytest.mark.parametrize("func", list(RENAMED), ids=lambda f: f.__name__)
def test_every_renamed_keyword_is_declared_on_its_function(func):
    assert func.renamed_keywords == RENAMED[func]
    params = inspect.signature(func).parameters
    for old, new in RENAMED[func].items():
        takes_new = new in params or any(p.kind is p.VAR_KEYWORD for p in params.values())  # or passes it on
        assert takes_new and old not in params  # the present name in the signature, the old one only mapped


def test_kband_noise_under_the_earlier_name_gives_the_same_numbers():
    rng = np.random.default_rng(5)
    t = np.arange(400.0)
    data = types.SimpleNamespace(kband=2.2e5 + 3.0 * np.sin(t / 40.0) + 1e-5 * rng.standard_normal(400),
                                 baseline=2.2e5 + 3.0 * np.sin(t / 40.0))
    new = kband_noise(data, savgol_length=15)
    with pytest.warns(DeprecationWarning, match="'window' is deprecated, use 'savgol_length'"):
        old = kband_noise(data, window=15)
    assert old == new and new["savgol_window"] == 15  # the same call, bit for bit
    with pytest.raises(InputError, match="give 'savgol_length' only"):
        kband_noise(data, window=15, savgol_length=11)


def test_errors_figure_under_the_earlier_name_draws_the_same_curves():
    t = np.arange(0.0, 3600.0, 10.0)
    errors = {"ekf": np.random.default_rng(1).standard_normal((t.size, 6)) * 0.03}
    new = errors_figure(t, errors, "gnss", rms_epochs=12)
    with pytest.warns(DeprecationWarning, match="'window' is deprecated, use 'rms_epochs'"):
        old = errors_figure(t, errors, "gnss", window=12)
    for a_new, a_old in zip(new.axes, old.axes):
        np.testing.assert_array_equal(a_new.lines[0].get_ydata(), a_old.lines[0].get_ydata())  # bit for bit


def test_the_rate_adaptive_chaser_filter_takes_its_memory_under_the_earlier_name():
    sc = ChaserScenario()
    assert build_augmented_thrust(sc, "adaptive").memory_steps == 50  # THRUST_MEMORY_STEPS (5 s at T = 0.1 s)
    with pytest.warns(DeprecationWarning, match="'window' is deprecated, use 'memory_steps'"):
        assert build_augmented_thrust(sc, "adaptive", window=9).memory_steps == 9
    with pytest.raises(InputError, match="give 'memory_steps' only"):
        build_augmented_thrust(sc, "adaptive", window=9, memory_steps=8)
