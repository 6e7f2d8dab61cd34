"""Checks the scene types share: a unit vector without overflow, a symmetric tensor."""

from __future__ import annotations

import numpy as np

from simparity.core.model.errors import SceneError
from simparity.core.model.ranges import INERTIA_RTOL

SAFE_NORM = (1e-150, 1e150)
"""Norms whose square neither under- nor overflows in float64; outside, a vector is first scaled
by its largest entry (which keeps the direction exact to rounding)."""


def unit_vector(vector, size: int, what: str) -> np.ndarray:
    """``vector`` normalised without overflow or underflow; SceneError if it has no direction."""
    v = np.asarray(vector, dtype=float).reshape(size)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        norm = float(np.linalg.norm(v))
    if not SAFE_NORM[0] < norm < SAFE_NORM[1]:
        largest = float(np.max(np.abs(v)))
        if not (np.isfinite(largest) and largest > 0):
            raise SceneError("<code>", what, f"{v.tolist()} has no direction", "a finite non-zero vector")
        v = v / largest
        norm = float(np.linalg.norm(v))
    return v / norm


def check_symmetric(tensor: np.ndarray, what: str) -> None:
    """SceneError unless the (3, 3) ``tensor`` is symmetric to :data:`~core.model.ranges.INERTIA_RTOL` of its largest
    entry (a rotated tensor, R I R^T, is symmetric to rounding): engines read one triangle or the other."""
    largest = float(np.max(np.abs(tensor)))
    asymmetry = float(np.max(np.abs(tensor / largest - tensor.T / largest))) if largest > 0 else 0.0
    if asymmetry > INERTIA_RTOL:
        raise SceneError("<code>", what, f"not symmetric: max |I - I^T| = {asymmetry * largest:.3g} kg m^2",
                         f"a symmetric tensor (to {INERTIA_RTOL:g} of its largest entry)")
