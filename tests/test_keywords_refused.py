"""Every accepted keyword is honoured or refused (issue 37, item 4): ``progress`` where it did nothing."""

import inspect

import pytest

from hinfnav.papers.attitude2018.chaser import chaser_study
from hinfnav.papers.sun2011.figures import paper_runs
from hinfnav.sim.montecarlo import simulate_batches


def test_progress_is_refused_where_it_was_silently_ignored():
    # issue 37 item 4: three public functions accepted `progress` and ignored it; now an unknown keyword
    for func in (simulate_batches, paper_runs, chaser_study):
        assert "progress" not in inspect.signature(func).parameters, func.__name__
    with pytest.raises(TypeError, match="progress"):
        paper_runs(progress=True)
