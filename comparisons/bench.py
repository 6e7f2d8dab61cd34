"""``simparity bench``: speed with its accuracy, core against the engines, measured in one run.

Three workloads, every time the median of repeats after a warm-up call, every ratio core / engine
computed from the same run:

1. rigid-body stepping of B identical boxes (torque-free tumbling; falling with drag), time per
   body-step of each engine's ``run`` (recording every step included), next to the error each
   reaches at that dt against the tight reference (DOP853 at 1e-13, on the first
   :data:`ERROR_BODIES` bodies over :data:`ERROR_STEPS` steps: bodies are independent, so the
   error does not depend on B);
2. forward kinematics + end-effector Jacobian of the iiwa and the UR5, time per configuration, with
   the largest difference to Pinocchio;
3. IK on the ``bench`` suite's arms (TRAC-IK protocol), solve rate and time per solve, failures
   inside the time, limit violations.

Results go to ``benchmarks.csv`` (one tidy row per measurement) and ``BENCHMARKS.md``.
"""

from __future__ import annotations

import csv
import functools
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from simparity.comparisons.scenes import library
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.ik_targets import random_targets
from simparity.comparisons.measure.metrics import kinematics_errors, trajectory_errors
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix
from simparity.core.model.scene import DynamicsScene, Forces, RigidBody, sample_configurations
from simparity.references.differential_ik import MinkIK, PinkIK, available
from simparity.references.mujoco.adapter import BatchRollout, MujocoChain
from simparity.references.pinocchio.adapter import PinocchioChain
from simparity.core.model.metric_catalogue import JACOBIAN_ERROR_MAX, ORIENTATION_ERROR_MAX, POSITION_ERROR_MAX

ERROR_BODIES = 4
"""Bodies whose trajectories are compared with the tight reference."""
ERROR_STEPS = 1000
"""Steps over which the error is measured (1 s at dt = 1e-3)."""
ERROR_METRIC = {"tumbling": ORIENTATION_ERROR_MAX, "falling-drag": POSITION_ERROR_MAX}
"""The error each workload is judged by: torque-free tumbling moves only the orientation in an interesting way."""
ERROR_UNIT = {"tumbling": "rad", "falling-drag": "m"}
DT = 1e-3
"""[s] Time step of every stepping measurement."""
BUDGET_SECONDS = 20.0
"""An engine's measurement at a batch size is skipped (n/a, with the estimate) when a probe of
:data:`PROBE_STEPS` steps at that size predicts more than this per call."""
PROBE_STEPS = 5
REPEATS = 5
"""Timed calls per measurement (median), after one warm-up call."""

DYNAMICS = (("core", "rk4"), ("core", "semi_implicit_euler"), ("core", "engine_euler"),
            ("mujoco", "euler"), ("mujoco", "rk4"), ("mujoco-rollout", "euler"), ("mujoco-rollout", "rk4"),
            ("pybullet", "euler"), ("pinocchio", "euler"), ("pinocchio", "rk4"))
"""(engine, integrator) of the stepping table; ``mujoco-rollout`` is :class:`BatchRollout`."""

KINEMATICS = ("core", "pinocchio", "mujoco", "pybullet")
KINEMATICS_SEED = 5
ERROR_CONFIGURATIONS = 100
"""Configurations of each batch (its first) whose FK and Jacobian are compared with Pinocchio's."""
IK = (("core", "damped_least_squares"), ("core", "damped_least_squares+restarts"), ("mujoco", "dls"),
      ("pybullet", "calculateInverseKinematics"), ("pybullet", "calculateInverseKinematics-tuned"),
      ("pinocchio", "clik"))
LIBRARY_IK = ("mink", "pink")
"""Differential-IK libraries (:mod:`references.differential_ik`): one QP per update, milliseconds per solve, so
they solve the first :data:`LIBRARY_TARGETS` targets of each arm."""
LIBRARY_TARGETS = 1000


@dataclass(frozen=True)
class BenchRow:
    """One measurement: ``value`` per ``unit`` (e.g. microseconds per body-step), with its accuracy."""

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


def boxes(n_bodies: int, drag: bool, seed: int = 0) -> DynamicsScene:
    """B identical boxes (2 kg, I = diag(0.1, 0.2, 0.3) kg m^2) from seeded random states: torque-free
    tumbling without gravity, or falling under gravity with linear and angular drag."""
    rng = np.random.default_rng(seed)
    bodies = []
    for k in range(n_bodies):
        q = quat_wxyz_normalize(rng.normal(size=4))
        bodies.append(RigidBody(f"box{k}", 2.0, np.diag([0.1, 0.2, 0.3]), rng.normal(size=3), q, rng.normal(size=3),
                                quat_wxyz_to_matrix(q) @ rng.normal(0, 2, size=3)))
    ones = np.ones(n_bodies)
    forces = (Forces(np.array([0.0, 0.0, -9.81]), linear_drag=0.5 * ones, angular_linear_drag=0.05 * ones) if drag
              else Forces())
    return DynamicsScene("falling-drag" if drag else "tumbling", "benchmark", "tight", tuple(bodies), forces,
                         ERROR_STEPS * DT, (DT,))


def _simulation(engine: str, integrator: str, scene: DynamicsScene):
    if engine == "mujoco-rollout":
        return BatchRollout(scene, integrator, DT, os.cpu_count() or 1)
    return make_engine(engine).build_dynamics(scene, integrator, DT)


def _steps(batch: int, quick: bool) -> int:
    """Steps timed at a batch size: about 10^6 body-steps (10^5 quick), 10 to 1000 steps."""
    return int(min(1000, max(10, (100_000 if quick else 1_000_000) // batch)))


def dynamics_rows(batches: list[int], quick: bool, say: Callable[[str], None]) -> list[BenchRow]:
    rows = []
    for drag in (False, True):
        workload = boxes(1, drag).name
        small = boxes(ERROR_BODIES, drag)
        reference = make_engine("tight").build_dynamics(small, "dop853", DT).run(ERROR_STEPS)
        for engine, integrator in DYNAMICS:
            try:
                errors = trajectory_errors(_simulation(engine, integrator, small).run(ERROR_STEPS), reference)
                error, note = errors[ERROR_METRIC[workload]].value, ""
            except Exception as err:  # noqa: BLE001 - an engine that cannot do the workload is a row saying why
                rows += [BenchRow("dynamics", workload, engine, integrator, b, math.nan, "us/body-step", math.nan,
                                  ERROR_UNIT[workload], f"n/a: {err}") for b in batches]
                continue
            for batch in batches:
                steps = _steps(batch, quick)
                try:
                    sim = _simulation(engine, integrator, boxes(batch, drag))
                    # A short probe at this batch size predicts the call (a smaller batch's cost per body-step
                    # would not: batching makes it fall up to a hundredfold).
                    probe = median_time(lambda: sim.run(PROBE_STEPS), 0) / PROBE_STEPS * steps
                    if probe > BUDGET_SECONDS:
                        rows.append(BenchRow("dynamics", workload, engine, integrator, batch, math.nan,
                                             "us/body-step", error, ERROR_UNIT[workload],
                                             f"n/a: skipped, {PROBE_STEPS} steps predict {probe:.0f} s per call of "
                                             f"{steps} steps (budget {BUDGET_SECONDS:g} s)"))
                        continue
                    seconds = median_time(lambda: sim.run(steps), 1 if probe > 1.0 else REPEATS)
                except Exception as err:  # noqa: BLE001
                    rows.append(BenchRow("dynamics", workload, engine, integrator, batch, math.nan, "us/body-step",
                                         error, ERROR_UNIT[workload], f"n/a: {err}"))
                    continue
                per_body_step = seconds / (batch * steps)
                rows.append(BenchRow("dynamics", workload, engine, integrator, batch, per_body_step * 1e6,
                                     "us/body-step", error, ERROR_UNIT[workload], note))
                say(f"  {workload:<13} {engine:<15} {integrator:<20} B={batch:<6} {per_body_step * 1e6:9.3f} "
                    f"us/body-step   error {error:.2e} {ERROR_UNIT[workload]}")
    return rows


def _kinematics_chains() -> list:
    return [library.load(["bench-iiwa-ik"])[0].chain, library.load(["bench-ur5-ik"])[0].chain]


def kinematics_rows(batches: list[int], say: Callable[[str], None]) -> list[BenchRow]:
    rows = []
    for chain in _kinematics_chains():
        # Errors on every batch's first ERROR_CONFIGURATIONS configurations (one seeded draw), judged once.
        judged = sample_configurations(chain, ERROR_CONFIGURATIONS, KINEMATICS_SEED)
        judge = make_engine("pinocchio").build_kinematics(chain)
        ref_poses, ref_jacobian = judge.forward_kinematics(judged), judge.jacobian_world(judged)
        for engine in KINEMATICS:
            model = make_engine(engine).build_kinematics(chain)
            for batch in batches:
                # Engines answer one configuration per call: their time per configuration is measured on
                # at most 1,000.
                count = batch if engine == "core" else min(batch, 1000)
                q = sample_configurations(chain, count, KINEMATICS_SEED)

                def both():
                    return model.forward_kinematics(q), model.jacobian_world(q)

                seconds = median_time(both, REPEATS if count * chain.n_joints < 50_000 else 2)
                poses, jac = both()
                k = min(count, ERROR_CONFIGURATIONS)
                errors = kinematics_errors(poses_slice(poses, k), jac[:k], poses_slice(ref_poses, k), ref_jacobian[:k])
                error = max(errors[POSITION_ERROR_MAX].value, errors[JACOBIAN_ERROR_MAX].value)
                rows.append(BenchRow("kinematics", chain.name, engine, "fk+jacobian", batch, seconds / count * 1e6,
                                     "us/configuration", error, "m", "vs pinocchio" if engine != "pinocchio" else ""))
                say(f"  {chain.name:<13} {engine:<10} B={batch:<6} {seconds / count * 1e6:9.3f} us/configuration")
    return rows


def poses_slice(poses, k: int):
    """The first k configurations' frame poses."""
    return replace(poses, position_world=poses.position_world[:k], rotation_world=poses.rotation_world[:k])


def _build_ik(engine: str, chain, solver: str, options: IKTolerances) -> Any:
    """Engine ``engine``'s IK solver ``solver`` for ``chain``, built when the bench reaches it."""
    return make_engine(engine).build_ik(chain, solver, options)


def _library_ik(name: str, chain, options: IKTolerances):
    """The differential-IK library ``name`` on the chain, through its engine's chain model."""
    if name == "mink":
        return MinkIK(MujocoChain(chain), chain, options)
    return PinkIK(PinocchioChain(chain), chain, options)


def ik_rows(n_targets: int | None, say: Callable[[str], None]) -> list[BenchRow]:
    rows = []
    for scene in library.suite("bench"):
        if n_targets is not None:
            scene = replace(scene, n_targets=n_targets)
        targets = random_targets(scene, make_engine(scene.reference).build_kinematics(scene.chain))
        options = IKTolerances(scene.position_tolerance, scene.orientation_tolerance, scene.max_iterations)
        solvers: list[tuple[str, str, Callable[[], Any]]] = [
            (engine, solver, functools.partial(_build_ik, engine, scene.chain, solver, options)) for engine, solver in IK]
        solvers += [(name, "documented loop", functools.partial(_library_ik, name, scene.chain, options))
                    for name in LIBRARY_IK]
        for engine, solver, build in solvers:
            count = min(scene.n_targets, LIBRARY_TARGETS) if engine in LIBRARY_IK else scene.n_targets
            missing = available(engine) if engine in LIBRARY_IK else ""
            if missing:
                rows.append(BenchRow("ik", scene.chain.name, engine, solver, count, math.nan, "ms/solve", math.nan,
                                     "solve rate", f"n/a: {missing}"))
                say(f"  {scene.chain.name:<13} {engine:<10} n/a: {missing}")
                continue
            model = build()
            start = time.perf_counter()
            rotation = None if targets.rotation_world is None else targets.rotation_world[:count]
            result = model.solve(targets.position_world[:count], rotation, scene.q_start)
            seconds = time.perf_counter() - start
            violations = int(np.sum(result.limit_violation > 0))
            sample = f"; the first {count:,} targets" if count < scene.n_targets else ""
            rows.append(BenchRow("ik", scene.chain.name, engine, solver, count, seconds / count * 1e3, "ms/solve",
                                 result.solve_rate, "solve rate", f"{violations} solutions outside the limits{sample}"))
            say(f"  {scene.chain.name:<13} {engine:<10} {solver:<34} {result.solve_rate:8.4f} solved "
                f"{seconds / count * 1e3:8.3f} ms/solve ({count / seconds:,.0f}/s)")
    return rows


MEMORY_SCENE = "hard-million-steps"
"""The built-in 10^6-step scene (a body thrown up at 490.5 m/s, 0.1 ms steps, every default engine)."""
MEMORY_LIMIT_MIB = 1024


def memory_rows(quick: bool, folder: Path, say: Callable[[str], None]) -> list[BenchRow]:
    """Peak memory of ``simparity run`` on :data:`MEMORY_SCENE` cut to 10^5 and 10^6 steps (10^4 and 10^5
    quick), each in its own process (one job): whether memory stays flat in the number of steps."""
    text = library.resolve(MEMORY_SCENE).read_text(encoding="utf-8")
    rows = []
    for steps in ((10_000, 100_000) if quick else (100_000, 1_000_000)):
        scene = folder / f"memory-{steps}.toml"
        scene.write_text(text.replace("duration = 100.0", f"duration = {steps * 1e-4!r}"), encoding="utf-8")
        command = [sys.executable, "-c", "import sys; from simparity.comparisons.cli.main import main; sys.exit(main())",
                   "run", str(scene), "--repeats", "0", "--jobs", "1", "--force", "--out", str(folder / f"run-{steps}")]
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True)
        seconds = time.perf_counter() - start
        found = re.search(r"peak memory ([\d,]+) MiB", done.stdout)
        peak = float(found.group(1).replace(",", "")) if found else math.nan
        rows.append(BenchRow("memory", MEMORY_SCENE, "simparity run", "every default engine", steps, peak, "MiB",
                             seconds, "s", "" if found else f"n/a: the run printed no peak memory: {done.stderr[-300:]}"))
        say(f"  {MEMORY_SCENE} cut to {steps:,} steps: peak {peak:,.0f} MiB in {seconds:.0f} s")
    return rows


def machine() -> dict[str, str]:
    """What the numbers were measured on."""
    import mujoco
    import pinocchio
    from importlib import metadata
    return {"python": platform.python_version(), "numpy": np.__version__, "mujoco": mujoco.__version__,
            "pinocchio": pinocchio.__version__, "pybullet": metadata.version("pybullet"),
            "cpu": platform.processor() or platform.machine(), "cores": str(os.cpu_count()),
            "system": platform.platform()}


def write_csv(rows: list[BenchRow], path: Path) -> None:
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(asdict(rows[0])))
        writer.writeheader()
        writer.writerows(asdict(r) for r in rows)


def _cell(value: float, digits: str = ".3g") -> str:
    return "n/a" if not math.isfinite(value) else format(value, digits)


def _best(rows: list[BenchRow], **match) -> BenchRow | None:
    """The fastest measured row matching every field given."""
    found = [r for r in rows if math.isfinite(r.value) and all(getattr(r, k) == v for k, v in match.items())]
    return min(found, key=lambda r: r.value) if found else None


RK4_ORDER = 4


def equal_error_factor(error: float, other_error: float, order: int) -> float:
    """Speed-ratio factor for reaching ``other_error`` instead of ``error`` with a scheme of ``order``: error ~ dt^p,
    so a scheme with the larger error needs (error / other_error)^(1/p) times the steps. Never above 1 (a smaller
    error is not converted into speed)."""
    if not (error > 0 and other_error > 0):
        return 1.0
    return min(1.0, (other_error / error) ** (1 / order))


def targets(rows: list[BenchRow]) -> list[tuple[str, str, bool | None]]:
    """(target, what was measured, met) for the issue's targets; met None where this run cannot tell."""
    out: list[tuple[str, str, bool | None]] = []
    largest = max((r.batch for r in rows if r.section == "dynamics"), default=0)
    core = _best(rows, section="dynamics", workload="tumbling", engine="core", method="rk4", batch=largest)
    for engine, method, factor in (("mujoco", "rk4", 5.0), ("mujoco-rollout", "rk4", 5.0),
                                   ("mujoco-rollout", "euler", 2.0)):
        other = _best(rows, section="dynamics", workload="tumbling", engine=engine, method=method)
        if core is None or other is None:
            out.append((f"core rk4 at B = {largest:,} >= {factor:g}x {engine} {method}", "not measured", None))
            continue
        ratio = other.value / core.value
        fair = ratio * equal_error_factor(core.accuracy, other.accuracy, RK4_ORDER)
        out.append((f"core rk4 at B = {largest:,} >= {factor:g}x the throughput of {engine} {method} (its best B) "
                    f"at equal or better error",
                    f"{ratio:.2f}x per body-step ({core.value:.3g} vs {other.value:.3g} us at B = {other.batch:,}); "
                    f"error {core.accuracy:.1e} vs {other.accuracy:.1e} {core.accuracy_unit}, so {fair:.2f}x at equal "
                    f"error", fair >= factor))
    for chain in sorted({r.workload for r in rows if r.section == "kinematics"}):
        big = max(r.batch for r in rows if r.section == "kinematics")
        c = _best(rows, section="kinematics", workload=chain, engine="core", batch=big)
        p = _best(rows, section="kinematics", workload=chain, engine="pinocchio")
        if c and p:
            out.append((f"{chain}: core FK + Jacobian at B = {big:,} >= 2x Pinocchio per configuration",
                        f"{p.value / c.value:.2f}x ({c.value:.3g} vs {p.value:.3g} us)", p.value / c.value >= 2))
    memory = sorted((r for r in rows if r.section == "memory" and math.isfinite(r.value)), key=lambda r: r.batch)
    if memory:
        most = memory[-1]
        out.append((f"peak memory <= {MEMORY_LIMIT_MIB:,} MiB for {most.batch:,} steps of {MEMORY_SCENE}",
                    f"{most.value:,.0f} MiB", most.value <= MEMORY_LIMIT_MIB))
    if len(memory) > 1:
        low, high = memory[0], memory[-1]
        per_step = (high.value - low.value) * 2**20 / (high.batch - low.batch)
        out.append((f"memory flat in the number of steps ({low.batch:,} -> {high.batch:,} steps)",
                    f"{low.value:,.0f} -> {high.value:,.0f} MiB, {per_step:,.0f} bytes per step: every step of the "
                    "engine's and the reference's trajectories is held for the metrics (no streaming yet)",
                    high.value <= 1.2 * low.value))
    for chain in sorted({r.workload for r in rows if r.section == "ik"}):
        mine = [r for r in rows if r.section == "ik" and r.workload == chain]
        c = next((r for r in mine if r.method == "damped_least_squares+restarts"), None)
        if c is None:
            continue
        others = [r for r in mine if r.engine != "core" and math.isfinite(r.value)]
        inside = c.note.startswith("0 ")
        out.append((f"{chain}: core restarts solve >= 99.9 % inside the limits", f"{c.accuracy:.2%}, {c.note}",
                    c.accuracy >= 0.999 and inside))
        out.append((f"{chain}: core restarts faster per solve and more often solved than every other solver "
                    f"({', '.join(sorted({r.engine for r in others}))})",
                    f"{c.value:.3g} ms vs the fastest other {min(r.value for r in others):.3g} ms; rate "
                    f"{c.accuracy:.2%} vs the best other {max(r.accuracy for r in others):.2%}",
                    c.value < min(r.value for r in others) and c.accuracy > max(r.accuracy for r in others)))
        if "iiwa" in chain:
            out.append((f"{chain}: >= 10,000 solves/s", f"{1e3 / c.value:,.0f} solves/s", 1e3 / c.value >= 10_000))
    return out


def markdown(rows: list[BenchRow], info: dict[str, str], command: str, profile: str, seconds: float) -> str:
    lines = ["# BENCHMARKS", "", f"Written by `{command}` in {seconds:.0f} s on "
             + ", ".join(f"{k} {v}" for k, v in info.items()) + ". Every time is the median of repeated calls "
             "after a warm-up; every ratio is from this run. The raw rows are in `benchmarks.csv`.", "",
             "## Targets", "", "| target | measured | met |", "|---|---|---|"]
    for target, measured, met in targets(rows):
        lines.append(f"| {target} | {measured} | {'n/a' if met is None else 'yes' if met else '**MISSED**'} |")
    lines += ["", "The default suite's wall time (target <= 3 min) is printed on the last line of every `simparity run`, "
              "with its peak memory.", ""]
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
    ik = [r for r in rows if r.section == "ik"]
    if ik:
        lines += [f"## IK, TRAC-IK protocol ({ik[0].batch:,} seeded pose targets per arm from mid-range, success at "
                  "1e-6 m and 1e-6 rad, inside the limits; failures inside the time)", "",
                  "| arm | engine | solver | targets | solve rate | ms per solve | solves/s | note |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in ik:
            lines.append(f"| {r.workload} | {r.engine} | {r.method} | {r.batch:,} | {_cell(r.accuracy, '.2%')} | "
                         f"{_cell(r.value)} | {_cell(1e3 / r.value, ',.0f')} | {r.note} |")
        lines.append("")
    memory = [r for r in rows if r.section == "memory"]
    if memory:
        lines += [f"## Memory of `simparity run` against the number of steps ({MEMORY_SCENE}, one process)", "",
                  "| steps | peak memory [MiB] | wall time [s] | note |", "|---|---|---|---|"]
        lines += [f"| {r.batch:,} | {_cell(r.value, ',.0f')} | {_cell(r.accuracy, '.0f')} | {r.note} |" for r in memory]
        lines.append("")
    lines += ["## Profile", "", "Where core's time goes (cProfile, functions by own time):", "", "```", profile.rstrip(),
              "```", ""]
    return "\n".join(lines)


def profile_summary(batch: int, say: Callable[[str], None]) -> str:
    """cProfile of core's rk4 on ``batch`` tumbling boxes and of its restarted IK on the iiwa, top functions."""
    import cProfile
    import io
    import pstats
    out = []
    sim = _simulation("core", "rk4", boxes(batch, False))
    scene = replace(library.load(["bench-iiwa-ik"])[0], n_targets=min(batch, 10_000))
    targets = random_targets(scene, make_engine("core").build_kinematics(scene.chain))
    model = make_engine("core").build_ik(scene.chain, "damped_least_squares+restarts",
                                         IKTolerances(scene.position_tolerance, scene.orientation_tolerance,
                                                      scene.max_iterations))
    for title, call in ((f"core rk4, {batch:,} tumbling boxes, 20 steps", lambda: sim.run(20)),
                        (f"core damped_least_squares+restarts, {scene.n_targets:,} iiwa targets",
                         lambda: model.solve(targets.position_world, targets.rotation_world, scene.q_start))):
        say(f"  profiling {title}")
        profiler = cProfile.Profile()
        profiler.runcall(call)
        text = io.StringIO()
        pstats.Stats(profiler, stream=text).strip_dirs().sort_stats("tottime").print_stats(8)
        body = [line for line in text.getvalue().splitlines() if line.strip()][2:]
        out += [title] + body + [""]
    return "\n".join(out)


def run_bench(out_dir: Path, quick: bool, command: str, say: Callable[[str], None]) -> Path:
    """Measure everything, write ``benchmarks.csv`` and ``BENCHMARKS.md`` into ``out_dir``; returns the latter."""
    start = time.perf_counter()
    out_dir.mkdir(parents=True, exist_ok=True)
    batches = [1, 100] if quick else [1, 100, 10_000]
    say("stepping (time per body-step, with the error at that dt)")
    rows = dynamics_rows(batches, quick, say)
    say("forward kinematics + Jacobian")
    rows += kinematics_rows(batches, say)
    say("IK")
    rows += ik_rows(300 if quick else None, say)
    say("memory of simparity run against the number of steps")
    with tempfile.TemporaryDirectory() as folder:
        rows += memory_rows(quick, Path(folder), say)
    say("profile")
    profile = profile_summary(batches[-1], say)
    write_csv(rows, out_dir / "benchmarks.csv")
    path = out_dir / "BENCHMARKS.md"
    path.write_text(markdown(rows, machine(), command, profile, time.perf_counter() - start))
    for target, measured, met in targets(rows):
        say(f"{'n/a   ' if met is None else 'met   ' if met else 'MISSED'} {target}: {measured}")
    return path
