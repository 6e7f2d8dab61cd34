"""Mass, centre of mass and inertia tensor of point masses, with the references' own code.

A body a scene file builds from ``[[body.point_mass]]`` reaches core with the mass properties
``core.dynamics.inertia`` computed; the references compute them here from the points as given, so that a bug in
either shows as a disagreement. The tensor is written through the second moment S = sum m_i r_i r_i^T about the
centre of mass: I = trace(S) E - S (the physical tensor, off-diagonal -sum m x y, as URDF and every engine use it),
not core's sum of m (|r|^2 E - r r^T).
"""

from __future__ import annotations

import numpy as np


def point_mass_properties(masses: np.ndarray, positions: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """(M [kg], the centre of mass (3,) in the points' frame [m], the inertia tensor about it (3, 3) [kg m^2])
    of masses (N,) [kg] at positions (N, 3) [m]."""
    masses, positions = np.asarray(masses, dtype=float), np.asarray(positions, dtype=float)
    total = float(np.sum(masses))
    center = masses @ positions / total
    relative = positions - center
    weighted = (relative * masses[:, None]).T @ relative
    second_moment = 0.5 * (weighted + weighted.T)  # exactly symmetric: the products rounded in either order
    return total, center, np.trace(second_moment) * np.eye(3) - second_moment
