"""Core's contact of a chain's spheres with a plane: the lecture's penalty method carried to a chain.

At each sphere whose lowest point ``c - r N`` is inside the plane (E < 0) the plane pushes along its normal with
F = (-k_s E - k_d u.N)^+ N (:func:`core.contact.particle.penalty_force`, never pulling), u the velocity of the
sphere's centre (its normal part is the contact point's). The force acts at the sphere's centre (on the normal
through the contact point: the same moment about every point) and enters the chain's dynamics as the generalized
force J^T F summed over spheres, with J the Jacobian of the centre: on a joint, (a_j x (p - P_j)) . F for a revolute
joint, a_j . F for a prismatic one (joints between the base and the sphere's frame); on a floating base, the force
itself and its moment (p - x_base) x F about the base origin, in world axes. With the scene's friction mu > 0 the
plane also resists the slip u_t of the contact point (the sphere's link's point at ``c - r N``, where the engines put
it too) with the penalty method's regularised Coulomb friction -mu |F_n| u_t / max(|u_t|, v_reg), v_reg the scene's
``friction_speed`` (:func:`core.contact.particle.sliding_friction`, as the free bodies'), and the whole force acts
there; without friction nothing acts along the plane.
"""

from __future__ import annotations

import numpy as np

from simparity.core.contact.particle import penalty_force, sliding_friction
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
        self._frames_of_spheres = [frame_index(s.frame, names, chain.end_effector_name, chain.base_link)
                        for s in contact.spheres]
        self._revolute = np.array([j.type == "revolute" for j in chain.joints])
        self._lowest = -contact.radii[:, None] * contact.plane.normal_world  # (S, 3): centre to contact point

    def _frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """(joint positions (B, n + 1, 3), frame rotations (B, n + 1, 3, 3), joint axes (B, n, 3), all in the base
        frame, and the base rotation (B, 3, 3) or None on a fixed base) at q (nq, B)."""
        n = self._chain.n_joints
        positions, rotations, axes = joint_frames(self._chain, q[q.shape[0] - n:].T)
        return positions, rotations, axes, quat_wxyz_to_matrix(q[3:7].T) if self._chain.floating_base else None

    def _centres_base(self, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
        """(B, S, 3) the spheres' centres in the base frame."""
        return np.stack([np.broadcast_to(sphere.centre_xyz, (positions.shape[0], 3)) if i < 0 else
                         positions[:, i] + rotations[:, i] @ sphere.centre_xyz
                         for i, sphere in zip(self._frames_of_spheres, self._contact.spheres)], axis=1)

    def _columns(self, positions: np.ndarray, axes: np.ndarray, centres_base: np.ndarray) -> list[np.ndarray]:
        """Per sphere its Jacobian's joint columns (B, k, 3) in the base frame (the k joints that move it)."""
        n = self._chain.n_joints
        columns = []
        for s, i in enumerate(self._frames_of_spheres):
            moved = n if i == n else i + 1  # joints 0..i move joint i's frame, all move the tip, none the base
            lever = centres_base[:, s, None] - positions[:, :moved]
            columns.append(np.where(self._revolute[:moved, None], np.cross(axes[:, :moved], lever), axes[:, :moved]))
        return columns

    def centres_world(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) the spheres' centres [m] at q (nq, B)."""
        positions, rotations, _, rotation = self._frames(q)
        centres_base = self._centres_base(positions, rotations)
        return centres_base if rotation is None else q[:3].T[:, None] + np.einsum("bij,bsj->bsi", rotation,
                                                                                  centres_base)

    def normal_jacobians(self, q: np.ndarray) -> np.ndarray:
        """(B, S, n) j_s = J_s^T N of a fixed base at q (n, B): the rate of sphere s's normal velocity N . u_s per
        joint rate (u_s = J_s qdot, J_s the Jacobian of its centre)."""
        positions, rotations, axes, _ = self._frames(q)
        return self._normal_rows(axes, self._columns(positions, axes, self._centres_base(positions, rotations)))

    def _normal_rows(self, axes: np.ndarray, columns: list[np.ndarray]) -> np.ndarray:
        out = np.zeros((axes.shape[0], len(columns), self._chain.n_joints))
        for s, cols in enumerate(columns):
            out[:, s, :cols.shape[1]] = cols @ self._contact.plane.normal_world
        return out

    def normal_kinematics(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(j (B, S, n) as :meth:`normal_jacobians`, N . (dJ_s/dt qdot) (B, S) [m/s^2]) of a fixed base at (q (n, B),
        qdot (n, B)): each sphere centre's normal acceleration is j_s . qddot + the second. For the joints j that
        move the centre p (positions P_j, axes a_j, rates w_j): u = sum_j c_j w_j with c_j = a_j x (p - P_j)
        (revolute) or a_j (prismatic); with qddot = 0, d/dt a_j = Omega_j x a_j (Omega_j = sum_{k<j} a_k w_k over
        revolute k: the frame before joint j turns), d/dt P_j = sum_{k<j} c_k(P_j) w_k, and d/dt c_j =
        a_j' x (p - P_j) + a_j x (u - P_j') (revolute) or a_j' (prismatic)."""
        positions, rotations, axes, _ = self._frames(q)
        centres = self._centres_base(positions, rotations)
        columns = self._columns(positions, axes, centres)
        rates = qdot.T  # (B, n)
        spins = np.where(self._revolute[None, :, None], axes, 0.0) * rates[:, :, None]  # (B, n, 3): a_k w_k
        axis_rates = np.cross(np.cumsum(spins, axis=1) - spins, axes)  # (B, n, 3): Omega_j x a_j
        n = self._chain.n_joints
        levers = positions[:, None, :n] - positions[:, :n, None]  # (B, k, j, 3): P_j - P_k
        moves = np.where(self._revolute[None, :, None, None], np.cross(axes[:, :, None], levers),
                         axes[:, :, None])  # (B, k, j, 3): c_k(P_j)
        origin_rates = np.einsum("bkjx,bk,kj->bjx", moves, rates, np.triu(np.ones((n, n)), 1))  # k < j
        bias = np.empty(centres.shape[:2])
        for s, cols in enumerate(columns):
            m = cols.shape[1]
            velocity = np.einsum("bkx,bk->bx", cols, rates[:, :m])
            revolute_rate = (np.cross(axis_rates[:, :m], centres[:, s, None] - positions[:, :m])
                             + np.cross(axes[:, :m], velocity[:, None] - origin_rates[:, :m]))
            column_rates = np.where(self._revolute[:m, None], revolute_rate, axis_rates[:, :m])
            bias[:, s] = np.einsum("bkx,bk->bx", column_rates, rates[:, :m]) @ self._contact.plane.normal_world
        return self._normal_rows(axes, columns), bias

    def _state(self, q: np.ndarray, qdot: np.ndarray):
        """(forces (B, S, 3) in the world, the base-to-application-point arms in world axes (B, S, 3) or None on a fixed
        base, the Jacobian columns, the base rotation or None) at the state. The force acts at the sphere's centre on
        a frictionless plane (on the normal through the contact point) and at its contact point, the link's point at
        ``centre - radius N``, with friction (the point whose slip it resists)."""
        positions, rotations, axes, rotation = self._frames(q)
        centres_base = self._centres_base(positions, rotations)
        c = self._contact
        points_base = centres_base
        if c.friction > 0:
            points_base = centres_base + (self._lowest if rotation is None
                                          else np.einsum("bji,sj->bsi", rotation, self._lowest))
        columns = self._columns(positions, axes, points_base)
        n = self._chain.n_joints
        rates = qdot[qdot.shape[0] - n:].T  # (B, n)
        relative = np.stack([np.einsum("bkj,bk->bj", cols, rates[:, :cols.shape[1]]) for cols in columns], axis=1)
        arms = None
        if rotation is None:
            centres, velocities = centres_base, relative
        else:
            arms = np.einsum("bij,bsj->bsi", rotation, points_base)
            centres = q[:3].T[:, None] + np.einsum("bij,bsj->bsi", rotation, centres_base)
            velocities = (qdot[:3].T[:, None] + np.cross(qdot[3:6].T[:, None], arms)
                          + np.einsum("bij,bsj->bsi", rotation, relative))
        if c.penalty_stiffness is None or c.penalty_damping is None:
            raise ValueError("a rigid contact has no penalty forces (core.articulated.chain_impulse steps it)")
        forces = penalty_force(centres + self._lowest, velocities, c.plane, c.penalty_stiffness, c.penalty_damping)
        if c.friction > 0:
            forces = forces - sliding_friction(forces, velocities, c.plane.normal_world, c.friction, c.friction_speed)
        return forces, arms, columns, rotation

    def forces_world(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, S, 3) the plane's force on each sphere [N] at the state (q (nq, B), qdot (nv, B))."""
        return self._state(q, qdot)[0]

    def generalized(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(nv, B) the generalized contact force J^T F [N m or N; a floating base's force N and moment N m first]."""
        forces, arms, columns, rotation = self._state(q, qdot)
        n = self._chain.n_joints
        base_forces = forces if rotation is None else np.einsum("bji,bsj->bsi", rotation, forces)  # base axes
        joints = np.zeros((forces.shape[0], n))
        for s, cols in enumerate(columns):
            joints[:, :cols.shape[1]] += np.einsum("bkj,bj->bk", cols, base_forces[:, s])
        if arms is None:
            return joints.T
        wrench = np.concatenate([forces.sum(axis=1), np.cross(arms, forces).sum(axis=1)], axis=1)
        return np.concatenate([wrench, joints], axis=1).T
