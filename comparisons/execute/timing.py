"""Timing: best of several repeats, after one warm-up call."""

from __future__ import annotations

import resource
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TypeVar

from simparity.comparisons.common.processes import status_bytes
from simparity.comparisons.common.zygote import RESIDENT_BYTES_PER_UNIT, children_usage
from simparity.core.model.results import RUN_INFO_FILE
from simparity.core.model.run_info import RunInfo

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
    results: list[T] = []

    def call() -> None:
        results[:] = [fn()]

    start = time.perf_counter()
    call()  # warm-up: caches, lazy allocations
    best = best_after(time.perf_counter() - start, call, repeats)
    return best, results[0]


def best_after(first: float, fn: Callable[[], object], repeats: int) -> float:
    """The wall time [s] :func:`best_of` gives a call whose warm-up (already made) took ``first``: ``first`` itself
    when it is at least :data:`LONG_CALL_SECONDS` or ``repeats = 0``, else the minimum over up to ``repeats``
    timed calls of ``fn`` (fewer once they used :data:`REPEAT_BUDGET_SECONDS`)."""
    if first >= LONG_CALL_SECONDS or repeats == 0:
        return first
    best, spent = float("inf"), 0.0
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        elapsed = time.perf_counter() - start
        best, spent = min(best, elapsed), spent + elapsed
        if spent >= REPEAT_BUDGET_SECONDS:
            break
    return best


def _high_water_mark_bytes() -> int | None:
    """This process's peak resident memory (VmHWM), None elsewhere. Unlike ru_maxrss, it starts afresh at exec: a
    process started by a large one (a benchmark, a test run) does not report its parent's size."""
    return status_bytes("VmHWM")


@dataclass(frozen=True)
class PeakMemory:
    """Peak resident memory of a run's processes [bytes], as ``run.json`` records it (``peak_memory``)."""

    this_process_bytes: int
    """[bytes] The process that ran (``simparity run``): its VmHWM, ru_maxrss where Linux's /proc is missing."""
    largest_child_bytes: int
    """[bytes] The largest child process it waited for: a case worker, or a child a worker forked to run one engine's
    cases (it holds the reference's and the engine's trajectories); engine probes and figure writers count too. Its
    ru_maxrss, which on Linux includes the resident memory of the process that started it at that moment (a worker:
    the zygote it was forked from), so it is at least that size; 0 without a child."""

    @property
    def tree_bytes(self) -> int:
        """[bytes] This process's peak plus its largest child's: with one worker at a time (``--jobs 1``), a bound of
        what the whole run held at once (a forked child's figure counts the pages it shares with its worker)."""
        return self.this_process_bytes + self.largest_child_bytes

    @classmethod
    def of_run(cls, run_dir: Path) -> PeakMemory | None:
        """What the stored run in ``run_dir`` recorded; None when it recorded none (an older or unfinished run)."""
        recorded = RunInfo.read(Path(run_dir) / RUN_INFO_FILE).peak_memory
        try:
            return cls(**recorded) if recorded else None
        except TypeError:  # another simparity's fields
            return None


def peak_memory() -> PeakMemory:
    """This process's and its largest finished child process's peak resident memory (a worker forked by the zygote
    included, :func:`comparisons.common.zygote.children_usage`)."""
    own = _high_water_mark_bytes() or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * RESIDENT_BYTES_PER_UNIT
    return PeakMemory(own, children_usage().max_resident_bytes)


def record_peak_memory(run_dir: Path) -> PeakMemory:
    """Write :func:`peak_memory` into the ``run.json`` of the run in ``run_dir`` (``peak_memory``) and return it: the
    run's workers must have been waited for (a worker still running is not counted)."""
    peak = peak_memory()
    path = Path(run_dir) / RUN_INFO_FILE
    replace(RunInfo.read(path), peak_memory=asdict(peak)).write(path)
    return peak


def resource_line(seconds: float) -> str:
    """What a run cost: its wall time and the peak memory of the process and of its largest child (worker)."""
    peak = peak_memory()
    return (f"wall time {seconds:.1f} s; peak memory {peak.this_process_bytes / 2**20:,.0f} MiB"
            + (f" (largest worker process {peak.largest_child_bytes / 2**20:,.0f} MiB)"
               if peak.largest_child_bytes else ""))
