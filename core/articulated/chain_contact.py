"""Core's contact of a chain's spheres with a plane: the lecture's penalty method carried to a chain.

At each sphere whose lowest point ``c - r N`` is inside the plane (E < 0) the plane pushes along its normal with
F = (-k_s E - k_d u.N)^+ N (:func:`core.contact.particle.penalty_force`, never pulling), u the velocity of the
sphere's centre (its normal part is the contact point's). The force acts at the sphere's centre (on the normal
through the contact point: the same moment about every point) and enters the chain's dynamics as the generalized
force J^T F summed over spheres, with J the Jacobian of the centre: on a joint, (a_j x (p - P_j)) . F for a revolute
joint, a_j . F for a prismatic one (joints between the base and the sphere's frame); on a floating base, the force
itself and its moment (p - x_base) x F about the base origin, in world axes. Frictionless: nothing acts along the
plane.
"""

from __future__ import annotations

import numpy as np

from simparity.core.contact.particle import penalty_force
from simparity.core.kinematics import joint_frames
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact, frame_index
from simparity.core.rotations import quat_wxyz_to_matrix


class ChainContactForces:
    """The penalty forces on a chain's contact spheres, batched over copies (see the module docstring).

    States are the stepping layout: q (nq, B), qdot (nv, B).
    """

    def __init__(self, chain: Chain, contact: ChainContact) -> None:
        self._chain, self._contact = chain, contact
        names = tuple(j.name for j in chain.joints)
        self._frames = [frame_index(s.frame, names, chain.end_effector_name, chain.base_link)
                        for s in contact.spheres]
        self._revolute = np.array([j.type == "revolute" for j in chain.joints])
        self._lowest = -contact.radii[:, None] * contact.plane.normal_world  # (S, 3): centre to contact point

    def _kinematics(self, q: np.ndarray) -> tuple[np.ndarray, list[np.ndarray], np.ndarray | None]:
        """(centres in the base frame (B, S, 3), per sphere its joint columns (B, k, 3) in the base frame (k joints
        move it), the base rotation (B, 3, 3) or None on a fixed base)."""
        n = self._chain.n_joints
        positions, rotations, axes = joint_frames(self._chain, q[q.shape[0] - n:].T)
        centres, columns = [], []
        for i, sphere in zip(self._frames, self._contact.spheres):
            centre = (np.broadcast_to(sphere.centre_xyz, (positions.shape[0], 3)) if i < 0 else
                      positions[:, i] + rotations[:, i] @ sphere.centre_xyz)
            moved = n if i == n else i + 1  # joints 0..i move joint i's frame, all move the tip, none the base
            lever = centre[:, None] - positions[:, :moved]
            columns.append(np.where(self._revolute[:moved, None], np.cross(axes[:, :moved], lever), axes[:, :moved]))
            centres.append(centre)
        rotation = quat_wxyz_to_matrix(q[3:7].T) if self._chain.floating_base else None
        return np.stack(centres, axis=1), columns, rotation

    def _world(self, q: np.ndarray, qdot: np.ndarray):
        """(centres (B, S, 3), velocities (B, S, 3), forces (B, S, 3)) in the world, and the kinematics."""
        centres_base, columns, rotation = self._kinematics(q)
        n = self._chain.n_joints
        rates = qdot[qdot.shape[0] - n:].T  # (B, n)
        relative = np.stack([np.einsum("bkj,bk->bj", cols, rates[:, :cols.shape[1]]) for cols in columns], axis=1)
        if rotation is None:
            centres, velocities = centres_base, relative
        else:
            arms = np.einsum("bij,bsj->bsi", rotation, centres_base)
            centres = q[:3].T[:, None] + arms
            velocities = (qdot[:3].T[:, None] + np.cross(qdot[3:6].T[:, None], arms)
                          + np.einsum("bij,bsj->bsi", rotation, relative))
        c = self._contact
        forces = penalty_force(centres + self._lowest, velocities, c.plane, c.penalty_stiffness, c.penalty_damping)
        return centres, forces, (centres_base, columns, rotation)

    def centres_world(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) the spheres' centres [m] at q (nq, B)."""
        return self._world(q, np.zeros((self._chain.nv, q.shape[1])))[0]

    def forces_world(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, S, 3) the plane's force on each sphere [N] at the state (q (nq, B), qdot (nv, B))."""
        return self._world(q, qdot)[1]

    def generalized(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(nv, B) the generalized contact force J^T F [N m or N; a floating base's force N and moment N m first]."""
        _, forces, (centres_base, columns, rotation) = self._world(q, qdot)
        n = self._chain.n_joints
        base_forces = forces if rotation is None else np.einsum("bji,bsj->bsi", rotation, forces)  # base axes
        joints = np.zeros((forces.shape[0], n))
        for s, cols in enumerate(columns):
            joints[:, :cols.shape[1]] += np.einsum("bkj,bj->bk", cols, base_forces[:, s])
        if rotation is None:
            return joints.T
        arms = np.einsum("bij,bsj->bsi", rotation, centres_base)
        wrench = np.concatenate([forces.sum(axis=1), np.cross(arms, forces).sum(axis=1)], axis=1)
        return np.concatenate([wrench, joints], axis=1).T
