"""Model-level parity: what an engine compiled from the chain's robot file against what the reference compiled,
rigid group by rigid group (:class:`core.model.rigid_groups.RigidGroups`), before any dynamics are compared.

A judge: it reads the engines' reports only (core's data model). Each field is a metric of its own, the largest over
the chain's joints and over the configurations (q = 0 and the scene's states), relative to a scale that means the
same in any unit, and its row names the joint where it is largest with both engines' values:

- mass: |m - m_ref| over the larger of the two (0 when both groups are massless);
- centre of mass: |c - c_ref| over the chain's extent X (the farthest joint origin or centre of mass from the first
  joint's origin, as the reference has it); a group massless in both engines has no centre of mass to compare;
- inertia: the largest entry of |I - I_ref| (about each one's own centre of mass, base-frame axes) over the larger
  of the two tensors' largest entries (0 when both are zero), floored at :data:`INERTIA_ROUNDING` of the group's
  m X^2 (a tensor of rounding size, iCub's 1.9e-35 kg m^2 against 0, is no difference);
- axis: the angle between the joints' axes [rad];
- origin: |o - o_ref| over X;

and of each joint as compiled (:class:`core.model.rigid_groups.CompiledJoints`), counts of joints: its type
(revolute or prismatic) differing, and its limits differing (limited in one engine and not the other, or a limit
apart by more than :data:`LIMIT_ROUNDING`), the first such joint named with both engines' values.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.rows import Measured
from simparity.core.model.metric_catalogue import (
    MODEL_AXIS_ERROR_MAX,
    MODEL_COM_ERROR_MAX,
    MODEL_INERTIA_ERROR_MAX,
    MODEL_JOINT_TYPE_MISMATCHES,
    MODEL_LIMIT_MISMATCHES,
    MODEL_MASS_ERROR_MAX,
    MODEL_ORIGIN_ERROR_MAX,
    units,
)
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups

GROUP_METRICS = units(MODEL_MASS_ERROR_MAX, MODEL_COM_ERROR_MAX, MODEL_INERTIA_ERROR_MAX, MODEL_AXIS_ERROR_MAX,
                      MODEL_ORIGIN_ERROR_MAX)
"""The rigid groups' metrics (:func:`model_parity`)."""
JOINT_METRICS = units(MODEL_JOINT_TYPE_MISMATCHES, MODEL_LIMIT_MISMATCHES)
"""The compiled joints' metrics (:func:`joint_parity`)."""
MODEL_METRICS = GROUP_METRICS | JOINT_METRICS
"""The model-parity metrics of a joint-dynamics case, in row order."""

LIMIT_ROUNDING = 4 * float(np.finfo(float).eps)
"""Limits apart by more than this fraction of the larger (and of 1 rad or 1 m near zero) differ: every importer parses
the same decimal of the same file, to the same double or within a rounding of a unit it converts through."""


INERTIA_ROUNDING = 64 * float(np.finfo(float).eps)
"""A tensor difference below this fraction of the group's m X^2 (its mass at the chain's extent: the rotational scale the
dynamics sees it against) is rounding: the written decimals of a tensor ~1e-35 kg m^2 and the sums of the group's
tensors, each rounded relative to m X^2."""


def configurations(q: np.ndarray) -> np.ndarray:
    """The configurations the models are compared at: q = 0 (the file's own placement) and the scene's (B, n)."""
    return np.vstack([np.zeros((1, q.shape[1])), q])


def _ratio(difference: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """difference / scale, 0 where both are 0 (nothing there to differ), (B, n)."""
    return np.divide(difference, scale, out=np.zeros_like(difference), where=scale > 0)


def _worst(values: np.ndarray, unit: str, joints: tuple[str, ...], what: str, own: np.ndarray, ref: np.ndarray,
           text) -> Measured:
    """The largest of ``values`` (B, n) with a note naming its joint and both engines' values there."""
    b, j = np.unravel_index(int(np.argmax(values)), values.shape)
    at = "q = 0" if b == 0 else f"state {b}"
    return Measured(float(values[b, j]), unit,
                    note=f"largest at joint '{joints[j]}' ({at}): {what} {text(own[b, j])} against the reference's "
                         f"{text(ref[b, j])}")


def _vector(values: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in np.ravel(values)) + "]"


def model_parity(own: RigidGroups, ref: RigidGroups, joints: tuple[str, ...]) -> dict[str, Measured]:
    """Each field of ``own`` against ``ref`` (the same configurations, :func:`configurations`) as the module docstring
    says; ``joints`` names the chain's joints."""
    extent = max(float(np.max(np.linalg.norm(ref.origin_world - ref.origin_world[:, :1], axis=-1))),
                 float(np.max(np.linalg.norm(ref.com_world - ref.origin_world[:, :1], axis=-1))))
    if not extent > 0:
        extent = 1.0  # every group at the first joint's origin: lengths in metres (said by no row: all are 0)
    mass = _ratio(np.abs(own.mass - ref.mass), np.maximum(np.abs(own.mass), np.abs(ref.mass)))
    weighed = (own.mass > 0) | (ref.mass > 0)
    com = np.where(weighed, np.linalg.norm(own.com_world - ref.com_world, axis=-1), 0.0) / extent
    largest = np.maximum(np.max(np.abs(own.inertia_world), axis=(-1, -2)), np.max(np.abs(ref.inertia_world),
                                                                                 axis=(-1, -2)))
    floor = INERTIA_ROUNDING * np.maximum(own.mass, ref.mass) * extent ** 2
    inertia = _ratio(np.max(np.abs(own.inertia_world - ref.inertia_world), axis=(-1, -2)), np.maximum(largest, floor))
    axis = np.arctan2(np.linalg.norm(np.cross(own.axis_world, ref.axis_world), axis=-1),
                      np.einsum("bni,bni->bn", own.axis_world, ref.axis_world))
    origin = np.linalg.norm(own.origin_world - ref.origin_world, axis=-1) / extent
    return {
        MODEL_MASS_ERROR_MAX: _worst(mass, "1", joints, "mass", own.mass, ref.mass, lambda v: f"{v:.10g} kg"),
        MODEL_COM_ERROR_MAX: _worst(com, "1", joints, "centre of mass", own.com_world, ref.com_world,
                                    lambda v: f"{_vector(v)} m"),
        MODEL_INERTIA_ERROR_MAX: _worst(inertia, "1", joints, "inertia about the centre of mass", own.inertia_world,
                                        ref.inertia_world, lambda v: f"{_vector(v)} kg m^2"),
        MODEL_AXIS_ERROR_MAX: _worst(axis, "rad", joints, "axis", own.axis_world, ref.axis_world, _vector),
        MODEL_ORIGIN_ERROR_MAX: _worst(origin, "1", joints, "origin", own.origin_world, ref.origin_world,
                                       lambda v: f"{_vector(v)} m"),
    }


def _limit_text(lower: float, upper: float) -> str:
    return "unlimited" if np.isinf(lower) and np.isinf(upper) else f"[{lower:.10g}, {upper:.10g}]"


def joint_parity(own: CompiledJoints, ref: CompiledJoints, joints: tuple[str, ...]) -> dict[str, Measured]:
    """Counts of ``own``'s joints whose type, or whose limits, differ from ``ref``'s (the module docstring); the note
    names the first with both engines' values."""
    kind = np.flatnonzero(own.prismatic != ref.prismatic)
    limits = []
    for i in range(len(joints)):
        pairs = ((own.lower[i], ref.lower[i]), (own.upper[i], ref.upper[i]))
        if any(np.isinf(a) != np.isinf(b) or (np.isfinite(a) and abs(a - b) > LIMIT_ROUNDING * max(abs(a), abs(b), 1.0))
               or (np.isinf(a) and np.isinf(b) and a != b) for a, b in pairs):
            limits.append(i)

    def count(found, what: str, text) -> Measured:
        if not len(found):
            return Measured(0.0, "1")
        i = int(found[0])
        return Measured(float(len(found)), "1",
                        note=f"first at joint '{joints[i]}': {what} {text(own, i)} against the reference's "
                             f"{text(ref, i)}")

    return {MODEL_JOINT_TYPE_MISMATCHES: count(kind, "type",
                                               lambda c, i: "prismatic" if c.prismatic[i] else "revolute"),
            MODEL_LIMIT_MISMATCHES: count(limits, "limits", lambda c, i: _limit_text(c.lower[i], c.upper[i]))}
