"""Rotations: quaternions (w, x, y, z), rotation matrices, rotation vectors.

Every function takes arrays with any number of leading batch axes (written ``...``) and
works in float64. Quaternions are unit quaternions in (w, x, y, z) order; ``q`` and ``-q``
are the same rotation. Rotation matrices map body-frame vectors to the world frame.
"""

from __future__ import annotations

import numpy as np

# Below this angle [rad] the series forms of sin(a)/a etc. are used: their truncation
# error at 1e-4 is ~1e-17, below float64 resolution.
_SMALL_ANGLE = 1e-4
# Below this cos(pitch) the roll-pitch-yaw decomposition is treated as gimbal-locked.
_GIMBAL_COS = 1e-12


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrix: ``skew(a) @ b == cross(a, b)``. (..., 3) -> (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for (..., 3) arrays (np.cross without its per-call overhead on small batches)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    out = np.empty(c0.shape + (3,))  # filled component by component: np.stack costs more than the products
    out[..., 0], out[..., 1], out[..., 2] = c0, c1, c2
    return out


def vector_lengths(vectors: np.ndarray) -> np.ndarray:
    """|a| of vectors (..., 3) as (..., 1): ``np.linalg.norm(a, axis=-1, keepdims=True)``'s sum, the same numbers,
    without its per-call checks (which cost more than the sum on a few vectors)."""
    return np.sqrt(np.add.reduce(vectors * vectors, axis=-1, keepdims=True))


def quat_wxyz_normalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternion with the same rotation. (..., 4) -> (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q / np.sqrt(np.sum(q * q, axis=-1, keepdims=True))


def quat_wxyz_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a * b`` (rotation b first, then a). (..., 4) x (..., 4) -> (..., 4)."""
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ], axis=-1)


def quat_wxyz_conjugate(q: np.ndarray) -> np.ndarray:
    """Conjugate (the inverse of a unit quaternion). (..., 4) -> (..., 4)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., :1], -q[..., 1:]], axis=-1)


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a quaternion (normalised first). (..., 4) -> (..., 3, 3)."""
    q = quat_wxyz_normalize(q)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    out = np.stack([
        1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy),
        2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx),
        2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy),
    ], axis=-1)
    return out.reshape(q.shape[:-1] + (3, 3))


def matrix_to_quat_wxyz(r: np.ndarray) -> np.ndarray:
    """Quaternion (w >= 0) of a rotation matrix, by Shepperd's method. (..., 3, 3) -> (..., 4)."""
    r = np.asarray(r, dtype=float)
    batch = r.shape[:-2]
    m = r.reshape(-1, 3, 3)
    trace = np.trace(m, axis1=1, axis2=2)
    # Candidates 4*q_i^2 for i = w, x, y, z; use the largest for a well-conditioned division.
    cand = np.stack(
        [1 + trace, 1 + 2 * m[:, 0, 0] - trace, 1 + 2 * m[:, 1, 1] - trace, 1 + 2 * m[:, 2, 2] - trace],
        axis=1,
    )
    pick = np.argmax(cand, axis=1)
    q = np.empty((m.shape[0], 4))
    s = 2.0 * np.sqrt(np.maximum(cand[np.arange(len(m)), pick], 0.0))
    for k in range(4):
        sel = pick == k
        if not np.any(sel):
            continue
        mk, sk = m[sel], s[sel]
        if k == 0:
            q[sel] = np.stack([sk / 4, (mk[:, 2, 1] - mk[:, 1, 2]) / sk,
                               (mk[:, 0, 2] - mk[:, 2, 0]) / sk, (mk[:, 1, 0] - mk[:, 0, 1]) / sk], axis=1)
        elif k == 1:
            q[sel] = np.stack([(mk[:, 2, 1] - mk[:, 1, 2]) / sk, sk / 4,
                               (mk[:, 0, 1] + mk[:, 1, 0]) / sk, (mk[:, 0, 2] + mk[:, 2, 0]) / sk], axis=1)
        elif k == 2:
            q[sel] = np.stack([(mk[:, 0, 2] - mk[:, 2, 0]) / sk, (mk[:, 0, 1] + mk[:, 1, 0]) / sk,
                               sk / 4, (mk[:, 1, 2] + mk[:, 2, 1]) / sk], axis=1)
        else:
            q[sel] = np.stack([(mk[:, 1, 0] - mk[:, 0, 1]) / sk, (mk[:, 0, 2] + mk[:, 2, 0]) / sk,
                               (mk[:, 1, 2] + mk[:, 2, 1]) / sk, sk / 4], axis=1)
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    return quat_wxyz_normalize(q).reshape(batch + (4,))


def _sinc_and_cosc(angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sin(a)/a and (1 - cos a)/a^2, accurate at small a."""
    small = angle < _SMALL_ANGLE
    a = np.where(small, 1.0, angle)
    a2 = angle * angle
    sinc = np.where(small, 1 - a2 / 6, np.sin(a) / a)
    cosc = np.where(small, 0.5 - a2 / 24, (1 - np.cos(a)) / (a * a))
    return sinc, cosc


def so3_exp(rotvec: np.ndarray) -> np.ndarray:
    """Rotation matrix exp(skew(rotvec)) by Rodrigues' formula. (..., 3) -> (..., 3, 3)."""
    rotvec = np.asarray(rotvec, dtype=float)
    angle = np.linalg.norm(rotvec, axis=-1)
    sinc, cosc = _sinc_and_cosc(angle)
    k = skew(rotvec)
    eye = np.broadcast_to(np.eye(3), k.shape)
    return eye + sinc[..., None, None] * k + cosc[..., None, None] * (k @ k)


def so3_log(r: np.ndarray) -> np.ndarray:
    """Rotation vector (axis * angle, angle in [0, pi]) of a rotation matrix. (..., 3, 3) -> (..., 3)."""
    return quat_wxyz_to_rotvec(matrix_to_quat_wxyz(r))


def quat_wxyz_from_rotvec(rotvec: np.ndarray) -> np.ndarray:
    """Quaternion of a rotation vector. (..., 3) -> (..., 4)."""
    rotvec = np.asarray(rotvec, dtype=float)
    half = 0.5 * np.linalg.norm(rotvec, axis=-1)
    small = half < _SMALL_ANGLE
    h = np.where(small, 1.0, half)
    scale = np.where(small, 0.5 * (1 - half * half / 6), np.sin(h) / (2 * h))
    return np.concatenate([np.cos(half)[..., None], scale[..., None] * rotvec], axis=-1)


def quat_wxyz_to_rotvec(q: np.ndarray) -> np.ndarray:
    """Rotation vector of a quaternion, angle in [0, pi]. (..., 4) -> (..., 3)."""
    q = quat_wxyz_normalize(q)
    q = q * np.where(q[..., :1] < 0, -1.0, 1.0)
    vnorm = np.linalg.norm(q[..., 1:], axis=-1)
    angle = 2 * np.arctan2(vnorm, q[..., 0])
    small = vnorm < 1e-12
    scale = np.where(small, 2.0 / np.where(small, q[..., 0], 1.0), angle / np.where(small, 1.0, vnorm))
    return scale[..., None] * q[..., 1:]


def geodesic_angle_quat_wxyz(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle [rad] of the rotation taking a to b, in [0, pi]; sign-blind. (..., 4) x (..., 4) -> (...)."""
    rel = quat_wxyz_multiply(quat_wxyz_conjugate(quat_wxyz_normalize(a)), quat_wxyz_normalize(b))
    return 2 * np.arctan2(np.linalg.norm(rel[..., 1:], axis=-1), np.abs(rel[..., 0]))


def geodesic_angle_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle [rad] of the rotation a^T b, in [0, pi]. (..., 3, 3) x (..., 3, 3) -> (...)."""
    return np.linalg.norm(so3_log(np.swapaxes(a, -1, -2) @ b), axis=-1)


def orthonormalize(r: np.ndarray) -> np.ndarray:
    """Nearest rotation matrix (polar decomposition by SVD). (..., 3, 3) -> (..., 3, 3)."""
    u, _, vt = np.linalg.svd(np.asarray(r, dtype=float))
    return u @ vt


def rpy_to_matrix(rpy: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw [rad] to a matrix: Rz(yaw) Ry(pitch) Rx(roll). (..., 3) -> (..., 3, 3)."""
    rpy = np.asarray(rpy, dtype=float)
    ex, ey, ez = np.eye(3)
    return (
        so3_exp(rpy[..., 2:3] * ez) @ so3_exp(rpy[..., 1:2] * ey) @ so3_exp(rpy[..., 0:1] * ex)
    )


def matrix_to_rpy(r: np.ndarray) -> np.ndarray:
    """Inverse of :func:`rpy_to_matrix`, pitch in [-pi/2, pi/2]. (..., 3, 3) -> (..., 3).

    At pitch = +-pi/2 (gimbal lock) roll and yaw are not separable; yaw is set to 0 there.
    """
    r = np.asarray(r, dtype=float)
    cos_pitch = np.hypot(r[..., 0, 0], r[..., 1, 0])
    locked = cos_pitch < _GIMBAL_COS
    pitch = np.arctan2(-r[..., 2, 0], cos_pitch)
    yaw = np.where(locked, 0.0, np.arctan2(r[..., 1, 0], r[..., 0, 0]))
    roll = np.where(
        locked,
        np.arctan2(-r[..., 2, 0] * r[..., 0, 1], r[..., 1, 1]),
        np.arctan2(r[..., 2, 1], r[..., 2, 2]),
    )
    return np.stack([roll, pitch, yaw], axis=-1)
