"""What a body's forces can give it over a run: the sums of the magnitudes of its applied forces and timed loads, and
of their torques about its centre of mass. Bounds of the exact motion (:mod:`comparisons.measure.divergence`) and
rounding scales (:mod:`comparisons.invariance.rounding_allowance`) are built on them."""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.time_functions import HeldFunction, TimeFunction


def largest_magnitude(function: TimeFunction | None, duration: float) -> float:
    """An upper bound of |f(t)| over [0, duration] [s]: the largest sample of a hold; sum |c_k| T^k + sum |A_s| of a
    smooth function (0 for None)."""
    if function is None:
        return 0.0
    if isinstance(function, HeldFunction):
        return float(np.max(np.linalg.norm(function.samples, axis=1)))
    powers = duration ** np.arange(len(function.polynomial))
    return (float(np.linalg.norm(function.polynomial, axis=1) @ powers)
            + sum(float(np.linalg.norm(s.amplitude)) for s in function.sinusoids))


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
