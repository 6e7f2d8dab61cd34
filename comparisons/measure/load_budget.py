"""What a body's forces can give it over a run: the sums of the magnitudes of its applied forces and timed loads, and
of their torques about its centre of mass. Bounds of the exact motion (:mod:`comparisons.measure.divergence`) and
rounding scales (:mod:`comparisons.invariance.rounding_allowance`) are built on them."""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.time_functions import TimeFunction


def largest_magnitude(function: TimeFunction | None, duration: float) -> float:
    """An upper bound of |f(t)| over [0, duration] [s] (0 for None): :meth:`SmoothFunction.largest_magnitude`,
    :meth:`HeldFunction.largest_magnitude`."""
    return 0.0 if function is None else function.largest_magnitude(duration)


def load_budget(scene: DynamicsScene, index: int) -> tuple[float, float]:
    """(sum of |F| [N], sum of |torque about the COM| [N m]) bounds over the run of body ``index``'s applied forces
    and timed loads (a force at a point p adds |p| |F| to the torque)."""
    force = torque = 0.0
    for applied in scene.forces.applied:
        if applied.body == index:
            magnitude = float(np.linalg.norm(applied.force_world))
            force += magnitude
            torque += float(np.linalg.norm(applied.point_body)) * magnitude
    for load in scene.forces.timed:
        if load.body == index:
            magnitude = largest_magnitude(load.force, scene.duration)
            force += magnitude
            torque += largest_magnitude(load.torque, scene.duration) + float(np.linalg.norm(load.point_body)) * magnitude
    return force, torque
