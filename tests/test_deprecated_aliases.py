"""The top-level API is generic; Sun 2011's names moved to ``hinfnav.papers.sun2011`` (issue 23, item 3).

Source: issue 23, "What to build" 3: ``hinfnav.__all__`` holds the generic names, the paper names
live in ``hinfnav.papers.<key>``, with deprecation aliases at the top level for one release,
warning when used. The warning is a FutureWarning (see the docstring of ``hinfnav/__init__.py``:
a DeprecationWarning raised through ``from hinfnav import X`` is hidden by Python's default filters).
"""

import warnings

import pytest

import hinfnav
import hinfnav.papers.sun2011 as sun2011

MOVED = sorted(hinfnav._MOVED)


def test_the_moved_names_are_sun2011s_exports():
    # the 19 names hinfnav re-exported from papers.sun2011 up to 0.2 (hinfnav/__init__.py at 98adc2f)
    assert len(MOVED) == 19
    assert set(MOVED) <= set(sun2011.__all__)


@pytest.mark.parametrize("name", MOVED)
def test_alias_warns_naming_the_new_home_and_returns_the_same_object(name):
    with pytest.warns(FutureWarning, match=rf"hinfnav\.papers\.sun2011\.{name}\b"):
        value = getattr(hinfnav, name)
    assert value is getattr(sun2011, name)


def test_from_import_warns_once_at_the_importing_line():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        namespace = {}
        exec(compile("from hinfnav import Scenario", "user_code.py", "exec"), namespace)
    moved = [w for w in caught if issubclass(w.category, FutureWarning)]
    assert len(moved) == 1, [str(w.message) for w in caught]
    assert moved[0].filename == "user_code.py"
    assert namespace["Scenario"] is sun2011.Scenario


def test_every_use_warns_not_only_the_first():
    for _ in range(2):
        with pytest.warns(FutureWarning):
            hinfnav.kalman_limit  # noqa: B018


def test_no_paper_name_in_the_top_level_api():
    assert not set(MOVED) & set(hinfnav.__all__)
    assert not set(MOVED) & set(dir(hinfnav))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no exported name is a deprecated alias
        for name in hinfnav.__all__:
            module = getattr(getattr(hinfnav, name), "__module__", "") or ""
            assert not module.startswith("hinfnav.papers"), f"hinfnav.{name} comes from {module}"


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'Scenarioo'"):
        hinfnav.Scenarioo  # noqa: B018
