"""Solvers after ``fork`` (issue 36): a known hang detected and refused in one line.

Clarabel keeps a thread pool alive after its first solve; a child created by
``os.fork`` (``multiprocessing``'s default "fork" start method on Linux) copies
the pool's locks but not its threads, and its first Clarabel solve can wait
forever. hinfnav's own process pools use "spawn" and are not affected; a user's
``multiprocessing.Pool`` (fork) after a design in the parent is. This module
records that a solve ran in this process and, in a child forked afterwards,
refuses a Clarabel solve with what to do instead (CVXOPT and SCS are not
affected and run).
"""

from __future__ import annotations

import os

from ..core.exceptions import SynthesisError

__all__ = ["note_solve"]

#: Solvers whose first solve in a child forked after a solve in the parent can hang.
FORK_UNSAFE_SOLVERS = ("CLARABEL",)

_STATE = {"solved_in": None, "forked_after_solve": False}


def _after_fork_in_child():
    if _STATE["solved_in"] is not None:
        _STATE["forked_after_solve"] = True


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


def note_solve(solver: str) -> None:
    """Called before every solve: refuse a fork-unsafe solver in a child forked after a solve; record this one."""
    if _STATE["forked_after_solve"] and solver in FORK_UNSAFE_SOLVERS:
        raise SynthesisError(
            f"solver {solver} cannot run in a process forked after an LMI solve in its parent (its thread pool does "
            "not survive fork and the solve can hang): start worker processes with multiprocessing's 'spawn' "
            "method (multiprocessing.get_context('spawn'), as hinfnav's own pools do), or pass solver='CVXOPT'")
    _STATE["solved_in"] = os.getpid()
