"""Core's joint motion behind the engine interface (:class:`JointSimulation`): the schemes of
:mod:`core.articulated.stepping`, energy from CRBA and the lecture's forward kinematics."""

from __future__ import annotations

import numpy as np

from simparity.core.articulated import stepping
from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.model import RecursiveDynamics
from simparity.core.articulated.recursive import Recursive
from simparity.core.articulated.step_jacobian import step_jacobian
from simparity.core.kinematics import forward_kinematics
from simparity.core.model.derivatives import StepJacobian
from simparity.core.model.engine import BatchedRun, JointSimulation
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory


class CoreJointMotion(JointSimulation):
    """A chain stepped by one of core's schemes at a fixed step, every copy of the scene in one batch."""

    def __init__(self, scene: JointMotionScene, scheme: str, dt: float) -> None:
        self._scene, self._dt, self._scheme = scene, dt, scheme
        self._step = stepping.stepper(scene, scheme, dt)
        gravity = np.zeros(3) if scene.gravity_world is None else scene.gravity_world
        self._gravity = np.asarray(gravity, dtype=float)
        self._dynamics = Recursive(chain_arrays(scene.chain), self._gravity)
        self._masses = np.array([j.link.mass if j.link is not None else 0.0 for j in scene.chain.joints])
        self._coms = np.array([j.link.com_xyz if j.link is not None else np.zeros(3) for j in scene.chain.joints])
        self.detail = (f"in-house {scheme} on (q, qdot), qddot by ABA (Featherstone), batched over copies"
                       + ("; damping by ABA with armature + dt D" if scheme == stepping.IMPLICIT_DAMPING else ""))

    def run(self, n_steps: int) -> JointTrajectory:
        q, qdot = stepping.run(self._step, np.asarray(self._scene.q0), np.asarray(self._scene.qdot0), n_steps,
                               self._dt)
        return JointTrajectory(np.arange(n_steps + 1) * self._dt, q, qdot)

    def step_jacobian(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> StepJacobian:
        """Carried analytically through the scheme with core's derivatives (:mod:`core.articulated.step_jacobian`;
        implicit damping on the chain with armature + dt D, as it steps)."""
        chain = self._scene.chain
        if self._scheme == stepping.IMPLICIT_DAMPING:
            chain = stepping.damped_armature(chain, self._dt)
        model = RecursiveDynamics(chain, self._gravity)
        return step_jacobian(model, self._scheme, self._dt, *(np.atleast_2d(np.asarray(x, dtype=float))
                                                             for x in (q, qdot, tau)))

    def batched(self, copies: int) -> BatchedRun:
        q0 = np.repeat(np.asarray(self._scene.q0)[:1], copies, axis=0)
        qdot0 = np.repeat(np.asarray(self._scene.qdot0)[:1], copies, axis=0)
        return lambda n_steps: stepping.run(self._step, q0, qdot0, n_steps, self._dt)

    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic 1/2 qdot^T M qdot (CRBA, armature included); potential -sum m g.c from core's FK."""
        mass_matrix = self._dynamics.mass_matrix(np.ascontiguousarray(q.T))  # (n, n, B)
        kinetic = 0.5 * np.einsum("bi,ijb,bj->b", qdot, mass_matrix, qdot)
        poses = forward_kinematics(self._scene.chain, q)
        n = self._scene.chain.n_joints
        coms = poses.position_world[:, :n] + np.einsum("bfij,fj->bfi", poses.rotation_world[:, :n], self._coms)
        potential = -np.einsum("f,bfi,i->b", self._masses, coms, self._gravity)
        return kinetic, potential

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        return np.asarray(forward_kinematics(self._scene.chain, q).position_world[:, -1])
