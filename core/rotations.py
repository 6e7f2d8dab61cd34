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


def quat_wxyz_normalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternion with the same rotation. (..., 4) -> (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_wxyz_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a * b`` (rotation b first, then a). (..., 4) x (..., 4) -> (..., 4)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    aw, av = a[..., :1], a[..., 1:]
    bw, bv = b[..., :1], b[..., 1:]
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    v = aw * bv + bw * av + np.cross(av, bv)
    return np.concatenate([w, v], axis=-1)


def quat_wxyz_conjugate(q: np.ndarray) -> np.ndarray:
    """Conjugate (the inverse of a unit quaternion). (..., 4) -> (..., 4)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., :1], -q[..., 1:]], axis=-1)


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a quaternion (normalised first). (..., 4) -> (..., 3, 3)."""
    w, x, y, z = np.moveaxis(quat_wxyz_normalize(q), -1, 0)
    out = np.empty(w.shape + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - w * z)
    out[..., 0, 2] = 2 * (x * z + w * y)
    out[..., 1, 0] = 2 * (x * y + w * z)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - w * x)
    out[..., 2, 0] = 2 * (x * z - w * y)
    out[..., 2, 1] = 2 * (y * z + w * x)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


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
