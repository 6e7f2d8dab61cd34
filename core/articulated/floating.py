"""Core's dynamics of a chain whose base floats free: Featherstone's RNEA, CRBA and ABA with a 6-DOF root (Rigid Body
Dynamics Algorithms, 2008, section 9.3), in the project's floating-base convention.

The convention (:class:`core.model.scenes.chain.Chain`, ``floating_base``): q = (base origin position in the world [m]
(3), base orientation quat_wxyz (4), joint values (n)); v = (base origin linear velocity in world axes (3), base
angular velocity in world axes (3), joint rates (n)) and a = dv/dt; a generalized force = (force on the base in world
axes (3), torque about the base origin in world axes (3), joint forces (n)), so that its power is f . v.

The algorithms run in base coordinates, Featherstone's spatial order (angular, linear): with R the base's
orientation and (w_b, v_b) = (R^T omega, R^T v) its spatial velocity in its own axes, the base's spatial acceleration
is a_0 = d/dt (w_b, v_b) = (R^T omega_dot, R^T p_ddot - w_b x v_b), and gravity enters as the base's fictitious
acceleration -(0, R^T g). A base wrench (n, f) in base axes is (R f, R n) in the project's order; M's base rows and
columns turn by the same map, B = [[0, R], [R, 0]]: M = B M_base B^T. The base's own mass properties are
``Chain.base_inertia``; the joint bodies are :mod:`core.articulated.recursive`'s.
"""

from __future__ import annotations

import numpy as np
from simparity.core.articulated.chain_arrays import chain_arrays, pack_symmetric, spatial_inertia
from simparity.core.articulated.floating_derivatives import floating_rnea_derivatives
from simparity.core.articulated.groups import chain_compiled_joints, chain_rigid_groups
from simparity.core.articulated.recursive import FloatingBase, Recursive, cross_force, unpack_symmetric
from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.scenes.chain import Chain
from simparity.core.rotations import quat_wxyz_to_matrix


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for (3, B) rows."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _turned_back(rotation: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """R^T x as (3, B) rows, of R (B, 3, 3) and x (B, 3)."""
    return np.einsum("bji,bj->ib", rotation, vectors)


def _turned(rotation: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """R x as (B, 3), of R (B, 3, 3) and x (3, B) rows."""
    return np.einsum("bij,jb->bi", rotation, rows)


class FloatingRecursiveDynamics(JointDynamicsModel):
    """CRBA for M, RNEA for h and tau, ABA for qddot of a floating-base chain (the module docstring); q (B, 7 + n),
    qdot, qddot and tau (B, 6 + n)."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        base = chain.base_inertia
        if not chain.floating_base or base is None:
            raise ValueError("a floating-base chain with the base's mass properties (Chain.base_inertia)")
        self._n, self._chain = chain.n_joints, chain
        self._algorithms = Recursive(chain_arrays(chain), np.zeros(3))  # gravity enters through the base
        self._gravity = np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float)
        self._base_inertia = spatial_inertia(base.mass, base.com_xyz, base.inertia_com)
        self._base_packed = pack_symmetric(self._base_inertia)
        self.detail = ("in-house recursive (Featherstone) with a 6-DOF root: CRBA for M, RNEA for h and tau, ABA "
                       "(floating base, section 9.3) for qddot, in base coordinates; the base's velocity in world axes "
                       "turned by its orientation")

    def _state(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(R (B, 3, 3), joint values (n, B), joint rates (n, B), the base's spatial velocity (6, B) in its axes)."""
        q, qdot = np.atleast_2d(np.asarray(q, dtype=float)), np.atleast_2d(np.asarray(qdot, dtype=float))
        n = self._n
        if q.shape[1] != 7 + n or qdot.shape != (len(q), 6 + n):
            raise ValueError(f"floating-base states have shapes {q.shape} and {qdot.shape}, expected (B, {7 + n}) "
                             f"and (B, {6 + n})")
        rotation = quat_wxyz_to_matrix(q[:, 3:7])
        velocity = np.concatenate([_turned_back(rotation, qdot[:, 3:6]), _turned_back(rotation, qdot[:, :3])])
        return rotation, np.ascontiguousarray(q[:, 7:].T), np.ascontiguousarray(qdot[:, 6:].T), velocity

    def _fictitious(self, rotation: np.ndarray) -> np.ndarray:
        """-(0, R^T g) (6, B): gravity as the base's acceleration in base coordinates."""
        down = _turned_back(rotation, np.broadcast_to(self._gravity, (len(rotation), 3)))
        return np.concatenate([np.zeros_like(down), -down])

    def _project(self, rotation: np.ndarray, wrench: np.ndarray, joints: np.ndarray) -> np.ndarray:
        """(B, 6 + n): a base wrench (6, B) (n, f) in base axes and joint forces (n, B) in the project's order."""
        return np.concatenate([_turned(rotation, wrench[3:]), _turned(rotation, wrench[:3]), joints.T], axis=1)

    def _rnea(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, damped: bool) -> np.ndarray:
        rotation, joints, rates, velocity = self._state(q, qdot)
        qddot = np.atleast_2d(np.asarray(qddot, dtype=float))
        angular, linear = velocity[:3], velocity[3:]
        base = np.concatenate([_turned_back(rotation, qddot[:, 3:6]),
                               _turned_back(rotation, qddot[:, :3]) - _cross_rows(angular, linear)])
        base += self._fictitious(rotation)
        tau, on_base = self._algorithms.rnea(joints, rates, np.ascontiguousarray(qddot[:, 6:].T), damped,
                                             np.ascontiguousarray(base), velocity)
        wrench = self._base_inertia @ base + cross_force(velocity, self._base_inertia @ velocity) + on_base
        return self._project(rotation, wrench, tau)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(np.asarray(q, dtype=float))
        rotation, joints, _, _ = self._state(q, np.zeros((len(q), 6 + self._n)))
        inner, on_base, columns = self._algorithms.crba(joints, True)
        turn = np.zeros((len(q), 6, 6))  # B = [[0, R], [R, 0]]
        turn[:, :3, 3:], turn[:, 3:, :3] = rotation, rotation
        out = np.empty((len(q), 6 + self._n, 6 + self._n))
        composite = unpack_symmetric(on_base + self._base_packed[:, None])
        out[:, :6, :6] = turn @ composite @ np.swapaxes(turn, -1, -2)
        out[:, :6, 6:] = turn @ columns.transpose(2, 0, 1)
        out[:, 6:, :6] = np.swapaxes(out[:, :6, 6:], -1, -2)
        out[:, 6:, 6:] = inner.transpose(2, 0, 1)
        return out

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return self._rnea(q, qdot, np.zeros(np.shape(qdot)), damped=False)

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        return self._rnea(q, qdot, qddot, damped=True)

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        rotation, joints, rates, velocity = self._state(q, qdot)
        tau = np.atleast_2d(np.asarray(tau, dtype=float))
        applied = np.concatenate([_turned_back(rotation, tau[:, 3:6]), _turned_back(rotation, tau[:, :3])])
        base = FloatingBase(velocity, self._base_packed, self._base_inertia, applied)
        qddot, fictitious = self._algorithms.aba(joints, rates, np.ascontiguousarray(tau[:, 6:].T), base)
        acceleration = fictitious - self._fictitious(rotation)
        angular, linear = velocity[:3], velocity[3:]
        return np.concatenate([_turned(rotation, acceleration[3:] + _cross_rows(angular, linear)),
                               _turned(rotation, acceleration[:3]), qddot.T], axis=1)

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        _, joints, rates, velocity = self._state(q, qdot)
        own = 0.5 * np.einsum("ib,ij,jb->b", velocity, self._base_inertia, velocity)
        return self._algorithms.kinetic_energy(joints, rates, velocity) + own

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """Each body's I v carried to the base and summed (:meth:`Recursive.momentum`) with the base's own, turned
        into world axes; the angular part moved from the base origin to the world's (+ p x linear)."""
        rotation, joints, rates, velocity = self._state(q, qdot)
        local = self._algorithms.momentum(joints, rates, velocity) + self._base_inertia @ velocity
        linear, angular = _turned(rotation, local[3:]), _turned(rotation, local[:3])
        position = np.atleast_2d(np.asarray(q, dtype=float))[:, :3]
        return np.concatenate([linear, angular + np.cross(position, linear)], axis=1)

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """RNEA differentiated in forward mode on the floating root (:mod:`core.articulated.floating_derivatives`: q's
        tangent with the base moved and turned in world axes) at q̈ = ABA(τ); forward dynamics' partials -M⁻¹ ∂τ/∂x
        with core's CRBA M."""
        q, qdot, tau = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qdot, tau))
        self._state(q, qdot)  # the shapes, said in one line
        qddot = self.forward_dynamics(q, qdot, tau)
        by_q, by_qdot = floating_rnea_derivatives(self._algorithms.arrays, self._base_inertia, self._gravity, q, qdot,
                                                  qddot)
        inverse = np.linalg.inv(self.mass_matrix(q))
        return DynamicsDerivatives(by_q, by_qdot, -inverse @ by_q, -inverse @ by_qdot, inverse)

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        """Core's compiled model with the base at the world's origin, unturned: q is the joint values (B, n)."""
        return chain_rigid_groups(self._chain, q)

    def compiled_joints(self) -> CompiledJoints:
        return chain_compiled_joints(self._chain)
