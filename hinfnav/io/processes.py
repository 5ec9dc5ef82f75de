"""Independent jobs in worker processes: spawned, one BLAS thread each, printed lines prefixed, all or nothing.

:func:`run_jobs` runs ``(name, function, args, kwargs)`` jobs on a pool of
spawned processes (``concurrent.futures``; ``spawn`` starts each worker from a
fresh interpreter, the same on every platform), in the order given (a caller
puts the longest first, so that the workers finish together). In each worker

* the BLAS libraries run on one thread (:func:`one_blas_thread`): the workers
  already fill the cores, and a product then gives the same numbers in a worker
  as in a serial run that holds the same limit;
* everything a job prints, to stdout or stderr, reaches the terminal line by
  line, each line prefixed with ``[name]`` (:class:`PrefixedLines`): lines of
  different jobs never mix mid-line, and tqdm bars (not a terminal any more)
  stay off.

The first job that fails stops the others (their processes are terminated)
and its exception is raised in the caller, with a note naming the job: a
caller that writes into an :func:`~hinfnav.io.outputs.atomic_output_dir`
leaves the previous folder as it was.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import io
import multiprocessing
import os
import resource
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TextIO

from threadpoolctl import threadpool_limits

from ..core.exceptions import InputError

__all__ = ["PrefixedLines"]


class PrefixedLines(io.TextIOBase):
    """A text stream that writes whole lines, each prefixed, to another stream (flushed line by line).

    A line is written by one ``write`` call of the target stream, so lines of
    several processes sharing a terminal or a log do not mix. A carriage
    return starts the line over (what a progress bar redraws is dropped);
    :meth:`close` writes a last unfinished line.

    Parameters
    ----------
    prefix : str
        Put before every line, e.g. ``"[yang2020] "``.
    stream : text stream
        Where the lines go.
    """

    def __init__(self, prefix: str, stream: TextIO) -> None:
        super().__init__()
        self.prefix, self.stream, self._pending = prefix, stream, ""

    def writable(self) -> bool:
        return True

    def isatty(self) -> bool:
        return False

    def write(self, text: str) -> int:
        *lines, self._pending = (self._pending + text).split("\n")
        self._pending = self._pending.rpartition("\r")[2]
        if lines:
            self.stream.write("".join(f"{self.prefix}{line.rpartition(chr(13))[2]}\n" for line in lines))
            self.stream.flush()
        return len(text)

    def flush(self) -> None:
        self.stream.flush()

    def close(self) -> None:
        if not self.closed and self._pending:
            self.write("\n")
        super().close()


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Context manager: the BLAS/OpenMP libraries loaded in this process run on one thread (threadpoolctl)."""
    with threadpool_limits(limits=1):
        yield


def cpu_seconds() -> float:
    """CPU seconds (user + system) of this process and of its finished children."""
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def check_jobs(jobs: Any, name: str = "jobs") -> int:
    """The number of worker processes: ``None`` → the machine's cores (``os.cpu_count()``), else an int ≥ 1."""
    if jobs is None:
        return os.cpu_count() or 1
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise InputError(f"{name} must be a whole number >= 1 (worker processes; None: one per core); got {jobs!r}")
    return jobs


def _run_job(name: str, fn: Callable[..., Any], args: tuple, kwargs: dict) -> tuple[Any, float, float]:
    """Run one job in a worker: one BLAS thread, prefixed output; ``(result, wall s, CPU s)``."""
    out, err = sys.stdout, sys.stderr
    t0, c0 = time.perf_counter(), cpu_seconds()
    sys.stdout, sys.stderr = PrefixedLines(f"[{name}] ", out), PrefixedLines(f"[{name}] ", err)
    try:
        with one_blas_thread():
            result = fn(*args, **kwargs)
    finally:
        for stream in (sys.stdout, sys.stderr):
            stream.close()
        sys.stdout, sys.stderr = out, err
    return result, time.perf_counter() - t0, cpu_seconds() - c0


def _terminate(pool: concurrent.futures.ProcessPoolExecutor) -> None:
    """Stop the pool now: pending jobs cancelled, running workers terminated."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    for p in procs:
        p.join()


def run_jobs(jobs: Sequence[tuple[str, Callable[..., Any], tuple, dict]], workers: int,
             done: Callable[[str, float, float], None] | None = None) -> dict[str, Any]:
    """Run the jobs on ``workers`` spawned processes; return ``{name: result}`` in the order of ``jobs``.

    Parameters
    ----------
    jobs : sequence of (str, callable, tuple, dict)
        ``(name, function, args, kwargs)``; the function and its arguments are
        pickled (a module-level function). Started in this order.
    workers : int
        Processes (at most one per job is started).
    done : callable, optional
        ``done(name, wall_s, cpu_s)``, called in this process as each job finishes.

    Raises
    ------
    Exception
        The exception of the first job that fails (the others are stopped), with a note naming it.
    """
    names = [job[0] for job in jobs]
    if len(set(names)) != len(names):
        raise InputError(f"job names must be distinct; got {names}")
    workers = check_jobs(workers, "workers")
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=min(workers, max(1, len(jobs))),
                                                  mp_context=multiprocessing.get_context("spawn"))
    finished = False
    try:
        futures = {pool.submit(_run_job, *job): job[0] for job in jobs}
        results = {}
        for fut in concurrent.futures.as_completed(futures):
            name = futures[fut]
            exc = fut.exception()
            if exc is not None:
                exc.add_note(f"(raised by job {name!r} in a worker process; the other jobs were stopped)")
                raise exc
            results[name], wall, cpu = fut.result()
            if done is not None:
                done(name, wall, cpu)
        finished = True
        return {name: results[name] for name in names}
    finally:
        if finished:
            pool.shutdown(wait=True)
        else:
            _terminate(pool)
