"""Campaigns layer: grids of (scenario, estimator, noise, conditions, settings) × runs, run on Dask.

A campaign (:class:`Campaign`, or a TOML file read by :func:`load_campaign`)
names registered scenarios (:func:`register_scenario`) and estimators
(:func:`hinfnav.estimators.register_estimator`); :func:`run_campaign` runs its
cells on a Dask cluster (a LocalCluster by default), keeps streaming statistics
only, writes each finished cell to the campaign folder and returns a tidy
:class:`pandas.DataFrame`. ``python -m hinfnav campaign SPEC --out DIR`` does
the same from the command line.

Names are loaded lazily (PEP 562), as at the package's top: a paper that
registers its scenario (``from hinfnav.campaign.registry import
register_scenario``) loads neither pandas nor Dask; they come with the runner.
"""

import importlib

#: Public name -> the module (relative to this package) it comes from.
_EXPORTS = {
    "register_scenario": "registry",
    "registered_scenarios": "registry",
    "scenario_entry": "registry",
    "scenario_parameters": "registry",
    "condition_parameters": "registry",
    "build_scenario": "registry",
    "load_providers": "registry",
    "PROVIDER_GROUP": "registry",
    "providers": "registry",
    "Campaign": "spec",
    "Cell": "spec",
    "load_campaign": "spec",
    "canonical": "spec",
    "digest": "spec",
    "LIMITS": "spec",
    "CellAccumulator": "stats",
    "group_summary": "stats",
    "rms_interval": "stats",
    "results_table": "table",
    "STATISTICS": "table",
    "run_campaign": "runner",
    "read_campaign": "runner",
    "campaign_client": "runner",
    "run_unit": "runner",
    "campaign_units": "runner",
    "clear_cache": "runner",
    "SERIAL": "runner",
}

__all__ = list(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
