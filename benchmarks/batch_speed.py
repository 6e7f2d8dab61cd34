"""Speed benchmark: time per body-step and per IK solve, core against the engines, same run.

The in-house methods are vectorised over a leading batch axis, so their cost per body falls
as the batch grows; the engines step a model holding the same B bodies. Every number is the
best of a few repeats of the stepping (or solving) alone, model building excluded, and each
row prints the ratio core / engine measured here and now.

    python benchmarks/batch_speed.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from simparity.comparisons.engines import make_engine  # noqa: E402
from simparity.comparisons.ik_targets import random_targets  # noqa: E402
from simparity.comparisons.library import load  # noqa: E402
from simparity.comparisons.timing import best_of  # noqa: E402
from simparity.core.ik.problem import IKTolerances  # noqa: E402
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix  # noqa: E402
from simparity.core.scene import DynamicsScene, Forces, RigidBody  # noqa: E402

# (engine, integrator) pairs on the same first-order scheme, then the fourth-order ones.
DYNAMICS = [("core", "engine_euler"), ("mujoco", "euler"), ("pybullet", "euler"), ("pinocchio", "euler"),
            ("core", "rk4"), ("mujoco", "rk4"), ("pinocchio", "rk4")]
IK = [("core", "damped_least_squares"), ("mujoco", "dls"), ("pybullet", "calculateInverseKinematics-tuned"),
      ("pinocchio", "clik")]


def tumbling_boxes(n_bodies: int, seed: int = 0) -> DynamicsScene:
    """B free boxes (I = diag(.1, .2, .3)) falling and tumbling from seeded random states."""
    rng = np.random.default_rng(seed)
    bodies = []
    for k in range(n_bodies):
        q = quat_wxyz_normalize(rng.normal(size=4))
        bodies.append(RigidBody(f"box{k}", 2.0, np.diag([0.1, 0.2, 0.3]), rng.normal(size=3), q, rng.normal(size=3),
                                quat_wxyz_to_matrix(q) @ rng.normal(0, 2, size=3)))
    return DynamicsScene("boxes", "benchmark", "core", tuple(bodies), Forces(np.array([0.0, 0.0, -9.81])), 0.5,
                         (1e-3,))


def dynamics_table(batches: list[int], steps: int) -> None:
    print(f"\nTime per body-step [us], {steps} steps of dt = 1e-3 (ratio = core's same-order scheme / engine)")
    header = f"{'engine':<14} {'integrator':<14}" + "".join(f"{'B=' + str(b):>12}" for b in batches)
    print(header)
    results = {}
    for engine, integrator in DYNAMICS:
        cells = []
        for b in batches:
            if engine == "pybullet" and b > 100:  # one Python call per body and step: minutes at B = 1000
                cells.append(float("nan"))
                continue
            sim = make_engine(engine).build_dynamics(tumbling_boxes(b), integrator, 1e-3)
            seconds, _ = best_of(lambda: sim.run(steps), repeats=3)
            cells.append(seconds / (steps * b) * 1e6)
        results[(engine, integrator)] = cells
        print(f"{engine:<14} {integrator:<14}" + "".join(f"{c:>12.3g}" for c in cells))
    for (engine, integrator), cells in results.items():
        if engine == "core":
            continue
        core = results[("core", "rk4" if integrator == "rk4" else "engine_euler")]
        ratios = "".join(f"{c / e:>12.3g}" for c, e in zip(core, cells))
        print(f"{'core/' + engine:<14} {integrator:<14}{ratios}")


def ik_table(n_targets: int) -> None:
    scene = load(["iiwa-ik"])[0]
    scene = replace(scene, n_targets=n_targets)
    targets = random_targets(scene, make_engine(scene.reference).build_kinematics(scene.chain))
    options = IKTolerances(scene.position_tolerance, scene.orientation_tolerance, scene.max_iterations)
    print(f"\nIK on the iiwa: {n_targets} pose targets from one start (failures inside the timing)")
    print(f"{'engine':<10} {'solver':<36}{'solve rate':>12}{'ms per solve':>14}{'core / engine':>15}")
    core_ms = None
    for engine, solver in IK:
        model = make_engine(engine).build_ik(scene.chain, solver, options)
        seconds, result = best_of(lambda: model.solve(targets.position_world, targets.rotation_world, scene.q_start),
                                  repeats=2)
        ms = seconds / n_targets * 1e3
        core_ms = ms if engine == "core" else core_ms
        print(f"{engine:<10} {solver:<36}{result.solve_rate:>12.3f}{ms:>14.3g}{core_ms / ms:>15.3g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller batches and fewer steps")
    args = parser.parse_args()
    if args.quick:
        dynamics_table([1, 10, 100], steps=200)
        ik_table(100)
    else:
        dynamics_table([1, 10, 100, 1000], steps=500)
        ik_table(1000)


if __name__ == "__main__":
    main()
