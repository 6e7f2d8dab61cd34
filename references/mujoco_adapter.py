"""MuJoCo behind the shared engine interface.

Conversions (each pinned by a test in ``tests/test_mujoco_adapter.py``)
----------------------------------------------------------------------
- ``qpos[3:7]`` and MJCF ``quat`` are (w, x, y, z): no reordering.
- Free-joint ``qvel[0:3]`` is the world-frame velocity of the body ORIGIN; the body origin
  is the centre of mass here (``<inertial pos="0 0 0">``), so it is the COM velocity.
- Free-joint ``qvel[3:6]`` is the angular velocity in the BODY frame: world = R qvel[3:6].
- Stepping uses ``mujoco.rollout`` (bit-identical to an ``mj_step`` loop), whose state
  rows are the state AFTER each step; the initial state is prepended.
- Kinematics: ``mj_kinematics`` then ``mj_comPos`` before ``mj_jacSite`` (the Jacobian is
  silently zero without ``mj_comPos``).
"""

from __future__ import annotations

import mujoco
import numpy as np
from mujoco import rollout

from core.engine import Engine, KinematicsModel, Simulation, Support
from core.rotations import quat_wxyz_to_matrix
from core.scene import Chain, DynamicsScene, KinematicsScene
from core.trajectory import FramePoses, Trajectory
from references.conventions import fmt
from references.mjcf import INTEGRATORS, chain_mjcf, dynamics_mjcf

_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS


class _Simulation(Simulation):
    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        self.model = mujoco.MjModel.from_xml_string(dynamics_mjcf(scene, integrator, dt))
        self._data = mujoco.MjData(self.model)
        self._n_bodies = len(scene.bodies)
        qvel = self._data.qvel.reshape(self._n_bodies, 6)
        for k, body in enumerate(scene.bodies):
            qvel[k, :3] = body.velocity_world
            qvel[k, 3:] = body.rotation_world.T @ body.angular_velocity_world
        self._state0 = np.empty(mujoco.mj_stateSize(self.model, _STATE))
        mujoco.mj_getState(self.model, self._data, self._state0, _STATE)
        self._qpos_at = mujoco.mj_stateSize(self.model, mujoco.mjtState.mjSTATE_TIME)
        self._dt = dt
        self.detail = (
            f"MuJoCo integrator {INTEGRATORS[integrator]}; explicit inertia; contact disabled"
            + ("" if scene.forces.gravity_world is not None else "; gravity disabled")
            + "; stepped by mujoco.rollout"
        )

    def run(self, n_steps: int) -> Trajectory:
        states, _ = rollout.rollout(self.model, self._data, self._state0[None], nstep=n_steps)
        states = np.concatenate([self._state0[None], states[0]], axis=0)
        nq, b = self.model.nq, self._n_bodies
        qpos = states[:, self._qpos_at : self._qpos_at + nq].reshape(-1, b, 7)
        qvel = states[:, self._qpos_at + nq : self._qpos_at + nq + self.model.nv].reshape(-1, b, 6)
        quat = qpos[..., 3:]
        omega_world = np.einsum("tbij,tbj->tbi", quat_wxyz_to_matrix(quat), qvel[..., 3:])
        times = np.arange(n_steps + 1) * self._dt
        return Trajectory(times, qpos[..., :3], quat, qvel[..., :3], omega_world)


class _Kinematics(KinematicsModel):
    def __init__(self, chain: Chain) -> None:
        self.model = mujoco.MjModel.from_xml_string(chain_mjcf(chain))
        self._data = mujoco.MjData(self.model)
        self._bodies = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, j.name) for j in chain.joints]
        joints = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, j.name) for j in chain.joints]
        self._qadr = self.model.jnt_qposadr[joints]
        self._dofadr = self.model.jnt_dofadr[joints]
        self._site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, chain.end_effector_name)
        self.detail = "mj_kinematics + mj_comPos; mj_jacSite at the end-effector site"

    def _set(self, q_row: np.ndarray) -> None:
        self._data.qpos[self._qadr] = q_row
        mujoco.mj_kinematics(self.model, self._data)
        mujoco.mj_comPos(self.model, self._data)

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        q = np.atleast_2d(q)
        n = len(self._bodies)
        pos, rot = np.empty((len(q), n + 1, 3)), np.empty((len(q), n + 1, 3, 3))
        for k, row in enumerate(q):
            self._set(row)
            pos[k, :n] = self._data.xpos[self._bodies]
            rot[k, :n] = self._data.xmat[self._bodies].reshape(n, 3, 3)
            pos[k, n] = self._data.site_xpos[self._site]
            rot[k, n] = self._data.site_xmat[self._site].reshape(3, 3)
        return FramePoses(pos, rot)

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        jacp, jacr = np.empty((3, self.model.nv)), np.empty((3, self.model.nv))
        out = np.empty((len(q), 6, len(self._bodies)))
        for k, row in enumerate(q):
            self._set(row)
            mujoco.mj_jacSite(self.model, self._data, jacp, jacr, self._site)
            out[k, :3], out[k, 3:] = jacp[:, self._dofadr], jacr[:, self._dofadr]
        return out


class MujocoEngine(Engine):
    """MuJoCo, built from MJCF the adapter writes (see :mod:`references.mjcf`)."""

    name = "mujoco"

    def version(self) -> str:
        return mujoco.__version__

    def integrators(self) -> tuple[str, ...]:
        return tuple(INTEGRATORS)

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        return self.check_integrator(integrator)

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, integrator, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return Support.yes()

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return _Kinematics(chain)

    def export(self, scene, integrator, dt) -> str:
        if isinstance(scene, KinematicsScene):
            return chain_mjcf(scene.chain)
        integrator, dt = self._export_settings(scene, integrator, dt)
        velocities = "".join(
            f"<!-- initial qvel of {b.name}: linear (world) {fmt(b.velocity_world)}, "
            f"angular (body) {fmt(b.rotation_world.T @ b.angular_velocity_world)} -->\n"
            for b in scene.bodies
        )
        return dynamics_mjcf(scene, integrator, dt) + velocities
