"""Every accepted keyword is honoured or refused (issue 37, item 4): an unknown keyword raises, naming it.

As python-control's ``test_kwargs`` does, the test walks the public API — every function and class in the
``__all__`` of every hinfnav module — and calls each with a keyword nobody accepts:

* a callable without ``**kwargs`` is called with that keyword alone: Python refuses it while binding the
  arguments (nothing runs), and the test checks the error names it (a wrapper that swallowed it would not);
* a callable with ``**kwargs`` is called with valid arguments plus the keyword, from the table :data:`CALLS`,
  which must cover every such callable (a new one fails :func:`test_every_var_keyword_callable_is_covered`
  until it is added); :data:`DATA_KEYWORDS` lists those whose keywords are data by design (field changes,
  covariances by name, provenance items), each with the check that holds instead.

Expected: a ``TypeError`` or the project's ``InputError`` whose message contains the keyword. Exceptions
(``BaseException`` subclasses), classes without ``__init__`` parameters (``X() takes no arguments``) and
numba kernels refuse every keyword without naming it; they are counted separately.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import hinfnav
from hinfnav.core.exceptions import InputError

BAD = "zz_unknown_keyword"


def _public_callables():
    """(module, name, object) of every callable in an ``__all__`` of hinfnav (each object once; no Protocol)."""
    names = ["hinfnav"] + [m.name for m in pkgutil.walk_packages(hinfnav.__path__, "hinfnav.")
                           if not m.name.endswith("__main__")]
    seen, out = set(), []
    for modname in names:
        module = importlib.import_module(modname)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name, None)
            if obj is None or not callable(obj) or id(obj) in seen:
                continue
            seen.add(id(obj))
            if isinstance(obj, type) and getattr(obj, "_is_protocol", False):
                continue  # a typing.Protocol is not called (runtime isinstance checks only)
            out.append((modname, name, obj))
    return out


PUBLIC = _public_callables()


def _takes_var_keyword(obj) -> bool:
    try:
        params = inspect.signature(obj).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.kind is p.VAR_KEYWORD for p in params)


VAR_KEYWORD = {f"{m}.{n}": obj for m, n, obj in PUBLIC if _takes_var_keyword(obj)}


def _refused(call, also=()) -> str:
    """The message of the error ``call()`` raises (failing the test when it returns or raises something else)."""
    with pytest.raises((TypeError, InputError, *also)) as info:
        call()
    return str(info.value)


def test_the_walk_sees_the_public_api():
    # a floor, not an exact count: the walk must reach every subpackage (the top level alone has ~50 names)
    assert len(PUBLIC) > 500
    assert {m for m, _, _ in PUBLIC} >= {"hinfnav", "hinfnav.estimators", "hinfnav.sim", "hinfnav.papers.sun2011"}


def test_callables_without_var_keyword_refuse_an_unknown_keyword_by_name():
    unnamed, wrong = [], []
    for modname, name, obj in PUBLIC:
        if _takes_var_keyword(obj):
            continue
        try:
            obj(**{BAD: 1})
        except BaseException as err:  # any escape is judged below
            if BAD in str(err) and isinstance(err, (TypeError, InputError)):
                continue
            kernel = type(obj).__module__.startswith("numba")
            no_init = isinstance(err, TypeError) and str(err).endswith("takes no arguments")
            exception_class = isinstance(obj, type) and issubclass(obj, BaseException) and isinstance(err, TypeError)
            if kernel or no_init or exception_class:
                unnamed.append(f"{modname}.{name}")
                continue
            wrong.append(f"{modname}.{name}: {type(err).__name__}: {str(err)[:120]}")
        else:
            wrong.append(f"{modname}.{name}: accepted {BAD}=")
    assert wrong == []
    assert len(unnamed) < 80, unnamed  # numba kernels (one per compiled model function), bare bases, exceptions


# ---- callables with **kwargs: valid arguments plus the unknown keyword --------------------------------------

def _sun():
    from hinfnav.papers import sun2011

    return sun2011.Scenario(duration_s=20.0, rms_window_s=(0.0, 20.0))


def _shi():
    from hinfnav.papers import shi2018

    return shi2018.Scenario()


def _att():
    from hinfnav.papers import attitude2018

    return attitude2018.Scenario(orbits=0.01)


def _estimator_class(cls):
    def call(**kw):
        ekf = hinfnav.build_estimator(_sun(), "ekf")  # its system, measurement and P0 (Sun 2011's chaser)
        return cls(ekf.system, ekf.measurement, P0=ekf.P0, **kw)

    return call


def _attitude_class(cls):
    def call(**kw):
        sc = _att()
        return cls(sc.system(), sc.measurement, P0=sc.P0, **kw)

    return call


def _mixin(cls):
    def call(**kw):
        if BAD in kw:  # object.__init__'s refusal does not name the keyword; name it for the shared assertion
            try:
                cls(**kw)
            except TypeError as err:
                raise TypeError(f"{err} ({BAD})") from err
        return cls(**kw)

    return call


def _fig_ax():
    from hinfnav.plotting import new_figure

    fig, axes = new_figure(1, 1)
    return axes[0, 0]


def _calls():
    """Name → function of the keyword arguments: a valid call that passes them on."""
    from hinfnav import estimators as est
    from hinfnav.estimators import attitude as att
    from hinfnav.estimators import correntropy, variational

    c = {
        "hinfnav.make_noise": lambda **kw: hinfnav.make_noise("gaussian", **kw),
        "hinfnav.build_estimator": lambda **kw: hinfnav.build_estimator(_sun(), "ekf", **kw),
        "hinfnav.simulate": lambda **kw: hinfnav.simulate(_sun(), "ekf", runs=1, **kw),
        "hinfnav.simulate_closed_loop": lambda **kw: hinfnav.simulate_closed_loop(_sun(), "ekf", runs=1, **kw),
        "hinfnav.monte_carlo_statistics": lambda **kw: hinfnav.monte_carlo_statistics(
            _sun(), "ekf", windows={"all": (0.0, 20.0)}, runs=1, **kw),
        "hinfnav.campaign.build_scenario": lambda **kw: importlib.import_module("hinfnav.campaign").build_scenario(
            "sun2011", **kw),
        "hinfnav.cli.simulate_report": lambda **kw: importlib.import_module("hinfnav.cli").simulate_report(
            None, "ekf", runs=1, **kw),
        "hinfnav.estimators.gated": lambda **kw: est.gated(_estimator_class(est.ExtendedKalmanFilter)(), **kw),
        "hinfnav.io.outputs.dumps_strict": lambda **kw: importlib.import_module("hinfnav.io.outputs").dumps_strict(
            {}, **kw),
        "hinfnav.sim.simulate_batches": lambda **kw: next(iter(importlib.import_module("hinfnav.sim").simulate_batches(
            _sun(), "ekf", runs=1, **kw))),
        "hinfnav.sim.run_monte_carlo": lambda **kw: importlib.import_module("hinfnav.sim").run_monte_carlo(
            _sun(), {"ekf": "ekf"}, sink=importlib.import_module("hinfnav.sim").HistorySink(_sun().xhat0, 1), runs=1,
            **kw),
        "hinfnav.sim.montecarlo.history_bytes": lambda **kw: importlib.import_module(
            "hinfnav.sim.montecarlo").history_bytes(_sun(), 1, **kw),
        "hinfnav.sim.montecarlo.check_history_memory": lambda **kw: importlib.import_module(
            "hinfnav.sim.montecarlo").check_history_memory(_sun(), 1, **kw),
        "hinfnav.systems.flexible_attitude": lambda **kw: importlib.import_module(
            "hinfnav.systems").flexible_attitude(**kw),
        "hinfnav.systems.flexible_attitude_closed_loop": lambda **kw: importlib.import_module(
            "hinfnav.systems").flexible_attitude_closed_loop(**kw),
        "hinfnav.plotting.new_figure": lambda **kw: importlib.import_module("hinfnav.plotting").new_figure(1, 1, **kw),
        "hinfnav.plotting.plot_error_axis": lambda **kw: importlib.import_module("hinfnav.plotting").plot_error_axis(
            np.arange(3.0), np.zeros(3), ax=_fig_ax(), **kw),
    }
    for name in ("AugmentedInputHuberSTKF", "StrongTrackingEKF",
                 "HuberStrongTrackingEKF", "RateAdaptiveEKF", "AugmentedInputSTKF",
                 "AugmentedInputAdaptiveKF", "StudentTFilter", "NoiseAdaptiveFilter", "CorrentropyFilter",
                 "SquareRootEKF", "SquareRootSigmaPointFilter"):
        c[f"hinfnav.estimators.{name}"] = _estimator_class(getattr(est, name))
    for name in ("AttitudeAAEKF", "AttitudeASTEKF", "AttitudeHuberEKF", "AttitudeHuberSTEKF"):
        c[f"hinfnav.estimators.attitude.{name}"] = _attitude_class(getattr(att, name))
    # a mixin alone ends in object.__init__, which refuses any keyword left over (its filters are above)
    for key, mixin in {"hinfnav.estimators.HuberCorrection": est.HuberCorrection,
                       "hinfnav.estimators.StrongTracking": est.StrongTracking,
                       "hinfnav.estimators.RateAdaptive": est.RateAdaptive,
                       "hinfnav.estimators.correntropy.CorrentropyCorrection": correntropy.CorrentropyCorrection,
                       "hinfnav.estimators.variational.StudentTCorrection": variational.StudentTCorrection,
                       "hinfnav.estimators.variational.NoiseAdaptiveCorrection": variational.NoiseAdaptiveCorrection,
                       }.items():
        c[key] = _mixin(mixin)

    from hinfnav.papers import attitude2018, shi2018, sun2011, yang2020
    from hinfnav.papers.benchmark import estimators as bench
    from hinfnav.papers.benchmark import linear_designs
    from hinfnav.papers.shi2018 import filters as shi_filters
    from hinfnav.papers.sun2011 import filters as sun_filters

    c.update({
        "hinfnav.papers.reproduce": lambda **kw: hinfnav.papers.reproduce("sun2011", "/proc/hinfnav-never-written", **kw),
        "hinfnav.papers.attitude2018.build_aaekf": lambda **kw: attitude2018.build_aaekf(_att(), **kw),
        "hinfnav.papers.attitude2018.build_aekf": lambda **kw: attitude2018.build_aekf(_att(), **kw),
        "hinfnav.papers.attitude2018.build_astekf": lambda **kw: attitude2018.build_astekf(_att(), **kw),
        "hinfnav.papers.attitude2018.build_attitude_filter": lambda **kw: attitude2018.build_attitude_filter(
            _att(), "aekf", **kw),
        "hinfnav.papers.attitude2018.build_augmented_thrust": lambda **kw: attitude2018.build_augmented_thrust(
            _sun(), **kw),
        "hinfnav.papers.attitude2018.run_batched": lambda **kw: attitude2018.run_batched(
            _att(), attitude2018.build_aekf, "Q", [1e-14], hinfnav.simulate_truth(_att().truth_model(), runs=1), **kw),
        "hinfnav.papers.benchmark.estimators.build_generic": lambda **kw: bench.build_generic(_shi(), "ekf", **kw),
        "hinfnav.papers.benchmark.estimators.build_attitude_hbf": lambda **kw: bench.build_attitude_hbf(_att(), **kw),
        "hinfnav.papers.benchmark.estimators.build_attitude_ukf": lambda **kw: bench.build_attitude_ukf(_att(), **kw),
        "hinfnav.papers.benchmark.linear_designs.build_model_hinf": lambda **kw: linear_designs.build_model_hinf(
            _shi(), **kw),
        "hinfnav.papers.benchmark.linear_designs.build_model_lmi": lambda **kw: linear_designs.build_model_lmi(
            _sun(), **kw),  # the LMI design needs a linear measurement: Sun 2011's
        "hinfnav.papers.shi2018.HBF": lambda **kw: shi2018.HBF(_shi(), **kw),
        "hinfnav.papers.shi2018.build_hbf": lambda **kw: shi2018.build_hbf(_shi(), **kw),
        "hinfnav.papers.shi2018.filters.build_ukf": lambda **kw: shi_filters.build_ukf(_shi(), **kw),
        "hinfnav.papers.shi2018.filters.build_stekf": lambda **kw: shi_filters.build_stekf(_shi(), **kw),
        "hinfnav.papers.shi2018.filters.build_huber_stekf": lambda **kw: shi_filters.build_huber_stekf(_shi(), **kw),
        "hinfnav.papers.sun2011.build_ekf": lambda **kw: sun2011.build_ekf(_sun(), **kw),
        "hinfnav.papers.sun2011.make_estimator": lambda **kw: sun2011.make_estimator(_sun(), "ekf", **kw),
        "hinfnav.papers.sun2011.design_for_scenario": lambda **kw: sun2011.design_for_scenario(None, 0.05, **kw),
        "hinfnav.papers.sun2011.gamma_sweep": lambda **kw: sun2011.gamma_sweep(None, [0.05], **kw),
        "hinfnav.papers.sun2011.mixed_design_for_scenario": lambda **kw: sun2011.mixed_design_for_scenario(
            None, 0.05, 0.5, **kw),
        "hinfnav.papers.sun2011.mixed_front_for_scenario": lambda **kw: sun2011.mixed_front_for_scenario(
            None, 0.05, **kw),
        "hinfnav.papers.sun2011.filters.build_published": lambda **kw: sun_filters.build_published(
            _sun(), name="published", uses_input=True, **kw),
        "hinfnav.papers.sun2011.filters.build_designed": lambda **kw: sun_filters.build_designed(
            _sun(), name="designed", uses_input=True, **kw),
        "hinfnav.papers.yang2020.plot_series": lambda **kw: yang2020.plot_series(
            np.arange(3.0), np.zeros(3), ax=_fig_ax(), **kw),
        "hinfnav.papers.yang2020.plot_asd": lambda **kw: yang2020.plot_asd(
            np.arange(1.0, 4.0), np.ones(3), ax=_fig_ax(), **kw),
    })
    return c


#: Callables whose ``**`` keywords are data by design, with what holds instead of a refusal.
DATA_KEYWORDS = {
    "hinfnav.estimators.steady.freeze_gain": "the covariances by name (each one checked for convergence)",
    "hinfnav.io.provenance": "extra provenance items, recorded as given",
    "hinfnav.papers.skeleton.Reproduction": "extra summary fields of a paper, recorded as given",
    "hinfnav.papers.sun2011.paper_scenario": "Scenario fields (an unknown one is a TypeError: tested below)",
    "hinfnav.papers.shi2018.paper_scenario": "Scenario fields (an unknown one is a TypeError: tested below)",
    "hinfnav.papers.shi2018.highfidelity.high_fidelity": "Scenario fields (an unknown one is a TypeError: below)",
    "hinfnav.systems.checks.wrap_user_methods": "method name → checking wrapper (internal decorator)",
    "hinfnav.papers.notebook_kernel.KernelManager": "jupyter_client's traitlets options (configurable)",
    "hinfnav.papers.notebook_kernel.SlicedPollKernelClient": "jupyter_client's traitlets options (configurable)",
    "hinfnav.plotting.plot_sigma": "matplotlib line properties (matplotlib refuses an unknown one by name)",
    "hinfnav.plotting.plot_worst_case_over_delta": "matplotlib line properties (matplotlib refuses by name)",
    "hinfnav.papers.grace2010.NonlinearPredictionEKF": "the EKF's options (the EKF refuses an unknown one)",
    "hinfnav.papers.grace2010.filters.CompiledNonlinearPredictionEKF": "the EKF's options (the EKF refuses one)",
    "hinfnav.design.certify_loop.loop_outcome": "extra fields of the outcome dict, recorded as given (internal)",
}

CALLS = _calls()


def test_every_var_keyword_callable_is_covered():
    missing = sorted(set(VAR_KEYWORD) - set(CALLS) - set(DATA_KEYWORDS))
    assert missing == [], "add these to CALLS (or DATA_KEYWORDS, with the reason): " + ", ".join(missing)
    assert not set(CALLS) & set(DATA_KEYWORDS)


@pytest.mark.parametrize("name", sorted(CALLS))
def test_var_keyword_callable_refuses_an_unknown_keyword_by_name(name):
    assert name in VAR_KEYWORD, f"{name} no longer takes **kwargs (or left __all__): drop it from CALLS"
    # matplotlib refuses an unknown line property with AttributeError, naming it
    also = (AttributeError,) if "plot" in name else ()
    assert BAD in _refused(lambda: CALLS[name](**{BAD: 1}), also)


@pytest.mark.parametrize("name", ["hinfnav.papers.sun2011.paper_scenario", "hinfnav.papers.shi2018.paper_scenario"])
def test_scenario_field_keywords_are_refused_by_name(name):
    module, _, func = name.rpartition(".")
    assert BAD in _refused(lambda: getattr(importlib.import_module(module), func)(**{BAD: 1}))
