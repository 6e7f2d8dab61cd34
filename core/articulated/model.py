"""Core's joint-space dynamics behind the engine interface (:class:`JointDynamicsModel`): the recursive
algorithms and the lecture's sum over link Jacobians."""

from __future__ import annotations

import numpy as np
from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.derivatives import rnea_derivatives
from simparity.core.articulated.floating import FloatingRecursiveDynamics
from simparity.core.articulated.groups import chain_compiled_joints, chain_rigid_groups
from simparity.core.articulated.jacobian_sum import JacobianSum
from simparity.core.articulated.recursive import Recursive
from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.scenes.chain import Chain

RECURSIVE, JACOBIAN_SUM = "recursive", "jacobian_sum"
METHODS = (RECURSIVE, JACOBIAN_SUM)
"""Core's joint-dynamics methods (scheme kinds of :data:`core.model.engine.SCHEME_KINDS`)."""


def _batch(values: np.ndarray, n: int) -> np.ndarray:
    """(B, n) float64 of (B, n) or (n,)."""
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        values = values[None, :]
    if values.ndim != 2 or values.shape[1] != n:
        raise ValueError(f"joint values have shape {values.shape}, expected (B, {n})")
    return values


def _rows(values: np.ndarray, n: int) -> np.ndarray:
    """(n, B) contiguous, the recursive algorithms' layout, of (B, n) or (n,)."""
    return np.ascontiguousarray(_batch(values, n).T)


def floating_problem(chain: Chain, method: str) -> str:
    """Why core's ``method`` cannot do ``chain``'s dynamics ("" when it can): the lecture's sum over link Jacobians is
    written for a fixed base."""
    if chain.floating_base and method != RECURSIVE:
        return (f"core's {method} is the lecture's sum over link Jacobians of a fixed-base chain; a floating base is "
                f"core's {RECURSIVE} (ABA and RNEA with a 6-DOF root)")
    return ""


class RecursiveDynamics(JointDynamicsModel):
    """CRBA for M, RNEA for h and tau, ABA for qddot (:mod:`core.articulated.recursive`)."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        self._n, self._chain = chain.n_joints, chain
        self._gravity = np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float)
        self._algorithms = Recursive(chain_arrays(chain), self._gravity)
        self.detail = ("in-house recursive (Featherstone): CRBA for M, RNEA for h and tau, ABA for qddot; "
                       "batched component-major, body frames with z along the joint axis; derivatives: RNEA in "
                       "forward mode, ABA's as -M^-1 dtau/dx")

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        return self._algorithms.mass_matrix(_rows(q, self._n)).transpose(2, 0, 1)

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        q = _rows(q, self._n)
        return self._algorithms.inverse_dynamics(q, _rows(qdot, self._n), np.zeros_like(q), damped=False).T

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        n = self._n
        return self._algorithms.inverse_dynamics(_rows(q, n), _rows(qdot, n), _rows(qddot, n), damped=True).T

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        n = self._n
        return self._algorithms.forward_dynamics(_rows(q, n), _rows(qdot, n), _rows(tau, n)).T

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return self._algorithms.kinetic_energy(_rows(q, self._n), _rows(qdot, self._n))

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        return chain_rigid_groups(self._chain, q)

    def compiled_joints(self) -> CompiledJoints:
        return chain_compiled_joints(self._chain)

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """RNEA differentiated in forward mode (:mod:`core.articulated.derivatives`) at q̈ = ABA(τ); forward dynamics'
        partials -M⁻¹ ∂τ/∂x with core's CRBA M."""
        q, qdot, tau = (_batch(x, self._n) for x in (q, qdot, tau))
        qddot = self.forward_dynamics(q, qdot, tau)
        by_q, by_qdot = rnea_derivatives(self._algorithms.arrays, self._gravity, q, qdot, qddot)
        inverse = np.linalg.inv(self.mass_matrix(q))
        return DynamicsDerivatives(by_q, by_qdot, -inverse @ by_q, -inverse @ by_qdot, inverse)


class JacobianSumDynamics(JointDynamicsModel):
    """The lecture's M and h summed over link Jacobians (:mod:`core.articulated.jacobian_sum`); inverse dynamics
    M qddot + h + D qdot, forward dynamics a linear solve."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        self._n, self._chain = chain.n_joints, chain
        self._sum = JacobianSum(chain, np.zeros(3) if gravity_world is None else gravity_world)
        self._damping = np.array([j.damping for j in chain.joints])
        self.detail = ("in-house jacobian_sum: the lecture's sum over link Jacobians at the centres of mass; "
                       "Jdot in closed form; forward dynamics by a linear solve of M")

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        return self._sum.mass_matrix(_batch(q, self._n))

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return self._sum.bias_forces(_batch(q, self._n), _batch(qdot, self._n))

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        q, qdot, qddot = (_batch(x, self._n) for x in (q, qdot, qddot))
        m = self._sum.mass_matrix(q)
        return (m @ qddot[..., None])[..., 0] + self._sum.bias_forces(q, qdot) + self._damping * qdot

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        q, qdot, tau = (_batch(x, self._n) for x in (q, qdot, tau))
        rhs = tau - self._sum.bias_forces(q, qdot) - self._damping * qdot
        return np.linalg.solve(self._sum.mass_matrix(q), rhs[..., None])[..., 0]

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return self._sum.kinetic_energy(_batch(q, self._n), _batch(qdot, self._n))

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        return chain_rigid_groups(self._chain, q)

    def compiled_joints(self) -> CompiledJoints:
        return chain_compiled_joints(self._chain)


def build(chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
    """Core's joint-space dynamics of ``chain`` by ``method`` (one of :data:`METHODS`; a floating base by
    :data:`RECURSIVE` only: :func:`floating_problem`)."""
    if chain.floating_base and method == RECURSIVE:
        return FloatingRecursiveDynamics(chain, gravity_world)
    if problem := floating_problem(chain, method):
        raise ValueError(problem)
    if method == RECURSIVE:
        return RecursiveDynamics(chain, gravity_world)
    if method == JACOBIAN_SUM:
        return JacobianSumDynamics(chain, gravity_world)
    raise ValueError(f"unknown joint-dynamics method {method!r} (allowed: {', '.join(METHODS)})")
