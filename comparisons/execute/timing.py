"""Timing: best of several repeats, after one warm-up call."""

from __future__ import annotations

import resource
import sys
import time
from typing import Callable, TypeVar

T = TypeVar("T")


LONG_CALL_SECONDS = 0.1
"""A call at least this long is timed once: its warm-up is its measurement (10^5 times the
timer's resolution, and caches matter little at that length). The harness's times are
indicative; precise speed is ``simparity bench``'s. Repeating every call of a second or less
used to take half of the default suite's time (measured: 379 s of calls for 174 s of
distinct work)."""

REPEAT_BUDGET_SECONDS = 0.3
"""Timed repeats stop early once they have used this much time (at least one is made)."""


def best_of(fn: Callable[[], T], repeats: int) -> tuple[float, T]:
    """(minimum wall time [s] over up to ``repeats`` timed calls, the last call's result).

    ``repeats = 0`` times the warm-up call itself (a cold, indicative time: the quick profile's).
    """
    start = time.perf_counter()
    result = fn()  # warm-up: caches, lazy allocations
    best = time.perf_counter() - start
    if best >= LONG_CALL_SECONDS or repeats == 0:
        return best, result
    best, spent = float("inf"), 0.0
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        elapsed = time.perf_counter() - start
        best, spent = min(best, elapsed), spent + elapsed
        if spent >= REPEAT_BUDGET_SECONDS:
            break
    return best, result


def status_bytes(field: str, pid: int | str = "self") -> int | None:
    """A memory field of a process from Linux's /proc (``VmHWM``, ``VmRSS``, ...) [bytes]; None when it cannot be
    read (not Linux, the process is gone)."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as status:
            for line in status:
                if line.startswith(f"{field}:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):
        return None
    return None


def _high_water_mark_bytes() -> int | None:
    """This process's peak resident memory (VmHWM), None elsewhere. Unlike ru_maxrss, it starts afresh at exec: a
    process started by a large one (a benchmark, a test run) does not report its parent's size."""
    return status_bytes("VmHWM")


def peak_memory_bytes() -> tuple[int, int]:
    """(peak resident memory of this process, of its largest finished child process) [bytes].

    A child's figure is ru_maxrss, which counts the parent's resident memory at the time it was started."""
    scale = 1 if sys.platform == "darwin" else 1024  # ru_maxrss is in bytes on macOS, KiB on Linux
    own = _high_water_mark_bytes() or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * scale
    return own, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * scale


def resource_line(seconds: float) -> str:
    """What a run cost: its wall time and the peak memory of the process and of its largest worker."""
    own, worker = peak_memory_bytes()
    return (f"wall time {seconds:.1f} s; peak memory {own / 2**20:,.0f} MiB"
            + (f" (largest worker process {worker / 2**20:,.0f} MiB)" if worker else ""))
