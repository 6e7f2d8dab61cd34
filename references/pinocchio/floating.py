"""A floating-base chain's dynamics in Pinocchio: its free flyer (``JointModelFreeFlyer``) converted to the project's
convention by :mod:`references.common.floating_base` (both pinned by ``tests/references/test_floating_base_conventions.py``).

Everything else is :mod:`references.pinocchio.joint_dynamics`'s (the model, armature, damping, gravity). Pinocchio's
free-flyer velocity is (linear, angular) in the base's LOCAL frame and its acceleration the time derivative of that
vector, so the project's acceleration reaches it as (R^T p_ddot - w_b x v_b, R^T omega_dot); h is ``rnea`` at that
acceleration of a zero project acceleration (``nle`` is h in Pinocchio's own velocity coordinates). The kinetic energy
sums ``Inertia.vtiv`` over every joint's body, the free flyer's (the base) included.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.conventions import xyzw_from_wxyz
from simparity.references.common.floating_base import (
    BASE_Q,
    BASE_V,
    base_rotations,
    local_offset,
    project_partials,
    turned_base,
    turned_mass,
)
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics
from simparity.references.pinocchio.mass import mass_matrix


class PinocchioFloatingDynamics(PinocchioJointDynamics):
    """The module docstring's: q (B, 7 + n), qdot, qddot and tau (B, 6 + n) in the project's convention."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        super().__init__(chain, gravity_world)
        self._index = np.r_[0:BASE_V, self.idx_v]
        self.detail += ("; the free flyer's LOCAL (linear, angular) velocity turned to world axes, its acceleration "
                        "given w_b x v_b")

    def configuration(self, q_row: np.ndarray) -> np.ndarray:
        """Pinocchio's configuration (nq,) of a project configuration (7 + n,): quat_xyzw."""
        out = self._configuration(q_row[BASE_Q:])
        out[:3], out[3:7] = q_row[:3], xyzw_from_wxyz(q_row[3:7])
        return out

    def _vector(self, local_row: np.ndarray) -> np.ndarray:
        """Pinocchio's (nv,) of a base-local vector (6 + n,) (velocity, acceleration or force)."""
        out = np.zeros(self.model.nv)
        out[self._index] = local_row
        return out

    def local_velocity(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """Pinocchio's velocity (nv,) (the free flyer's in its LOCAL frame) of a project state q (1, 7 + n),
        qdot (1, 6 + n) (world axes)."""
        return self._vector(turned_base(base_rotations(q), qdot, True, True, inverse=True)[0])

    def project_velocity(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(1, 6 + n): the project's velocity (world axes) of Pinocchio's ``v`` (nv,) at q (1, 7 + n); a velocity
        change converts the same way (the base's rows turned by R)."""
        return turned_base(base_rotations(q), v[self._index][None], True, True)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((len(q), len(self._index), len(self._index)))
        for k, row in enumerate(q):
            out[k] = mass_matrix(self.model, self.data, self.configuration(row))[np.ix_(self._index, self._index)]
        return turned_mass(base_rotations(q), out, True, True)

    def _rnea(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        """The project's tau (B, 6 + n) without damping."""
        rotation = base_rotations(q)
        velocity = turned_base(rotation, qdot, True, True, inverse=True)
        acceleration = turned_base(rotation, qddot, True, True, inverse=True)
        acceleration[:, :3] -= local_offset(rotation, qdot)
        local = np.array([pin.rnea(self.model, self.data, self.configuration(row), self._vector(rates),
                                   self._vector(accelerations))[self._index]
                          for row, rates, accelerations in zip(q, velocity, acceleration)])
        return turned_base(rotation, local, True, True)

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return self._rnea(q, qdot, np.zeros_like(qdot))

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        out = self._rnea(q, qdot, qddot)
        out[:, BASE_V:] += self.damping * qdot[:, BASE_V:]
        return out

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        rotation = base_rotations(q)
        damped = np.array(tau, dtype=float)
        damped[:, BASE_V:] -= self.damping * qdot[:, BASE_V:]
        velocity = turned_base(rotation, qdot, True, True, inverse=True)
        force = turned_base(rotation, damped, True, True, inverse=True)
        local = np.array([pin.aba(self.model, self.data, self.configuration(row), self._vector(rates),
                                  self._vector(forces))[self._index]
                          for row, rates, forces in zip(q, velocity, force)])
        local[:, :3] += local_offset(rotation, qdot)
        return turned_base(rotation, local, True, True)

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        rotation = base_rotations(q)
        velocity = turned_base(rotation, qdot, True, True, inverse=True)
        out = np.empty(len(q))
        for k, (row, rates) in enumerate(zip(q, velocity)):
            pin.forwardKinematics(self.model, self.data, self.configuration(row), self._vector(rates))
            out[k] = sum(0.5 * self.model.inertias[i].vtiv(self.data.v[i]) for i in range(1, self.model.njoints))
        return out

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """:meth:`centroidal_momentum`'s angular part moved from the centre of mass to the world origin."""
        linear, angular, centre = self.centroidal_momentum(q, qdot)
        return np.concatenate([linear, angular + np.cross(centre, linear)], axis=1)

    def centroidal_momentum(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(linear momentum, angular momentum about the centre of mass, the centre of mass), each (B, 3) in world
        axes: ``computeCentroidalMomentum``'s ``hg`` and ``com[0]``."""
        velocity = turned_base(base_rotations(q), qdot, True, True, inverse=True)
        out = np.empty((3, len(q), 3))
        for k, (row, rates) in enumerate(zip(q, velocity)):
            momentum = pin.computeCentroidalMomentum(self.model, self.data, self.configuration(row), self._vector(rates))
            out[:, k] = np.array(momentum.linear), np.array(momentum.angular), self.data.com[0]
        return out[0], out[1], out[2]

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """``computeRNEADerivatives`` in the free flyer's LOCAL coordinates (its tangent R exp(δφ), its velocity and
        acceleration) at q̈ = this model's forward dynamics of τ, converted to the project's
        (:func:`references.common.floating_base.project_partials`), + D on the joints' ∂τ/∂q̇; forward dynamics'
        partials -M⁻¹ ∂τ/∂x with Pinocchio's M (its computeABADerivatives' local outputs are not converted)."""
        rotation = base_rotations(q)
        accelerations = self.forward_dynamics(q, qdot, tau)
        velocity = turned_base(rotation, qdot, True, True, inverse=True)
        acceleration = turned_base(rotation, accelerations, True, True, inverse=True)
        acceleration[:, :3] -= local_offset(rotation, qdot)
        index = np.ix_(self._index, self._index)
        own = [np.empty((len(q), len(self._index), len(self._index))) for _ in range(3)]
        for k, (row, rates, rate_of_rates) in enumerate(zip(q, velocity, acceleration)):
            found = pin.computeRNEADerivatives(self.model, self.data, self.configuration(row), self._vector(rates),
                                               self._vector(rate_of_rates))
            for out, matrix in zip(own, found):
                out[k] = np.asarray(matrix)[index]
        mass = np.triu(own[2]) + np.swapaxes(np.triu(own[2], 1), -1, -2)  # Pinocchio fills M's upper triangle
        by_q, by_v = project_partials(rotation, qdot, accelerations, tau, own[0], own[1], mass, True, True, True)
        by_v[:, BASE_V:, BASE_V:] += np.diag(self.damping)
        inverse = np.linalg.inv(self.mass_matrix(q))
        return DynamicsDerivatives(by_q, by_v, -inverse @ by_q, -inverse @ by_v, inverse)
