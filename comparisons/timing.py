"""Timing: best of several repeats, after one untimed warm-up call."""

from __future__ import annotations

import time
from typing import Callable, TypeVar

T = TypeVar("T")


def best_of(fn: Callable[[], T], repeats: int) -> tuple[float, T]:
    """(minimum wall time [s] over ``repeats`` timed calls, the last call's result)."""
    result = fn()  # warm-up: caches, lazy allocations
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result
