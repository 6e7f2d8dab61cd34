"""``simparity bench``'s suite times (issue #41): the wall time a user waits for the default suite and for the quick CI
gate, each a ``simparity run`` in a process of its own as the README runs it (report included, the default number of
worker processes), judged against the targets set for an idle 2-core machine.

A full bench only: the two runs take minutes, which a quick bench (the tests' own) does not spend, and a suite time
measured under ``--quick`` would say nothing of the target. The test run's time (``python -m pytest``) is not the
installed package's to measure: CI (``.ci/run``) measures it in a fresh clone, and the README gives it.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from simparity.comparisons.bench.rows import QUIET_LOAD, BenchRow, Meter, settle
from simparity.comparisons.bench.sweep import RunMemory
from simparity.comparisons.bench.verdict import OTHERS_LOAD_PER_CPU, Verdict, missed_because

SECTION = "suites"
"""The bench rows' section."""
ENGINE = "simparity run"
"""The rows' engine: the whole command, every engine it runs included."""


@dataclass(frozen=True)
class SuiteTarget:
    """A suite a user waits for: the arguments of ``simparity run`` that run it and the wall time it may take."""

    name: str
    arguments: tuple[str, ...]
    seconds_max: float
    """[s] Wall time on an idle 2-core machine (issue #41)."""

    @property
    def command(self) -> str:
        """The command as a user types it."""
        return " ".join((ENGINE, *self.arguments))


SUITES_MISSED = (
    "measured on 2026-11-29 (the sampled profile of the quick suite in one process, below): 56 % of its CPU is "
    "core's (contact 43 s, free-body stepping 43 s, IK 11 s, chains 10 s: NumPy's per-call cost at B = 1-3 bodies, "
    "17-80x MuJoCo per step), 18 % the other engines' (Pinocchio 18 s, MuJoCo 12 s) and 18 % the report's; the quick "
    "gate's report alone takes ~30 s. A 4x cut needs every part cut: core batched over each scene's time steps and "
    "variants so that B = 1 disappears (or compiled), the report left out of a gate (--no-report) or drawn in "
    "parallel, Pinocchio's stepping batched.")
"""Why the suites miss their times, as measured when the target was last worked on."""

SUITES = (SuiteTarget("default suite", (), 90.0), SuiteTarget("quick gate", ("--quick", "--check"), 30.0))
"""The suites timed: ``simparity run`` (the default suite) and the README's CI gate."""


def suite_rows(run: RunMemory, say: Callable[[str], None],
               settle_first: Callable[[], object] | None = None) -> list[BenchRow]:
    """One row per suite of :data:`SUITES`: its wall time [s] (value) and the CPU time of the run and every process it
    started [s] (accuracy), each run by ``run`` (:func:`comparisons.bench.memory.run_peak_memory`) in a fresh folder
    with a scratch history database (the bench's runs are not results), after ``settle_first()`` (default: waiting for
    the load of what ran before, the previous suite's workers included, to fade: :func:`comparisons.bench.rows.settle`)."""
    wait = settle_first or (lambda: settle(QUIET_LOAD, say))
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for index, suite in enumerate(SUITES):
            wait()
            with Meter(children=True) as meter:
                peak, seconds, stderr = run([*suite.arguments, "--history", str(Path(folder) / "history.sqlite")],
                                            Path(folder) / f"run-{index}")
            note = "report included, default --jobs" if peak else f"n/a: the run recorded nothing: {stderr}"
            rows.append(meter.stamp(BenchRow(SECTION, suite.name, ENGINE, suite.command, 1,
                                             seconds if peak else math.nan, "s", meter.cpu_seconds, "CPU s", note)))
            say(f"  {suite.command}: {seconds:.0f} s wall, {meter.cpu_seconds:.0f} s CPU with its processes")
    return rows


def others_load(row: BenchRow, cpus: int) -> str:
    """Why a suite's row was measured on a loaded machine, or "": the load average when it started, less the bench's
    own thread, above :data:`OTHERS_LOAD_PER_CPU` per CPU. Only the reading before the run counts: the run's own
    worker processes load every CPU while it runs, and the CPU / wall of a run of several processes says nothing of
    others."""
    if row.load_before - 1 > OTHERS_LOAD_PER_CPU * cpus:
        return f"machine loaded (load {row.load_before:.2f} on {cpus} CPUs when the run started)"
    return ""


def suite_targets(rows: list[BenchRow], cpus: int) -> list[Verdict]:
    """Per suite of :data:`SUITES`: its wall time within its target, judged only on a machine others left idle
    (:func:`others_load`); not measured (a quick bench) is said so, never met or missed."""
    out = []
    for suite in SUITES:
        target = f"{suite.command} (the {suite.name}) <= {suite.seconds_max:g} s on an idle {cpus}-CPU machine"
        row = next((r for r in rows if r.section == SECTION and r.workload == suite.name), None)
        if row is None:
            out.append(Verdict(target, "not measured: a quick bench leaves the suites out (minutes each)", None))
        elif not math.isfinite(row.value):
            out.append(Verdict(target, row.note, None))
        else:
            compared = (f"{row.value:.0f} s wall, {row.accuracy:.0f} s CPU with its processes; where a run's time "
                        "goes: the profile below")
            loaded = others_load(row, cpus)
            out.append(missed_because(Verdict(target, compared, None if loaded else row.value <= suite.seconds_max,
                                              loaded=loaded), SUITES_MISSED))
    return out
