"""The written protocols (hinfnav.core.protocols) hold for every scenario of the package and for a user's own.

Source of the expectations: the members the simulation and the campaigns look up (hinfnav.sim.engine,
hinfnav.sim.truth, hinfnav.campaign.registry), written down in hinfnav.core.protocols.
"""

import importlib

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.campaign.registry import build_scenario, registered_scenarios
from hinfnav.core.protocols import (
    CampaignTruthScenario, DesignResultProtocol, DynamicsProtocol, EstimatorHooks, MeasurementProtocol,
    OwnTruthScenario, ScenarioProtocol, TruthModelProtocol,
)

PAPERS = ("sun2011", "shi2018", "attitude2018", "yang2020")


def _scenarios():
    out = [pytest.param(lambda name=name: build_scenario(name), id=f"registered-{name}") for name in registered_scenarios()]
    return out + [pytest.param(lambda key=key: importlib.import_module(f"hinfnav.papers.{key}").Scenario(),
                               id=f"paper-{key}") for key in PAPERS]


class OwnScenario:
    """A user's scenario, written from the protocol alone: a 1-D random walk measured directly."""

    xhat0 = np.zeros(1)

    def truth_model(self, n_steps=20):
        system = hn.LinearSystem(np.eye(1), np.zeros((1, 0)), 0.1 * np.eye(1), 1.0,
                                 hn.StateSpec(("x",), ("m",)))
        return hn.TruthModel(system, hn.LinearMeasurement(np.eye(1), np.eye(1)), np.zeros(1), n_steps)


class NoStart:
    """Missing ``xhat0``: not a scenario."""

    def truth_model(self):
        return None


def test_registered_scenarios_are_the_four_papers():
    # each paper registers its scenario (hinfnav/papers/<key>/__init__.py or campaign.py)
    assert set(registered_scenarios()) >= set(PAPERS)


@pytest.mark.parametrize("make", _scenarios())
def test_every_scenario_satisfies_the_protocols(make):
    scenario = make()
    assert isinstance(scenario, ScenarioProtocol)
    model = scenario.truth_model()
    assert isinstance(model, TruthModelProtocol)
    assert isinstance(model.system, DynamicsProtocol) and isinstance(model.measurement, MeasurementProtocol)
    # the engine's dispatch: a scenario with its own truth is one of the optional protocols exactly when it
    # has the callable the engine looks up
    assert isinstance(scenario, OwnTruthScenario) == callable(getattr(scenario, "simulate_truth", None))
    assert isinstance(scenario, CampaignTruthScenario) == callable(getattr(scenario, "campaign_truth", None))


def test_a_users_scenario_satisfies_them_and_runs():
    scenario = OwnScenario()
    assert isinstance(scenario, ScenarioProtocol)
    assert not isinstance(scenario, (OwnTruthScenario, CampaignTruthScenario))
    model = scenario.truth_model()
    assert isinstance(model, TruthModelProtocol) and isinstance(model.system, DynamicsProtocol)
    truth = hn.simulate_truth(model, runs=3, seed=1)
    assert truth.x.shape == (3, 21, 1)
    # the truth is the closed form x(k+1) = x(k) + 0.1 w(k), y = x + v with w then v from run r's child generator
    rng = np.random.default_rng(1).spawn(3)[2]
    w, v = rng.standard_normal((21, 1)), rng.standard_normal((21, 1))
    x = np.concatenate([[0.0], np.cumsum(0.1 * w[:-1, 0])])
    np.testing.assert_allclose(truth.x[2, :, 0], x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(truth.y[2, :, 0], x + v[:, 0], rtol=0, atol=1e-12)


def test_a_class_missing_a_member_is_not_a_scenario():
    assert not isinstance(NoStart(), ScenarioProtocol)
    assert not isinstance(object(), DynamicsProtocol)
    assert not isinstance(OwnScenario().truth_model().system, MeasurementProtocol)  # a system is not a sensor

    class NoNoise(OwnScenario):  # a scenario whose truth model lacks its measurement is not a truth model
        def truth_model(self):
            return type("Half", (), {"system": None, "x0": None, "n_steps": 1, "controller": None, "settings": {}})()

    assert isinstance(NoNoise(), ScenarioProtocol) and not isinstance(NoNoise().truth_model(), TruthModelProtocol)


def test_estimators_and_designs_satisfy_theirs():
    from hinfnav.papers.sun2011 import load_design

    scenario = build_scenario("sun2011")
    for name in ("ekf", "published", "recursive_hinf"):  # an EKF, the LTI filter (12), a recursive H∞ filter
        assert isinstance(hn.build_estimator(scenario, name), EstimatorHooks), name
    assert not isinstance(scenario, EstimatorHooks)
    from pathlib import Path

    design = load_design(Path(__file__).parent / "data" / "designs" / "sun2011_dbar0.3_design2_98adc2f.json")
    assert isinstance(design, DesignResultProtocol)
    assert not isinstance(scenario, DesignResultProtocol)


def test_the_protocols_are_exported():
    for name in ("ScenarioProtocol", "TruthModelProtocol", "DynamicsProtocol", "MeasurementProtocol",
                 "EstimatorHooks", "DesignResultProtocol", "OwnTruthScenario", "CampaignTruthScenario"):
        assert getattr(hn, name) is getattr(hn.core, name) and name in hn.__all__
