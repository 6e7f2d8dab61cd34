"""``simparity bench``'s sweep scaling (issue #29): the wall time and the client's peak memory of ``simparity run`` on
a sweep of 10, 100 and 1,000 variants of a cheap scene (:func:`sweep_scene`), its cases on a local Dask cluster.

Each run is a ``simparity run`` in a process of its own (so each peak is its own), its cases on a ``LocalCluster`` of
:data:`WORKERS` worker processes (``--executor dask``). The client is that process: it plans the variants, receives
every case as it finishes (rows and sampled series), appends them to the stored run scene by scene and writes the
report. Its peak resident memory (``peak_memory.this_process_bytes`` of ``run.json``: its VmHWM, which includes the
``LocalCluster``'s scheduler, running in the same process) must stay bounded as the variants grow: the rows stay in
the run folder, never all in memory at once. The workers (children) hold a case's trajectories while it runs.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable
from pathlib import Path

from simparity.comparisons.bench.rows import Meter
from simparity.comparisons.execute.timing import PeakMemory

SECTION = "sweep"
"""The bench rows' section."""
WORKLOAD = "thrown-ball-sweep"
"""The rows' workload: :func:`sweep_scene`."""
VARIANTS = (10, 100, 1000)
"""Variants per measured run: a tenfold twice, up to :data:`comparisons.scenes.sweep.MAX_VARIANTS`."""
QUICK_VARIANTS = (10, 100)
"""``--quick``: the 1,000-variant run (several minutes on 2 cores) left out."""
WORKERS = 2
"""Dask worker processes of the local cluster (one per core of the 2-core machine the numbers are for)."""
SPEEDS = 10
"""Values of the first swept key (the ball's vertical speed); the second (gravity) takes variants / SPEEDS."""
ENGINES = "core"
"""The engines run: core alone (the analytic reference is computed in each case's worker), so a variant is two
cases (RK4 and semi-implicit Euler at one time step)."""
CLIENT = "client process"
"""Method of the rows of the client's peak resident memory [MiB]."""
WALL = "wall time"
"""Method of the rows of the run's wall time [s]."""


def sweep_scene(variants: int) -> str:
    """A scene file (TOML text) whose ``[sweep]`` has ``variants`` variants (a multiple of :data:`SPEEDS`, at least
    :data:`SPEEDS`): a ball thrown under gravity for 0.5 s at one time step (10 ms), core's RK4 and semi-implicit
    Euler against the closed form, its vertical speed [m/s] x gravity [m/s^2] swept. Milliseconds of work per case:
    what is measured is the harness."""
    if variants < SPEEDS or variants % SPEEDS:
        raise ValueError(f"variants {variants}: not a multiple of {SPEEDS}")
    gravities = variants // SPEEDS
    speeds = ", ".join(repr(float(k)) for k in range(SPEEDS))
    gravity = ", ".join(repr(-1.0 - 10.0 * k / gravities) for k in range(gravities))
    return f"""[scene]
name = "throw-sweep"
description = "A ball thrown under gravity, {variants} variants of its vertical speed x gravity: the harness's cost."
kind = "dynamics"
reference = "analytic"

[world]
gravity_world = [0.0, 0.0, -9.81]

[[body]]
name = "ball"
mass = 1.0
inertia_body_diagonal = [0.1, 0.1, 0.1]
position_world = [0.0, 0.0, 10.0]
velocity_world = [1.0, 0.0, 0.0]

[simulation]
duration = 0.5
dt = [0.01]
integrators = ["rk4", "semi_implicit_euler"]

[sweep]
"body[ball].velocity_world[2]" = [{speeds}]
"world.gravity_world[2]" = [{gravity}]
"""


RunMemory = Callable[[list[str], Path], tuple[PeakMemory | None, float, str]]
"""``simparity run ARGUMENTS --out RUN`` in a process of its own: (its recorded peak memory or None, its wall time
[s], the end of its standard error) (:func:`comparisons.bench.memory.run_peak_memory`)."""


def run_arguments(scene: Path, history: Path) -> list[str]:
    """The arguments of ``simparity run`` for a measured sweep: core alone, no repeats, on a local Dask cluster,
    recorded in the history database ``history`` (a scratch one: the bench's runs are no results)."""
    return [str(scene), "--engines", ENGINES, "--repeats", "0", "--executor", "dask", "--jobs", str(WORKERS),
            "--history", str(history)]


def sweep_rows(quick: bool, run: RunMemory, row: type, say: Callable[[str], None]) -> list:
    """A :data:`CLIENT` row [MiB] (accuracy: the run's wall time [s]) per number of variants of
    :data:`VARIANTS` (:data:`QUICK_VARIANTS` quick), each measured by ``run`` in a fresh folder; ``row`` is
    :class:`comparisons.bench.rows.BenchRow`."""
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for variants in QUICK_VARIANTS if quick else VARIANTS:
            scene = Path(folder) / f"throw-sweep-{variants}.toml"
            scene.write_text(sweep_scene(variants), encoding="utf-8")
            with Meter(children=True) as meter:
                peak, seconds, stderr = run(run_arguments(scene, Path(folder) / "history.sqlite"),
                                            Path(folder) / f"run-{variants}")
            note = (f"{WORKERS} Dask workers, engines {ENGINES}, 2 cases per variant" if peak else
                    f"n/a: the run recorded no peak memory: {stderr}")
            mib = peak.this_process_bytes / 2**20 if peak else math.nan
            rows.append(meter.stamp(row(SECTION, WORKLOAD, "simparity run --executor dask", CLIENT, variants, mib,
                                        "MiB", seconds, "s", note)))
            say(f"  {variants:,} variants: client peak {mib:,.0f} MiB, wall time {seconds:.0f} s")
    return rows


def markdown_lines(rows: list) -> list[str]:
    """The section of ``BENCHMARKS.md``: per number of variants, the client's peak memory and the wall time."""
    mine = [r for r in rows if r.section == SECTION]
    if not mine:
        return []
    lines = [f"## Sweeps: `simparity run` against the number of variants ({WORKLOAD}, on a local Dask cluster)", "",
             ("Peak resident memory of the client (the `simparity run` process, with the LocalCluster's scheduler; "
              "from `run.json`) and the run's wall time, report included. Cases stream back one by one; the client "
              "keeps only the scenes not yet stored."), "",
             "| variants | cases | client peak [MiB] | wall time [s] | note |", "|---|---|---|---|---|"]
    for r in mine:
        lines.append(f"| {r.batch:,} | {2 * r.batch:,} | {_cell(r.value, ',.0f')} | {_cell(r.accuracy, '.0f')} | "
                     f"{r.note} |")
    return lines + [""]


def _cell(value: float, digits: str) -> str:
    return "n/a" if not math.isfinite(value) else format(value, digits)
