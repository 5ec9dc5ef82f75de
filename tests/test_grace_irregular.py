"""The irregular-log study of notebook 41 (``hinfnav.papers.grace2010.irregular``)."""

import numpy as np
import pytest

from hinfnav.papers import grace2010 as g
from hinfnav.papers.grace2010.irregular import filter_and_smooth, hill_timed_model, irregular_log


@pytest.fixture(scope="module")
def data():
    return g.load()


def test_every_epoch_kept_without_gaps(data):
    # closed form: 0.5 h of 10 s epochs = 180 stamps, all kept; the grid adds nothing (no step above 10 s)
    log = irregular_log(data, np.random.default_rng(0), hours=0.5, keep_fraction=1.0, gap_starts_min=())
    assert log.t.size == 180 and log.grid.t.size == 180
    np.testing.assert_array_equal(log.truth, data.truth[:180])


def test_gaps_cut_and_filled_by_the_grid(data):
    # closed form: a 150 s gap from 10 min removes the 15 epochs at 600, 610, ..., 740 s; the grid puts them back
    log = irregular_log(data, np.random.default_rng(0), hours=0.5, keep_fraction=1.0, gap_starts_min=(10.0,),
                        gap_s=150.0)
    assert log.t.size == 165
    assert not np.any((log.t >= 600.0) & (log.t < 750.0))
    np.testing.assert_allclose(log.grid.t, data.t[:180])
    np.testing.assert_array_equal(log.truth_grid, data.truth[:180])


def test_smoother_ends_on_the_filter(data):
    # the RTS smoother's estimate at the last stamp is the filter's there (its recursion starts from it), to 1e-9 m
    rng = np.random.default_rng(1)
    log = irregular_log(data, rng, hours=0.25, keep_fraction=0.5)
    timed, q = hill_timed_model(data, q=6.6e-4)   # the measured density's order (notebook 41)
    filt, sm, _ = filter_and_smooth(log, timed, rng)
    np.testing.assert_allclose(sm.xhat[0, -1], filt.xhat[0, -1], atol=1e-9)


@pytest.mark.parametrize("kwargs, name", [({"keep_fraction": 1.5}, "keep_fraction"), ({"hours": -1.0}, "hours"),
                                          ({"gap_s": -5.0}, "gap_s"), ({"hours": 100.0}, "hours")])
def test_bad_arguments_named(data, kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        irregular_log(data, np.random.default_rng(0), **kwargs)
