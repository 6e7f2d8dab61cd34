"""The bench's memory of ``simparity run --jobs 1`` against the number of steps (each run in a process of its own,
its peaks read from the run's ``run.json``), and the memory targets judged on it."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

from simparity.comparisons.bench.rows import BenchRow, Meter
from simparity.comparisons.bench.verdict import TARGET_MEMORY_STEPS, Verdict, sized
from simparity.comparisons.execute.timing import PeakMemory
from simparity.comparisons.scenes import library
from simparity.core.model.errors import ResultsError

MEMORY_SCENE = "hard-million-steps"
"""The built-in 10^6-step scene (a body thrown up at 490.5 m/s, 0.1 ms steps, every default engine)."""
MEMORY_LIMIT_MIB = 1024
"""[MiB] What a run of :data:`TARGET_MEMORY_STEPS` steps may hold at once (this process and its largest child)."""
FLAT_GROWTH = 1.2
"""Memory is flat in the number of steps when the largest child's peak grows by at most this factor over the
measured tenfold of steps."""
MEMORY_PROCESS = "this process"
"""Method of the memory rows of ``simparity run``'s own process (:attr:`PeakMemory.this_process_bytes`)."""
MEMORY_CHILD = "largest child process"
"""Method of the memory rows of its largest child, a case worker or a child a worker forked to run one engine's
cases, which holds the trajectories (:attr:`PeakMemory.largest_child_bytes`)."""
_RUN_AND_RECORD = ("import sys; from simparity.comparisons.cli.main import main; "
                   "from simparity.comparisons.execute.timing import record_peak_memory; "
                   "code = main(); record_peak_memory(sys.argv[-1]); sys.exit(code)")
"""``simparity run`` with its arguments, then its peak memory written into the run's ``run.json`` (the folder after
``--out`` is the last argument)."""


def run_peak_memory(arguments: list[str], run: Path, cwd: Path | None = None) -> tuple[PeakMemory | None, float, str]:
    """``simparity run ARGUMENTS --out RUN`` in a process of its own (in ``cwd``): the peak memory it recorded in its
    ``run.json`` (None if it recorded none), its wall time [s] and the end of its standard error."""
    command = [sys.executable, "-c", _RUN_AND_RECORD, "run", *arguments, "--force", "--out", str(run)]
    start = time.perf_counter()
    done = subprocess.run(command, check=False, capture_output=True, text=True, cwd=cwd)
    seconds = time.perf_counter() - start
    try:
        peak = PeakMemory.of_run(run)
    except ResultsError:
        peak = None
    return peak, seconds, done.stderr[-300:]


CHEAP_MEMORY = f"{MEMORY_SCENE} (core taylor2, analytic exact)"
"""The workload of the memory rows that reach 10^7 steps: :data:`MEMORY_SCENE` with the cheapest stepping there is,
core's particle rule and the closed form (its reference streamed beside each case)."""
CHEAP_MEMORY_STEPS = (100_000, 1_000_000, 3_000_000, 10_000_000)
"""Steps of the cheap memory rows: the slope between them says whether memory grows with the steps; the last is
run by the closed form alone (core's Python loop would take ten minutes)."""
QUICK_SCALE = 100
"""``--quick`` runs each memory run at this fraction of its steps (a run's start-up then dominates its memory)."""
WORKER_LIMIT_MIB = 1024
"""[MiB] What a worker may hold for :data:`CHEAP_MEMORY_STEPS`' largest run."""


def memory_rows(quick: bool, folder: Path, say: Callable[[str], None]) -> list[BenchRow]:
    """Peak memory of ``simparity run --jobs 1``, each run in its own process: on :data:`MEMORY_SCENE` with every
    default engine cut to 10^5 and 10^6 steps, and on :data:`CHEAP_MEMORY` at :data:`CHEAP_MEMORY_STEPS` (a
    :data:`QUICK_SCALE`-th of each quick: a check that the runs work, not a measurement). A :data:`MEMORY_PROCESS` and
    a :data:`MEMORY_CHILD` row per run [MiB], read from the run's ``run.json``, with the run's wall time [s] as
    accuracy."""
    text = library.resolve(MEMORY_SCENE).read_text(encoding="utf-8")
    scale = QUICK_SCALE if quick else 1
    runs: list[tuple[str, int, str | None, list[str]]] = [
        (MEMORY_SCENE, steps // scale, None, []) for steps in (100_000, TARGET_MEMORY_STEPS)]
    runs += [(CHEAP_MEMORY, steps // scale, '["taylor2", "exact"]', ["--engines", "core,analytic"])
             for steps in CHEAP_MEMORY_STEPS[:-1]]
    runs.append((CHEAP_MEMORY, CHEAP_MEMORY_STEPS[-1] // scale, '["exact"]', ["--engines", "analytic"]))
    rows = []
    for index, (workload, steps, integrators, engines) in enumerate(runs):
        scene = folder / f"memory-{index}.toml"
        scene_text = text.replace("duration = 100.0", f"duration = {steps * 1e-4!r}")
        if integrators:
            scene_text = scene_text.replace('integrators = ["taylor2", "semi_implicit_euler+matrix", "euler", "exact"]',
                                            f"integrators = {integrators}")
        scene.write_text(scene_text, encoding="utf-8")
        with Meter(children=True) as meter:
            peak, seconds, stderr = run_peak_memory([str(scene), "--repeats", "0", "--jobs", "1", "--max-steps",
                                                     str(steps), *engines], folder / f"run-{index}")
        note = "" if peak else f"n/a: the run recorded no peak memory: {stderr}"
        method_of = "simparity run --jobs 1" + (f" {' '.join(engines)}" if engines else "")
        for method, mib in ((MEMORY_PROCESS, peak.this_process_bytes / 2**20 if peak else math.nan),
                            (MEMORY_CHILD, peak.largest_child_bytes / 2**20 if peak else math.nan)):
            rows.append(meter.stamp(BenchRow("memory", workload, method_of, method, steps, mib, "MiB", seconds, "s",
                                             note)))
        say(f"  {workload} cut to {steps:,} steps: peak {rows[-2].value:,.0f} MiB in this process, "
            f"{rows[-1].value:,.0f} MiB in its largest child, in {seconds:.0f} s")
    return rows


def memory_targets(rows: list[BenchRow]) -> list[Verdict]:
    """The memory targets: the whole run within :data:`MEMORY_LIMIT_MIB` (this process plus its largest child), and
    the largest child, which holds the trajectories, flat in the number of steps."""
    def measured(method: str, workload: str = MEMORY_SCENE) -> list[BenchRow]:
        return sorted((r for r in rows if r.section == "memory" and r.method == method and r.workload == workload
                       and math.isfinite(r.value)), key=lambda r: r.batch)

    own = {r.batch: r.value for r in measured(MEMORY_PROCESS)}
    child = measured(MEMORY_CHILD)
    if not child or child[-1].batch not in own:
        return []
    most = child[-1]
    tree = own[most.batch] + most.value
    steps = f"{most.batch:,} steps"
    out = [sized(f"peak memory of `simparity run --jobs 1` (this process + its largest child process) <= "
                  f"{MEMORY_LIMIT_MIB:,} MiB for {TARGET_MEMORY_STEPS:,} steps of {MEMORY_SCENE}",
                  f"at {steps}: {own[most.batch]:,.0f} + {most.value:,.0f} = {tree:,.0f} MiB", tree <= MEMORY_LIMIT_MIB,
                  steps, f"{TARGET_MEMORY_STEPS:,} steps")]
    if len(child) > 1:
        low = child[0]
        per_step = (most.value - low.value) * 2**20 / (most.batch - low.batch)
        flat = most.value <= FLAT_GROWTH * low.value
        out.append(sized(f"memory flat in the number of steps ({TARGET_MEMORY_STEPS // 10:,} -> "
                          f"{TARGET_MEMORY_STEPS:,} steps): the largest child process's peak grows <= "
                          f"{FLAT_GROWTH - 1:.0%}",
                          f"largest child process {low.value:,.0f} -> {most.value:,.0f} MiB ({low.batch:,} -> "
                          f"{most.batch:,} steps), {per_step:,.0f} bytes per step" + (
                              "" if flat else ": something holds every step (an engine that does not stream, a "
                              "contact scene)"), flat,
                          f"{low.batch:,} -> {most.batch:,} steps",
                          f"{TARGET_MEMORY_STEPS // 10:,} -> {TARGET_MEMORY_STEPS:,} steps"))
    return out + _cheap_memory_targets(measured(MEMORY_CHILD, CHEAP_MEMORY))


def _cheap_memory_targets(child: list[BenchRow]) -> list[Verdict]:
    """On :data:`CHEAP_MEMORY`: the largest child flat from the first to the last of its core runs (the slope in
    bytes per step between each two), and within :data:`WORKER_LIMIT_MIB` at the largest run."""
    if len(child) < 2:
        return []
    cored = [r for r in child if "core" in r.engine]
    low, high = cored[0], cored[-1]
    slopes = ", ".join(f"{(b.value - a.value) * 2**20 / (b.batch - a.batch):,.1f} bytes per step from {a.batch:,}"
                       for a, b in zip(cored, cored[1:]))
    measured_at = f"{low.batch:,} -> {high.batch:,} steps"
    set_for = f"{CHEAP_MEMORY_STEPS[0]:,} -> {CHEAP_MEMORY_STEPS[-2]:,} steps"
    out = [sized(f"memory flat in the number of steps on the cheap scene ({set_for}): the largest child process's "
                  f"peak grows <= {FLAT_GROWTH - 1:.0%}",
                  f"largest child process {low.value:,.0f} -> {high.value:,.0f} MiB; {slopes}",
                  high.value <= FLAT_GROWTH * low.value, measured_at, set_for)]
    last = child[-1]
    out.append(sized(f"{CHEAP_MEMORY_STEPS[-1]:,} steps within {WORKER_LIMIT_MIB:,} MiB per worker",
                      f"largest child process {last.value:,.0f} MiB at {last.batch:,} steps ({last.engine})",
                      last.value <= WORKER_LIMIT_MIB, f"{last.batch:,} steps", f"{CHEAP_MEMORY_STEPS[-1]:,} steps"))
    return out
