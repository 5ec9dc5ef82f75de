"""A Clarabel solve in a child forked after a solve in the parent is refused, not hung (issue 36, item 7)."""

import multiprocessing
import os

import pytest

from hinfnav.core.exceptions import SynthesisError
from hinfnav.lmi import forksafety


def _child(queue):
    try:
        forksafety.note_solve("CLARABEL")
        queue.put("ran")
    except SynthesisError as exc:
        queue.put(str(exc))
    try:
        forksafety.note_solve("CVXOPT")
        queue.put("cvxopt ran")
    except SynthesisError as exc:  # pragma: no cover - the failure this test guards against
        queue.put(str(exc))


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork only")
def test_clarabel_after_fork_is_refused_and_spawn_is_fine():
    forksafety.note_solve("CVXOPT")  # a solve in this (parent) process
    for method, first in (("fork", "spawn"), ("spawn", "ran")):
        ctx = multiprocessing.get_context(method)
        queue = ctx.Queue()
        proc = ctx.Process(target=_child, args=(queue,))
        proc.start()
        got = [queue.get(timeout=60), queue.get(timeout=60)]
        proc.join(60)
        assert got[1] == "cvxopt ran"
        assert (first in got[0]) if method == "fork" else got[0] == "ran"
