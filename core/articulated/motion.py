"""Core's joint motion behind the engine interface (:class:`JointSimulation`): the schemes of
:mod:`core.articulated.stepping`, energy from CRBA and the lecture's forward kinematics."""

from __future__ import annotations

import numpy as np

from simparity.core.articulated import stepping
from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.chain_impulse import RigidContact
from simparity.core.articulated.floating import FloatingRecursiveDynamics
from simparity.core.articulated.model import RecursiveDynamics
from simparity.core.articulated.recursive import Recursive
from simparity.core.articulated.step_jacobian import step_jacobian
from simparity.core.kinematics import forward_kinematics
from simparity.core.model.derivatives import StepJacobian
from simparity.core.model.engine import BatchedRun, JointSimulation
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory
from simparity.core.rotations import quat_wxyz_to_matrix

OFF_THE_RUN = "core reports a rigid contact's forces for states of its own run only"
"""Why a rigid contact's forces are not reported at a state: rest is the run's history, not a function of the state."""


class CoreJointMotion(JointSimulation):
    """A chain stepped by one of core's schemes at a fixed step, every copy of the scene in one batch."""

    def __init__(self, scene: JointMotionScene, scheme: str, dt: float) -> None:
        self._scene, self._dt, self._scheme = scene, dt, scheme
        rigid = scene.contact is not None and scene.contact.rigid
        self._rigid = RigidContact(scene, scheme) if rigid else None
        self._step = (stepping.stepper(scene, scheme, dt) if self._rigid is None else
                      lambda t, q, qdot: self._rigid_step(t, q, qdot))
        self._rigid_run: tuple[np.ndarray, np.ndarray] | None = None  # (q, resting) of the last run, rigid contact
        gravity = np.zeros(3) if scene.gravity_world is None else scene.gravity_world
        self._gravity = np.asarray(gravity, dtype=float)
        chain = scene.chain
        self._floating = FloatingRecursiveDynamics(chain, self._gravity) if chain.floating_base else None
        self._dynamics = Recursive(chain_arrays(chain), self._gravity)
        self._contact = ChainContactForces(chain, scene.contact) if scene.contact is not None else None
        self._masses = np.array([j.link.mass if j.link is not None else 0.0 for j in chain.joints])
        self._coms = np.array([j.link.com_xyz if j.link is not None else np.zeros(3) for j in chain.joints])
        self.detail = (f"in-house {scheme} on (q, qdot), qddot by ABA (Featherstone), batched over copies"
                       + ("; damping by ABA with armature + dt D" if scheme == stepping.IMPLICIT_DAMPING else "")
                       + ("; the floating base's quaternion stepped in R^4 by dq/dt = 1/2 (0, omega) q and "
                          "normalised after each step" if chain.floating_base else "")
                       + _contact_detail(scene))

    def _rigid_step(self, t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        assert self._rigid is not None
        if self._rigid.resting.shape != (q.shape[1],):
            self._rigid.start(q.shape[1])
        return self._rigid.step(t, q, qdot, self._dt)

    def run(self, n_steps: int) -> JointTrajectory:
        q0, qdot0 = np.asarray(self._scene.q0), np.asarray(self._scene.qdot0)
        if self._rigid is not None:
            q, qdot, resting = self._rigid.run(q0, qdot0, n_steps, self._dt)
            self._rigid_run = (q, resting)
        else:
            q, qdot = stepping.run(self._step, q0, qdot0, n_steps, self._dt)
        return JointTrajectory(np.arange(n_steps + 1) * self._dt, q, qdot)

    def step_jacobian(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> StepJacobian:
        """Carried analytically through the scheme with core's derivatives (:mod:`core.articulated.step_jacobian`;
        implicit damping on the chain with armature + dt D, as it steps); not for a floating base yet."""
        chain = self._scene.chain
        if self._contact is not None:
            raise NotImplementedError("core's step Jacobian is not carried through contact forces yet")
        if chain.floating_base:
            raise NotImplementedError("core's step Jacobian is carried on a fixed base only (a floating base's "
                                      "quaternion step is not differentiated yet)")
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
        """Kinetic 1/2 qdot^T M qdot (CRBA, armature included; a floating base's with its 6-DOF root); potential
        -sum m g.c from core's FK (a floating base's own mass included, every frame placed by the base's pose)."""
        if self._floating is not None:
            kinetic = 0.5 * np.einsum("bi,bij,bj->b", qdot, self._floating.mass_matrix(q), qdot)
        else:
            mass_matrix = self._dynamics.mass_matrix(np.ascontiguousarray(q.T))  # (n, n, B)
            kinetic = 0.5 * np.einsum("bi,ijb,bj->b", qdot, mass_matrix, qdot)
        masses, coms = self._mass_centres(q)
        potential = -np.einsum("f,bfi,i->b", masses, coms, self._gravity)
        return kinetic, potential

    def _mass_centres(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(masses (F,) [kg], centres of mass (B, F, 3) [m]) of the chain's links from core's FK (a floating base's own
        first, every frame placed by the base's pose)."""
        n = self._scene.chain.n_joints
        poses = forward_kinematics(self._scene.chain, q[:, q.shape[1] - n:])
        coms = poses.position_world[:, :n] + np.einsum("bfij,fj->bfi", poses.rotation_world[:, :n], self._coms)
        if self._floating is None:
            return self._masses, coms
        base = self._scene.chain.base_inertia
        assert base is not None  # a floating chain's dynamics_problem() says so
        coms = _placed(q, np.concatenate([np.broadcast_to(base.com_xyz, (len(q), 1, 3)), coms], axis=1))
        return np.concatenate([[base.mass], self._masses]), coms

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        n = self._scene.chain.n_joints
        tip = np.asarray(forward_kinematics(self._scene.chain, q[:, q.shape[1] - n:]).position_world[:, -1])
        return _placed(q, tip[:, None])[:, 0] if self._floating is not None else tip

    def contact_centres(self, q: np.ndarray) -> np.ndarray:
        """The spheres' centres by core's FK (:class:`ChainContactForces`)."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        return self._contact.centres_world(np.ascontiguousarray(np.asarray(q, dtype=float).T))

    def contact_forces(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray) -> np.ndarray:
        """Soft contact: the penalty force on each sphere at the state (:class:`ChainContactForces`: a spring-damper
        of the state alone, whatever the applied forces). Rigid contact: the resting force of the sphere the run
        rested on at that sample (:meth:`RigidContact.forces_world`), for states of its own last run only."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        q, qdot = np.asarray(q, dtype=float), np.asarray(qdot, dtype=float)
        if self._rigid is None:
            return self._contact.forces_world(*(np.ascontiguousarray(x.T) for x in (q, qdot)))
        resting = self._resting_at(q, np.asarray(times, dtype=float))
        return self._rigid.forces_world(q, qdot, np.asarray(times, dtype=float), resting)

    def _resting_at(self, q: np.ndarray, times: np.ndarray) -> np.ndarray:
        """(B,) the sphere the last run rested on at each state q (B, n) at ``times`` (B,), found among that
        sample's copies by its joint values; NotImplementedError for a state off the run."""
        if self._rigid_run is None:
            raise NotImplementedError(OFF_THE_RUN)
        run_q, resting = self._rigid_run
        samples = np.rint(times / self._dt).astype(int)
        if np.any((samples < 0) | (samples >= len(run_q))):
            raise NotImplementedError(OFF_THE_RUN)
        off = np.abs(run_q[samples] - q[:, None]).max(axis=2)  # (B, copies)
        copy = np.argmin(off, axis=1)
        if np.any(off[np.arange(len(q)), copy] > 0):
            raise NotImplementedError(OFF_THE_RUN)
        return resting[samples, copy]

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """Core's floating-base momentum (:meth:`FloatingRecursiveDynamics.momentum`: each body's I v summed, about the
        world origin), the angular part moved to the centre of mass of core's FK (L_c = L_o - c x P)."""
        if self._floating is None:
            raise NotImplementedError("a fixed base's momentum is not conserved: it is not reported")
        momentum = self._floating.momentum(q, qdot)
        masses, coms = self._mass_centres(q)
        centre = np.einsum("f,bfi->bi", masses, coms) / masses.sum()
        return np.concatenate([momentum[:, :3], momentum[:, 3:] - np.cross(centre, momentum[:, :3])], axis=1)


def _contact_detail(scene: JointMotionScene) -> str:
    """How core's run puts the scene's contact into its steps ("" without contact)."""
    contact = scene.contact
    if contact is None:
        return ""
    if contact.rigid:
        return (f"; rigid contact by impulses at each sphere, restitution {contact.restitution:g} (plastic below "
                f"{contact.rest_speed:g} m/s, then resting), time backed up to each impact, through J M^-1 J^T, "
                "one contact at a time, frictionless")
    friction = (f"regularised Coulomb friction mu = {contact.friction:g} (full above a slip of "
                f"{contact.friction_speed:g} m/s) at the contact point" if contact.friction > 0 else "frictionless")
    return (f"; contact by the penalty method at each sphere, k_s = {contact.penalty_stiffness:g} N/m, k_d = "
            f"{contact.penalty_damping:g} N s/m, {friction}, through ABA as J^T F")


def _placed(q: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(B, F, 3) points given in the floating base's frame, placed in the world by the base's pose in q (B, 7 + n)."""
    rotation = quat_wxyz_to_matrix(q[:, 3:7])
    return q[:, None, :3] + np.einsum("bij,bfj->bfi", rotation, points)
