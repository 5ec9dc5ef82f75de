"""Every core option on every registered filter (issue 36, item 6).

``build_estimator`` applies ``missing`` (:data:`CORE_OPTIONS`)
to whatever its builder returns, so every registered estimator accepts them;
an option a builder does not have is refused by name (never a raw TypeError).
With ``missing="skip"`` a reading whose channels are all NaN leaves the
prediction as the estimate: the run with the NaN at step 3 equals, up to step
3 exclusive, the run without it (the filter is causal: the same readings give
the same estimates, 1e-12 relative).
"""

import warnings

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.estimators import build_estimator, registered_estimators
from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
from hinfnav.papers.shi2018 import Scenario as ShiScenario
from hinfnav.papers.sun2011 import Scenario
from hinfnav.papers.yang2020 import SUBSYSTEM_OF
from hinfnav.papers.yang2020 import Scenario as YangScenario
from hinfnav.sim import simulate_truth

SCENARIOS = [Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0)),
             ShiScenario(duration_s=40.0, rms_window_s=(4.0, 40.0), maneuver_time_s=20.0),
             AttitudeScenario(orbits=0.05)]
YANG = YangScenario(n_steps=300)


def scenario_of(name):
    for sc in SCENARIOS:
        if name in registered_estimators(sc):
            return sc
    return YANG.linear_truth(SUBSYSTEM_OF[name])


def truth_of(sc):
    if isinstance(sc, AttitudeScenario):
        return simulate_truth(sc.truth_model(), runs=2, seed=3)
    return simulate_truth(sc.truth_model(), runs=2, seed=3)


# the LMI-designed filters solve a design per build (2-7 s): slow
CHEAP = [pytest.param(n, marks=pytest.mark.slow) if n.startswith("designed") else n for n in registered_estimators()]


@pytest.mark.parametrize("name", CHEAP)
def test_core_options_accepted_and_unknown_ones_named(name):
    sc = scenario_of(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = build_estimator(sc, name, missing="skip")
        assert est.missing == "skip"
        with pytest.raises(InputError, match="missing"):
            build_estimator(sc, name, missing="sometimes")
        with pytest.raises(InputError, match="hbff"):
            build_estimator(sc, name, hbff=1.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", registered_estimators())
def test_missing_skip_runs_every_filter(name):
    sc = scenario_of(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = build_estimator(sc, name, missing="skip")
    tr = truth_of(sc)
    y, u = tr.y[:, :8].copy(), tr.u[:, :8]
    x0 = getattr(sc, "xhat0", None)
    x0 = tr.x[0, 0] if x0 is None else x0
    full = est.estimate(y, u, x0).xhat
    y[:, 3] = np.nan
    gap = est.estimate(y, u, x0).xhat
    assert np.isfinite(gap).all()
    np.testing.assert_allclose(gap[:, :3], full[:, :3], rtol=1e-12, atol=1e-12)
