"""Joint frames of a Denavit-Hartenberg table, with the references' own code (not ``core.dh``).

A chain a scene file gives as ``[chain.dh]`` reaches core as joint frames ``core.dh`` computed; the references
build the same frames here from the table itself (:class:`~core.model.scenes.chain.DHTable`), so that a bug in either
shows as a disagreement. This module writes each row's transform as the textbook's closed-form 4 x 4 matrix
(Spong's A_i for the standard convention, Craig's for the modified one) instead of core's product of elementary
rotations and translations.

The chain's joint i frame is the frame reached before the joint's own motion Rz(q_i) (URDF semantics, as
``core.dh`` states): with the standard convention, the fixed part of row i - 1 (Tx(a_{i-1}) Rx(alpha_{i-1}),
the closed form at theta = d = 0) followed by Rz(theta_offset_i) Tz(d_i) (the closed form at a = alpha = 0), and
the end effector Tx(a_n) Rx(alpha_n); with the modified convention, row i's whole closed form at theta_offset_i
and the end effector the identity. The table's base placement (``base_xyz``, ``base_rotation``) goes before the
first joint.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.chain import DHTable

Frame = tuple[np.ndarray, np.ndarray]
"""(origin (3,) [m], rotation (3, 3)) of a frame in its parent's."""


def standard_row(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Spong's A = Rz(theta) Tz(d) Tx(a) Rx(alpha) in closed form, (4, 4)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct],
                     [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


def modified_row(alpha: float, a: float, theta: float, d: float) -> np.ndarray:
    """Craig's T = Rx(alpha) Tx(a) Rz(theta) Tz(d) in closed form, (4, 4)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st, 0.0, a],
                     [st * ca, ct * ca, -sa, -sa * d],
                     [st * sa, ct * sa, ca, ca * d],
                     [0.0, 0.0, 0.0, 1.0]])


def _frame(transform: np.ndarray) -> Frame:
    return transform[:3, 3].copy(), transform[:3, :3].copy()


def dh_frames(table: DHTable) -> tuple[list[Frame], Frame]:
    """(each joint's frame in its parent link's frame, base to tip; the end effector's in the last link's)."""
    base = np.eye(4)
    base[:3, :3], base[:3, 3] = table.base_rotation, table.base_xyz
    joints = []
    fixed = base  # what stands between the previous link's frame and this joint's
    for i in range(len(table.a)):
        if table.convention == "standard":
            joints.append(_frame(fixed @ standard_row(table.theta_offset[i], table.d[i], 0.0, 0.0)))
            fixed = standard_row(0.0, 0.0, table.a[i], table.alpha[i])
        else:
            joints.append(_frame(fixed @ modified_row(table.alpha[i], table.a[i], table.theta_offset[i], table.d[i])))
            fixed = np.eye(4)
    return joints, _frame(fixed)
