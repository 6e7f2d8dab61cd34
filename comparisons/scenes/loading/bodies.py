"""The free bodies of a dynamics scene: ``[[body]]`` with its mass (given or from ``[[body.point_mass]]``), its
state, drag, applied forces and loads that change with time (``[[body.load]]``)."""

from __future__ import annotations

import numpy as np

from simparity.comparisons.scenes.loading.contact import CONTACT_BODY_KEYS
from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.core.dynamics.inertia import (
    INERTIA_RTOL,
    inertia_from_point_masses,
    inertia_problem,
    mass_and_center_of_mass,
)
from simparity.core.model.ranges import RANGES
from simparity.core.model.scenes.bodies import AppliedForce, PointMasses, RigidBody
from simparity.references.common.conventions import quat_wxyz_to_matrix

# Drag coefficients and the power of length in their units (for length_unit scaling).
DRAG_KEYS = {"linear_drag": 0, "quadratic_drag": -1, "angular_linear_drag": 2, "angular_quadratic_drag": 2}
BODY_KEYS = ("name", "mass", "inertia_body_diagonal", "inertia_body", "point_mass", "position_world", "quat_wxyz",
             "velocity_world", "angular_velocity_world", "force", "load") + tuple(DRAG_KEYS) + CONTACT_BODY_KEYS
_POINT_MASS = ("mass", "position")
_FORCE = ("force_world", "point_body")


def read_body_forces(r: TableReader, index: int) -> tuple[dict, list[AppliedForce]]:
    """Drag coefficients (key -> value, only those set) and applied forces of one body."""
    drags = {key: r.number(key, length=power) for key, power in DRAG_KEYS.items() if r.has(key)}
    for key, value in drags.items():
        if value < 0:
            raise r.fail(key, f"{value} is negative", "numbers >= 0")
    applied = []
    if r.has("force"):
        for f in r.array_of_tables("force", _FORCE, "max_bodies"):
            applied.append(AppliedForce(index, f.vector("force_world", 3, length=1),
                                        f.vector("point_body", 3, [0.0] * 3, length=1)))
    return drags, applied


def _inertia(r: TableReader) -> np.ndarray:
    """The inertia tensor [kg m^2]: physical, and its principal moments in their range."""
    if r.has("inertia_body_diagonal") == r.has("inertia_body"):
        raise r.fail("inertia_body_diagonal", "give exactly one of inertia_body_diagonal and inertia_body",
                     "inertia_body_diagonal = [a, b, c] or inertia_body = a 3 x 3 tensor")
    if r.has("inertia_body"):
        key, inertia = "inertia_body", r.matrix("inertia_body", 3, length=2)
    else:
        key, inertia = "inertia_body_diagonal", np.diag(r.vector("inertia_body_diagonal", 3, length=2, positive=True))
    moments = RANGES["inertia_moment"]
    largest = float(np.max(np.abs(inertia)))
    if largest > moments.high:
        raise r.fail(key, f"an entry of {largest:.3g} kg m^2 is outside the physical range", moments.text())
    problem = inertia_problem(inertia)
    if problem:
        raise r.fail(key, problem, "a symmetric positive-definite tensor obeying the triangle inequality")
    smallest = float(np.linalg.eigvalsh(inertia)[0])
    if smallest < moments.low:
        raise r.fail(key, f"a principal moment of {smallest:.3g} kg m^2 is outside the physical range", moments.text())
    return inertia


def _point_masses(r: TableReader, frame_position_world: np.ndarray) -> tuple[float, np.ndarray, PointMasses]:
    """(M, inertia about the COM, the points) of a body built from ``[[body.point_mass]]`` whose points are given
    in a frame at ``frame_position_world`` [m]; the points keep the numbers as given, for the references."""
    for key in ("mass", "inertia_body", "inertia_body_diagonal"):
        if r.has(key):
            raise r.fail(key, "given with point_mass: the mass and inertia are computed from the point masses",
                         "either point_mass entries or mass with inertia_body(_diagonal)")
    points = r.array_of_tables("point_mass", _POINT_MASS, "max_bodies")
    masses = np.array([p.number("mass", positive=True) for p in points])
    given = np.stack([p.vector("position", 3, length=1) for p in points])
    total, center = mass_and_center_of_mass(masses, given)
    relative = given - center
    inertia = inertia_from_point_masses(masses, relative)
    problem = inertia_problem(inertia)
    moments = np.linalg.eigvalsh(inertia)
    if problem or moments[0] < RANGES["inertia_moment"].low:
        raise r.fail("point_mass", f"the points give no solid body ({problem or 'a principal moment is ~0'}: "
                     "collinear or coincident points)", "at least three points not on one line")
    if moments[0] + moments[1] - moments[2] <= INERTIA_RTOL * moments[2]:
        raise r.fail("point_mass", "the points lie in one plane: their tensor sits on the edge of the triangle "
                     "inequality (A + B = C), which MuJoCo refuses after rounding and PyBullet turns wrongly",
                     "at least four points, one of them off the plane of the others")
    return float(total), inertia, PointMasses(masses, relative, center, given, frame_position_world)


def read_body(r: TableReader) -> RigidBody:
    quat = r.vector("quat_wxyz", 4, [1.0, 0.0, 0.0, 0.0], nonzero=True)
    position = r.vector("position_world", 3, [0.0] * 3, length=1)
    if r.has("point_mass"):
        mass, inertia, points = _point_masses(r, position)
        # position_world places the frame the points are given in; the body's state is its COM's.
        position = position + quat_wxyz_to_matrix(quat) @ points.center_of_mass_given
    else:
        mass, inertia, points = r.number("mass", positive=True), _inertia(r), None
    return RigidBody(
        name=r.name("name"), mass=mass, inertia_body=inertia, position_world=position, quat_wxyz=quat,
        velocity_world=r.vector("velocity_world", 3, [0.0] * 3, length=1),
        angular_velocity_world=r.vector("angular_velocity_world", 3, [0.0] * 3), point_masses=points,
    )
