"""Run a campaign on Dask: cells as tasks, streaming statistics only, one JSON per finished cell, resumable.

:func:`run_campaign` sends the campaign's cells to a Dask cluster — by default
a :class:`distributed.LocalCluster` with one single-threaded worker process per
core of this machine, or the cluster of a given :class:`distributed.Client` or
scheduler address — and collects each cell's statistics as it finishes. With
``share_truth`` (the default) one task simulates a grid point's truth batch by
batch and runs every estimator of that point on it; otherwise one task runs
one cell. A task keeps streaming statistics only (:mod:`.stats`), so its
memory is that of one batch of runs, whatever ``runs``.

Finished cells are written to ``out_dir/cells/<cell_id>.json`` by the client
as they arrive (written to a temporary name, then renamed: a cell file is
whole or absent), so an interrupted campaign, run again into the same folder,
computes only the cells that are missing. ``out_dir/campaign.json`` holds the
spec and ``out_dir/results.csv`` the tidy table.

Each cell also gets its consistency (NEES, NIS, χ² bounds, ``diverged``;
:mod:`hinfnav.metrics.consistency`) and a ``diverged`` field: true when
runs blew up (then the status is ``"diverged"`` too) or when the mean NEES
is beyond its 95 % bound (status ``"ok"``: the estimates are usable, the
covariance is not); :func:`run_campaign` warns
(:class:`~hinfnav.core.exceptions.FilterDivergenceWarning`) for each such
cell it computes. The covariance histories this needs are kept for
:data:`CONSISTENCY_BYTES` at most: a batch is run in chunks of runs below that.

The numbers do not depend on the number of workers, the order of completion
or a resume: each cell's seed comes from the spec (:mod:`.spec`), each run
draws from its own child generator, and the batches are those of the spec's
``batch_size`` (tested bitwise against a serial run).
"""

from __future__ import annotations

import contextlib
from collections import defaultdict
import importlib
import json
import logging
import os
import signal
import threading
import time
from collections.abc import Collection, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tqdm import tqdm

from ..core.exceptions import HinfnavError, InputError
from ..io.outputs import MARKER, check_output_dir, output_lock, to_json
from ..io.progress import bar_disabled
from ..io.provenance import package_version
from ..estimators.registry import build_estimator, estimator_entry
from ..metrics.accumulator import GATE_KEY, StatisticsSink
from ..metrics.consistency import NIS_KEYS, warn_if_diverged
from ..sim.engine import run_monte_carlo, truth_batch
from .registry import build_scenario, scenario_entry
from .spec import canonical, load_campaign
from .table import results_table

if TYPE_CHECKING:
    import pandas as pd

    from .spec import Campaign

__all__ = ["run_campaign", "read_campaign", "campaign_client", "run_unit", "campaign_units", "clear_cache", "cell_truth",
           "SERIAL"]

#: ``client=SERIAL`` runs every task in this process, one after another (no cluster; for debugging and tests).
SERIAL = "serial"
#: Bytes of covariance, innovation and S histories one estimator run may keep (the runs of a batch are chunked below).
CONSISTENCY_BYTES = 2**29

_BUILT = {}  # per process: (scenario, settings, estimator, options) -> Estimator (designs are solved once)
_MAX_BUILT = 64


def clear_cache() -> None:
    """Forget the estimators this process has built (designs are solved again on next use)."""
    _BUILT.clear()


def _key(*parts):
    return json.dumps(canonical(list(parts)), sort_keys=True)


def _scenario(name, settings):
    key = _key("scenario", name, settings)
    if key not in _BUILT:
        _BUILT[key] = build_scenario(name, **settings)
    return _BUILT[key]


def _estimator(scenario, name, settings, est, options):
    key = _key("estimator", name, settings, est, options)
    if key not in _BUILT:
        if len(_BUILT) >= _MAX_BUILT:
            _BUILT.clear()
        _BUILT[key] = build_estimator(scenario, est, **options)
    built = _BUILT[key]
    built.nonfinite = "flag"  # a run that blows up is counted (status "diverged"), not the end of the cell
    return built


def campaign_units(campaign: Campaign, pending: Collection[str] | None = None) -> list[dict[str, Any]]:
    """The tasks of a campaign: dicts holding one truth and the cells (estimators) to run on it.

    Parameters
    ----------
    campaign : Campaign
    pending : set of str, optional
        Cell ids still to compute (default: all).
    """
    units = {}
    for cell in campaign.cells():
        if pending is not None and cell.cell_id not in pending:
            continue
        key = cell.truth_key if campaign.share_truth else cell.cell_id
        if key not in units:
            modules = {scenario_entry(cell.scenario).factory.__module__}
            units[key] = {"scenario": cell.scenario, "settings": cell.settings, "conditions": cell.conditions,
                          "noise": cell.noise, "seed": cell.seed, "runs": campaign.runs,
                          "batch_size": campaign.batch_size, "windows": campaign.windows, "tol": campaign.tol,
                          "cells": [], "modules": modules}
        units[key]["cells"].append({"cell_id": cell.cell_id, "estimator": cell.estimator, "options": cell.options,
                                    "params": cell.params})
        units[key]["modules"].add(estimator_entry(cell.estimator).builder.__module__)
    out = list(units.values())
    for unit in out:
        unit["modules"] = sorted(unit["modules"])
    return out


def run_unit(unit: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Run one task (see :func:`campaign_units`); return one result dict per cell.

    Executed on a worker: imports the modules that register the scenario and
    the estimators, simulates the truth batch by batch and runs every
    estimator of the unit on each batch. An estimator that fails is reported
    with ``status="error"`` (and is not written: a resume tries it again); one
    whose estimates are not finite or whose error left the divergence bound gets ``status="diverged"``.
    """
    for module in unit["modules"]:
        importlib.import_module(module)
    _BUILT.update(unit.get("built", {}))  # the estimators built (and designed) once by the validation
    t_start, c_start = time.perf_counter(), time.process_time()
    scenario = _scenario(unit["scenario"], unit["settings"])
    runs, bs = unit["runs"], unit["batch_size"]
    cells = unit["cells"]
    estimators = {}
    sink = _UnitSink(unit["windows"], runs, scenario.xhat0, unit["tol"])
    for c in cells:
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            estimators[c["cell_id"]] = _estimator(scenario, unit["scenario"], unit["settings"], c["estimator"],
                                                  c["options"])
        except Exception as exc:
            sink.fail(c["cell_id"], exc)
        sink.timed(c["cell_id"], time.perf_counter() - t0, time.process_time() - c0)
    if estimators:  # the engine's open loop; each cell's failures and time kept apart by the sink
        run_monte_carlo(scenario, estimators, sink=sink, runs=runs, seed=unit["seed"], batch_size=bs,
                        noise=unit["noise"], keep_covariance=True, diagnostics=NIS_KEYS + (GATE_KEY,), max_bytes=CONSISTENCY_BYTES,
                        **unit["conditions"])
    errors, elapsed, cpu, accs = sink.errors, sink.elapsed, sink.cpu, sink.accumulators
    truth_s, truth_cpu = sink.truth_s, sink.truth_cpu
    out = []
    for c in cells:
        cid = c["cell_id"]
        res = {"cell_id": cid, "params": c["params"], "options": c["options"], "seed": unit["seed"], "runs": runs,
               "batch_size": bs, "hinfnav": package_version(),
               "timing": {"estimator_s": elapsed[cid], "estimator_cpu_s": cpu[cid], "truth_s": truth_s,
                          "truth_cpu_s": truth_cpu, "unit_s": time.perf_counter() - t_start,
                          "unit_cpu_s": time.process_time() - c_start, "unit_cells": len(cells)}}
        if cid in errors:
            res.update(status="error", error=errors[cid])
        else:
            stats = accs[cid].result(c["estimator"])
            blown = stats["nonfinite_runs"] or stats["consistency"]["diverged_runs"]
            res.update(status="diverged" if blown else "ok", diverged=stats["consistency"]["diverged"], statistics=stats)
        out.append(res)
    return out


def cell_truth(scenario, conditions, noise, *, seed, runs, first_run=0):
    """Runs ``first_run … first_run + runs − 1`` of a cell's truth (:class:`~hinfnav.sim.truth.Truth`): the engine's
    :func:`~hinfnav.sim.engine.truth_batch` (the scenario's own ``campaign_truth`` or ``simulate_truth`` when it has
    one, else its ``truth_model(**conditions)``, linear or stepping itself). The same seed gives the same runs whatever
    the batches."""
    return truth_batch(scenario, conditions, noise=noise, runs=runs, seed=seed, first_run=first_run)


class _UnitSink(StatisticsSink):
    """The engine's statistics sink of one task: also each cell's error (the cell then stops, the others go on)
    and its wall and CPU seconds, and the seconds spent on the truth."""

    def __init__(self, windows, runs, xhat0, tol):
        super().__init__(windows, runs, xhat0, tol)
        self.errors, self.elapsed, self.cpu = {}, defaultdict(float), defaultdict(float)
        self.truth_s = self.truth_cpu = 0.0

    def fail(self, name, exc):
        self.errors[name] = f"{type(exc).__name__}: {exc}"

    def timed(self, name, wall_s, cpu_s):
        if name is None:
            self.truth_s += wall_s
            self.truth_cpu += cpu_s
        else:
            self.elapsed[name] += wall_s
            self.cpu[name] += cpu_s


class CellResults(tuple):
    """The cell results kept in a table's ``attrs["cells"]``: a tuple that is not copied with the table.

    pandas deep-copies ``attrs`` whenever it makes a new frame from the table
    (a selection, a row of ``itertuples``…); with hundreds of cells that
    made a 20 000-row table take minutes to iterate. The results are
    read-only records, so a copy is the same object.
    """

    def __deepcopy__(self, memo):
        return self

    def __copy__(self):
        return self


def _clean(obj):
    """JSON-ready, with NaN and inf as null (strict JSON)."""
    return to_json(obj, strict=True)


def _atomic_write(path, text):
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    except BaseException:  # a full disk or Ctrl-C: no temporary file left behind
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise


def _read_cell(path, cell_id):
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("cell_id") != cell_id or data.get("status") not in ("ok", "diverged"):
        return None
    return data


def _main_thread():
    return threading.current_thread() is threading.main_thread()


def _open_client(client, workers, connect_timeout):
    """``(client, owned)``: the client to use and whether this call made it (and must close it)."""
    from distributed import Client, LocalCluster  # heavy optional library: imported when a campaign runs

    if client is None:
        n = workers if workers is not None else (os.cpu_count() or 1)
        try:
            # the worker processes start with Ctrl-C ignored (an ignored signal stays ignored in a child): a Ctrl-C
            # then reaches this process alone, which stops the campaign in one line and closes the cluster, instead
            # of every worker printing its own traceback
            previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if _main_thread() else None
            try:
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                       silence_logs=logging.ERROR)
            finally:
                if previous is not None:
                    signal.signal(signal.SIGINT, previous)
        except KeyboardInterrupt:
            raise
        except Exception as exc:  # "Nanny failed to start" and the like: one line, the cause named
            cause = exc.__cause__ or exc.__context__ or exc
            raise HinfnavError(f"the local Dask cluster did not start ({n} worker processes): {type(exc).__name__}: "
                               f"{exc} (cause: {type(cause).__name__}: {cause}); a worker killed or out of memory "
                               "while starting? try again, or with fewer --workers") from None
        return Client(cluster), True
    if isinstance(client, str):
        try:
            return Client(client, timeout=connect_timeout), True
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"scheduler: cannot connect to {client!r} within {connect_timeout:g} s ({exc})") from None
    if isinstance(client, Client):
        return client, False
    raise InputError(f"client must be None, {SERIAL!r}, a scheduler address or a distributed.Client; "
                     f"got {type(client).__name__}")


@contextlib.contextmanager
def campaign_client(client: Any = None, *, workers: int | None = None,
                    connect_timeout: float = 5.0) -> Iterator[Any]:
    """Context manager: the Dask client for several campaigns (a LocalCluster started once, closed at the end).

    ``client`` as in :func:`run_campaign`; ``"serial"`` is passed through. Yields what to pass as ``client``.
    """
    if client == SERIAL:
        yield SERIAL
        return
    dask_client, owned = _open_client(client, workers, connect_timeout)
    try:
        yield dask_client
    finally:
        if owned:
            _close(dask_client)


def _close(dask_client):
    cluster = dask_client.cluster
    dask_client.close()
    if cluster is not None:
        cluster.close()


def _differences(old, new):
    """Fields in which two spec dicts (``Campaign.as_dict``) differ, as ``field: old → new`` strings."""
    same = lambda a, b: canonical(a) == canonical(b)
    out = []
    for key in sorted(set(old) | set(new)):
        a, b = old.get(key), new.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            out += [f"{key}.{k}: {a.get(k)!r} there, {b.get(k)!r} here" for k in sorted(set(a) | set(b))
                    if not same(a.get(k), b.get(k))]
        elif not same(a, b):
            out.append(f"{key}: {a!r} there, {b!r} here")
    return out


def _prepare_out(out, campaign):
    """Make the campaign folder ready (the caller holds its lock): same spec or none, no orphan temporary files."""
    meta = {"spec": _clean(campaign.as_dict()), "cells": [c.cell_id for c in campaign.cells()]}
    meta = json.loads(json.dumps(meta))  # what campaign.json will hold, to compare like with like
    try:
        old = json.loads((out / "campaign.json").read_text())["spec"]
    except (OSError, ValueError, KeyError, TypeError):
        old = None
    if old is not None and canonical(old) != canonical(meta["spec"]):
        diff = _differences(old, meta["spec"])
        raise InputError(f"out_dir {out} holds another campaign ({old.get('name')!r}; this spec is "
                         f"{campaign.name!r}); they differ in {'; '.join(diff)}. Choose another folder, or delete "
                         "this one to start over")
    (out / "cells").mkdir(parents=True, exist_ok=True)
    for orphan in [*(out / "cells").glob(".*.tmp"), *out.glob(".*.tmp")]:  # writes of a killed run
        orphan.unlink(missing_ok=True)
    if not (out / MARKER).exists():
        (out / MARKER).write_text("written by hinfnav: a campaign folder; finished cells are kept and reused\n")
    _atomic_write(out / "campaign.json", json.dumps(meta, indent=2) + "\n")
    return out


def _check_estimators(campaign):
    """Build every estimator once on every validated scenario (cached): bad options, a filter for another dt…"""
    for scenario_name, settings, scenario, names in campaign.tried():
        for est in names:
            options = campaign.estimator_options.get(est, {})
            try:
                _estimator(scenario, scenario_name, settings, est, options)
            except (HinfnavError, TypeError, ValueError) as exc:
                field = f"estimator_options.{est}" if options else f"grid.estimator ({est!r})"
                where = ", ".join([f"scenario = {scenario_name!r}"] + [f"{k} = {v!r}" for k, v in settings.items()])
                raise InputError(f"{field}: cannot build {est!r} for {where}: {exc}") from None


def run_campaign(spec: Campaign | Mapping[str, Any] | str | os.PathLike[str], client: Any = None,
                 out_dir: str | os.PathLike[str] | None = None, progress: bool = True, *, workers: int | None = None,
                 connect_timeout: float = 5.0, limits: Mapping[str, float] | None = None) -> pd.DataFrame:
    """Run a campaign on Dask and return its tidy results table.

    With the default LocalCluster, a script must call it under ``if __name__ == "__main__":`` (Dask starts its
    worker processes by re-importing the script, which without the guard would start the campaign again)::

        import hinfnav as hn

        if __name__ == "__main__":
            table = hn.run_campaign("benchmarks/campaign_example.toml", out_dir="results/example")

    Before any work the spec is checked whole (:meth:`hinfnav.campaign.spec.Campaign.cells`: limits, names,
    values; then every estimator is built once on every validated scenario), and ``out_dir`` is locked (an
    OS-level lock beside it: a second process into the same folder is refused) and must hold no campaign
    or this one (a folder holding another spec is refused, naming what differs).

    Parameters
    ----------
    spec : Campaign, dict or path of a TOML file
        See :mod:`hinfnav.campaign.spec`.
    client : None, "serial", str or distributed.Client
        None: a new :class:`distributed.LocalCluster` (``workers`` processes,
        default one per core), closed at the end. A string: the address of a
        running scheduler (``tcp://host:8786``). A Client: its cluster.
        ``"serial"``: every task in this process, one after another.
    out_dir : str or Path, optional
        Folder of the campaign: cells already there are reused, new ones are
        written as they finish, ``results.csv`` at the end. None: nothing is
        written (and nothing can be resumed).
    progress : bool
        Show a progress bar over the cells (and the runs they hold).
    workers : int, optional
        Worker processes of the LocalCluster (only with ``client=None``).
    connect_timeout : float
        Seconds to wait for a scheduler address before giving up.
    limits : dict, optional
        Overrides of the stated maxima :data:`hinfnav.campaign.spec.LIMITS` (``runs``, ``cells``, ``steps``,
        ``batch_bytes``), e.g. ``{"runs": 10**7}``.

    Returns
    -------
    pandas.DataFrame
        One row per cell, window, quantity (state component or group) and
        statistic (:func:`hinfnav.campaign.table.results_table`);
        ``attrs`` holds ``campaign`` (the spec), ``computed`` and ``reused``
        (cell counts), ``errors`` (cell id → message) and ``cells`` (the cell
        results, in grid order).
    """
    campaign = load_campaign(spec)
    cells = campaign.cells(limits)  # limits, names and values, before any work
    _check_estimators(campaign)
    if workers is not None:
        if client is not None:
            raise InputError(f"workers applies to the LocalCluster that run_campaign starts (client=None) only; "
                             f"got client={client!r}")
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise InputError(f"workers must be an integer >= 1; got {workers!r}")
    if not (isinstance(connect_timeout, (int, float)) and connect_timeout > 0):
        raise InputError(f"connect_timeout must be a number of seconds > 0; got {connect_timeout!r}")
    out = check_output_dir(out_dir, "out_dir") if out_dir is not None else None
    with output_lock(out, "out_dir") if out is not None else contextlib.nullcontext():
        return _run_locked(campaign, cells, client, out, progress, workers, connect_timeout)


def _run_locked(campaign, cells, client, out, progress, workers, connect_timeout):
    if out is not None:
        _prepare_out(out, campaign)
    results = {}
    if out is not None:
        for cell in cells:
            found = _read_cell(out / "cells" / f"{cell.cell_id}.json", cell.cell_id)
            if found is not None:
                results[cell.cell_id] = found
    reused = len(results)
    units = campaign_units(campaign, pending={c.cell_id for c in cells} - set(results))
    units.sort(key=lambda u: -len(u["cells"]) * u["runs"])  # largest first: a shorter tail
    errors, computed = {}, 0
    bar = tqdm(total=len(cells), initial=reused, disable=bar_disabled(progress), desc=campaign.name, unit="cell")

    def collect(unit_results):
        nonlocal computed
        for res in unit_results:
            if res["status"] == "error":
                errors[res["cell_id"]] = res["error"]
            else:
                computed += 1
                results[res["cell_id"]] = res
                warn_if_diverged(res["statistics"]["consistency"], f"{res['params'].get('estimator')} in cell "
                                 f"{res['cell_id']}")
                if out is not None:
                    _atomic_write(out / "cells" / f"{res['cell_id']}.json", json.dumps(_clean(res), indent=1) + "\n")
        bar.update(len(unit_results))
        bar.set_postfix(runs=f"{(len(results) + len(errors)) * campaign.runs}/{len(cells) * campaign.runs}")

    try:
        if units and client == SERIAL:
            for unit in units:
                collect(run_unit(unit))
        elif units:
            for unit in units:  # ship the estimators the validation built: no worker designs them again
                keys = {_key("estimator", unit["scenario"], unit["settings"], c["estimator"], c["options"])
                        for c in unit["cells"]}
                unit["built"] = {k: _BUILT[k] for k in keys if k in _BUILT}
            _run_distributed(units, client, workers, connect_timeout, collect)
    finally:
        bar.close()
    ordered = [results[c.cell_id] for c in cells if c.cell_id in results]
    table = results_table(ordered)
    if out is not None:
        tmp = out / f".results.csv.{os.getpid()}.tmp"
        table.to_csv(tmp, index=False)
        os.replace(tmp, out / "results.csv")
    table.attrs.update(campaign=campaign.as_dict(), computed=computed, reused=reused, errors=errors,
                       cells=CellResults(ordered), out_dir=None if out is None else str(out))
    return table


def _run_distributed(units, client, workers, connect_timeout, collect):
    from distributed import as_completed  # heavy optional library: imported when a campaign runs

    dask_client, owned = _open_client(client, workers, connect_timeout)
    futures = []
    try:
        for i, unit in enumerate(units):
            futures.append(dask_client.submit(run_unit, unit, pure=False, priority=len(units) - i,
                                              key=f"campaign-unit-{unit['cells'][0]['cell_id']}"))
        for fut in as_completed(futures):
            collect(fut.result())
    finally:
        for fut in futures:
            fut.cancel()
        if owned:
            _close(dask_client)


def read_campaign(out_dir: str | os.PathLike[str]) -> pd.DataFrame:
    """The tidy table of the cells a campaign folder holds (finished cells only), without running anything.

    Returns
    -------
    pandas.DataFrame
        As :func:`run_campaign` returns, ``attrs`` with ``campaign``, ``cells``, ``missing`` (cell ids not yet there).
    """
    out = Path(out_dir).expanduser()
    try:
        meta = json.loads((out / "campaign.json").read_text())
    except (OSError, ValueError):
        raise InputError(f"out_dir: {out} holds no campaign (no readable campaign.json)") from None
    cells, missing = [], []
    for cid in meta["cells"]:
        found = _read_cell(out / "cells" / f"{cid}.json", cid)
        (cells.append(found) if found is not None else missing.append(cid))
    table = results_table(cells)
    table.attrs.update(campaign=meta["spec"], cells=CellResults(cells), missing=missing, out_dir=str(out))
    return table

