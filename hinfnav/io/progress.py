"""Progress bars that show on a terminal and stay silent elsewhere (logs, CI, pipes)."""

__all__ = ["bar_disabled"]


def bar_disabled(progress: bool | None) -> bool | None:
    """The ``disable`` argument of tqdm: off when not asked for, and off when output is not a terminal.

    tqdm's ``disable=None`` turns the bar off on a non-TTY stream, so a log
    or a CI transcript gets no runs of carriage returns.
    """
    return None if progress else True
