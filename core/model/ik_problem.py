"""The IK problem every solver is given: tolerances, iteration cap, and checked targets.

This is data model, shared by the in-house solvers and every engine's adapter; the
solvers themselves are in :mod:`simparity.core.ik.jacobian_solvers` (in-house) and in the
adapters (engines).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.scenes.chain import Chain

MAX_TARGET_DISTANCE = 1e9
"""[m] Largest distance of a target from the origin: a million kilometres is beyond any robot, and its
residual's square (1e18) stays far from float64's overflow (1e308), where a 1e300 m target overflowed."""

# Largest |R^T R - I| accepted for a target rotation: rotations built in float64 are
# orthonormal to ~1e-15; 1e-9 still rejects anything that is not a rotation.
_ROTATION_TOLERANCE = 1e-9


@dataclass(frozen=True)
class IKTolerances:
    """When a solve counts as a success, and how long a solver may try.

    Attributes
    ----------
    position_tolerance : float
        Success needs |p_target - p| <= this [m].
    orientation_tolerance : float
        ... and, for pose targets, the angle of R_target R^T <= this [rad].
    max_iterations : int
        Joint updates per target at most.
    """

    position_tolerance: float = 1e-6
    orientation_tolerance: float = 1e-6
    max_iterations: int = 200

    def __post_init__(self) -> None:
        for name in ("position_tolerance", "orientation_tolerance"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{type(self).__name__}.{name} must be finite and > 0, got {value}")
        if self.max_iterations < 1:
            raise ValueError(f"{type(self).__name__}.max_iterations must be >= 1, got {self.max_iterations}")


def check_inputs(chain: Chain, target_position, target_rotation, q_start):
    """Checked IK inputs: (p (B, 3), R (B, 3, 3) or None, q_start broadcast to (B, n)).

    Used by every solver, in-house or engine; raises ValueError naming the bad argument.
    """
    p = np.asarray(target_position, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"target_position must be a finite (B, 3) array, got shape {p.shape}")
    farthest = float(np.max(np.abs(p), initial=0.0))
    if farthest > MAX_TARGET_DISTANCE:
        raise ValueError(f"target_position has a coordinate of {farthest:.3g} m (allowed: up to "
                         f"{MAX_TARGET_DISTANCE:.0e} m from the origin)")
    batch = p.shape[0]
    r = None
    if target_rotation is not None:
        r = np.asarray(target_rotation, dtype=float)
        if r.shape != (batch, 3, 3) or not np.all(np.isfinite(r)):
            raise ValueError(f"target_rotation must be a finite ({batch}, 3, 3) array, got shape {r.shape}")
        off = np.abs(np.swapaxes(r, 1, 2) @ r - np.eye(3)).max(initial=0.0)
        if off > _ROTATION_TOLERANCE or np.any(np.linalg.det(r) <= 0):
            raise ValueError(f"target_rotation must hold rotation matrices (max |R^T R - I| = {off:.1e})")
    n = chain.n_joints
    q = np.zeros(n) if q_start is None else np.asarray(q_start, dtype=float)
    if q.shape not in ((n,), (batch, n)) or not np.all(np.isfinite(q)):
        raise ValueError(f"q_start must be a finite ({n},) or ({batch}, {n}) array, got shape {q.shape}")
    return p, r, np.array(np.broadcast_to(q, (batch, n)))
