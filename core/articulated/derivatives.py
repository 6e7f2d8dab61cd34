"""Core's analytic derivatives of its joint-space dynamics (issue #44): RNEA differentiated in forward mode, and
forward dynamics' derivatives from them, ∂q̈/∂x = -M⁻¹ ∂τ/∂x at q̈ = ABA(τ) (the route Pinocchio takes).

Forward mode carries, beside each body's velocity v_i, acceleration a_i and force f_i, their derivatives along every
direction at once: q_j and q̇_j for each joint j (D = 2n directions), batched over states. With X_i = X_J(q_i) X_T,i the
parent-to-body transform (:mod:`core.articulated.chain_arrays`: body frames with z along the joint axis) and S_i = e_k
its motion subspace, dX_i/dq_i m = -S_i x (X_i m), so (Featherstone's recursions, differentiated term by term):

    δv_i = X_i δv_λ - (S_i δq_i) x v_i + S_i δq̇_i                                   (S_i x S_i = 0)
    δa_i = X_i δa_λ - (S_i δq_i) x (X_i a_λ) + δv_i x S_i q̇_i + v_i x S_i δq̇_i
    δf_i = I_i δa_i + δv_i x* I_i v_i + v_i x* I_i δv_i
    δτ_i = S_iᵀ δf_i + damping_i δq̇_i,      δf_λ += X_iᵀ (δf_i + (S_i δq_i) x* f_i)

the last from d(X_iᵀ f)/dq_i = X_iᵀ (S_i x* f). Gravity is the base's constant acceleration -g: its derivative is 0.
Written on plain (B, ..., 6) arrays, one body at a time; spatial vectors (angular, linear) in body coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.articulated.chain_arrays import ChainArrays


def motion_cross(v: np.ndarray, m: np.ndarray) -> np.ndarray:
    """v x m of motion vectors (..., 6), broadcast: (w x m_w, w x m_v + v_o x m_w)."""
    w, vo = v[..., :3], v[..., 3:]
    return np.concatenate([np.cross(w, m[..., :3]), np.cross(w, m[..., 3:]) + np.cross(vo, m[..., :3])], axis=-1)


def force_cross(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """v x* f of a motion and a force vector (..., 6), broadcast: (w x n + v_o x f, w x f)."""
    w, vo = v[..., :3], v[..., 3:]
    return np.concatenate([np.cross(w, f[..., :3]) + np.cross(vo, f[..., 3:]), np.cross(w, f[..., 3:])], axis=-1)


def _joint_transforms(arrays: ChainArrays, q: np.ndarray) -> np.ndarray:
    """(B, n, 6, 6): X_i = X_J(q_i) X_T,i for B configurations (B, n)."""
    count, n = q.shape
    joint = np.tile(np.eye(6), (count, n, 1, 1))
    c, s = np.cos(q), np.sin(q)
    for i in range(n):
        if arrays.revolute[i]:  # E = Rz(q)^T on both halves
            for half in (0, 3):
                joint[:, i, half, half], joint[:, i, half, half + 1] = c[:, i], s[:, i]
                joint[:, i, half + 1, half], joint[:, i, half + 1, half + 1] = -s[:, i], c[:, i]
        else:  # a slide r = q z: the linear rows get -r x w
            joint[:, i, 3, 1], joint[:, i, 4, 0] = q[:, i], -q[:, i]
    return joint @ arrays.tree_transform[None]


@dataclass(frozen=True)
class Root:
    """What a chain's bodies on the base see of it: its spatial velocity and acceleration (B, 6) in base coordinates
    (gravity as its fictitious acceleration -g), and their derivatives (B, D, 6) along the D directions."""

    velocity: np.ndarray
    acceleration: np.ndarray
    d_velocity: np.ndarray
    d_acceleration: np.ndarray


def rnea_derivatives(arrays: ChainArrays, gravity_world: np.ndarray, q: np.ndarray, qdot: np.ndarray,
                     qddot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(∂τ/∂q, ∂τ/∂q̇), each (B, n, n) with column j the derivative by joint j's variable, of τ = M q̈ + h + D q̇ at B
    states (B, n) (armature and damping included; the module docstring)."""
    count, n = q.shape
    directions = 2 * n
    fixed = Root(np.zeros((count, 6)), np.broadcast_to(np.r_[np.zeros(3), -np.asarray(gravity_world, dtype=float)],
                                                      (count, 6)),
                 np.zeros((count, directions, 6)), np.zeros((count, directions, 6)))
    dtau, _, _ = forward_mode(arrays, q, qdot, qddot, fixed, np.eye(n, directions), np.eye(n, directions, n))
    return dtau[:, :, :n], dtau[:, :, n:]


def forward_mode(arrays: ChainArrays, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, root: Root,
                 along_q: np.ndarray, along_qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The joints' RNEA differentiated along D directions at B states of the joints (B, n) on a ``root`` (a fixed
    base, or a floating one's): (∂τ (B, n, D), the wrench the bodies put on the root (B, 6) and its derivative
    (B, D, 6), both (n, f) in base coordinates). ``along_q``, ``along_qd`` (n, D): each joint's δq_i and δq̇_i in each
    direction."""
    count, n = q.shape
    transforms = _joint_transforms(arrays, q)
    directions = along_q.shape[1]
    v: list[np.ndarray] = []
    a: list[np.ndarray] = []
    dv: list[np.ndarray] = []
    da: list[np.ndarray] = []
    f: list[np.ndarray] = []
    df: list[np.ndarray] = []
    moved: list[np.ndarray] = []
    for i in range(n):
        x = transforms[:, i]
        subspace = np.zeros(6)
        subspace[arrays.subspace[i]] = 1.0
        parent = int(arrays.parents[i])
        parent_v = root.velocity if parent < 0 else v[parent]
        parent_a = root.acceleration if parent < 0 else a[parent]
        parent_dv = root.d_velocity if parent < 0 else dv[parent]
        parent_da = root.d_acceleration if parent < 0 else da[parent]
        spin = subspace * qdot[:, i, None]  # S q̇_i (B, 6)
        carried_a = np.einsum("bij,bj->bi", x, parent_a)
        v_i = np.einsum("bij,bj->bi", x, parent_v) + spin
        a_i = carried_a + subspace * qddot[:, i, None] + motion_cross(v_i, spin)
        turned = subspace * along_q[i][:, None]  # S δq_i per direction (D, 6)
        rate = subspace * along_qd[i][:, None]  # S δq̇_i (D, 6)
        dv_i = (np.einsum("bij,bdj->bdi", x, parent_dv) - motion_cross(turned[None], v_i[:, None]) + rate[None])
        da_i = (np.einsum("bij,bdj->bdi", x, parent_da) - motion_cross(turned[None], carried_a[:, None])
                + motion_cross(dv_i, spin[:, None]) + motion_cross(v_i[:, None], rate[None]))
        inertia = arrays.inertia[i]
        momentum = v_i @ inertia.T
        f.append(a_i @ inertia.T + force_cross(v_i, momentum))
        df.append(da_i @ inertia.T + force_cross(dv_i, momentum[:, None]) + force_cross(v_i[:, None], dv_i @ inertia.T))
        v.append(v_i)
        a.append(a_i)
        dv.append(dv_i)
        da.append(da_i)
        moved.append(turned)
    dtau = np.empty((count, n, directions))
    on_root, d_on_root = np.zeros((count, 6)), np.zeros((count, directions, 6))
    for i in reversed(range(n)):
        dtau[:, i] = df[i][..., arrays.subspace[i]] + arrays.damping[i] * along_qd[i]
        parent = int(arrays.parents[i])
        x = transforms[:, i]
        carried_df = np.einsum("bji,bdj->bdi", x, df[i] + force_cross(moved[i][None], f[i][:, None]))
        carried_f = np.einsum("bji,bj->bi", x, f[i])
        if parent >= 0:
            df[parent] = df[parent] + carried_df
            f[parent] = f[parent] + carried_f
        else:
            d_on_root, on_root = d_on_root + carried_df, on_root + carried_f
    return dtau, on_root, d_on_root
