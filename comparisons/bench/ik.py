"""The bench's IK on the ``bench`` suite's arms and a 5-DOF arm (TRAC-IK protocol): solve rate and time per solve,
failures inside the time, limit violations."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from simparity.comparisons.bench.rows import BenchRow, Meter
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.ik_targets import random_targets
from simparity.comparisons.scenes import library
from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_ROBOTS
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.scenes.ik import IKScene
from simparity.core.urdf import chain_from_urdf
from simparity.references.differential_ik import MinkIK, PinkIK, available
from simparity.references.mujoco.adapter import MujocoChain
from simparity.references.pinocchio.adapter import PinocchioChain

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
they solve the first :func:`library_targets` targets of each arm."""
LIBRARY_TARGETS = 1000
LIBRARY_SHARE = 10
"""The libraries solve one target in this many of an arm's (at most :data:`LIBRARY_TARGETS`): 1,000 of the 10,000,
30 of ``--quick``'s 300."""


def library_targets(n_targets: int) -> int:
    """Targets a differential-IK library solves on an arm of ``n_targets`` (its first; at least one)."""
    return max(1, min(n_targets // LIBRARY_SHARE, LIBRARY_TARGETS))


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
            count = library_targets(scene.n_targets) if engine in LIBRARY_IK else scene.n_targets
            missing = available(engine) if engine in LIBRARY_IK else ""
            if missing:
                rows.append(BenchRow("ik", scene.chain.name, engine, solver, count, math.nan, "ms/solve", math.nan,
                                     "solve rate", f"n/a: {missing}"))
                say(f"  {scene.chain.name:<13} {engine:<10} n/a: {missing}")
                continue
            model = build()
            rotation = None if targets.rotation_world is None else targets.rotation_world[:count]
            with Meter() as meter:
                result = model.solve(targets.position_world[:count], rotation, scene.q_start)
            seconds = meter.wall_seconds
            violations = int(np.sum(result.limit_violation > 0))
            sample = f"; the first {count:,} targets" if count < scene.n_targets else ""
            rows.append(meter.stamp(BenchRow("ik", scene.chain.name, engine, solver, count, seconds / count * 1e3,
                                             "ms/solve", result.solve_rate, "solve rate",
                                             f"{violations} solutions outside the limits{sample}")))
            say(f"  {scene.chain.name:<13} {engine:<10} {solver:<34} {result.solve_rate:8.4f} solved "
                f"{seconds / count * 1e3:8.3f} ms/solve ({count / seconds:,.0f}/s)")
    return rows
