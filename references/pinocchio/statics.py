"""A chain's static balance under point forces, in Pinocchio: the truth a robot at rest on the ground meets.

``balance(q, forces)`` is the generalized force (the project's convention, B x nv) that holds the chain still at q
under gravity and the given forces on its contact spheres: ``rnea(q, 0, 0, fext)``, each sphere's force given to
Pinocchio as an external force on the joint that carries its frame, expressed in that joint's LOCAL frame with its
moment about the joint's origin (Pinocchio's convention for ``fext``), the sphere's centre placed by Pinocchio's own
frames (a chain joint's frame is its joint's; the end effector is the URDF link's frame; the base link is the free
flyer's, or the universe on a fixed base, where a force holds nothing); with friction at the sphere's contact point
``centre - radius N`` instead, where a tangential force acts (on a frictionless plane both lie on the force's
line). A floating base's rows are turned to world
axes (:mod:`references.common.floating_base`). At rest the joints' rows equal the applied joint forces less the
damping and a floating base's rows are zero: g(q) - sum_s J_s^T f_s = tau.

Nothing of core's: Pinocchio's model of the chain's file, frames and recursion.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact
from simparity.references.common.floating_base import base_rotations, turned_base
from simparity.references.pinocchio.contact import sphere_anchors
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics


class PinocchioStatics:
    """The static balance of a chain with its contact spheres (see the module docstring)."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None, contact: ChainContact) -> None:
        self._floating = chain.floating_base
        dynamics = (PinocchioFloatingDynamics(chain, gravity_world) if chain.floating_base
                    else PinocchioJointDynamics(chain, gravity_world))
        self._model, self._data = dynamics.model, dynamics.model.createData()
        self._configuration, self._velocity = dynamics.configuration, dynamics.local_velocity
        self._index = np.r_[0:6, dynamics.idx_v] if chain.floating_base else np.asarray(dynamics.idx_v)
        self._joints, self._points = sphere_anchors(self._model, chain, contact)
        self._centre_to_point = -contact.radii[:, None] * np.asarray(contact.plane.normal_world, dtype=float)  # (S, 3)
        self._at_contact_point = contact.friction > 0  # where the forces act: the centres on a frictionless plane

    def balance(self, q: np.ndarray, forces_world: np.ndarray) -> np.ndarray:
        """(B, nv): the generalized force that holds the chain still at q (B, nq) under gravity and ``forces_world``
        (B, S, 3) [N] on its spheres (the project's convention: a floating base's force and moment in world axes)."""
        m, d = self._model, self._data
        out = np.empty((len(q), len(self._index)))
        zero = np.zeros(m.nv)
        for b, row in enumerate(np.asarray(q, dtype=float)):
            configuration = self._configuration(row)
            pin.forwardKinematics(m, d, configuration)
            external = pin.StdVec_Force()
            for _ in range(m.njoints):
                external.append(pin.Force.Zero())
            for k, (joint, point, force) in enumerate(zip(self._joints, self._points, forces_world[b])):
                rotation = d.oMi[joint].rotation
                local = rotation.T @ force
                at = point + rotation.T @ self._centre_to_point[k] if self._at_contact_point else point
                external[joint] = external[joint] + pin.Force(local, np.cross(at, local))
            out[b] = pin.rnea(m, d, configuration, zero, zero, external)[self._index]
        return turned_base(base_rotations(q), out, True, True) if self._floating else out

    def centres(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) [m] the spheres' centres in the world at q (B, nq) by Pinocchio's ``forwardKinematics``."""
        m, d = self._model, self._data
        out = np.empty((len(q), len(self._joints), 3))
        for b, row in enumerate(np.asarray(q, dtype=float)):
            pin.forwardKinematics(m, d, self._configuration(row))
            out[b] = [d.oMi[joint].act(point) for joint, point in zip(self._joints, self._points)]
        return out

    def contact_point_velocities(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, S, 3) [m/s] in world axes: the velocity of each sphere's contact point, the point of its link at
        ``centre - radius N``, at the states q (B, nq), qdot (B, nv) (the project's convention), by Pinocchio's
        ``forwardKinematics`` and ``getVelocity`` (the joint's LOCAL spatial velocity moved to the point)."""
        m, d = self._model, self._data
        out = np.empty((len(q), len(self._joints), 3))
        for b, (row, rates) in enumerate(zip(np.asarray(q, dtype=float), np.asarray(qdot, dtype=float))):
            pin.forwardKinematics(m, d, self._configuration(row), self._velocity(row[None], rates[None]))
            for k, (joint, point) in enumerate(zip(self._joints, self._points)):
                rotation = d.oMi[joint].rotation
                at = point + rotation.T @ self._centre_to_point[k]
                motion = pin.getVelocity(m, d, joint, pin.LOCAL)
                out[b, k] = rotation @ (motion.linear + np.cross(motion.angular, at))
        return out
