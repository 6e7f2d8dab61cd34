"""A chain's constants for the recursive algorithms, as arrays: every body in a frame whose z axis is its joint's.

Body i's frame here has the origin of the chain's link frame i and axes ``L_i A_i``, with ``L_i`` the link frame's
axes and ``A_i`` a constant rotation taking z onto the joint axis (``A_i = 1`` when the axis already is z, as in
most URDF files). The joint then turns the body about, or slides it along, its own z axis, so its motion
subspace is a unit vector and its transform a rotation about z (Pinocchio's ``JointModelRZ``): the parent-to-body
transform is ``X_i = X_J(q_i) X_T,i`` with the tree part constant,

    X_T,i = [[C_i^T, 0], [-C_i^T r_i x, C_i^T]],   C_i = A_p^T O_i A_i,   r_i = A_p^T o_i,

(``O_i``, ``o_i`` the joint's origin rotation and offset in the parent link frame, ``A_p`` the parent's alignment,
1 for the base). Spatial vectors are Featherstone's: motion (omega, v_origin), force (n_origin, f), in body axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from simparity.core.model.scenes.chain import Chain
from simparity.core.rotations import skew

SYMMETRIC_PAIRS = ((0, 2), (0, 5), (2, 3), (3, 5),  # x parts of the 2-vectors a rotation about z turns
                   (1, 2), (1, 5), (2, 4), (4, 5),  # their y parts
                   (0, 0), (3, 3), (0, 3),  # a of the 2 x 2 blocks [[a, b], [e, d]] it turns by congruence
                   (1, 1), (4, 4), (1, 4),  # d
                   (0, 1), (3, 4), (0, 4),  # b
                   (1, 3),  # e of the one block that is not symmetric
                   (2, 2), (2, 5), (5, 5))  # unchanged
"""(row, column) of each of the 21 packed entries of a symmetric 6 x 6 matrix, ordered so that a rotation of both
halves about z turns contiguous runs of rows (:func:`core.articulated.recursive.turn_inertia`)."""

PACKED = np.array([[SYMMETRIC_PAIRS.index((min(i, j), max(i, j))) for j in range(6)] for i in range(6)])
"""(6, 6): the packed row of entry (i, j) of a symmetric 6 x 6 matrix."""

ANGULAR_Z, LINEAR_Z = 2, 5
"""The spatial index of a revolute joint's motion subspace (rotation about z) and a prismatic one's."""


def pack_symmetric(m: np.ndarray) -> np.ndarray:
    """(..., 6, 6) symmetric -> (21, ...) packed upper triangle (component-major)."""
    return np.stack([m[..., i, j] for i, j in SYMMETRIC_PAIRS])


def z_alignment(axis: np.ndarray) -> np.ndarray:
    """A rotation A with A e_z = axis (unit); the identity when the axis is e_z, diag(1, -1, -1) when -e_z."""
    axis = np.asarray(axis, dtype=float)
    if np.array_equal(axis, [0.0, 0.0, 1.0]):
        return np.eye(3)
    if np.array_equal(axis, [0.0, 0.0, -1.0]):
        return np.diag([1.0, -1.0, -1.0])
    if axis[2] < -0.5:  # 1 + axis[2] below loses a bit per halving, all at 1e-16 from -e_z (iCub's knee axis
        return z_alignment(-axis) @ np.diag([1.0, -1.0, -1.0])  # (0, 1.2e-16, -1)): align -axis, turn e_z over
    v = np.cross([0.0, 0.0, 1.0], axis)  # rotation about e_z x axis by the angle between them (Rodrigues)
    k = skew(v)
    return np.eye(3) + k + k @ k / (1.0 + axis[2])


def motion_transform(rotation: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """(6, 6) Plucker transform of motion vectors from frame A to frame B, B's axes ``rotation`` (3, 3) and origin
    ``offset`` (3,) [m] in A's coordinates: [[E, 0], [-E r x, E]] with E = rotation^T."""
    e = rotation.T
    out = np.zeros((6, 6))
    out[:3, :3] = out[3:, 3:] = e
    out[3:, :3] = -e @ skew(offset)
    return out


def spatial_inertia(mass: float, com: np.ndarray, inertia_com: np.ndarray) -> np.ndarray:
    """(6, 6) spatial inertia about a frame's origin [kg m^2, kg m, kg] from the mass [kg], the centre of mass
    (3,) [m] and the inertia about it (3, 3) [kg m^2], all in the frame's axes."""
    c = skew(com)
    out = np.empty((6, 6))
    out[:3, :3] = inertia_com - mass * c @ c
    out[:3, 3:] = mass * c
    out[3:, :3] = -mass * c
    out[3:, 3:] = mass * np.eye(3)
    return out


def congruence_matrix(x: np.ndarray) -> np.ndarray:
    """(21, 21): the linear map of packed symmetric matrices I -> X^T I X for a constant (6, 6) X."""
    out = np.empty((21, 21))
    for k, (i, j) in enumerate(SYMMETRIC_PAIRS):
        basis = np.zeros((6, 6))
        basis[i, j] = basis[j, i] = 1.0
        out[:, k] = pack_symmetric(x.T @ basis @ x)
    return out


@dataclass(frozen=True)
class ChainArrays:
    """The constants of a chain with mass properties on every link (:meth:`Chain.dynamics_problem` is "").

    Attributes
    ----------
    parents : (n,) int ndarray
        Each body's parent, lambda(i) (Featherstone), -1 for the base; every parent numbered before its children.
        A chain's body i hangs from body i - 1 (the first from the base); a tree's bodies may share a parent, and
        ``tree_transform`` is then from each body's own parent.
    revolute : (n,) bool ndarray
        True for a revolute joint, False for a prismatic one.
    subspace : (n,) int ndarray
        The spatial index of each joint's motion subspace (:data:`ANGULAR_Z` or :data:`LINEAR_Z`).
    alignment : (n, 3, 3) ndarray
        A_i: body axes in link axes.
    tree_transform : (n, 6, 6) ndarray
        X_T,i: parent body frame (the world for a root) to joint frame, motion vectors.
    tree_force_transform : (n, 6, 6) ndarray
        X_T,i^T: joint-frame forces to the parent body frame.
    tree_congruence : (n, 21, 21) ndarray
        Packed I -> X_T,i^T I X_T,i (a joint-frame inertia in the parent body frame).
    inertia : (n, 6, 6) ndarray
        Each body's spatial inertia about its origin, in body axes.
    inertia_packed : (n, 21) ndarray
        The same, packed.
    mass : (n,) ndarray
        [kg].
    com_body : (n, 3) ndarray
        Centres of mass in body axes [m].
    inertia_com_body : (n, 3, 3) ndarray
        Inertias about the centres of mass in body axes [kg m^2].
    armature, damping : (n,) ndarray
        [kg m^2 or kg], [N m s/rad or N s/m].
    """

    parents: np.ndarray
    revolute: np.ndarray
    subspace: np.ndarray
    alignment: np.ndarray
    tree_transform: np.ndarray
    tree_force_transform: np.ndarray
    tree_congruence: np.ndarray
    inertia: np.ndarray
    inertia_packed: np.ndarray
    mass: np.ndarray
    com_body: np.ndarray
    inertia_com_body: np.ndarray
    armature: np.ndarray
    damping: np.ndarray

    @property
    def n(self) -> int:
        return len(self.revolute)


def chain_arrays(chain: Chain) -> ChainArrays:
    """The arrays of ``chain`` (its links' mass properties must all be declared)."""
    revolute = np.array([j.type == "revolute" for j in chain.joints], dtype=bool)
    alignment = np.stack([z_alignment(j.axis) for j in chain.joints]) if chain.joints else np.zeros((0, 3, 3))
    tree, mass, com, inertia_com = [], [], [], []
    parent_alignment = np.eye(3)
    for joint, align in zip(chain.joints, alignment):
        link = joint.link
        if link is None:
            raise ValueError(f"joint {joint.name!r}'s link has no mass properties: {chain.dynamics_problem()}")
        rotation = parent_alignment.T @ np.asarray(joint.origin_rotation) @ align
        tree.append(motion_transform(rotation, parent_alignment.T @ np.asarray(joint.origin_xyz)))
        mass.append(link.mass)
        com.append(align.T @ np.asarray(link.com_xyz))
        inertia_com.append(align.T @ np.asarray(link.inertia_com) @ align)
        parent_alignment = align
    n = chain.n_joints
    tree_transform = np.array(tree).reshape(n, 6, 6)
    inertia = np.array([spatial_inertia(m, c, i) for m, c, i in zip(mass, com, inertia_com)]).reshape(n, 6, 6)
    return ChainArrays(
        parents=np.arange(n) - 1,
        revolute=revolute,
        subspace=np.where(revolute, ANGULAR_Z, LINEAR_Z),
        alignment=alignment,
        tree_transform=tree_transform,
        tree_force_transform=np.ascontiguousarray(tree_transform.transpose(0, 2, 1)),
        tree_congruence=np.array([congruence_matrix(x) for x in tree_transform]).reshape(n, 21, 21),
        inertia=inertia,
        inertia_packed=pack_symmetric(inertia).T.reshape(n, 21),
        mass=np.array(mass, dtype=float),
        com_body=np.array(com, dtype=float).reshape(n, 3),
        inertia_com_body=np.array(inertia_com, dtype=float).reshape(n, 3, 3),
        armature=np.array([j.armature for j in chain.joints], dtype=float),
        damping=np.array([j.damping for j in chain.joints], dtype=float),
    )
