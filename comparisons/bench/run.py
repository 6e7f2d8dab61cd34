"""``simparity bench``'s entry: every workload measured in one run, the verdicts printed, the files written."""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from simparity.comparisons.bench import derivatives, joint_dynamics, joint_motion, small_batch, sweep
from simparity.comparisons.bench.blas import one_blas_thread
from simparity.comparisons.bench.ik import ik_rows
from simparity.comparisons.bench.kinematics import kinematics_rows
from simparity.comparisons.bench.memory import memory_rows, run_peak_memory
from simparity.comparisons.bench.profiling import profile_summary
from simparity.comparisons.bench.run_profile import profile_markdown, run_profile
from simparity.comparisons.bench.report import cpus, machine, markdown, write_csv
from simparity.comparisons.bench.rows import QUIET_LOAD, REPEATS, BenchRow, Meter, median_time, settle
from simparity.comparisons.bench.stepping import dynamics_rows
from simparity.comparisons.bench.suites import suite_rows
from simparity.comparisons.bench.targets import targets
from simparity.comparisons.bench.verdict import TARGET_BATCH
from simparity.comparisons.engines.registry import DEFAULT_ENGINES
from simparity.comparisons.scenes import library
from simparity.core.model.errors import SimparityError, one_line

QUICK_PROFILE_SCENES = ("lecture-projectile", "lecture-2link-ik", "damped-joint")
"""The scenes ``--quick`` profiles a run of (the full bench: the default suite's): a free body, an IK scene and a
joint motion, one of each kind of case a suite is mostly made of."""


def run_bench(out_dir: Path, quick: bool, command: str, say: Callable[[str], None]) -> Path:
    """Measure everything on one BLAS thread, write ``benchmarks.csv`` and ``BENCHMARKS.md`` into ``out_dir``;
    returns the latter."""
    start = time.perf_counter()
    out_dir.mkdir(parents=True, exist_ok=True)
    with one_blas_thread():
        info = machine()
        say(f"BLAS threads: {info['BLAS threads']}")
        rows, profile, run_lines = _measure(quick, say)
    for verdict in targets(rows, cpus(info)):  # before the files: a write that fails loses no verdict
        reason = verdict.label.removeprefix(verdict.status).strip()
        say(f"{verdict.status:<14} {verdict.target}: {verdict.compared}" + (f" {reason}" if reason else ""))
    path = out_dir / "BENCHMARKS.md"
    try:
        write_csv(rows, out_dir / "benchmarks.csv")
        path.write_text(markdown(rows, info, command, profile, time.perf_counter() - start, run_lines))
    except OSError as err:  # a full device, a folder removed meanwhile: the folder was probed before the bench
        raise SimparityError(f"--out {one_line(out_dir)}: cannot write the benchmarks: {err.strerror or err} "
                             "(allowed: a folder you can write); the targets met or missed are printed above") from None
    return path


def _measure(quick: bool, say: Callable[[str], None]) -> tuple[list[BenchRow], str, list[str]]:
    """Every workload's rows, each workload's wall and CPU time and load said after it, core's profile and the
    section on where a run spends its time."""
    batches = [1, 100] if quick else [1, 100, TARGET_BATCH]
    workloads: list[tuple[str, Callable[[], list[BenchRow]]]] = [
        ("stepping (time per body-step, with the error at that dt)", lambda: dynamics_rows(batches, quick, say)),
        ("small batches: core against MuJoCo's same scheme at B = 1 and 3 (time per step)",
         lambda: small_batch.small_batch_rows(quick, say)),
        ("forward kinematics + Jacobian", lambda: kinematics_rows(batches, say)),
        ("joint-space dynamics (time per state, with the difference to Pinocchio)",
         lambda: joint_dynamics.joint_dynamics_rows(batches, lambda fn: median_time(fn, REPEATS), BenchRow, say)),
        ("derivatives of the dynamics (time per state, with the error against the complex-step truth)",
         lambda: derivatives.derivative_rows(batches, lambda fn: median_time(fn, REPEATS), BenchRow, say)),
        ("joint motion (time per copy-step, with the error against DOP853 and the difference to Pinocchio's RK4)",
         lambda: joint_motion.joint_motion_rows(batches, median_time, BenchRow, say)),
        ("IK", lambda: ik_rows(300 if quick else None, say)),
        ("memory of simparity run against the number of steps", lambda: _memory_rows(quick, say)),
        ("sweeps: simparity run's wall time and client memory against the number of variants",
         lambda: sweep.sweep_rows(quick, run_peak_memory, BenchRow, say))]
    if not quick:  # minutes each, and a quick bench's suite time would say nothing of the targets
        workloads.append(("suites: the wall time of the default suite and of the quick CI gate, as a user runs them",
                          lambda: suite_rows(run_peak_memory, say)))
    rows: list[BenchRow] = []
    for title, measure in workloads:
        say(title)
        if not quick:  # the previous workload's processes (or what ran before the bench) fade first; a quick bench
            settle(QUIET_LOAD, say)  # judges no target and does not wait
        with Meter(children=True) as meter:
            rows += measure()
        say(f"  ({meter.wall_seconds:.0f} s wall, {meter.cpu_seconds:.0f} s CPU with the processes it started, load "
            f"{meter.load_before:.2f} -> {meter.load_after:.2f})")
    say("profile")
    profile = profile_summary(batches[-1], say)
    scenes = QUICK_PROFILE_SCENES if quick else tuple(s.name for s in library.suite("default"))
    say(f"where a run spends its time: simparity run --quick of {len(scenes)} scenes in this process")
    return rows, profile, profile_markdown(run_profile(list(scenes), DEFAULT_ENGINES), "simparity run --quick" + (
        " " + " ".join(scenes) if quick else ""))


def _memory_rows(quick: bool, say: Callable[[str], None]) -> list[BenchRow]:
    with tempfile.TemporaryDirectory() as folder:
        return memory_rows(quick, Path(folder), say)
