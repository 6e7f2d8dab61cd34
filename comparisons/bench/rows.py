"""The bench's measurement row, how a call is timed (the median of repeats after a warm-up call), and the machine's
load and the process's CPU time over the wall time beside each timed row (:class:`Meter`)."""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

from simparity.comparisons.common.zygote import children_usage

REPEATS = 5
"""Timed calls per measurement (median), after one warm-up call."""


@dataclass(frozen=True)
class BenchRow:
    """One measurement: ``value`` per ``unit`` (e.g. microseconds per body-step), with its accuracy, and the machine
    it was measured on (:class:`Meter`; NaN for a row that times nothing)."""

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
    load_before: float = math.nan
    """The 1-minute load average when the row's measurement started (``os.getloadavg()[0]``)."""
    load_after: float = math.nan
    """The 1-minute load average when it ended."""
    cpu_seconds: float = math.nan
    """CPU time of this process over the measurement (``time.process_time``) [s]."""
    wall_seconds: float = math.nan
    """Wall time of the measurement (``time.perf_counter``) [s]; CPU / wall well below 1: the process waited for
    the CPU (the machine was busy with something else); above 1: it used more than one thread."""

    @property
    def cpu_per_wall(self) -> float:
        """CPU time over wall time of the row's measurement (NaN when not metered)."""
        return self.cpu_seconds / self.wall_seconds if self.wall_seconds > 0 else math.nan

    @property
    def load(self) -> float:
        """The larger load average of the two readings around the measurement."""
        return max(self.load_before, self.load_after)


LoadReader = Callable[[], float]
"""The machine's 1-minute load average (runnable and waiting processes, averaged)."""


def load_average() -> float:
    """``os.getloadavg()[0]``, NaN where the system has none."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return math.nan


QUIET_LOAD = 1.0
"""The 1-minute load average :func:`settle` waits for while idle: once the bench's next thread starts, the average
rises toward 1 + what others run, so from at most 1 its rows are judged by others' work alone (a row is loaded above
1 + ``OTHERS_LOAD_PER_CPU`` per CPU, :mod:`comparisons.bench.verdict`)."""
SETTLE_SECONDS_MAX = 240.0
"""[s] The longest the bench waits for the machine to settle before a workload (:func:`settle`): four time constants
of the 1-minute load average, enough for its own previous workload's processes (a suite's two workers: ~2.4) to fade
below the quiet level; a machine others keep busy longer is measured anyway, and its rows say so."""
SETTLE_POLL_SECONDS = 5.0
"""[s] Between two readings of the load while settling."""


def settle(quiet_load: float, say: Callable[[str], None], read_load: LoadReader = load_average,
           sleep: Callable[[float], None] = time.sleep, most: float = SETTLE_SECONDS_MAX) -> float:
    """Wait, idle, until the 1-minute load average is at most ``quiet_load`` or ``most`` seconds have passed; returns
    the seconds waited. The average lags a minute behind: without the wait a workload run right after another (or
    after the tests, or a suite's worker processes) inherits their load in its first rows, which are then judged
    loaded though nobody else used the machine."""
    waited = 0.0
    load = read_load()
    while load > quiet_load and waited < most:
        sleep(SETTLE_POLL_SECONDS)
        waited += SETTLE_POLL_SECONDS
        load = read_load()
    if waited:
        say(f"  (waited {waited:.0f} s for the machine to settle: load {load:.2f}, quiet at {quiet_load:.2f})")
    return waited


def _cpu_with_children() -> float:
    """CPU time [s] of this process and of its children that have ended, the zygote's included
    (:func:`comparisons.common.zygote.children_usage`)."""
    spent = os.times()
    return spent.user + spent.system + children_usage().cpu_seconds


class Meter:
    """The load average before and after, and the CPU and wall time of, the measurement inside ``with Meter() as m``;
    :meth:`stamp` writes them into a row. ``children``: the CPU time of the processes the measurement started and
    waited for counts too (a ``simparity run`` in a process of its own)."""

    def __init__(self, read_load: LoadReader = load_average, children: bool = False) -> None:
        self._read_load = read_load
        self._cpu_time = _cpu_with_children if children else time.process_time
        self.load_before = self.load_after = math.nan
        self.cpu_seconds = self.wall_seconds = 0.0

    def __enter__(self) -> Meter:
        self.load_before = self._read_load()
        self._cpu, self._wall = self._cpu_time(), time.perf_counter()
        return self

    def __exit__(self, *exc) -> None:
        self.cpu_seconds = self._cpu_time() - self._cpu
        self.wall_seconds = time.perf_counter() - self._wall
        self.load_after = self._read_load()

    def stamp(self, row: BenchRow) -> BenchRow:
        """The row with this measurement's load and CPU and wall time."""
        return replace(row, load_before=self.load_before, load_after=self.load_after, cpu_seconds=self.cpu_seconds,
                       wall_seconds=self.wall_seconds)


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


def by_batch(rows: list) -> Iterator[tuple[tuple[str, str, str], dict[int, BenchRow], str, float]]:
    """Per (workload, engine, method) of ``rows``, in their order: its rows by batch, the markdown cells of its values
    at every batch of ``rows`` ("n/a" where none is finite) and its largest finite accuracy (NaN when none)."""
    batches = sorted({r.batch for r in rows})
    for key in dict.fromkeys((r.workload, r.engine, r.method) for r in rows):
        cells = {r.batch: r for r in rows if (r.workload, r.engine, r.method) == key}
        values = " | ".join(f"{cells[b].value:.3g}" if b in cells and math.isfinite(cells[b].value) else "n/a"
                            for b in batches)
        yield key, cells, values, max((c.accuracy for c in cells.values() if math.isfinite(c.accuracy)),
                                      default=math.nan)
