"""A chain's configurations moved along a velocity, for finite differences of configuration-dependent quantities
(M's time derivative): joints by q + s qdot; a floating base's pose by its exact motion at constant world-axes
velocity (:class:`core.model.scenes.chain.Chain`, ``floating_base``): p + s v, and the orientation turned by the
rotation vector s omega in world axes (R(s) = exp(s [omega]x) R), so that a quaternion stays a unit quaternion and
d/ds at 0 is the state's own velocity. SciPy's rotations: a judge does not borrow core's."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from simparity.core.model.scenes.chain import Chain


def moved(chain: Chain, q: np.ndarray, qdot: np.ndarray, step: float) -> np.ndarray:
    """(B, nq): configurations q (B, nq) moved by ``step`` [s] at velocities qdot (B, nv)."""
    if not chain.floating_base:
        return q + step * qdot
    out = np.array(q, dtype=float)
    out[:, :3] += step * qdot[:, :3]
    turned = Rotation.from_rotvec(step * qdot[:, 3:6]) * Rotation.from_quat(q[:, 3:7], scalar_first=True)
    out[:, 3:7] = turned.as_quat(scalar_first=True)
    out[:, 7:] += step * qdot[:, 6:]
    return out
