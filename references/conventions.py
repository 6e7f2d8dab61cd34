"""Conventions shared by the adapters: quaternion order, principal axes, exact numbers in model files."""

from __future__ import annotations

import numpy as np

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
