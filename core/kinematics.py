"""Forward kinematics and the geometric Jacobian of a serial chain (the lecture's method).

All functions take a batch of configurations ``q`` of shape (B, n) and loop only over the
n joints; every joint step is one vectorised NumPy operation over the batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.rotations import skew, so3_log
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.trajectory import FramePoses


def _as_batch(chain: Chain, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        q = q[None, :]
    if q.ndim != 2 or q.shape[1] != chain.n_joints:
        raise ValueError(f"q has shape {q.shape}, expected (B, {chain.n_joints}) for chain '{chain.name}'")
    return q


SparseVector = tuple[tuple[int, float], ...]
"""The nonzero entries of a constant vector ((k, value), ...)."""
SparseMatrix = tuple[tuple[int, int, float], ...]
"""The nonzero entries of a constant matrix ((k, j, value), ...)."""


def _sparse_vector(a: np.ndarray) -> SparseVector:
    return tuple((int(k), float(a[k])) for (k,) in zip(*np.nonzero(a)))


def _sparse_matrix(a: np.ndarray) -> SparseMatrix:
    return tuple((int(k), int(j), float(a[k, j])) for k, j in zip(*np.nonzero(a)))


@dataclass(frozen=True)
class _JointPlan:
    """Constants of one joint for the packed FK, as their nonzero entries: its origin, its axis and the
    axis's cross-product matrices K, K^2."""

    revolute: bool
    origin_xyz: SparseVector
    origin_rotation: SparseMatrix | None  # None: the identity
    axis: SparseVector
    k: SparseMatrix
    k2: SparseMatrix


@dataclass(frozen=True)
class _ChainPlan:
    """A chain's constants for the packed FK: its joints', then the end effector's offset and rotation."""

    joints: tuple[_JointPlan, ...]
    end_xyz: SparseVector
    end_rotation: SparseMatrix


_PLANS: dict[int, tuple[Chain, _ChainPlan]] = {}
"""Joint plans of recently used chains, by id (a chain's arrays make it unhashable); checked by identity."""
_PLAN_CACHE_SIZE = 64


def _plan(chain: Chain) -> _ChainPlan:
    cached = _PLANS.get(id(chain))
    if cached is not None and cached[0] is chain:
        return cached[1]
    joint_plans = []
    for joint in chain.joints:
        rotation = np.asarray(joint.origin_rotation, dtype=float)
        k = skew(np.asarray(joint.axis, dtype=float))
        joint_plans.append(_JointPlan(joint.type == "revolute",
                                      _sparse_vector(np.asarray(joint.origin_xyz, dtype=float)),
                                      None if np.array_equal(rotation, np.eye(3)) else _sparse_matrix(rotation),
                                      _sparse_vector(np.asarray(joint.axis, dtype=float)), _sparse_matrix(k),
                                      _sparse_matrix(k @ k)))
    plan = _ChainPlan(tuple(joint_plans), _sparse_vector(np.asarray(chain.end_effector_xyz, dtype=float)),
                      _sparse_matrix(np.asarray(chain.end_effector_rotation, dtype=float)))
    if len(_PLANS) >= _PLAN_CACHE_SIZE:
        _PLANS.clear()
    _PLANS[id(chain)] = (chain, plan)
    return plan


def _times_constant(r: np.ndarray, m: SparseMatrix) -> np.ndarray:
    """r m for packed rotations r (3, 3, B) and a constant matrix given by its nonzeros."""
    out = np.zeros_like(r)
    for k, j, value in m:
        out[:, j] += r[:, k] * value
    return out


def _apply_constant(r: np.ndarray, v: SparseVector) -> np.ndarray:
    """r v for packed rotations r (3, 3, B) and a constant vector given by its nonzeros. -> (3, B)."""
    out = np.zeros(r.shape[::2])
    for k, value in v:
        out += r[:, k] * value
    return out


@dataclass(frozen=True)
class PackedFrames:
    """The frames of :func:`joint_frames`, component-major (batch last).

    Attributes
    ----------
    positions : (n + 1, 3, B) ndarray
        Joint positions P_i, then the end effector E [m].
    end_rotation : (3, 3, B) ndarray
        The end effector's rotation to world.
    axes_world : (n, 3, B) ndarray
        Joint axes a_i in world axes.
    rotations : (n + 1, 3, 3, B) ndarray or None
        Every frame's rotation, when asked for.
    """

    positions: np.ndarray
    end_rotation: np.ndarray
    axes_world: np.ndarray
    rotations: np.ndarray | None = None


def packed_frames(chain: Chain, q: np.ndarray, all_rotations: bool = False) -> PackedFrames:
    """FK of a batch of configurations (B, n), one joint at a time, each joint's terms a few element-wise
    operations over the batch (the lecture's chain of frames: p += R o; R = R R_o exp(q K); a = R axis)."""
    q = _as_batch(chain, q)
    batch = q.shape[0]
    p = np.zeros((3, batch))
    r = np.zeros((3, 3, batch))
    r[0, 0] = r[1, 1] = r[2, 2] = 1.0
    positions, axes, rotations = [], [], []
    plan = _plan(chain)
    for i, joint in enumerate(plan.joints):
        p = p + _apply_constant(r, joint.origin_xyz)
        if joint.origin_rotation is not None:
            r = _times_constant(r, joint.origin_rotation)
        axis_world = _apply_constant(r, joint.axis)
        if joint.revolute:
            angle = q[:, i]
            r = r + np.sin(angle) * _times_constant(r, joint.k) + (1 - np.cos(angle)) * _times_constant(r, joint.k2)
        else:
            p = p + q[:, i] * axis_world
        positions.append(p)
        axes.append(axis_world)
        if all_rotations:
            rotations.append(r)
    positions.append(p + _apply_constant(r, plan.end_xyz))
    end = _times_constant(r, plan.end_rotation)
    if all_rotations:
        rotations.append(end)
    return PackedFrames(np.stack(positions), end, np.stack(axes) if axes else np.zeros((0, 3, batch)),
                        np.stack(rotations) if all_rotations else None)


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
    frames = packed_frames(chain, q, all_rotations=True)
    assert frames.rotations is not None  # all_rotations=True always fills them
    return (frames.positions.transpose(2, 0, 1), frames.rotations.transpose(3, 0, 1, 2),
            frames.axes_world.transpose(2, 0, 1))


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
    return jacobian_of_frames(chain, packed_frames(chain, q))


def jacobian_of_frames(chain: Chain, frames: PackedFrames) -> np.ndarray:
    """:func:`jacobian_world` from the frames :func:`packed_frames` returned (no second FK pass). -> (B, 6, n)."""
    axes = frames.axes_world  # (n, 3, B)
    lever = frames.positions[-1] - frames.positions[:-1]
    revolute = np.array([j.type == "revolute" for j in chain.joints])[:, None, None]
    linear = np.where(revolute, np.cross(axes, lever, axis=1), axes)
    angular = np.where(revolute, axes, 0.0)
    return np.concatenate([linear, angular], axis=1).transpose(2, 1, 0)


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
