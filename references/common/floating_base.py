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


def _skew_rows(x: np.ndarray) -> np.ndarray:
    """(B, 3, 3) [x]x of (B, 3)."""
    zero = np.zeros(len(x))
    return np.stack([np.stack([zero, -x[:, 2], x[:, 1]], -1), np.stack([x[:, 2], zero, -x[:, 0]], -1),
                     np.stack([-x[:, 1], x[:, 0], zero], -1)], -2)


def project_partials(rotation: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, tau: np.ndarray, by_q: np.ndarray,
                     by_v: np.ndarray, mass: np.ndarray, linear: bool, angular: bool,
                     offset: bool) -> tuple[np.ndarray, np.ndarray]:
    """(∂τ/∂q, ∂τ/∂q̇) (B, 6 + n, 6 + n) in the project's convention of an engine's RNEA partials ``by_q``, ``by_v``
    and its M ``mass``, all in its own coordinates, whose base velocity is the project's turned by R^T in its
    ``linear`` and/or ``angular`` part, whose q tangent turns the same parts into the base frame, and whose linear
    acceleration carries -w_b x v_b when ``offset`` (Pinocchio's free flyer: all three; MuJoCo's free joint: angular
    only). ``qdot``, ``qddot``, ``tau`` (B, 6 + n): the project's state and τ there.

    The project's q tangent is (δp, δθ, joints) with the base moved and turned in world axes (R' = exp([δθ]x) R). With
    T = diag(R^T or 1, R^T or 1, 1) the engine's map of velocities, forces and q tangents (orthogonal), τ = T^T
    τ_engine(q_engine, T v, T a - offset): d(R^T x)/dθ = R^T [x]x, d(R y)/dθ = -[R y]x, so

        ∂τ/∂q = T^T (J_q T + J_v V_θ + M A_θ) + F_θ,    ∂τ/∂q̇ = T^T (J_v T + M C),

    V_θ, A_θ, F_θ nonzero in the δθ columns only (R^T [v]x, R^T [ω]x; R^T [a - ω x v]x, R^T [ω̇]x; -[f]x, -[n]x, each
    on a turned part), C the offset's -d(R^T (ω x v))/dq̇ = (-R^T [ω]x, R^T [v]x) on the linear rows."""
    count, nv = qdot.shape
    turn = np.tile(np.eye(nv), (count, 1, 1))
    back = np.swapaxes(rotation, -1, -2)
    parts = [(part, rows) for part, rows in ((linear, slice(0, 3)), (angular, slice(3, 6))) if part]
    for _, rows in parts:
        turn[:, rows, rows] = back
    v, omega, a, alpha = qdot[:, :3], qdot[:, 3:6], qddot[:, :3], qddot[:, 3:6]
    linear_acceleration = a - np.cross(omega, v) if offset else a
    by_turn_v, by_turn_a, by_turn_f = (np.zeros((count, nv, 3)) for _ in range(3))
    for rows, velocity, acceleration, force in ((slice(0, 3), v, linear_acceleration, tau[:, :3]),
                                                (slice(3, 6), omega, alpha, tau[:, 3:6])):
        if (rows.start == 0 and linear) or (rows.start == 3 and angular):
            by_turn_v[:, rows] = back @ _skew_rows(velocity)
            by_turn_a[:, rows] = back @ _skew_rows(acceleration)
            by_turn_f[:, rows] = -_skew_rows(force)
    widen = np.zeros((3, nv))
    widen[:, 3:6] = np.eye(3)  # into the δθ columns
    transposed = np.swapaxes(turn, -1, -2)
    dq = transposed @ (by_q @ turn + by_v @ (by_turn_v @ widen) + mass @ (by_turn_a @ widen)) + by_turn_f @ widen
    coupling = np.zeros((count, nv, nv))
    if offset:
        coupling[:, :3, :3] = -back @ _skew_rows(omega)
        coupling[:, :3, 3:6] = back @ _skew_rows(v)
    return dq, transposed @ (by_v @ turn + mass @ coupling)


def configuration_rate(q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
    """dq/dt (B, 7 + n) of project states q (B, 7 + n), qdot (B, 6 + n): the base origin's velocity, the quaternion's
    rate 1/2 (0, omega) q (omega in world axes, so its product on the left), the joint rates."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float)[:, 3:7], -1, 0)
    ox, oy, oz = np.moveaxis(np.asarray(qdot, dtype=float)[:, 3:6], -1, 0)
    rate = 0.5 * np.stack([-ox * x - oy * y - oz * z, ox * w + oy * z - oz * y, oy * w + oz * x - ox * z,
                           oz * w + ox * y - oy * x], axis=-1)
    return np.concatenate([qdot[:, :3], rate, qdot[:, BASE_V:]], axis=1)


def unit_quaternions(q: np.ndarray) -> np.ndarray:
    """Project configurations (B, 7 + n) with their quaternions scaled to unit length."""
    out = np.array(q, dtype=float)
    out[:, 3:7] /= np.linalg.norm(out[:, 3:7], axis=1, keepdims=True)
    return out
