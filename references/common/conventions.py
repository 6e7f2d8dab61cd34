"""Conventions shared by the references: rotations, quaternion order, principal axes, numbers in model files.

A reference must not borrow the code it checks, so the rotations here are SciPy's
(``scipy.spatial.transform.Rotation``), not core's: quaternions are (w, x, y, z) in and out
(``scalar_first=True``), rotation matrices map body to world, every function takes any
number of leading batch axes (``...``). URDF roll-pitch-yaw is R = Rz(yaw) Ry(pitch)
Rx(roll), SciPy's extrinsic ``"xyz"`` sequence.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

PLACEHOLDER_MASS = 1.0  # [kg]
PLACEHOLDER_INERTIA = 1e-3  # [kg m^2]
"""Inertia given to the links of kinematics-only models: MuJoCo rejects massless moving bodies and
PyBullet would invent mass 1, inertia 1. It does not affect kinematics."""


def fmt(values) -> str:
    """Space-separated shortest round-trip decimal forms of the values (float64-exact)."""
    return " ".join(repr(float(v)) for v in np.ravel(values))


def principal_axes(inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (3,) and a proper rotation (3, 3) with inertia = Q diag(moments) Q^T."""
    moments, q = np.linalg.eigh(np.asarray(inertia, dtype=float))
    if np.linalg.det(q) < 0:
        q[:, 2] = -q[:, 2]
    return moments, q


def xyzw_from_wxyz(q: np.ndarray) -> np.ndarray:
    """(..., 4) w,x,y,z -> x,y,z,w (PyBullet's and Pinocchio's order)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def wxyz_from_xyzw(q: np.ndarray) -> np.ndarray:
    """(..., 4) x,y,z,w -> w,x,y,z (the project's order)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def _batched(values: np.ndarray, item: tuple[int, ...]) -> tuple[np.ndarray, tuple[int, ...]]:
    """(values flattened to (N, *item), the leading batch shape)."""
    values = np.asarray(values, dtype=float)
    batch = values.shape[: values.ndim - len(item)]
    return values.reshape((-1,) + item), batch


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a (normalised) quaternion. (..., 4) -> (..., 3, 3)."""
    flat, batch = _batched(q, (4,))
    return Rotation.from_quat(flat, scalar_first=True).as_matrix().reshape(batch + (3, 3))


def matrix_to_quat_wxyz(r: np.ndarray) -> np.ndarray:
    """Unit quaternion of a rotation matrix (sign as SciPy returns it); NaN for a non-finite matrix.
    (..., 3, 3) -> (..., 4)."""
    flat, batch = _batched(r, (3, 3))
    finite = np.isfinite(flat).all(axis=(1, 2))
    quat = np.full((len(flat), 4), np.nan)  # a blown-up state stays non-finite, for the runner to call diverged
    if finite.any():
        quat[finite] = Rotation.from_matrix(flat[finite]).as_quat(scalar_first=True)
    return quat.reshape(batch + (4,))


def quat_wxyz_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation ``a * b`` (b first, then a) as a quaternion. (..., 4) x (..., 4) -> (..., 4)."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    fa, batch = _batched(a, (4,))
    fb, _ = _batched(b, (4,))
    product = Rotation.from_quat(fa, scalar_first=True) * Rotation.from_quat(fb, scalar_first=True)
    return product.as_quat(scalar_first=True).reshape(batch + (4,))


def quat_wxyz_conjugate(q: np.ndarray) -> np.ndarray:
    """The inverse rotation of a unit quaternion. (..., 4) -> (..., 4)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., :1], -q[..., 1:]], axis=-1)


def quat_wxyz_from_rotvec(rotvec: np.ndarray) -> np.ndarray:
    """Quaternion of a rotation vector (axis times angle [rad]). (..., 3) -> (..., 4)."""
    flat, batch = _batched(rotvec, (3,))
    return Rotation.from_rotvec(flat).as_quat(scalar_first=True).reshape(batch + (4,))


def rotvec_to_matrix(rotvec: np.ndarray) -> np.ndarray:
    """exp of a rotation vector [rad] as a matrix. (..., 3) -> (..., 3, 3)."""
    flat, batch = _batched(rotvec, (3,))
    return Rotation.from_rotvec(flat).as_matrix().reshape(batch + (3, 3))


def rpy_to_matrix(rpy: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw [rad] to a matrix, Rz(yaw) Ry(pitch) Rx(roll). (..., 3) -> (..., 3, 3)."""
    flat, batch = _batched(rpy, (3,))
    return Rotation.from_euler("xyz", flat).as_matrix().reshape(batch + (3, 3))


def matrix_to_rpy(r: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw [rad] of a rotation matrix. (..., 3, 3) -> (..., 3).

    At pitch = +-pi/2 roll and yaw are not separable; SciPy then sets yaw to 0 (its
    gimbal-lock warning is silenced: the angles still give the same matrix).
    """
    flat, batch = _batched(r, (3, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return Rotation.from_matrix(flat).as_euler("xyz").reshape(batch + (3,))


def rotation_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle [rad] in [0, pi] of the rotation a^T b between two rotation matrices.

    (..., 3, 3) x (..., 3, 3) -> (...).
    """
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    relative, batch = _batched(np.swapaxes(a, -1, -2) @ b, (3, 3))
    return Rotation.from_matrix(relative).magnitude().reshape(batch)


def quat_wxyz_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle [rad] in [0, pi] of the rotation between two orientations given as quaternions.

    (..., 4) x (..., 4) -> (...); accurate at small angles (SciPy takes it from the relative
    quaternion's vector part, not from an arccos).
    """
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    flat_a, batch = _batched(a, (4,))
    flat_b, _ = _batched(b, (4,))
    relative = Rotation.from_quat(flat_a, scalar_first=True).inv() * Rotation.from_quat(flat_b, scalar_first=True)
    return relative.magnitude().reshape(batch)
