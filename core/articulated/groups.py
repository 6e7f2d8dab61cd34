"""Core's reading of a chain's compiled model, rigid group by rigid group (:class:`RigidGroups`)."""

from __future__ import annotations

import numpy as np
from simparity.core.kinematics import forward_kinematics
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.scenes.chain import Chain


def chain_rigid_groups(chain: Chain, q: np.ndarray) -> RigidGroups:
    """Core's reading of the chain, joint by joint (:class:`RigidGroups`): each link's mass properties as core's URDF
    parser merged them (the links welded to a chain link folded into it), placed by core's forward kinematics."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    poses = forward_kinematics(chain, q)
    n = chain.n_joints
    position, rotation = poses.position_world[:, :n], poses.rotation_world[:, :n]  # (B, n, 3), (B, n, 3, 3)
    links = [joint.link for joint in chain.joints]
    mass = np.array([0.0 if link is None else link.mass for link in links])
    com = np.array([np.zeros(3) if link is None else link.com_xyz for link in links])
    inertia = np.array([np.zeros((3, 3)) if link is None else link.inertia_com for link in links])
    axes = np.array([joint.axis for joint in chain.joints])
    return RigidGroups(mass=np.broadcast_to(mass, q.shape),
                       com_world=position + np.einsum("bnij,nj->bni", rotation, com),
                       inertia_world=rotation @ inertia @ np.swapaxes(rotation, -1, -2),
                       axis_world=np.einsum("bnij,nj->bni", rotation, axes), origin_world=position)


def chain_compiled_joints(chain: Chain) -> CompiledJoints:
    """Core's reading of each chain joint: its type and limits as core's parser (or the scene file) gave them."""
    return CompiledJoints(np.array([j.type == "prismatic" for j in chain.joints], dtype=bool), chain.lower, chain.upper)
