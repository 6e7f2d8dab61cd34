"""Joint limits as hard bounds: wrapping revolute joints into them and crossing narrow gaps.

A revolute joint's angle is only defined modulo 2 pi, so a value outside [lower, upper]
whose equivalent q + 2 pi k lies inside is the same pose inside the limits. When a range
spans almost a full turn, what is left of the circle is a narrow *gap*
2 pi - (upper - lower); a joint at one limit that needs to turn further can instead
reach the pose it is heading for from the other limit, which is the same angle as a turn
of ``gap`` through the gap.
"""

from __future__ import annotations

import numpy as np


def inside(q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """(B, n) True where lower <= q <= upper."""
    return (q >= lower) & (q <= upper)


def wrap_into_limits(q: np.ndarray, revolute: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """q with each revolute joint outside its limits moved by a multiple of 2 pi into them.

    Parameters
    ----------
    q : (B, n) ndarray
        [rad or m].
    revolute : (n,) bool ndarray
    lower, upper : (n,) ndarray
        Limits, infinite when unlimited.

    Returns
    -------
    (B, n) ndarray
        Values with no equivalent inside the limits (or of prismatic joints) unchanged.
    """
    shifted = q + 2 * np.pi * np.ceil((lower - q) / (2 * np.pi))  # smallest equivalent >= lower
    shifted = np.where(np.isfinite(shifted), shifted, q)
    return np.where(revolute & ~inside(q, lower, upper) & inside(shifted, lower, upper), shifted, q)


def crossable_gap(revolute: np.ndarray, lower: np.ndarray, upper: np.ndarray, max_step: float) -> np.ndarray:
    """(n,) True for revolute joints whose gap 2 pi - (upper - lower) is in (0, max_step]."""
    gap = 2 * np.pi - (upper - lower)
    return revolute & np.isfinite(gap) & (gap > 0) & (gap <= max_step)


def cross_gap(q: np.ndarray, joints: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """q with the ``joints`` (B, n) mask moved from the limit they sit at to the other one."""
    return np.where(joints, np.where(q >= upper, lower, upper), q)
