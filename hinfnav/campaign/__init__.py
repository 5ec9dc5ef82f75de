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

if TYPE_CHECKING:  # the lazy exports: read by type checkers, and by lazy_exports (each loaded on first use)
    from .registry import (
        build_scenario, condition_parameters, load_providers, PROVIDER_GROUP, providers, register_scenario,
        registered_scenarios, scenario_entry, scenario_parameters,
    )
    from .spec import Campaign, canonical, Cell, digest, LIMITS, load_campaign
    from .stats import CellAccumulator, group_summary, rms_interval
    from .table import results_table, STATISTICS
    from .runner import campaign_client, campaign_units, clear_cache, read_campaign, run_campaign, run_unit, SERIAL

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

__getattr__, __dir__ = lazy_exports(__name__)
