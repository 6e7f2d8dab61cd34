"""The bench's measurement row and how a call is timed: the median of repeats after a warm-up call."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

REPEATS = 5
"""Timed calls per measurement (median), after one warm-up call."""


@dataclass(frozen=True)
class BenchRow:
    """One measurement: ``value`` per ``unit`` (e.g. microseconds per body-step), with its accuracy."""

    section: str
    workload: str
    engine: str
    method: str
    batch: int
    value: float
    unit: str
    accuracy: float
    accuracy_unit: str
    note: str = ""


def median_time(fn: Callable[[], object], repeats: int) -> float:
    """Median wall time [s] of ``repeats`` calls after one warm-up call (0 repeats: the warm-up's)."""
    start = time.perf_counter()
    fn()
    first = time.perf_counter() - start
    if repeats == 0:
        return first
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)
