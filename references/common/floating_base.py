"""The project's floating-base state in each engine's own convention, and back: the references' own code (SciPy's
rotations), never core's.

The project's convention (:class:`core.model.scenes.chain.Chain`, ``floating_base``): q = (base origin position in
the world (3), quat_wxyz (4), joints (n)); v = (base origin linear velocity in world axes (3), angular velocity in
world axes (3), joint rates (n)), a = dv/dt; a generalized force (force on the base in world axes (3), torque about
the base origin in world axes (3), joint forces (n)). Each engine's (pinned by
``tests/references/test_floating_base_conventions.py``):

- Pinocchio's free flyer (``JointModelFreeFlyer``): q = (position, quat_xyzw, ...); v = (R^T v, R^T omega) (both in
  the base's LOCAL frame), a = dv/dt, so a_local = (R^T p_ddot - w_b x v_b, R^T omega_dot); forces (R^T f, R^T n).
- MuJoCo's free joint: qpos = (position, quat_wxyz, ...); qvel = (v in WORLD axes, R^T omega in the BODY frame),
  qacc = dqvel/dt = (p_ddot, R^T omega_dot); qfrc = (f in world axes, R^T n).

With T the engine's velocity map (v_engine = T v), a generalized force maps back as f = T^T f_engine and the mass
matrix as M = T^T M_engine T; T is orthogonal here (a block of R^T), so T^T = T^-1.
"""

from __future__ import annotations

import numpy as np

from simparity.references.common.conventions import quat_wxyz_to_matrix

BASE_Q, BASE_V = 7, 6
"""The base's share of a floating-base configuration and velocity."""


def base_rotations(q: np.ndarray) -> np.ndarray:
    """(B, 3, 3) the base's orientations of floating-base configurations q (B, 7 + n)."""
    return quat_wxyz_to_matrix(np.asarray(q, dtype=float)[:, 3:7])


def turned_base(rotation: np.ndarray, values: np.ndarray, linear: bool, angular: bool,
                inverse: bool = False) -> np.ndarray:
    """(B, 6 + n): ``values`` with the base's linear (first 3) and/or angular (next 3) parts turned by R (B, 3, 3),
    or by R^T when ``inverse``; joints unchanged."""
    out = np.array(values, dtype=float)
    turn = np.swapaxes(rotation, -1, -2) if inverse else rotation
    for turned, part in ((linear, slice(0, 3)), (angular, slice(3, 6))):
        if turned:
            out[:, part] = np.einsum("bij,bj->bi", turn, out[:, part])
    return out


def turned_mass(rotation: np.ndarray, mass: np.ndarray, linear: bool, angular: bool) -> np.ndarray:
    """T^T M T of an engine's M (B, 6 + n, 6 + n) whose base velocity is the project's turned by R^T in its linear
    and/or angular part (T = diag(R^T or 1, R^T or 1, 1))."""
    out = np.array(mass, dtype=float)
    for turned, part in ((linear, slice(0, 3)), (angular, slice(3, 6))):
        if turned:
            out[:, part, :] = np.einsum("bij,bjk->bik", rotation, out[:, part, :])
            out[:, :, part] = np.einsum("bkj,bij->bki", out[:, :, part], rotation)
    return out


def local_offset(rotation: np.ndarray, qdot: np.ndarray) -> np.ndarray:
    """(B, 3): w_b x v_b, what d/dt (R^T v) adds to R^T p_ddot (w_b = R^T omega, v_b = R^T v)."""
    local = turned_base(rotation, qdot[:, :6], True, True, inverse=True)
    return np.cross(local[:, 3:6], local[:, :3])
