"""A kernel client that never sleeps through a reply: what every notebook of the workbook executes with.

Why (issue 37, item 7)
----------------------
nbclient waits for a cell's ``execute_reply`` with one ``poll`` of the kernel's shell socket, armed
for the whole cell timeout (900 s here). When a cell writes into an ``ipywidgets.Output`` (notebook
91), nbclient keeps that widget's state and sends it back to the kernel — on the *same* shell socket —
while the poll is pending. ØMQ signals a socket's readiness edge-triggered: a send that lands after
the reply has arrived, but before the pending poll has woken, consumes the edge, and the poll then
sleeps until its timeout runs out and returns the reply without an error. Notebook 91 thus took
900 s + its 4 s of cells (``jupyter/nbclient`` issue 312 reports the same with widgets). The
reproduction: five cells, each printing 3 MB into an ``Output`` widget, with nbclient's own client
and a 10 s timeout, took 34–43 s instead of 3 s (``tests/test_notebook_execution.py``).

The fix
-------
:class:`SlicedPollChannel` polls the shell socket in slices of at most :data:`POLL_SLICE_S`: a lost
edge then costs one slice, not the timeout, and the cell timeout still holds (the slices stop at its
deadline). :class:`KernelManager` hands out clients with that channel; pass it as nbclient's (or
papermill's) ``kernel_manager_class``. :func:`hinfnav.papers.notebooks.execute_notebook` does, and
also raises (instead of warning) when the kernel does not report idle after a cell's reply, and when
the run took much longer than its cells (:class:`NotebookStallError`): a silent wait fails loudly.

This module imports ``jupyter_client``; only notebook execution loads it.
"""

import time
from queue import Empty

from jupyter_client.channels import AsyncZMQSocketChannel
from jupyter_client.manager import AsyncKernelManager
from jupyter_client.asynchronous import AsyncKernelClient
from traitlets import DottedObjectName, Type

__all__ = ["KernelManager", "SlicedPollKernelClient"]

#: Longest a single poll of the shell socket waits before it looks again (s): the most a lost
#: readiness edge can cost.
POLL_SLICE_S = 0.25


class SlicedPollChannel(AsyncZMQSocketChannel):
    """The shell channel, polled in slices of at most :data:`POLL_SLICE_S` up to the caller's timeout."""

    async def get_msg(self, timeout=None):
        """The next message; ``queue.Empty`` once ``timeout`` seconds (None: forever) pass without one."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            left = POLL_SLICE_S if deadline is None else min(POLL_SLICE_S, max(0.0, deadline - time.monotonic()))
            try:
                return await super().get_msg(timeout=left)
            except Empty:
                if deadline is not None and time.monotonic() >= deadline:
                    raise


class SlicedPollKernelClient(AsyncKernelClient):
    """nbclient's asynchronous kernel client with :class:`SlicedPollChannel` as its shell channel."""

    shell_channel_class = Type(SlicedPollChannel)


class KernelManager(AsyncKernelManager):
    """nbclient's kernel manager, handing out :class:`SlicedPollKernelClient` clients."""

    client_class = DottedObjectName("hinfnav.papers.notebook_kernel.SlicedPollKernelClient")
    client_factory = Type(SlicedPollKernelClient)
