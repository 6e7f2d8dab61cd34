"""Scene builders shared by the tests (seeded generators take an explicit rng)."""

from __future__ import annotations

import numpy as np

from comparisons.library import builtin_paths
from comparisons.scene_loader import load_scene
from core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix, rpy_to_matrix
from core.scene import Chain, DynamicsScene, Forces, Joint, RigidBody


def builtin(name: str):
    """A built-in scene, loaded through the same loader users go through."""
    return load_scene(builtin_paths()[name])


def random_chain(rng: np.random.Generator, n_joints: int, prismatic_every: int = 3) -> Chain:
    """A spatial chain with random axes, origins (up to 0.5 m) and rotations; every k-th joint prismatic."""
    joints = []
    for i in range(n_joints):
        prismatic = prismatic_every and i % prismatic_every == prismatic_every - 1
        joints.append(Joint(
            name=f"j{i}", type="prismatic" if prismatic else "revolute",
            axis=rng.normal(size=3), origin_xyz=rng.uniform(-0.5, 0.5, size=3),
            origin_rotation=rpy_to_matrix(rng.uniform(-np.pi, np.pi, size=3)),
            lower=-2.0 if prismatic else -np.pi, upper=2.0 if prismatic else np.pi,
        ))
    return Chain(f"random{n_joints}", tuple(joints), "tool", rng.uniform(-0.3, 0.3, size=3),
                 rpy_to_matrix(rng.uniform(-np.pi, np.pi, size=3)))


def tumbling_box(inertia_body=np.diag([0.1, 0.2, 0.3]), quat_wxyz=(0.9, 0.1, -0.3, 0.2),
                 gravity=(0.0, 0.0, -9.81), duration=2.5, dt=1 / 240) -> DynamicsScene:
    """The notes' tumbling, falling box: m = 2 kg, omega0 = (.1, 3, .1) rad/s in body axes."""
    q = quat_wxyz_normalize(np.array(quat_wxyz, dtype=float))
    body = RigidBody("box", 2.0, inertia_body, [0.0, 0.0, 1.0], q, [0.5, -0.2, 1.0],
                     quat_wxyz_to_matrix(q) @ np.array([0.1, 3.0, 0.1]))
    forces = Forces(None if gravity is None else np.array(gravity))
    return DynamicsScene("tumbling-box", "test scene", "core", (body,), forces, duration, (dt,))


def exact_projectile(scene: DynamicsScene, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form position and velocity (T, B, 3) of the scene's bodies under its gravity."""
    g = scene.forces.gravity_world
    x0 = np.stack([b.position_world for b in scene.bodies])
    v0 = np.stack([b.velocity_world for b in scene.bodies])
    t = times[:, None, None]
    return x0 + v0 * t + 0.5 * g * t * t, v0 + g * t
