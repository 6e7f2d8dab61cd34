"""``simparity bench``'s small batches (issue #41): core at B = 1 and B = 3 against MuJoCo's integrator of the same
scheme, time per step of the whole scene and the ratio core / MuJoCo, where simparity's scenes live (one to three
bodies), not where core's batching wins.

Pairs: every integrator of core and every one of MuJoCo whose engines name the same scheme on the scene
(``Engine.scheme``: MuJoCo's Euler is core's ``engine_euler`` on a body, its ``euler_explicit_damping`` core's
``semi_implicit_euler`` on a chain, ...), so no pair is named here. Workloads: the tumbling boxes of
:mod:`comparisons.bench.stepping` (B boxes in one scene) and the falling iiwa of :mod:`comparisons.bench.joint_motion`
(B copies), each engine's ``run`` timed (the recorded trajectory included), on one BLAS thread."""

from __future__ import annotations

import math
from collections.abc import Callable

from simparity.comparisons.bench import joint_motion, stepping
from simparity.comparisons.bench.rows import REPEATS, BenchRow, Meter, median_time
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes import library

BATCHES = (1, 3)
"""Bodies (or arm copies) per scene: simparity's scenes have one to three."""
ENGINES = ("core", "mujoco")
"""The engine whose time is divided (core) and the one it is divided by."""
ARM = joint_motion.ARMS[0]
"""The arm of the joint-space pairs."""
STEPS = {"bodies": 1000, "arm": 200}
"""Steps per timed call (a fifth quick): 1 s of the boxes at :data:`comparisons.bench.stepping.DT`, 0.4 s of the arm
at :data:`comparisons.bench.joint_motion.DT`."""
SECTION, RATIO_SECTION = "small_batch", "small_batch_ratio"
UNIT = "us/step"


def _integrators(engine, kind: str) -> tuple[str, ...]:
    return engine.integrators() if kind == "bodies" else engine.joint_motion_integrators()


def same_scheme_pairs(kind: str, scene) -> list[tuple[str, str, str]]:
    """(scheme, core's integrator, MuJoCo's integrator) of every pair the two engines name the same scheme on
    ``scene`` (``kind``: ``bodies`` or ``arm``)."""
    core, other = (make_engine(name) for name in ENGINES)
    theirs = [(other.scheme(i, scene), i) for i in _integrators(other, kind)]
    return [(scheme, mine, i) for mine in _integrators(core, kind) for scheme, i in theirs
            if scheme and core.scheme(mine, scene) == scheme]


def _simulation(engine: str, integrator: str, kind: str, batch: int, steps: int):
    if kind == "bodies":
        return stepping.simulation(engine, integrator, stepping.boxes(batch, False))
    arm = joint_motion.copies(library.load([ARM])[0], batch, steps)
    return make_engine(engine).build_joint_motion(arm, integrator, joint_motion.DT)


def small_batch_rows(quick: bool, say: Callable[[str], None]) -> list[BenchRow]:
    """A row per workload x engine x integrator x B of :data:`BATCHES` [us per step of the whole scene], and a
    :data:`RATIO_SECTION` row per same-scheme pair x B: core's time over MuJoCo's (> 1: core is slower)."""
    rows: list[BenchRow] = []
    for kind, workload, scene in (("bodies", "tumbling", stepping.boxes(1, False)),
                                  ("arm", ARM, library.load([ARM])[0])):
        pairs = same_scheme_pairs(kind, scene)
        steps = STEPS[kind] // (5 if quick else 1)
        for batch in BATCHES:
            timed: dict[tuple[str, str], BenchRow] = {}
            for scheme, *integrators in pairs:
                for engine, integrator in zip(ENGINES, integrators):
                    if (engine, integrator) in timed:
                        continue
                    timed[engine, integrator] = _timed(engine, integrator, kind, workload, batch, steps, scheme)
                    rows.append(timed[engine, integrator])
                mine, theirs = (timed[engine, integrator] for engine, integrator in zip(ENGINES, integrators))
                ratio = mine.value / theirs.value
                rows.append(BenchRow(RATIO_SECTION, workload, " / ".join(ENGINES), " / ".join(integrators), batch,
                                     ratio, "x", math.nan, "", scheme))
                say(f"  {workload:<13} {scheme:<20} B={batch} core {integrators[0]:<22} {mine.value:8.1f} us/step, "
                    f"mujoco {integrators[1]:<22} {theirs.value:8.1f} us/step: {ratio:6.1f}x")
    return rows


def _timed(engine: str, integrator: str, kind: str, workload: str, batch: int, steps: int, scheme: str) -> BenchRow:
    """The row of one engine's ``run`` of ``steps`` steps of ``batch`` bodies or copies (n/a with why if it fails)."""
    try:
        sim = _simulation(engine, integrator, kind, batch, steps)
        with Meter() as meter:
            seconds = median_time(lambda: sim.run(steps), REPEATS)
    except Exception as err:  # noqa: BLE001 - an engine that cannot: its row says why
        return BenchRow(SECTION, workload, engine, integrator, batch, math.nan, UNIT, math.nan, "", f"n/a: {err}")
    return meter.stamp(BenchRow(SECTION, workload, engine, integrator, batch, seconds / steps * 1e6, UNIT, math.nan,
                                "", f"{scheme}; {steps} steps per call"))


def markdown_lines(rows: list[BenchRow]) -> list[str]:
    """The BENCHMARKS.md section: per workload and same-scheme pair, core's and MuJoCo's time per step and the
    ratio at each B."""
    ratios = [r for r in rows if r.section == RATIO_SECTION]
    if not ratios:
        return []
    timed = {(r.workload, r.engine, r.method, r.batch): r.value for r in rows if r.section == SECTION}
    lines = ["## Small batches: core against MuJoCo's same scheme at B = 1 and B = 3 (us per step of the scene)", "",
             "Every integrator pair the two engines name the same scheme; B boxes tumbling in one scene, or B copies "
             f"of {ARM}. Ratio core / MuJoCo: > 1, core is slower.", "",
             "| workload | scheme | core | MuJoCo | " + " | ".join(f"B = {b} core | B = {b} MuJoCo | B = {b} ratio" for b in BATCHES)
             + " |", "|---|---|---|---|" + "---|---|---|" * len(BATCHES)]
    for workload, method, scheme in dict.fromkeys((r.workload, r.method, r.note) for r in ratios):
        mine, theirs = method.split(" / ")
        cells = []
        for batch in BATCHES:
            core, other = timed.get((workload, ENGINES[0], mine, batch), math.nan), timed.get(
                (workload, ENGINES[1], theirs, batch), math.nan)
            cells.append(f"{_cell(core)} | {_cell(other)} | {_cell(core / other)}")
        lines.append(f"| {workload} | {scheme} | {mine} | {theirs} | " + " | ".join(cells) + " |")
    return lines + [""]


def _cell(value: float, digits: str = ",.1f") -> str:
    return format(value, digits) if math.isfinite(value) else "n/a"
