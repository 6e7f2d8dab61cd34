"""Forward kinematics and the geometric Jacobian of a serial chain (the lecture's method).

All functions take a batch of configurations ``q`` of shape (B, n) and loop only over the
n joints; every joint step is one vectorised NumPy operation over the batch.
"""

from __future__ import annotations

import numpy as np

from simparity.core.rotations import so3_exp, so3_log
from simparity.core.scene import Chain
from simparity.core.trajectory import FramePoses


def _as_batch(chain: Chain, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        q = q[None, :]
    if q.ndim != 2 or q.shape[1] != chain.n_joints:
        raise ValueError(f"q has shape {q.shape}, expected (B, {chain.n_joints}) for chain '{chain.name}'")
    return q


def joint_frames(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint positions, joint axes and link frames of a batch of configurations.

    Parameters
    ----------
    chain : Chain
    q : (B, n) ndarray

    Returns
    -------
    positions : (B, n + 1, 3) ndarray
        World origin of each joint's child-link frame (= the joint position P_i), then the
        end effector E [m].
    rotations : (B, n + 1, 3, 3) ndarray
        The same frames' rotations to world.
    axes_world : (B, n, 3) ndarray
        Joint axes a_i in world axes.
    """
    q = _as_batch(chain, q)
    batch = q.shape[0]
    p = np.zeros((batch, 3))
    r = np.broadcast_to(np.eye(3), (batch, 3, 3))
    positions, rotations, axes = [], [], []
    for i, joint in enumerate(chain.joints):
        p = p + r @ joint.origin_xyz
        r = r @ joint.origin_rotation
        axis_world = r @ joint.axis
        if joint.type == "revolute":
            r = r @ so3_exp(q[:, i, None] * joint.axis)
        else:
            p = p + q[:, i, None] * axis_world
        positions.append(p)
        rotations.append(r)
        axes.append(axis_world)
    positions.append(p + r @ chain.end_effector_xyz)
    rotations.append(r @ chain.end_effector_rotation)
    return np.stack(positions, axis=1), np.stack(rotations, axis=1), np.stack(axes, axis=1)


def forward_kinematics(chain: Chain, q: np.ndarray) -> FramePoses:
    """Poses of every link frame and of the end effector. (B, n) -> FramePoses with F = n + 1."""
    positions, rotations, _ = joint_frames(chain, q)
    return FramePoses(positions, rotations)


def jacobian_world(chain: Chain, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian of the end effector, as on the lecture's slide.

    Column i is (a_i x (E - P_i), a_i) for a revolute joint and (a_i, 0) for a prismatic
    one, with a_i the joint axis, P_i the joint position and E the end effector, all in
    world axes. (B, n) -> (B, 6, n), linear rows first.
    """
    positions, _, axes = joint_frames(chain, q)
    return jacobian_of_frames(chain, positions, axes)


def jacobian_of_frames(chain: Chain, positions: np.ndarray, axes_world: np.ndarray) -> np.ndarray:
    """:func:`jacobian_world` from the frames :func:`joint_frames` returned (no second FK pass).

    positions (B, n + 1, 3), axes_world (B, n, 3) -> (B, 6, n).
    """
    axes = axes_world
    end = positions[:, -1:, :]
    revolute = np.array([j.type == "revolute" for j in chain.joints])[None, :, None]
    linear = np.where(revolute, np.cross(axes, end - positions[:, :-1, :]), axes)
    angular = np.where(revolute, axes, 0.0)
    return np.concatenate([linear, angular], axis=2).transpose(0, 2, 1)


def finite_difference_jacobian_world(chain: Chain, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """Central-difference Jacobian of the end effector, for tests. (B, n) -> (B, 6, n).

    Linear rows difference the end-effector position; angular rows difference the
    rotation through the manifold: (R(q + h e_i) R(q - h e_i)^T) -> rotation vector / 2h.
    ``step`` is in [rad or m]; the truncation error is O(step^2).
    """
    q = _as_batch(chain, q)
    columns = []
    for i in range(chain.n_joints):
        dq = np.zeros(chain.n_joints)
        dq[i] = step
        pp, rp, _ = joint_frames(chain, q + dq)
        pm, rm, _ = joint_frames(chain, q - dq)
        lin = (pp[:, -1] - pm[:, -1]) / (2 * step)
        ang = so3_log(rp[:, -1] @ np.swapaxes(rm[:, -1], -1, -2)) / (2 * step)
        columns.append(np.concatenate([lin, ang], axis=1))
    return np.stack(columns, axis=2)
