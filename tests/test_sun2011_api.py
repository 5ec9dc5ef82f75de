"""Issue 23, generic public API on Sun 2011's side: one builder per registered variant, the scenario first."""

import functools
import warnings

import numpy as np
import pytest

from hinfnav.estimators.registry import estimator_entry
from hinfnav.papers.sun2011 import FILTER_NAMES, Scenario, lti_from_matrices, make_estimator, published_filter
from hinfnav.papers.sun2011.designs import small_gain_bounds
from hinfnav.papers.sun2011.filters import BUILDERS, build_designed, build_published


def test_each_variant_is_registered_with_its_own_builder_and_bound_settings():
    # the registry holds the very builder of each name (no wrapper that re-reads the name); the variant's
    # settings are bound in it, so nothing parses a name to find them
    for name in FILTER_NAMES:
        assert estimator_entry(name).builder is BUILDERS[name]
        assert isinstance(BUILDERS[name], functools.partial)
    expected = {  # (builder, told the thrust, form): the module table of hinfnav.papers.sun2011.filters
        "published": (build_published, True, None),
        "published_closed_loop": (build_published, False, None),
        "designed": (build_designed, True, None),
        "designed_closed_loop": (build_designed, False, None),
        "designed_observer": (build_designed, True, "observer"),
        "designed_observer_closed_loop": (build_designed, False, "observer"),
    }
    for name, (func, told, form) in expected.items():
        b = BUILDERS[name]
        assert b.func is func and b.keywords["name"] == name and b.keywords["uses_input"] is told
        assert b.keywords.get("form") == form
    assert BUILDERS["ekf"].keywords == {"known_input": False}
    assert BUILDERS["ekf_known_input"].keywords == {"known_input": True}
    sc = Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))
    for name in ("published", "published_closed_loop", "ekf", "ekf_known_input"):
        assert make_estimator(sc, name).name == name


def test_the_earlier_argument_order_still_works_with_a_warning():
    # the same call in both orders gives the same numbers (same function underneath: exact equality)
    sc = Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))
    pub = published_filter()
    new = lti_from_matrices(sc, pub.A_F, pub.B_F, pub.C_F, name="published")
    with pytest.warns(DeprecationWarning, match=r"lti_from_matrices\(A_F, B_F, C_F, scenario\)"):
        old = lti_from_matrices(pub.A_F, pub.B_F, pub.C_F, sc, name="published")
    assert np.array_equal(old.A_F, new.A_F) and old.name == new.name
    with pytest.warns(DeprecationWarning, match="make_estimator"):
        assert make_estimator("ekf", sc).name == "ekf"
    with pytest.warns(DeprecationWarning, match="small_gain_bounds"):
        old_sg = small_gain_bounds([1.5])  # the scenario was optional and last: the paper's
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        new_sg = small_gain_bounds(None, [1.5])
    assert np.array_equal(old_sg["printed"], new_sg["printed"])
    with pytest.raises(TypeError, match="at most 2 positional"):
        make_estimator("ekf", sc, "extra")
    with pytest.raises(TypeError, match="multiple values for argument 'scenario'"):
        make_estimator("ekf", sc, scenario=sc)


def test_synthesis_result_old_attribute_names_warn_and_agree():
    """``delta_bar``/``deltas``/``worst_delta`` (before issue 23) map to the generic names, with a warning."""
    import warnings

    from hinfnav.design.result import _RENAMED, DesignResult

    res = DesignResult(A_F=np.eye(1), B_F=np.eye(1), C_F=np.eye(1), gamma=1.0, lmi_gamma=1.0, verified_norm=1.0,
                          sample_norms=np.array([0.5, 1.0]), worst_sample=1, spectral_radius=0.5, solver="x",
                          solve_time_s=0.0, total_time_s=0.0, method="minimize", uncertainty_bound=0.3,
                          sample_values=np.array([-0.3, 0.3]))
    for old, new in _RENAMED.items():
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            value = getattr(res, old)
        assert np.array_equal(value, getattr(res, new))  # the same object's value: exact
        assert any(issubclass(w.category, DeprecationWarning) and new in str(w.message) for w in caught)
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        res.nonsense  # noqa: B018
