"""Streaming statistics of one campaign cell: the metrics layer's accumulator (:mod:`hinfnav.metrics.accumulator`).

A cell's statistics are those of :class:`hinfnav.metrics.StatisticsAccumulator`
(the same quantities as :func:`hinfnav.metrics.monte_carlo_statistics`, which
uses it too); the names are kept here for the campaign's public interface.
"""

from ..metrics.accumulator import StatisticsAccumulator as CellAccumulator
from ..metrics.accumulator import group_summary, rms_interval

__all__ = ["CellAccumulator", "group_summary", "rms_interval"]
