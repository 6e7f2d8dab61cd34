"""The bench's files: ``benchmarks.csv`` (one tidy row per measurement) and ``BENCHMARKS.md`` (the verdicts, a table
per workload, the profile), with the machine they were measured on."""

from __future__ import annotations

import csv
import math
import os
import platform
from dataclasses import asdict
from pathlib import Path

import numpy as np

from simparity.comparisons.bench import derivatives, joint_dynamics, joint_motion, small_batch, sweep
from simparity.comparisons.bench.blas import describe_threads
from simparity.comparisons.bench.memory import MEMORY_CHILD, MEMORY_PROCESS
from simparity.comparisons.bench.rows import BenchRow
from simparity.comparisons.bench.stepping import DT, ERROR_METRIC, ERROR_STEPS, ERROR_UNIT
from simparity.comparisons.bench.targets import targets
from simparity.comparisons.bench.verdict import MIN_CPU_PER_WALL, OTHERS_LOAD_PER_CPU, machine_loaded


CPUS = "cores"
"""The key of :func:`machine`'s CPU count."""


def machine() -> dict[str, str]:
    """What the numbers were measured on, with the BLAS threads in effect when called (inside
    :func:`comparisons.bench.blas.one_blas_thread`: the timed rows')."""
    import mujoco
    import pinocchio
    from importlib import metadata
    return {"python": platform.python_version(), "numpy": np.__version__, "mujoco": mujoco.__version__,
            "pinocchio": pinocchio.__version__, "pybullet": metadata.version("pybullet"),
            "cpu": platform.processor() or platform.machine(), CPUS: str(os.cpu_count()),
            "BLAS threads": describe_threads(), "system": platform.platform()}


def cpus(info: dict[str, str]) -> int:
    """The machine's CPU count from :func:`machine`'s answer (1 when not known)."""
    return int(info.get(CPUS) or 1)


def write_csv(rows: list[BenchRow], path: Path) -> None:
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(asdict(rows[0])))
        writer.writeheader()
        writer.writerows(asdict(r) for r in rows)


def _cell(value: float, digits: str = ".3g") -> str:
    return "n/a" if not math.isfinite(value) else format(value, digits)


def markdown(rows: list[BenchRow], info: dict[str, str], command: str, profile: str, seconds: float,
             run_profile: list[str] | None = None) -> str:
    """BENCHMARKS.md: the targets, every workload's table, the machine's load, ``run_profile`` (the lines of the
    section on where a run spends its time, :func:`comparisons.bench.run_profile.profile_markdown`) and core's
    profile."""
    lines = ["# BENCHMARKS", "", f"Written by `{command}` in {seconds:.0f} s on "
             + ", ".join(f"{k} {v}" for k, v in info.items()) + ". Every time is the median of repeated calls "
             "after a warm-up, on one BLAS thread (the bench sets it) unless its row says otherwise; every ratio is "
             "from this run. The raw rows are in `benchmarks.csv`, each with the load average before and after its "
             "measurement and its CPU and wall time.", "",
             "## Targets", "", ("Each target as set, what this run compared for it, and the verdict; a target set for "
                                "another size than this run measured (`--quick`) is not comparable; a target one of whose "
                                "rows (an absolute rate's, or either of a ratio's two) was measured on a loaded machine "
                                f"is not judged: the load average around the row, less the bench's own thread, above "
                                f"{OTHERS_LOAD_PER_CPU:g} per CPU, or its CPU / wall below {MIN_CPU_PER_WALL:g}."), "",
             "| target | compared | verdict |", "|---|---|---|"]
    verdicts = targets(rows, cpus(info))
    for verdict in verdicts:
        label = "**MISSED**" if verdict.met is False else verdict.label
        lines.append(f"| {verdict.target} | {verdict.compared} | {label} |")
    reasons = dict.fromkeys(v.because for v in verdicts if v.met is False and v.because)
    if reasons:  # one paragraph per reason, naming the missed targets it explains
        lines += ["", "### Why the missed targets are missed", ""]
        for reason in reasons:
            names = "; ".join(v.target for v in verdicts if v.met is False and v.because == reason)
            lines += [f"- **{names}**: {reason}"]
    lines += ["", "The suites' times are judged on the load when their run started (their own worker processes load "
              "every CPU). The test run's (`python -m pytest`, target <= 300 s on 2 cores) is not the installed "
              "package's to measure: CI (`.ci/run`) measures it in a fresh clone, and the README gives it.", ""]
    lines += load_lines(rows, cpus(info))
    for workload in dict.fromkeys(r.workload for r in rows if r.section == "dynamics"):
        mine = [r for r in rows if r.section == "dynamics" and r.workload == workload]
        batches = sorted({r.batch for r in mine})
        error_label = f"{ERROR_METRIC[workload].removesuffix('_max').replace('_', ' ')} [{ERROR_UNIT[workload]}]"
        lines += [f"## Stepping: {workload} (us per body-step; error after {ERROR_STEPS * DT:g} s at dt {DT:g} s "
                  "against DOP853)", "",
                  "| engine | integrator | " + " | ".join(f"B = {b:,}" for b in batches) + f" | {error_label} |",
                  "|---|---|" + "---|" * (len(batches) + 1)]
        for engine, method in dict.fromkeys((r.engine, r.method) for r in mine):
            cells = {r.batch: r for r in mine if (r.engine, r.method) == (engine, method)}
            error = next(iter(cells.values())).accuracy
            lines.append(f"| {engine} | {method} | " + " | ".join(_cell(cells[b].value) for b in batches)
                         + f" | {_cell(error, '.2e')} |")
        notes = sorted({f"{r.engine} {r.method} B = {r.batch:,}: {r.note}" for r in mine if r.note})
        lines += [""] + [f"- {n}" for n in notes] + ([""] if notes else [])
        core: dict[int, float] = {r.batch: r.value for r in mine if (r.engine, r.method) == ("core", "rk4")}
        lines += ["Ratio engine / core rk4 (> 1: core is faster per body-step):", "",
                  "| engine | integrator | " + " | ".join(f"B = {b:,}" for b in batches) + " |",
                  "|---|---|" + "---|" * len(batches)]
        for engine, method in dict.fromkeys((r.engine, r.method) for r in mine if r.engine != "core"):
            values = {r.batch: r.value for r in mine if (r.engine, r.method) == (engine, method)}
            lines.append(f"| {engine} | {method} | " + " | ".join(_cell(values[b] / core[b]) for b in batches) + " |")
        lines.append("")
    kin = [r for r in rows if r.section == "kinematics"]
    if kin:
        batches = sorted({r.batch for r in kin})
        lines += ["## Forward kinematics + Jacobian (us per configuration; largest difference to Pinocchio)", "",
                  "Engines answer one configuration per call through their adapters; their time per configuration is "
                  "measured on at most 1,000.", "",
                  "| chain | engine | " + " | ".join(f"B = {b:,}" for b in batches) + " | difference |",
                  "|---|---|" + "---|" * (len(batches) + 1)]
        for chain, engine in dict.fromkeys((r.workload, r.engine) for r in kin):
            cells = {r.batch: r for r in kin if (r.workload, r.engine) == (chain, engine)}
            lines.append(f"| {chain} | {engine} | " + " | ".join(_cell(cells[b].value) for b in batches)
                         + f" | {_cell(max(c.accuracy for c in cells.values()), '.1e')} |")
        lines.append("")
    lines += small_batch.markdown_lines(rows)
    lines += joint_dynamics.markdown_lines(rows)
    lines += derivatives.markdown_lines(rows)
    lines += joint_motion.markdown_lines(rows)
    lines += sweep.markdown_lines(rows)
    ik = [r for r in rows if r.section == "ik"]
    if ik:
        lines += [f"## IK, TRAC-IK protocol ({ik[0].batch:,} seeded pose targets per arm from mid-range, success at "
                  "1e-6 m and 1e-6 rad, inside the limits; failures inside the time)", "",
                  "| arm | engine | solver | targets | solve rate | ms per solve | solves/s | load | CPU/wall | note |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for r in ik:
            lines.append(f"| {r.workload} | {r.engine} | {r.method} | {r.batch:,} | {_cell(r.accuracy, '.2%')} | "
                         f"{_cell(r.value)} | {_cell(1e3 / r.value, ',.0f')} | {_cell(r.load, '.2f')} | "
                         f"{_cell(r.cpu_per_wall, '.2f')} | {r.note} |")
        lines.append("")
    memory = [r for r in rows if r.section == "memory"]
    if memory:
        lines += ["## Memory of `simparity run --jobs 1` against the number of steps", "",
                  ("Peak resident memory of the run's own process and of its largest child process (a case worker or "
                   "a child it forked to run one engine's cases, which holds the trajectories), from the run's "
                   "`run.json`. A child's figure is its ru_maxrss: at least the run's own size when the worker was "
                   "started, which Linux carries over exec."), "",
                  f"| scene | steps | {MEMORY_PROCESS} [MiB] | {MEMORY_CHILD} [MiB] | wall time [s] | note |",
                  "|---|---|---|---|---|---|"]
        for workload, steps in dict.fromkeys((r.workload, r.batch) for r in memory):
            by_method = {r.method: r for r in memory if (r.workload, r.batch) == (workload, steps)}
            first = next(iter(by_method.values()))
            lines.append(f"| {workload} | {steps:,} | " + " | ".join(_cell(by_method[m].value, ",.0f") if m in by_method else "n/a"
                                                         for m in (MEMORY_PROCESS, MEMORY_CHILD))
                         + f" | {_cell(first.accuracy, '.0f')} | {first.note} |")
        lines.append("")
    lines += list(run_profile or ())
    lines += ["## Profile", "", "Where core's time goes (cProfile, functions by own time):", "", "```", profile.rstrip(),
              "```", ""]
    return "\n".join(lines)


def load_lines(rows: list[BenchRow], cpu_count: int) -> list[str]:
    """The section of the machine's load: per section and workload, the range of the load averages around its rows
    and of their CPU / wall, and how many of its rows were measured on a loaded machine
    (:func:`comparisons.bench.verdict.machine_loaded`)."""
    metered = [r for r in rows if math.isfinite(r.wall_seconds)]
    if not metered:
        return []
    lines = [f"## Machine load ({cpu_count} CPUs)", "",
             "Per workload, the 1-minute load average before and after each timed row and the row's CPU time over "
             "its wall time (below 1: the process waited for a CPU; above 1: more than one thread); every row's in "
             "`benchmarks.csv`.", "",
             "| section | workload | rows | load average | CPU/wall | rows on a loaded machine |", "|---|---|---|---|---|---|"]
    for section, workload in dict.fromkeys((r.section, r.workload) for r in metered):
        mine = [r for r in metered if (r.section, r.workload) == (section, workload)]
        loads = [x for r in mine for x in (r.load_before, r.load_after) if math.isfinite(x)]
        shares = [r.cpu_per_wall for r in mine if math.isfinite(r.cpu_per_wall)]
        loaded = sum(1 for r in mine if machine_loaded(r, cpu_count))
        lines.append(f"| {section} | {workload} | {len(mine)} | {_span(loads)} | {_span(shares)} | {loaded} |")
    return lines + [""]


def _span(values: list[float]) -> str:
    return f"{min(values):.2f}-{max(values):.2f}" if values else "n/a"
