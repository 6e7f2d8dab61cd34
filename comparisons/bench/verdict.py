"""The bench's verdict on one of the issue's targets, and the sizes the targets are set for: a target measured at
another size (``--quick``) is "not comparable", never met or missed; a target whose rows were measured while the
machine was loaded is "not judged" (an absolute rate reads low; a ratio of two rows timed minutes apart moves with
the load of one and not the other); a missed target says why (``because``)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from simparity.comparisons.bench.rows import BenchRow

TARGET_BATCH = 10_000
"""Bodies and configurations per batch the speed targets are set for (the largest batch of a full bench)."""
TARGET_IK_TARGETS = 10_000
"""IK targets per arm the IK targets are set for (the ``bench`` suite's count; core solves them as one batch)."""
TARGET_MEMORY_STEPS = 1_000_000
"""Steps the memory targets are set for (:data:`comparisons.bench.memory.MEMORY_SCENE` uncut)."""
OTHERS_LOAD_PER_CPU = 0.25
"""A row was measured on a loaded machine when the load average around it, less the bench's own thread (1), is
above this many per CPU (on 2 CPUs: above 1.5, half a CPU taken by others): the bench's thread then shares a CPU
part of the time, and an absolute speed reads low by up to that share."""
MIN_CPU_PER_WALL = 0.9
"""A row was measured on a loaded machine when its process's CPU time was below this fraction of its wall time:
single-threaded work waited for the CPU more than a tenth of the time."""


@dataclass(frozen=True)
class Verdict:
    """One of the issue's targets: what it requires, what this run compared for it (with the numbers), whether met."""

    target: str
    compared: str
    met: bool | None
    """None: not judged, because not measured, (``set_for``) measured at another size than the target's, or
    (``loaded``) an absolute target measured on a loaded machine."""
    measured_at: str = ""
    set_for: str = ""
    """The size the target is set for (``B = 10,000``) where this run measured at another, ``measured_at``."""
    loaded: str = ""
    """Why a target was not judged: the machine's load during one of its rows (:func:`machine_loaded`)."""
    because: str = ""
    """Why the target is missed, as measured when it was last worked on: what its time goes to and what would close
    it (BENCHMARKS.md prints it under the targets when the target is missed)."""

    @property
    def status(self) -> str:
        """``met``, ``MISSED``, ``not comparable`` (measured at another size), ``not judged`` (an absolute target on
        a loaded machine) or ``n/a`` (not measured)."""
        if self.met is not None:
            return "met" if self.met else "MISSED"
        if self.set_for:
            return "not comparable"
        return "not judged" if self.loaded else "n/a"

    @property
    def label(self) -> str:
        """The status with why a target was not comparable or not judged."""
        if self.set_for and self.met is None:
            return f"{self.status} (measured at {self.measured_at}, target set for {self.set_for})"
        return f"{self.status}: {self.loaded}" if self.loaded else self.status


def sized(target: str, compared: str, met: bool, measured_at: str, set_for: str) -> Verdict:
    """The verdict on a target set for one size (batch, targets, steps): judged only at that size. Core's batched
    speed and a run's memory change with the size, so a verdict at a quick size would be an artefact of it."""
    if measured_at != set_for:
        return Verdict(target, compared, None, measured_at, set_for)
    return Verdict(target, compared, met)


def machine_loaded(row: BenchRow, cpus: int) -> str:
    """Why ``row`` was measured on a loaded machine (its load average, less the bench's own thread, above
    :data:`OTHERS_LOAD_PER_CPU` per CPU, or its CPU / wall below :data:`MIN_CPU_PER_WALL`), or "" when it was not
    (or not metered)."""
    if row.load - 1 > OTHERS_LOAD_PER_CPU * cpus:
        return f"machine loaded (load {row.load:.2f} on {cpus} CPUs)"
    if row.cpu_per_wall < MIN_CPU_PER_WALL:
        return f"machine loaded (CPU/wall {row.cpu_per_wall:.2f} over the row, load {row.load:.2f} on {cpus} CPUs)"
    return ""


def absolute(verdict: Verdict, row: BenchRow, cpus: int) -> Verdict:
    """The verdict on an absolute target measured in ``row``: not judged (saying why) when the machine was loaded
    during that row, as a rate measured then would read low whatever the code does."""
    return judged_on(verdict, (row,), cpus)


def judged_on(verdict: Verdict, rows: tuple[BenchRow, ...], cpus: int) -> Verdict:
    """The verdict on a target measured in ``rows`` (one row: an absolute rate; two: a ratio of rows timed minutes
    apart): not judged (saying which row's load) when the machine was loaded during any of them, as the load of one
    row and not the other moves a ratio whatever the code does."""
    loaded = next((r for r in rows if machine_loaded(r, cpus)), None) if verdict.met is not None else None
    if loaded is None:
        return verdict
    why = machine_loaded(loaded, cpus) + (f", in the row of {loaded.engine} {loaded.method} at B = {loaded.batch:,}"
                                          if len(rows) > 1 else "")
    return replace(verdict, met=None, loaded=why)


def missed_because(verdict: Verdict, because: str) -> Verdict:
    """``verdict`` with the reason it misses its target (printed only when it does)."""
    return replace(verdict, because=because)

