"""Issue 23, generic public API on Sun 2011's side: one builder per registered variant, the scenario first."""

import functools


from hinfnav.estimators.registry import estimator_entry
from hinfnav.papers.sun2011 import FILTER_NAMES, Scenario, make_estimator
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
