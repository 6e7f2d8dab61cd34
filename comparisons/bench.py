"""``simparity bench``: speed with its accuracy, core against the engines, measured in one run.

Five workloads, every time the median of repeats after a warm-up call, every ratio core / engine
computed from the same run:

1. rigid-body stepping of B identical boxes (torque-free tumbling; falling with drag), time per
   body-step of each engine's ``run`` (recording every step included), next to the error each
   reaches at that dt against the tight reference (DOP853 at 1e-13, on the first
   :data:`ERROR_BODIES` bodies over :data:`ERROR_STEPS` steps: bodies are independent, so the
   error does not depend on B);
2. forward kinematics + end-effector Jacobian of the iiwa and the UR5, time per configuration, with
   the largest difference to Pinocchio;
3. IK on the ``bench`` suite's arms (TRAC-IK protocol), solve rate and time per solve, failures
   inside the time, limit violations;
4. joint-space dynamics (M + h, RNEA, ABA) of the ``articulated`` suite's real arms, time per state with the largest
   relative difference to Pinocchio (:mod:`comparisons.bench_joint_dynamics`);
5. joint motion of the falling arms, time per copy-step of each engine's RK4 at equal accuracy (the error against
   DOP853 and the difference to Pinocchio's RK4) (:mod:`comparisons.bench_joint_motion`).

Results go to ``benchmarks.csv`` (one tidy row per measurement) and ``BENCHMARKS.md``, with a verdict on each of
the issue's targets that says what it compared. The targets are set for the full sizes (:data:`TARGET_BATCH` bodies
and configurations, :data:`TARGET_IK_TARGETS` IK targets, :data:`TARGET_MEMORY_STEPS` steps); measured at other sizes
(``--quick``), a target is "not comparable", never met or missed. IK speed is compared only among solvers that solve
at least :data:`COMPARABLE_SOLVE_RATE` times as often as core at the harness's tolerance.
"""

from __future__ import annotations

import csv
import functools
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from collections.abc import Callable
from typing import Any

import numpy as np

from simparity.comparisons import bench_joint_dynamics, bench_joint_motion, bench_sweep
from simparity.comparisons.scenes import library
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.ik_targets import random_targets
from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_ROBOTS
from simparity.comparisons.execute.timing import PeakMemory
from simparity.comparisons.measure.metrics import kinematics_errors, trajectory_errors
from simparity.core.model.errors import ResultsError, SimparityError, one_line
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.chain import sample_configurations
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.urdf import chain_from_urdf
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
FIVE_DOF_ARM = "so_arm100"
"""The IK section's under-actuated arm (:func:`five_dof_scene`): 5 joints cannot reach a generic 6-D pose, but they
reach the TRAC-IK protocol's targets, the poses of configurations within the limits."""
FIVE_DOF_IK = (("core", "damped_least_squares"), ("core", "damped_least_squares+restarts"))
"""Solvers timed on the 5-DOF arm: core's (its target there is the solve rate; the other engines' IK is compared on
the bench suite's arms)."""
LIBRARY_IK = ("mink", "pink")
"""Differential-IK libraries (:mod:`references.differential_ik`): one QP per update, milliseconds per solve, so
they solve the first :data:`LIBRARY_TARGETS` targets of each arm."""
LIBRARY_TARGETS = 1000
TARGET_BATCH = 10_000
"""Bodies and configurations per batch the speed targets are set for (the largest batch of a full bench)."""
TARGET_IK_TARGETS = 10_000
"""IK targets per arm the IK targets are set for (the ``bench`` suite's count; core solves them as one batch)."""
TARGET_MEMORY_STEPS = 1_000_000
"""Steps the memory targets are set for (:data:`MEMORY_SCENE` uncut)."""
COMPARABLE_SOLVE_RATE = 0.5
"""A solver's speed is compared with core's only if it solves at least this fraction of core's solve rate: one that
fails most targets is not doing the same job faster (PyBullet's default stops at 1e-4 m and solves 0 % at the
harness's 1e-6 m)."""


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


def five_dof_scene() -> IKScene:
    """The 5-DOF SO-100 arm of the example-robot-data wheel (``so_arm_description/urdf/so100.urdf``, base to
    gripper) on the UR5 bench scene's protocol: its seed, count, tolerances and iteration cap, solved from the middle
    of the joint ranges."""
    from importlib import metadata

    robots = Path(str(metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)))
    chain = chain_from_urdf(str(robots / "so_arm_description" / "urdf" / "so100.urdf"), "base", "gripper")
    protocol = library.load(["bench-ur5-ik"])[0]
    return replace(protocol, name="bench-so100-ik", chain=chain, q_start=(chain.lower + chain.upper) / 2,
                   description="Benchmark: the example-robot-data wheel's 5-DOF SO-100 (so100.urdf, base to gripper), "
                               "10,000 seeded pose targets from mid-range (TRAC-IK protocol), reachable by "
                               "construction.")


def ik_rows(n_targets: int | None, say: Callable[[str], None]) -> list[BenchRow]:
    rows = []
    for scene in library.suite("bench") + [five_dof_scene()]:
        if n_targets is not None:
            scene = replace(scene, n_targets=n_targets)
        targets = random_targets(scene, make_engine(scene.reference).build_kinematics(scene.chain))
        options = IKTolerances(scene.position_tolerance, scene.orientation_tolerance, scene.max_iterations)
        five_dof = scene.chain.name == FIVE_DOF_ARM
        solvers: list[tuple[str, str, Callable[[], Any]]] = [
            (engine, solver, functools.partial(_build_ik, engine, scene.chain, solver, options))
            for engine, solver in (FIVE_DOF_IK if five_dof else IK)]
        solvers += [(name, "documented loop", functools.partial(_library_ik, name, scene.chain, options))
                    for name in (() if five_dof else LIBRARY_IK)]
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
WORKER_LIMIT_MIB = 1024
"""[MiB] What a worker may hold for :data:`CHEAP_MEMORY_STEPS`' largest run."""


def memory_rows(quick: bool, folder: Path, say: Callable[[str], None]) -> list[BenchRow]:
    """Peak memory of ``simparity run --jobs 1``, each run in its own process: on :data:`MEMORY_SCENE` with every
    default engine cut to 10^5 and 10^6 steps, and on :data:`CHEAP_MEMORY` at :data:`CHEAP_MEMORY_STEPS` (a tenth
    of each quick). A :data:`MEMORY_PROCESS` and a :data:`MEMORY_CHILD` row per run [MiB], read from the run's
    ``run.json``, with the run's wall time [s] as accuracy."""
    text = library.resolve(MEMORY_SCENE).read_text(encoding="utf-8")
    scale = 10 if quick else 1
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
        peak, seconds, stderr = run_peak_memory([str(scene), "--repeats", "0", "--jobs", "1", "--max-steps",
                                                 str(steps), *engines], folder / f"run-{index}")
        note = "" if peak else f"n/a: the run recorded no peak memory: {stderr}"
        method_of = "simparity run --jobs 1" + (f" {' '.join(engines)}" if engines else "")
        for method, mib in ((MEMORY_PROCESS, peak.this_process_bytes / 2**20 if peak else math.nan),
                            (MEMORY_CHILD, peak.largest_child_bytes / 2**20 if peak else math.nan)):
            rows.append(BenchRow("memory", workload, method_of, method, steps, mib, "MiB", seconds, "s", note))
        say(f"  {workload} cut to {steps:,} steps: peak {rows[-2].value:,.0f} MiB in this process, "
            f"{rows[-1].value:,.0f} MiB in its largest child, in {seconds:.0f} s")
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


@dataclass(frozen=True)
class Verdict:
    """One of the issue's targets: what it requires, what this run compared for it (with the numbers), whether met."""

    target: str
    compared: str
    met: bool | None
    """None: not judged, because not measured or (``set_for``) measured at another size than the target's."""
    measured_at: str = ""
    set_for: str = ""
    """The size the target is set for (``B = 10,000``) where this run measured at another, ``measured_at``."""

    @property
    def status(self) -> str:
        """``met``, ``MISSED``, ``not comparable`` (measured at another size) or ``n/a`` (not measured)."""
        if self.met is not None:
            return "met" if self.met else "MISSED"
        return "not comparable" if self.set_for else "n/a"

    @property
    def label(self) -> str:
        """The status with why a target was not comparable."""
        return (f"{self.status} (measured at {self.measured_at}, target set for {self.set_for})" if self.set_for
                else self.status)


def _sized(target: str, compared: str, met: bool, measured_at: str, set_for: str) -> Verdict:
    """The verdict on a target set for one size (batch, targets, steps): judged only at that size. Core's batched
    speed and a run's memory change with the size, so a verdict at a quick size would be an artefact of it."""
    if measured_at != set_for:
        return Verdict(target, compared, None, measured_at, set_for)
    return Verdict(target, compared, met)


def _solver(row: BenchRow) -> str:
    return f"{row.engine} {row.method}"


def _ik_speed(chain: str, core: BenchRow, others: list[BenchRow]) -> Verdict:
    """Core's restarts faster per solve than every other solver that solves at least :data:`COMPARABLE_SOLVE_RATE`
    times as often as core (on the same targets, at the harness's tolerance); the others are named as excluded."""
    floor = COMPARABLE_SOLVE_RATE * core.accuracy
    compared = sorted((r for r in others if r.accuracy >= floor), key=lambda r: r.value)
    excluded = [r for r in others if r.accuracy < floor]
    target = (f"{chain}: core restarts at {TARGET_IK_TARGETS:,} targets faster per solve than every other solver "
              f"that solves >= {COMPARABLE_SOLVE_RATE:.0%} as often as core")
    text = (f"core {core.value:.3g} ms at {core.batch:,} targets (solves {core.accuracy:.2%}); compared, solving >= "
            f"{floor:.2%}: " + (", ".join(f"{_solver(r)} {r.value:.3g} ms" for r in compared) or "none")
            + ("; excluded: " + ", ".join(f"{_solver(r)} solves {r.accuracy:.2%}" for r in excluded) if excluded
               else ""))
    if not compared:
        return Verdict(target, text, None)
    return _sized(target, text, core.value < compared[0].value, f"{core.batch:,} targets",
                  f"{TARGET_IK_TARGETS:,} targets")


def targets(rows: list[BenchRow]) -> list[Verdict]:
    """The issue's targets, each with what this run compared for it; a target set for another size than this run
    measured (``--quick``) is not comparable, never met or missed."""
    out: list[Verdict] = []
    largest = max((r.batch for r in rows if r.section == "dynamics"), default=0)
    core = _best(rows, section="dynamics", workload="tumbling", engine="core", method="rk4", batch=largest)
    for engine, method, factor in (("mujoco", "rk4", 5.0), ("mujoco-rollout", "rk4", 5.0),
                                   ("mujoco-rollout", "euler", 2.0)):
        target = (f"core rk4 at B = {TARGET_BATCH:,} >= {factor:g}x the throughput of {engine} {method} (its best B) "
                  "at equal or better error")
        other = _best(rows, section="dynamics", workload="tumbling", engine=engine, method=method)
        if core is None or other is None:
            out.append(Verdict(target, "not measured", None))
            continue
        ratio = other.value / core.value
        fair = ratio * equal_error_factor(core.accuracy, other.accuracy, RK4_ORDER)
        out.append(_sized(target, f"core rk4 at B = {largest:,} vs {engine} {method} at B = {other.batch:,}: "
                          f"{ratio:.2f}x per body-step ({core.value:.3g} vs {other.value:.3g} us); error "
                          f"{core.accuracy:.1e} vs {other.accuracy:.1e} {core.accuracy_unit}, so {fair:.2f}x at equal "
                          "error", fair >= factor, f"B = {largest:,}", f"B = {TARGET_BATCH:,}"))
    for chain in sorted({r.workload for r in rows if r.section == "kinematics"}):
        big = max(r.batch for r in rows if r.section == "kinematics")
        c = _best(rows, section="kinematics", workload=chain, engine="core", batch=big)
        p = _best(rows, section="kinematics", workload=chain, engine="pinocchio")
        if c and p:
            out.append(_sized(f"{chain}: core FK + Jacobian at B = {TARGET_BATCH:,} >= 2x Pinocchio per configuration",
                              f"core at B = {big:,} vs Pinocchio at B = {p.batch:,} (its best): {p.value / c.value:.2f}x "
                              f"({c.value:.3g} vs {p.value:.3g} us per configuration)", p.value / c.value >= 2,
                              f"B = {big:,}", f"B = {TARGET_BATCH:,}"))
    largest_states = max((r.batch for r in rows if r.section == "joint_dynamics"), default=0)
    out += [_sized(target, compared, met, f"B = {largest_states:,}", f"B = {TARGET_BATCH:,}")
            for target, compared, met in bench_joint_dynamics.target_lines(rows)]
    out += _memory_targets(rows)
    for chain in sorted({r.workload for r in rows if r.section == "ik"}):
        mine = [r for r in rows if r.section == "ik" and r.workload == chain]
        c = next((r for r in mine if r.method == "damped_least_squares+restarts"), None)
        if c is None:
            continue
        others = [r for r in mine if r.engine != "core" and math.isfinite(r.value)]
        counted = (f"{c.batch:,} targets", f"{TARGET_IK_TARGETS:,} targets")
        out.append(_sized(f"{chain}: core restarts solve >= 99.9 % of {TARGET_IK_TARGETS:,} targets inside the limits",
                          f"core damped_least_squares+restarts on {c.batch:,} targets: {c.accuracy:.2%}, {c.note}",
                          c.accuracy >= 0.999 and c.note.startswith("0 "), *counted))
        if chain == FIVE_DOF_ARM:  # the target on the under-actuated arm is its solve rate
            continue
        out.append(_ik_speed(chain, c, others))
        best = max(others, key=lambda r: r.accuracy, default=None)
        if best is not None:
            out.append(Verdict(f"{chain}: core restarts solved more often than every other solver "
                               f"({', '.join(sorted({r.engine for r in others}))})",
                               f"core {c.accuracy:.2%} of {c.batch:,} targets vs the best other, {_solver(best)}, "
                               f"{best.accuracy:.2%} of its {best.batch:,} (the first of the same targets)",
                               c.accuracy > best.accuracy))
        out.append(_sized(f"{chain}: >= 10,000 solves/s at {TARGET_IK_TARGETS:,} targets",
                          f"core damped_least_squares+restarts on {c.batch:,} targets: {1e3 / c.value:,.0f} "
                          "solves/s", 1e3 / c.value >= 10_000, *counted))
    return out


def _memory_targets(rows: list[BenchRow]) -> list[Verdict]:
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
    out = [_sized(f"peak memory of `simparity run --jobs 1` (this process + its largest child process) <= "
                  f"{MEMORY_LIMIT_MIB:,} MiB for {TARGET_MEMORY_STEPS:,} steps of {MEMORY_SCENE}",
                  f"at {steps}: {own[most.batch]:,.0f} + {most.value:,.0f} = {tree:,.0f} MiB", tree <= MEMORY_LIMIT_MIB,
                  steps, f"{TARGET_MEMORY_STEPS:,} steps")]
    if len(child) > 1:
        low = child[0]
        per_step = (most.value - low.value) * 2**20 / (most.batch - low.batch)
        flat = most.value <= FLAT_GROWTH * low.value
        out.append(_sized(f"memory flat in the number of steps ({TARGET_MEMORY_STEPS // 10:,} -> "
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
    out = [_sized(f"memory flat in the number of steps on the cheap scene ({set_for}): the largest child process's "
                  f"peak grows <= {FLAT_GROWTH - 1:.0%}",
                  f"largest child process {low.value:,.0f} -> {high.value:,.0f} MiB; {slopes}",
                  high.value <= FLAT_GROWTH * low.value, measured_at, set_for)]
    last = child[-1]
    out.append(_sized(f"{CHEAP_MEMORY_STEPS[-1]:,} steps within {WORKER_LIMIT_MIB:,} MiB per worker",
                      f"largest child process {last.value:,.0f} MiB at {last.batch:,} steps ({last.engine})",
                      last.value <= WORKER_LIMIT_MIB, f"{last.batch:,} steps", f"{CHEAP_MEMORY_STEPS[-1]:,} steps"))
    return out


def markdown(rows: list[BenchRow], info: dict[str, str], command: str, profile: str, seconds: float) -> str:
    lines = ["# BENCHMARKS", "", f"Written by `{command}` in {seconds:.0f} s on "
             + ", ".join(f"{k} {v}" for k, v in info.items()) + ". Every time is the median of repeated calls "
             "after a warm-up; every ratio is from this run. The raw rows are in `benchmarks.csv`.", "",
             "## Targets", "", ("Each target as set, what this run compared for it, and the verdict; a target set for "
                                "another size than this run measured (`--quick`) is not comparable."), "",
             "| target | compared | verdict |", "|---|---|---|"]
    for verdict in targets(rows):
        label = "**MISSED**" if verdict.met is False else verdict.label
        lines.append(f"| {verdict.target} | {verdict.compared} | {label} |")
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
    lines += bench_joint_dynamics.markdown_lines(rows)
    lines += bench_joint_motion.markdown_lines(rows)
    lines += bench_sweep.markdown_lines(rows)
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
    lines += ["## Profile", "", "Where core's time goes (cProfile, functions by own time):", "", "```", profile.rstrip(),
              "```", ""]
    return "\n".join(lines)


def profile_summary(batch: int, say: Callable[[str], None]) -> str:
    """cProfile of core's rk4 on ``batch`` tumbling boxes, of its restarted IK on the iiwa, of its ABA on ``batch``
    iiwa states and of its rk4 joint motion on ``batch`` falling iiwas, top functions."""
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
    arm = replace(library.load(["iiwa-dynamics"])[0], n_states=batch)
    q, qd, _, tau = arm.states()
    dynamics = make_engine("core").build_joint_dynamics(arm.chain, "recursive", arm.gravity_world)
    for title, call in ((f"core rk4, {batch:,} tumbling boxes, 20 steps", lambda: sim.run(20)),
                        (f"core damped_least_squares+restarts, {scene.n_targets:,} iiwa targets",
                         lambda: model.solve(targets.position_world, targets.rotation_world, scene.q_start)),
                        (f"core recursive forward dynamics (ABA), {batch:,} iiwa states, 20 calls",
                         lambda: [dynamics.forward_dynamics(q, qd, tau) for _ in range(20)]),
                        bench_joint_motion.profile_case(batch)):
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
    batches = [1, 100] if quick else [1, 100, TARGET_BATCH]
    say("stepping (time per body-step, with the error at that dt)")
    rows = dynamics_rows(batches, quick, say)
    say("forward kinematics + Jacobian")
    rows += kinematics_rows(batches, say)
    say("joint-space dynamics (time per state, with the difference to Pinocchio)")
    rows += bench_joint_dynamics.joint_dynamics_rows(batches, lambda fn: median_time(fn, REPEATS), BenchRow, say)
    say("joint motion (time per copy-step, with the error against DOP853 and the difference to Pinocchio's RK4)")
    rows += bench_joint_motion.joint_motion_rows(batches, median_time, BenchRow, say)
    say("IK")
    rows += ik_rows(300 if quick else None, say)
    say("memory of simparity run against the number of steps")
    with tempfile.TemporaryDirectory() as folder:
        rows += memory_rows(quick, Path(folder), say)
    say("sweeps: simparity run's wall time and client memory against the number of variants")
    rows += bench_sweep.sweep_rows(quick, run_peak_memory, BenchRow, say)
    say("profile")
    profile = profile_summary(batches[-1], say)
    for verdict in targets(rows):  # before the files: a write that fails loses no verdict
        reason = verdict.label.removeprefix(verdict.status).strip()
        say(f"{verdict.status:<14} {verdict.target}: {verdict.compared}" + (f" {reason}" if reason else ""))
    path = out_dir / "BENCHMARKS.md"
    try:
        write_csv(rows, out_dir / "benchmarks.csv")
        path.write_text(markdown(rows, machine(), command, profile, time.perf_counter() - start))
    except OSError as err:  # a full device, a folder removed meanwhile: the folder was probed before the bench
        raise SimparityError(f"--out {one_line(out_dir)}: cannot write the benchmarks: {err.strerror or err} "
                             "(allowed: a folder you can write); the targets met or missed are printed above") from None
    return path
