"""The bench's forward kinematics + end-effector Jacobian of the iiwa and the UR5: time per configuration, with the
largest difference to Pinocchio."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from simparity.comparisons.bench.rows import REPEATS, BenchRow, Meter, median_time
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.metrics import kinematics_errors
from simparity.comparisons.scenes import library
from simparity.core.model.metric_catalogue import JACOBIAN_ERROR_MAX, POSITION_ERROR_MAX
from simparity.core.model.scenes.chain import sample_configurations

KINEMATICS = ("core", "pinocchio", "mujoco", "pybullet")
KINEMATICS_SEED = 5
ERROR_CONFIGURATIONS = 100
"""Configurations of each batch (its first) whose FK and Jacobian are compared with Pinocchio's."""


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

                with Meter() as meter:
                    seconds = median_time(both, REPEATS if count * chain.n_joints < 50_000 else 2)
                poses, jac = both()
                k = min(count, ERROR_CONFIGURATIONS)
                errors = kinematics_errors(poses_slice(poses, k), jac[:k], poses_slice(ref_poses, k), ref_jacobian[:k])
                error = max(errors[POSITION_ERROR_MAX].value, errors[JACOBIAN_ERROR_MAX].value)
                rows.append(meter.stamp(BenchRow("kinematics", chain.name, engine, "fk+jacobian", batch,
                                                 seconds / count * 1e6, "us/configuration", error, "m",
                                                 "vs pinocchio" if engine != "pinocchio" else "")))
                say(f"  {chain.name:<13} {engine:<10} B={batch:<6} {seconds / count * 1e6:9.3f} us/configuration")
    return rows


def poses_slice(poses, k: int):
    """The first k configurations' frame poses."""
    return replace(poses, position_world=poses.position_world[:k], rotation_world=poses.rotation_world[:k])
