"""Core's analytic derivatives of a floating-base chain's inverse dynamics (issue #44), in the project's convention
(:mod:`core.articulated.floating`): the joints' RNEA in forward mode (:func:`core.articulated.derivatives
.forward_mode`) on a root whose velocity and acceleration are differentiated here.

The tangent of q is (δp, δθ, δq_joints) with the base turned in world axes, R' = exp([δθ]x) R, and moved in world
axes, p' = p + δp: the chart whose rate is the project's velocity (ṗ = v, Ṙ = [ω]x R). With (ω, v) the base's world
velocity, (ω̇, a) = its acceleration and g gravity, the root in base coordinates is

    V_0 = (Rᵀ ω, Rᵀ v),      A_0 = (Rᵀ ω̇, Rᵀ (a - ω x v - g)),

and d(Rᵀ x)/dθ = Rᵀ [x]x (R' ᵀ x = Rᵀ (x - δθ x x)), so along δθ: δV_0 = (Rᵀ [ω]x, Rᵀ [v]x) δθ and
δA_0 = (Rᵀ [ω̇]x, Rᵀ [a - ω x v - g]x) δθ; along δv: δA_0's linear part -Rᵀ [ω]x δv, along δω: +Rᵀ [v]x δω.
Position does not enter (gravity is uniform): its columns are 0. The base wrench W = I_0 A_0 + V_0 x* I_0 V_0 + what
the bodies put on it is (R f, R n) in the project's order; d(R y)/dθ = -[R y]x.
"""

from __future__ import annotations

import numpy as np

from simparity.core.articulated.chain_arrays import ChainArrays
from simparity.core.articulated.derivatives import Root, force_cross, forward_mode
from simparity.core.rotations import quat_wxyz_to_matrix

BASE = 6
"""Base entries of a floating-base velocity, force or tangent: linear (3), then angular (3)."""


def _skew(x: np.ndarray) -> np.ndarray:
    """(B, 3, 3) [x]x of (B, 3)."""
    zero = np.zeros(len(x))
    return np.stack([np.stack([zero, -x[:, 2], x[:, 1]], -1), np.stack([x[:, 2], zero, -x[:, 0]], -1),
                     np.stack([-x[:, 1], x[:, 0], zero], -1)], -2)


def _back(rotation: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Rᵀ x (B, 3) or Rᵀ X (B, 3, 3)."""
    return np.einsum("bji,bj...->bi...", rotation, x)


def _root(rotation: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, gravity: np.ndarray, nv: int) -> Root:
    """The root seen by the joints' bodies and its derivatives along the 2 nv directions (q's tangent, then q̇)."""
    count = len(rotation)
    v, omega, a, alpha = qdot[:, :3], qdot[:, 3:6], qddot[:, :3], qddot[:, 3:6]
    linear = a - np.cross(omega, v) - gravity
    velocity = np.concatenate([_back(rotation, omega), _back(rotation, v)], axis=1)
    acceleration = np.concatenate([_back(rotation, alpha), _back(rotation, linear)], axis=1)
    d_velocity, d_acceleration = np.zeros((count, 2 * nv, 6)), np.zeros((count, 2 * nv, 6))
    turn = slice(3, 6)  # δθ among q's directions
    d_velocity[:, turn, :3] = np.swapaxes(_back(rotation, _skew(omega)), 1, 2)
    d_velocity[:, turn, 3:] = np.swapaxes(_back(rotation, _skew(v)), 1, 2)
    d_acceleration[:, turn, :3] = np.swapaxes(_back(rotation, _skew(alpha)), 1, 2)
    d_acceleration[:, turn, 3:] = np.swapaxes(_back(rotation, _skew(linear)), 1, 2)
    by_v, by_omega = slice(nv, nv + 3), slice(nv + 3, nv + 6)
    d_velocity[:, by_v, 3:] = rotation  # d(Rᵀ v)/dv_k = Rᵀ e_k: row k of R... as direction k's vector
    d_velocity[:, by_omega, :3] = rotation
    d_acceleration[:, by_v, 3:] = np.swapaxes(_back(rotation, -_skew(omega)), 1, 2)
    d_acceleration[:, by_omega, 3:] = np.swapaxes(_back(rotation, _skew(v)), 1, 2)
    return Root(velocity, acceleration, d_velocity, d_acceleration)


def floating_rnea_derivatives(arrays: ChainArrays, base_inertia: np.ndarray, gravity_world: np.ndarray, q: np.ndarray,
                              qdot: np.ndarray, qddot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(∂τ/∂q, ∂τ/∂q̇), each (B, 6 + n, 6 + n), column j by tangent (or velocity) entry j (the module docstring), of a
    floating-base chain's τ at B states: q (B, 7 + n), q̇ and q̈ (B, 6 + n); ``base_inertia`` (6, 6) the base's spatial
    inertia about its origin, base axes, (angular, linear)."""
    count, nv = qdot.shape
    n = nv - BASE
    rotation = quat_wxyz_to_matrix(q[:, 3:7])
    root = _root(rotation, qdot, qddot, np.asarray(gravity_world, dtype=float), nv)
    along_q, along_qd = np.eye(n, 2 * nv, BASE), np.eye(n, 2 * nv, nv + BASE)
    joint_rows, on_root, d_on_root = forward_mode(arrays, q[:, 7:], qdot[:, BASE:], qddot[:, BASE:], root, along_q,
                                                  along_qd)
    momentum = root.velocity @ base_inertia.T
    wrench = root.acceleration @ base_inertia.T + force_cross(root.velocity, momentum) + on_root
    d_wrench = (root.d_acceleration @ base_inertia.T + force_cross(root.d_velocity, momentum[:, None])
                + force_cross(root.velocity[:, None], root.d_velocity @ base_inertia.T) + d_on_root)
    dtau = np.empty((count, nv, 2 * nv))
    dtau[:, :3] = np.einsum("bij,bdj->bid", rotation, d_wrench[..., 3:])  # R df
    dtau[:, 3:6] = np.einsum("bij,bdj->bid", rotation, d_wrench[..., :3])  # R dn
    force, torque = (np.einsum("bij,bj->bi", rotation, part) for part in (wrench[:, 3:], wrench[:, :3]))
    dtau[:, :3, 3:6] -= _skew(force)
    dtau[:, 3:6, 3:6] -= _skew(torque)
    dtau[:, BASE:] = joint_rows
    return dtau[:, :, :nv], dtau[:, :, nv:]
