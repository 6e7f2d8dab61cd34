"""A floating-base chain's dynamics in MuJoCo: a free joint (``add_freejoint`` on the URDF's root body, through
``MjSpec``) converted to the project's convention by :mod:`references.common.floating_base` (both pinned by
``tests/references/test_floating_base_conventions.py``).

Everything else is :mod:`references.mujoco.joint_dynamics`'s (compiler options, constraints off, damping, armature,
gravity). MuJoCo's free joint: qpos (body origin position, quat_wxyz), qvel (linear velocity in WORLD axes, angular
velocity in the BODY frame); qacc is the time derivative of qvel, so only the angular parts turn (by R^T in, by R
out) and no velocity product enters. The kinetic energy sums every body, the base's included.
"""

from __future__ import annotations

import mujoco
import numpy as np

from simparity.core.model.rigid_groups import RigidGroups
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.derivatives import DynamicsDerivatives, FiniteDifferences
from simparity.references.common.floating_base import (
    BASE_Q,
    BASE_V,
    base_rotations,
    project_partials,
    turned_base,
    turned_mass,
)
from simparity.references.mujoco.joint_dynamics import FORWARD_MISSING, INVERSE_FD_STEP, MujocoJointDynamics

IDENTITY_POSE = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
"""A free joint's qpos at the world's origin, unturned (quat_wxyz)."""


class MujocoFloatingDynamics(MujocoJointDynamics):
    """The module docstring's: q (B, 7 + n), qdot, qddot and tau (B, 6 + n) in the project's convention."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        super().__init__(chain, gravity_world)
        m = self.model
        free = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
        if len(free) != 1:
            raise ValueError(f"MuJoCo's model has {len(free)} free joints, expected the base's one")
        self._free_qpos = int(m.jnt_qposadr[free[0]])
        self.state_qpos = np.r_[self._free_qpos:self._free_qpos + BASE_Q, self.qpos]
        self.state_dof = np.r_[int(m.jnt_dofadr[free[0]]):int(m.jnt_dofadr[free[0]]) + BASE_V, self.dof]
        self.detail += ("; the base a free joint (MjSpec add_freejoint on the root body), its BODY-frame angular "
                        "velocity turned to world axes")

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        return turned_mass(base_rotations(q), super().mass_matrix(q), False, True)

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        rotation = base_rotations(q)
        own = super().bias_forces(q, turned_base(rotation, qdot, False, True, inverse=True))
        return turned_base(rotation, own, False, True)

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        rotation = base_rotations(q)
        own = super().inverse_dynamics(q, turned_base(rotation, qdot, False, True, inverse=True),
                                       turned_base(rotation, qddot, False, True, inverse=True))
        return turned_base(rotation, own, False, True)

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        rotation = base_rotations(q)
        own = super().forward_dynamics(q, turned_base(rotation, qdot, False, True, inverse=True),
                                       turned_base(rotation, tau, False, True, inverse=True))
        return turned_base(rotation, own, False, True)

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return super().link_kinetic_energy(q, turned_base(base_rotations(q), qdot, False, True, inverse=True))

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """:meth:`centroidal_momentum`'s angular part moved from the centre of mass to the world origin."""
        linear, angular, centre = self.centroidal_momentum(q, qdot)
        return np.concatenate([linear, angular + np.cross(centre, linear)], axis=1)

    def centroidal_momentum(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(linear momentum, angular momentum about the centre of mass, the centre of mass), each (B, 3) in world
        axes: ``mj_subtreeVel`` at the free body after ``mj_forward``, its subtree's mass x ``subtree_linvel`` (the
        centre of mass's velocity), ``subtree_angmom`` (about ``subtree_com``) and ``subtree_com``."""
        m, d = self.model, self.data
        body = int(m.jnt_bodyid[[j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE][0]])
        out = np.empty((3, len(q), 3))
        for k, (row, rates) in enumerate(zip(q, turned_base(base_rotations(q), qdot, False, True, inverse=True))):
            self._set(row, rates)
            mujoco.mj_subtreeVel(m, d)
            out[:, k] = (m.body_subtreemass[body] * d.subtree_linvel[body], d.subtree_angmom[body],
                         d.subtree_com[body])
        return out[0], out[1], out[2]

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """``mjd_inverseFD`` in MuJoCo's own coordinates (its q tangent: position in world axes, the quaternion turned
        in the body frame; its qvel and qacc) converted to the project's
        (:func:`references.common.floating_base.project_partials`); forward differences at the steps of
        :meth:`MujocoJointDynamics.derivatives`."""
        rotation = base_rotations(q)
        accelerations = self.forward_dynamics(q, qdot, tau)
        by_q, by_v, mass, steps = self.own_partials(q, turned_base(rotation, qdot, False, True, inverse=True),
                                                    turned_base(rotation, accelerations, False, True, inverse=True))
        by_q, by_v = project_partials(rotation, qdot, accelerations, tau, by_q, by_v, mass, False, True, False)
        return DynamicsDerivatives(by_q, by_v, forward_missing=FORWARD_MISSING,
                                   differences=FiniteDifferences(False, np.full(len(q), INVERSE_FD_STEP), steps))

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        """The joints' groups with the base at the world's origin, unturned (q: the joint values (B, n))."""
        self.data.qpos[self._free_qpos:self._free_qpos + BASE_Q] = IDENTITY_POSE
        return super().rigid_groups(q)
