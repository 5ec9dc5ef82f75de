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

from typing import TYPE_CHECKING

from ..core.lazy import lazy_exports

if TYPE_CHECKING:  # what static type checkers read; the same names as _EXPORTS (tests/test_import_time.py)
    from .registry import (
        build_scenario, condition_parameters, load_providers, PROVIDER_GROUP, providers, register_scenario,
        registered_scenarios, scenario_entry, scenario_parameters,
    )
    from .spec import Campaign, canonical, Cell, digest, LIMITS, load_campaign
    from .stats import CellAccumulator, group_summary, rms_interval
    from .table import results_table, STATISTICS
    from .runner import campaign_client, campaign_units, clear_cache, read_campaign, run_campaign, run_unit, SERIAL

#: Public name -> the module (relative to this package) it comes from.
_EXPORTS = {
    "register_scenario": ".registry",
    "registered_scenarios": ".registry",
    "scenario_entry": ".registry",
    "scenario_parameters": ".registry",
    "condition_parameters": ".registry",
    "build_scenario": ".registry",
    "load_providers": ".registry",
    "PROVIDER_GROUP": ".registry",
    "providers": ".registry",
    "Campaign": ".spec",
    "Cell": ".spec",
    "load_campaign": ".spec",
    "canonical": ".spec",
    "digest": ".spec",
    "LIMITS": ".spec",
    "CellAccumulator": ".stats",
    "group_summary": ".stats",
    "rms_interval": ".stats",
    "results_table": ".table",
    "STATISTICS": ".table",
    "run_campaign": ".runner",
    "read_campaign": ".runner",
    "campaign_client": ".runner",
    "run_unit": ".runner",
    "campaign_units": ".runner",
    "clear_cache": ".runner",
    "SERIAL": ".runner",
}

__all__ = [
    "register_scenario",
    "registered_scenarios",
    "scenario_entry",
    "scenario_parameters",
    "condition_parameters",
    "build_scenario",
    "load_providers",
    "PROVIDER_GROUP",
    "providers",
    "Campaign",
    "Cell",
    "load_campaign",
    "canonical",
    "digest",
    "LIMITS",
    "CellAccumulator",
    "group_summary",
    "rms_interval",
    "results_table",
    "STATISTICS",
    "run_campaign",
    "read_campaign",
    "campaign_client",
    "run_unit",
    "campaign_units",
    "clear_cache",
    "SERIAL",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
