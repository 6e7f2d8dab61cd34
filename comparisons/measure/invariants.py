"""Energy and angular momentum of rigid bodies (the lecture's "Linear Momentum", "Angular Momentum").

All functions broadcast over leading axes (times, bodies).
"""

from __future__ import annotations

import numpy as np


def kinetic_energy(mass, inertia_body, velocity_world, angular_velocity_world, rotation_world) -> np.ndarray:
    """E = m |v|^2 / 2 + omega_b . I_body omega_b / 2, omega_b = R^T omega. Batched.

    Parameters
    ----------
    mass : (...) array_like
        [kg].
    inertia_body : (..., 3, 3) array_like
        [kg m^2] about the COM, body axes.
    velocity_world, angular_velocity_world : (..., 3) array_like
        [m/s], [rad/s].
    rotation_world : (..., 3, 3) array_like
        Body to world.

    Returns
    -------
    (...) ndarray
        [J].
    """
    v = np.asarray(velocity_world, dtype=float)
    rotation = np.asarray(rotation_world, dtype=float)
    omega_body = np.einsum("...ji,...j->...i", rotation, angular_velocity_world)
    spin = np.einsum("...i,...ij,...j->...", omega_body, np.asarray(inertia_body, dtype=float), omega_body)
    return 0.5 * np.asarray(mass, dtype=float) * np.sum(v * v, axis=-1) + 0.5 * spin


def angular_momentum_world(inertia_body, angular_velocity_world, rotation_world) -> np.ndarray:
    """L = R I_body R^T omega about the COM, world axes. Batched.

    Parameters
    ----------
    inertia_body : (..., 3, 3) array_like
        [kg m^2].
    angular_velocity_world : (..., 3) array_like
        [rad/s].
    rotation_world : (..., 3, 3) array_like
        Body to world.

    Returns
    -------
    (..., 3) ndarray
        [kg m^2 / s].
    """
    rotation = np.asarray(rotation_world, dtype=float)
    omega_body = np.einsum("...ji,...j->...i", rotation, angular_velocity_world)
    return np.einsum("...ij,...jk,...k->...i", rotation, np.asarray(inertia_body, dtype=float), omega_body)


def potential_energy(mass, gravity_world, position_world) -> np.ndarray:
    """-M g.x [J] (zero at the origin). mass (...), g (3,), x (..., 3) -> (...)."""
    return -np.asarray(mass) * (np.asarray(position_world, dtype=float) @ np.asarray(gravity_world, dtype=float))
