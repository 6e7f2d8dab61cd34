"""Analytic ground truth behind the shared engine interface.

Dynamics: closed forms from :mod:`references.analytic_solutions`, evaluated at the sample
times of the step being compared (the "integrator" is ``exact``). Supported: bodies under
gravity or no force, whose rotation is steady (angular velocity zero, or along a principal
axis, or any with an isotropic inertia). Anything else gets ``n/a`` with the reason.

Kinematics: planar chains (revolute joints about z, origins in the xy plane): the
end effector is a sum of rotated link vectors, sum_k Rz(phi_k) o_k with phi_k the
cumulative angle, and the Jacobian is its closed-form derivative.
"""

from __future__ import annotations

import numpy as np

from core.engine import Engine, KinematicsModel, Simulation, Support
from core.rotations import matrix_to_quat_wxyz, so3_exp
from core.scene import Chain, DynamicsScene, RigidBody
from core.trajectory import FramePoses, Trajectory
from references.analytic_solutions import projectile

# Relative tolerance deciding that an inertia is isotropic or that omega lies on a
# principal axis: such scenes are built exactly so, 1e-12 only absorbs rounding.
_STEADY_RTOL = 1e-12


def _steady_rotation(body: RigidBody) -> bool:
    """True when the torque-free body spins at constant angular velocity."""
    omega = body.angular_velocity_world
    if not np.any(omega):
        return True
    inertia = body.rotation_world @ body.inertia_body @ body.rotation_world.T
    l_world = inertia @ omega
    return bool(np.linalg.norm(np.cross(l_world, omega)) <= _STEADY_RTOL * np.linalg.norm(l_world) * np.linalg.norm(omega))


class _Simulation(Simulation):
    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        self._scene = scene
        self._dt = dt
        self.detail = "closed form: projectile, steady rotation"

    def run(self, n_steps: int) -> Trajectory:
        times = np.arange(n_steps + 1) * self._dt
        gravity = self._scene.forces.gravity_world
        gravity = np.zeros(3) if gravity is None else gravity
        pos, vel, quat, omg = [], [], [], []
        for body in self._scene.bodies:
            p, v = projectile(body.position_world, body.velocity_world, gravity, times)
            rotation = so3_exp(times[:, None] * body.angular_velocity_world) @ body.rotation_world
            pos.append(p)
            vel.append(v)
            quat.append(matrix_to_quat_wxyz(rotation))
            omg.append(np.broadcast_to(body.angular_velocity_world, (len(times), 3)))
        return Trajectory(times, *(np.stack(a, axis=1) for a in (pos, quat, vel, omg)))


def _planar(chain: Chain) -> Support:
    ez = np.array([0.0, 0.0, 1.0])
    for joint in chain.joints:
        if joint.type != "revolute" or not np.array_equal(joint.axis, ez):
            return Support.no(f"no closed form: joint '{joint.name}' is not a revolute joint about +z")
        if not np.array_equal(joint.origin_rotation, np.eye(3)) or joint.origin_xyz[2] != 0:
            return Support.no(f"no closed form: joint '{joint.name}' is not in the xy plane of its parent")
    if chain.end_effector_xyz[2] != 0 or not np.array_equal(chain.end_effector_rotation, np.eye(3)):
        return Support.no("no closed form: the end effector is not in the xy plane of the last link")
    return Support.yes()


class _PlanarKinematics(KinematicsModel):
    def __init__(self, chain: Chain) -> None:
        # Link vectors o_1..o_n (joint origins) and the end-effector offset, in the xy plane.
        self._offsets = np.stack([j.origin_xyz[:2] for j in chain.joints] + [chain.end_effector_xyz[:2]])
        self.detail = "closed form: sum of rotated link vectors"

    def _terms(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cumulative angles (B, n + 1), rotated offsets (B, n + 1, 2), their derivatives."""
        q = np.atleast_2d(q)
        # The k-th offset is rotated by the sum of the joint angles before it.
        phi = np.concatenate([np.zeros((len(q), 1)), np.cumsum(q, axis=1)], axis=1)
        c, s = np.cos(phi), np.sin(phi)
        ox, oy = self._offsets[:, 0], self._offsets[:, 1]
        rotated = np.stack([c * ox - s * oy, s * ox + c * oy], axis=-1)
        derivative = np.stack([-s * ox - c * oy, c * ox - s * oy], axis=-1)
        return phi, rotated, derivative

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        phi, rotated, _ = self._terms(q)
        # Frame i (joint i's link, then the end effector) sits at o_1 + ... rotated: a cumsum.
        xy = np.cumsum(rotated, axis=1)
        angles = np.concatenate([phi[:, 1:], phi[:, -1:]], axis=1)
        b, f = xy.shape[:2]
        pos = np.concatenate([xy, np.zeros((b, f, 1))], axis=-1)
        rot = np.zeros((b, f, 3, 3))
        rot[..., 0, 0], rot[..., 0, 1] = np.cos(angles), -np.sin(angles)
        rot[..., 1, 0], rot[..., 1, 1] = np.sin(angles), np.cos(angles)
        rot[..., 2, 2] = 1.0
        return FramePoses(pos, rot)

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        _, _, derivative = self._terms(q)
        b, n = derivative.shape[0], derivative.shape[1] - 1
        # d/dq_j of Rz(phi_k) o_k is Rz'(phi_k) o_k for every k > j (phi_k contains q_j).
        tail = np.cumsum(derivative[:, ::-1], axis=1)[:, ::-1]  # sum over k >= index
        jac = np.zeros((b, 6, n))
        jac[:, :2, :] = tail[:, 1:, :].transpose(0, 2, 1)
        jac[:, 5, :] = 1.0
        return jac


class AnalyticEngine(Engine):
    """Closed-form ground truths; ``n/a`` wherever no closed form is implemented."""

    name = "analytic"

    def version(self) -> str:
        return "closed form"

    def integrators(self) -> tuple[str, ...]:
        return ("exact",)

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        named = self.check_integrator(integrator)
        if not named.ok:
            return named
        for body in scene.bodies:
            if not _steady_rotation(body):
                return Support.no(f"no closed form here for the unsteady rotation of body '{body.name}'")
        return Support.yes()

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return _planar(chain)

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return _PlanarKinematics(chain)
