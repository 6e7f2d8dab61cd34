"""Physical scales of a scene's bodies, which verdicts are judged against instead of absolute constants.

A verdict must not depend on where the scene's origin is, how the scene is turned, in what order its
bodies are listed or in what units it is written (docs/invariance.md). Each scale here is built from the
scene and a trajectory so that it moves with the scene: a body's size, the energy a body has to lose, the
gap within which a body touches a plane. Geometry is written from the scene's data (rotations are
SciPy's), never core's code.
"""

from __future__ import annotations

import itertools
from typing import cast

import numpy as np

from simparity.core.model.scenes.contact import Contact
from simparity.core.model.scenes.dynamics import DynamicsScene

TOUCH_RTOL = 1e-9
"""A sample whose support distance is within this fraction of the body's size touches the plane: a body
resting on it sits at 0 up to the rounding of its position (~1e-16 relative; 1e-14 m for positions of order
100 m), 10^5 times below this for a body of a decimetre; free-flight samples are farther, unless the impact
falls within 1e-9 of a step's length of them. Relative to the size, so it scales with the scene's length
unit and does not depend on where the origin is."""


def contact_of(scene: DynamicsScene) -> Contact:
    """The contact of a scene with planes (every contact metric and scale is asked only of those)."""
    return cast(Contact, scene.contact)


def shape_points_body(shape) -> np.ndarray:
    """(V, 3) the points of a shape that can be lowest or highest against a plane, relative to the COM in body
    axes [m], written here from the shape's data (not core's): a box's 8 corners, the given points, the
    centre of a point or a sphere (whose radius is added apart)."""
    if shape.kind == "box":
        signs = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))
        return shape.center_body + signs * shape.half_extents_body
    if shape.kind == "points":
        return np.asarray(shape.points_body, dtype=float)
    return np.zeros((1, 3))


def shape_reach(scene: DynamicsScene) -> np.ndarray:
    """(B,) the largest distance of a body's contact shape from its COM [m] (0 for a point)."""
    return np.array([np.linalg.norm(shape_points_body(s), axis=1).max() + s.radius for s in contact_of(scene).shapes])


def body_sizes(scene: DynamicsScene) -> np.ndarray:
    """(B,) a body's size [m]: its radius of gyration about the COM, sqrt(tr(I) / (2 m)) (the RMS distance of
    its mass from the COM), or its contact shape's reach from the COM where that is larger."""
    mass = np.array([b.mass for b in scene.bodies])
    trace = np.array([np.trace(b.inertia_body) for b in scene.bodies])
    size = np.sqrt(np.maximum(trace, 0.0) / (2 * mass))
    return size if scene.contact is None else np.maximum(size, shape_reach(scene))


def touch_gaps(scene: DynamicsScene) -> np.ndarray:
    """(B,) the support distance [m] within which a body touches a plane (:data:`TOUCH_RTOL` of its size)."""
    return TOUCH_RTOL * body_sizes(scene)


def gravity_magnitude(scene: DynamicsScene) -> float:
    """|g| [m/s^2]; 0 without gravity."""
    gravity = scene.forces.gravity_world
    return 0.0 if gravity is None else float(np.linalg.norm(gravity))


def lift_energies(scene: DynamicsScene) -> np.ndarray:
    """(B,) m |g| size [J]: the energy that lifts a body by its own size, the least energy scale a body under
    gravity has (a body at rest on a plane has no other); 0 without gravity."""
    mass = np.array([b.mass for b in scene.bodies])
    return mass * gravity_magnitude(scene) * body_sizes(scene)


def energy_scales(scene: DynamicsScene, kinetic0: np.ndarray, potential0: np.ndarray,
                  potential_min: np.ndarray) -> np.ndarray:
    """(B,) the energy a body has to trade over a run [J]: its kinetic energy at the start plus the largest drop
    of its potential energy along the run, KE(0) + PE(0) - min_t PE(t) (the kinetic energy it would have at the
    lowest point it reaches, were energy conserved), at least :func:`lift_energies`.

    Unlike |E(0)|, it does not depend on where the potential is zero (the origin); without gravity it is KE(0),
    which is |E(0)|. ``kinetic0``, ``potential0``: (B,) [J] at the start; ``potential_min``: (B,) [J] the least
    potential energy over the run."""
    drop = potential0 - potential_min
    return np.maximum(kinetic0 + drop, lift_energies(scene))
