"""The physical ranges (:mod:`core.model.ranges`) held on a scene built in code.

A scene file is held to the ranges as it is read (``comparisons/scenes/loading/``, :mod:`core.urdf`); a scene object
a user builds and hands to ``simparity.run_scene`` or the pytest fixture is held here, field by field: every number
of a field named like a range key (``mass``, ``damping``, ``com_xyz``, ...) must lie in that range, and no number may
be subnormal. An infinite joint limit is the data model's "no limit" and is passed over.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from simparity.core.model.errors import SceneError
from simparity.core.model.ranges import RANGE_INERTIA_HIGH, RANGES, SUBNORMAL_RULE, Range, subnormal

FIELD_RANGES = {"dts": "dt", "half_extents_body": "half_extents", "center_body": "shape_center_body",
                "points_body": "point_body", "positions_given": "position", "frame_position_world": "position_world",
                "center_of_mass_given": "com_xyz", "base_xyz": "origin_xyz", "masses": "mass", "offset": "position_world",
                "q_start": "q"}
"""Data-model fields whose range goes by another key's name (the scene file's key, or the quantity's)."""

TENSOR_RANGE = Range(0.0, RANGE_INERTIA_HIGH, "kg m^2", "an inertia tensor's entries, within the moments of inertia")
"""The entries of an inertia tensor (off-diagonal entries may be 0 or tiny: the moments are checked by the model)."""
TENSOR_FIELDS = ("inertia_body", "inertia_com")

UNLIMITED = ("lower", "upper")
"""Fields where an infinite value means "no limit"."""

UNUSED_ZERO = ("radius", "half_extents_body")
"""A shape's sizes its kind does not use are 0 in the data model (a box's radius, a sphere's half extents)."""

MASSLESS = "LinkInertia"
"""The data-model type whose ``mass`` may be exactly 0: a chain's massless link (a URDF link without ``<inertial>``,
human.urdf's virtual links), which the chain's dynamics check judges as a whole (``Chain.dynamics_problem``)."""


def check_scene_ranges(scene) -> None:
    """Raise :class:`SceneError` (source, key path, value, the allowed range) for the first number of ``scene`` (any
    scene dataclass) outside its range or subnormal."""
    problem = _first_problem(scene, "")
    if problem is not None:
        key, value, allowed = problem
        raise SceneError(getattr(scene, "source", "<code>"), key, f"{value!r:.40} is out of range", allowed)


def _first_problem(node, path: str) -> tuple[str, float, str] | None:
    if dataclasses.is_dataclass(node) and not isinstance(node, type):
        for item in dataclasses.fields(node):
            value = getattr(node, item.name)
            if type(node).__name__ == MASSLESS and item.name == "mass" and value == 0:
                continue
            found = _field_problem(item.name, value, f"{path}.{item.name}" if path else item.name)
            if found is not None:
                return found
    elif isinstance(node, (tuple, list)):
        for index, child in enumerate(node):
            found = _first_problem(child, f"{path}[{index}]")
            if found is not None:
                return found
    return None


def _field_problem(name: str, value, path: str) -> tuple[str, float, str] | None:
    if dataclasses.is_dataclass(value) or (isinstance(value, (tuple, list)) and value
                                           and dataclasses.is_dataclass(value[0])):
        return _first_problem(value, path)
    numbers = _numbers(value)
    if numbers is None:
        return None
    held = TENSOR_RANGE if name in TENSOR_FIELDS else RANGES.get(FIELD_RANGES.get(name, name))
    for number in numbers:
        if (name in UNLIMITED and math.isinf(number)) or (name in UNUSED_ZERO and number == 0):
            continue
        if subnormal(number):
            return path, number, SUBNORMAL_RULE
        if held is not None and not held.allows(abs(number)):
            return path, number, held.text()
    return None


def _numbers(value) -> list[float] | None:
    """The float64 numbers a field holds (a number, an array, a tuple of numbers), else None (text, None, ...)."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return None
    if isinstance(value, (int, float, np.floating, np.integer)):
        return [float(value)]
    if isinstance(value, np.ndarray) and value.dtype.kind in "fi":
        return [float(v) for v in value.ravel()]
    if isinstance(value, (tuple, list)) and value and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                          for v in value):
        return [float(v) for v in value]
    return None
