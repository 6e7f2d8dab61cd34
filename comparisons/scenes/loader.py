"""Scene files (TOML) -> :class:`core.scene.DynamicsScene`, ``KinematicsScene``, ``IKScene``, ``JointDynamicsScene``.

Every value is checked; a bad one raises :class:`core.errors.SceneError` naming the file,
the key path, what was wrong and what is allowed. A file with a ``[sweep]`` is several scenes, one per
variant (:mod:`comparisons.sweep`; :func:`load_scenes`). The format is documented in ``docs/scenes.md``.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from simparity.comparisons.engines.registry import ENGINE_NAMES, EngineSet
from simparity.comparisons.common.integrators import NO_INTEGRATOR, motion_reference_integrator
from simparity.core.model.engine import Support
from simparity.comparisons.scenes.limits import DEFAULT_LIMITS, POSITION_TOLERANCE_OF_REACH, Limits, allowed_at_most
from simparity.comparisons.scenes.sweep import SWEEP_TABLE, read_sweep
from simparity.core.dh import chain_from_dh
from simparity.core.model.errors import SceneError, echo, one_line
from simparity.core.model.files import file_problem, read_toml
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.dynamics.inertia import (
    INERTIA_RTOL,
    LINK_TENSOR_RULE,
    inertia_from_point_masses,
    inertia_problem,
    link_tensor_problem,
    mass_and_center_of_mass,
)
from simparity.core.model.names import NAME_RULE, TEXT_RULE, name_problem, text_problem
from simparity.core.model.ranges import NORM_RANGES, RANGES, SUBNORMAL_RULE, safe_norm, subnormal
from simparity.core.rotations import rpy_to_matrix
from simparity.core.model.scene import (
    CONTACT_METHODS,
    HARD_TARGETS,
    SHAPES,
    SUITES,
    AppliedForce,
    Chain,
    Contact,
    DHTable,
    DynamicsScene,
    Forces,
    IKScene,
    Joint,
    JointDynamicsScene,
    JointMotionScene,
    KinematicsScene,
    LinkInertia,
    Material,
    Plane,
    PointMasses,
    RigidBody,
    Scene,
    Shape,
    sample_configurations,
)
from simparity.core.urdf import chain_from_urdf
from simparity.references.common.conventions import quat_wxyz_to_matrix

LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "ft": 0.3048, "in": 0.0254}
"""Units a scene may declare for lengths, and their size in metres."""

KINDS = ("dynamics", "kinematics", "ik", "joint_dynamics", "joint_motion")
JOINT_TYPES = ("revolute", "prismatic")

_REQUIRED = object()  # marks a key without a default


class _Reader:
    """Typed access to one table of a scene file, with key paths for error messages."""

    def __init__(self, source: str, table: dict, path: str, allowed: tuple[str, ...], length_scale: float,
                 limits: Limits = DEFAULT_LIMITS) -> None:
        self.source, self.table, self.path, self.scale, self.limits = source, table, path, length_scale, limits
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            raise SceneError(source, self._key(unknown[0]), "unknown key", ", ".join(allowed))

    def _key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def fail(self, key: str, problem: str, allowed: str) -> SceneError:
        """The error for ``key``: what was wrong and what is allowed (every rejection says both)."""
        return SceneError(self.source, self._key(key), problem, allowed)

    def has(self, key: str) -> bool:
        return key in self.table

    def _get(self, key: str, default, allowed: str):
        if key in self.table:
            return self.table[key]
        if default is _REQUIRED:
            raise self.fail(key, "missing required key", allowed)
        return default

    def string(self, key: str, default=None, choices: tuple[str, ...] | None = None) -> str:
        allowed = ", ".join(choices) if choices else "a non-empty string"
        value = self._get(key, _REQUIRED if default is None else default, allowed)
        if not isinstance(value, str) or not value:
            raise self.fail(key, f"expected a non-empty string, got {echo(value)}", allowed)
        if choices and value not in choices:
            raise self.fail(key, f"{echo(value)} is not allowed", allowed)
        return value

    def text(self, key: str, default: str) -> str:
        """Free text for people (a description): one line of printable characters (:mod:`core.names`); ``default``
        when the key is absent."""
        if not self.has(key):
            return default
        value = self.string(key)
        problem = text_problem(value)
        if problem:
            raise self.fail(key, problem, TEXT_RULE)
        return value

    def name(self, key: str, default=None) -> str:
        """A string that names something (see :mod:`core.names`)."""
        value = self.string(key, default)
        problem = name_problem(value)
        if problem:
            raise self.fail(key, problem, NAME_RULE)
        return value

    def _in_range(self, key: str, value: float) -> float:
        """``value`` (SI) if its magnitude is in the key's physical range (:data:`RANGES`)."""
        allowed = RANGES.get(key.rsplit(".", 1)[-1].split("[", 1)[0])
        if allowed is not None and not allowed.allows(abs(value)):
            raise self.fail(key, f"{value:.6g} is outside the physical range", allowed.text())
        return value

    def _checked(self, key: str, value, positive: bool) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"expected a number, got {echo(value)}", "a number" + (" > 0" if positive else ""))
        try:
            finite = math.isfinite(value)
        except OverflowError:
            finite = False
        if not finite:
            raise self.fail(key, f"{value!s:.30} is not finite", "finite numbers")
        if subnormal(value):
            raise self.fail(key, f"{value:.3g} is a subnormal number", SUBNORMAL_RULE)
        if positive and value <= 0:
            raise self.fail(key, f"{value} is not positive", "numbers > 0")
        return float(value)

    def number(self, key: str, default=None, *, positive=False, length=0) -> float:
        value = self._get(key, _REQUIRED if default is None else default, "a number" + (" > 0" if positive else ""))
        return self._in_range(key, self._checked(key, value, positive) * self.scale**length)

    def integer(self, key: str, default=None, *, minimum=0, maximum=2**63 - 1, why: str = "") -> int:
        value = self._get(key, _REQUIRED if default is None else default, f"whole numbers {minimum} to {maximum:,}")
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"expected a whole number, got {echo(value)}", f"whole numbers {minimum} to {maximum}")
        if not minimum <= value <= maximum:
            raise self.fail(key, f"{value} is out of range", f"whole numbers {minimum} to {maximum:,}{why}")
        return value

    def vector(self, key: str, size: int, default=None, *, length=0, nonzero=False, positive=False) -> np.ndarray:
        allowed = f"a list of {size} numbers"
        value = self._get(key, _REQUIRED if default is None else default, allowed)
        if not isinstance(value, list) or len(value) != size:
            got = f"{len(value):,} values" if isinstance(value, list) else echo(value)
            raise self.fail(key, f"expected a list of {size} numbers, got {got}", allowed)
        out = np.array([self._checked(f"{key}[{i}]", v, positive) for i, v in enumerate(value)])
        out *= self.scale**length
        if nonzero and not np.any(out):
            raise self.fail(key, "is all zeros", "a vector with a non-zero entry")
        norm_range = NORM_RANGES.get(key)
        if norm_range is not None and not norm_range.allows(norm := safe_norm(out)):
            raise self.fail(key, f"its norm {norm:.3g} is outside the usable range", norm_range.text())
        for i, v in enumerate(out):
            self._in_range(f"{key}[{i}]", v)
        return out

    def matrix(self, key: str, size: int, *, length=0) -> np.ndarray:
        allowed = f"{size} rows of {size} numbers"
        rows = self._get(key, _REQUIRED, allowed)
        if not isinstance(rows, list) or len(rows) != size:
            raise self.fail(key, f"expected {size} rows of {size} numbers", allowed)
        for i, row in enumerate(rows):
            if not isinstance(row, list) or len(row) != size:
                got = f"{len(row):,} values" if isinstance(row, list) else echo(row)
                raise self.fail(f"{key}[{i}]", f"expected a list of {size} numbers, got {got}", allowed)
        values = [[self._checked(f"{key}[{i}][{j}]", v, False) for j, v in enumerate(row)] for i, row in enumerate(rows)]
        return np.array(values) * self.scale**length

    def numbers(self, key: str) -> tuple[float, ...]:
        """A non-empty list of positive numbers."""
        value = self._get(key, _REQUIRED, "a list like [0.01, 0.02]")
        if not isinstance(value, list) or not value:
            raise self.fail(key, f"expected a non-empty list of numbers, got {echo(value)}", "a list like [0.01, 0.02]")
        return tuple(self._in_range(f"{key}[{i}]", self._checked(f"{key}[{i}]", v, True)) for i, v in enumerate(value))

    def strings(self, key: str, choices: tuple[str, ...], unknown: str = "{} is not allowed") -> tuple[str, ...]:
        """A non-empty list of distinct names, each one of ``choices`` (``unknown`` words the error)."""
        allowed = f"a list of distinct names from: {', '.join(choices)}"
        value = self._get(key, _REQUIRED, allowed)
        if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
            raise self.fail(key, f"expected a non-empty list of names, got {echo(value)}", allowed)
        for i, name in enumerate(value):
            if name not in choices:
                raise self.fail(f"{key}[{i}]", unknown.format(echo(name)), allowed)
            if name in value[:i]:
                raise self.fail(f"{key}[{i}]", f"{echo(name)} is given twice", allowed)
        return tuple(value)

    def subtable(self, key: str, allowed: tuple[str, ...]) -> "_Reader":
        """The table ``key``, which must be there."""
        found = self.optional_subtable(key, allowed)
        if found is None:
            raise self.fail(key, "missing required table", f"a [{self._key(key)}] table of {', '.join(allowed)}")
        return found

    def optional_subtable(self, key: str, allowed: tuple[str, ...]) -> "_Reader | None":
        """The table ``key``, or None when the file has none."""
        table = f"a [{self._key(key)}] table of {', '.join(allowed)}"
        if key not in self.table:
            return None
        value = self.table[key]
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a table, got {echo(value)}", table)
        return _Reader(self.source, value, self._key(key), allowed, self.scale, self.limits)

    def array_of_tables(self, key: str, allowed: tuple[str, ...], limit: str) -> list["_Reader"]:
        """One reader per ``[[key]]`` entry; at most the ``limit`` field of :class:`Limits`."""
        tables = f"[[{self._key(key)}]] entries"
        value = self._get(key, _REQUIRED, tables)
        if not isinstance(value, list) or not value or not all(isinstance(v, dict) for v in value):
            raise self.fail(key, "expected one or more tables", tables)
        if len(value) > getattr(self.limits, limit):
            raise self.fail(key, f"{len(value):,} entries", allowed_at_most(self.limits, limit))
        return [_Reader(self.source, v, f"{self._key(key)}[{i}]", allowed, self.scale, self.limits)
                for i, v in enumerate(value)]



_TOP = ("scene", "world", "body", "simulation", "plane", "contact", "chain", "sampling", "targets", "initial", "drive")
_PARTS = {"dynamics": ("world", "body", "simulation", "plane", "contact"), "kinematics": ("chain", "sampling"),
          "ik": ("chain", "targets"), "joint_dynamics": ("chain", "world", "sampling"),
          "joint_motion": ("chain", "world", "initial", "drive", "simulation")}
_SCENE = ("name", "description", "kind", "reference", "length_unit", "suites")
# Drag coefficients and the power of length in their units (for length_unit scaling).
DRAG_KEYS = {"linear_drag": 0, "quadratic_drag": -1, "angular_linear_drag": 2, "angular_quadratic_drag": 2}
_MATERIAL = ("restitution", "friction_static", "friction_kinetic")
_SHAPE = ("shape", "radius", "half_extents", "shape_center_body")
_BODY = ("name", "mass", "inertia_body_diagonal", "inertia_body", "point_mass", "position_world", "quat_wxyz",
         "velocity_world", "angular_velocity_world", "force") + tuple(DRAG_KEYS) + _SHAPE + _MATERIAL
_POINT_MASS = ("mass", "position")
_PLANE = ("name", "coefficients")
_CONTACT = ("methods", "rest_speed", "penalty_stiffness", "penalty_damping", "pair") + _MATERIAL
_PAIR = ("body", "plane") + _MATERIAL
START_INSIDE_TOLERANCE = 1e-9
"""[m] A body may start this far inside a plane (a value typed to 9 digits that puts it on the plane);
deeper is a body that starts inside the plane: an error, not an impact at t = 0."""
_FORCE = ("force_world", "point_body")
_CHAIN = ("name", "joint", "end_effector", "end_effector_xyz", "end_effector_rpy", "urdf", "base_link", "tip_link",
          "dh")
_DH = ("convention", "a", "alpha", "d", "theta_offset", "lower", "upper")
_TARGETS = ("count", "seed", "kind", "start", "position_tolerance", "orientation_tolerance", "max_iterations",
            "hard")
DEFAULT_POSITION_TOLERANCE = 1e-6  # [m], in any length unit the scene declares
PYBULLET_DATA_PREFIX = "pybullet_data:"
"""A ``urdf`` path starting with this is inside the installed pybullet_data package."""
EXAMPLE_ROBOT_DATA_PREFIX = "example-robot-data:"
"""A ``urdf`` path starting with this is inside the installed example-robot-data package's
``robots`` folder (``pip install example-robot-data``)."""
EXAMPLE_ROBOT_DATA_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"
"""Where the example-robot-data wheel keeps its robots, relative to its installation."""
_LINK = ("mass", "com_xyz", "inertia")
_JOINT = ("name", "type", "axis", "origin_xyz", "origin_rpy", "lower", "upper", "damping", "armature") + _LINK
_JOINT_DYNAMICS_SAMPLING = ("states", "seed", "velocity_scale", "acceleration_scale", "torque_scale")
_INITIAL = ("q", "qdot", "seed")
_MOTION_SIMULATION = ("duration", "dt", "integrators", "segments", "perturbation")
MAX_PERTURBATION = 1e-3
"""[rad] The largest start perturbation for predictability: at the parting threshold itself the runs would part at once."""
MAX_SEGMENTS = 1000
"""Segments of a self-consistency scene at most: each is a copy stepped twice (at dt and dt / 16)."""

# duration / dt may differ from a whole number by this much (rounding of a decimal dt).
_STEP_COUNT_RTOL = 1e-9
_MAX_SEED = 2**63 - 1
_SAMPLES_WHY = "; simparity run --max-samples N raises it"
_WHERE_URDF = (f"a URDF file relative to the scene file, or {PYBULLET_DATA_PREFIX}... or "
               f"{EXAMPLE_ROBOT_DATA_PREFIX}... inside that package")


def _body_forces(r: _Reader, index: int) -> tuple[dict, list[AppliedForce]]:
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


def _inertia(r: _Reader) -> np.ndarray:
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


def _point_masses(r: _Reader, frame_position_world: np.ndarray) -> tuple[float, np.ndarray, PointMasses]:
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


def _body(r: _Reader) -> RigidBody:
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


def _material(r: _Reader, default: Material) -> Material:
    """The restitution and friction a table sets, the others from ``default``."""
    k = r.number("restitution", default.restitution)
    if not 0.0 <= k <= 1.0:
        raise r.fail("restitution", f"{k:g} is outside [0, 1]", "0 (plastic) to 1 (elastic)")
    kinetic = r.number("friction_kinetic", default.friction_kinetic)
    static = r.number("friction_static", max(default.friction_static, kinetic) if r.has("friction_kinetic")
                      else default.friction_static)
    if min(static, kinetic) < 0:
        raise r.fail("friction_static" if static < 0 else "friction_kinetic", "is negative", "numbers >= 0")
    if kinetic > static:
        allowed = "friction_kinetic <= friction_static (sliding never grips harder than sticking)"
        if not r.has("friction_kinetic"):
            raise r.fail("friction_static", f"{static:g} is below the friction_kinetic {kinetic:g} this table inherits "
                         "([contact], or the body for a pair)", allowed)
        source = "" if r.has("friction_static") else " (inherited from [contact], or the body for a pair)"
        raise r.fail("friction_kinetic", f"{kinetic:g} exceeds friction_static {static:g}{source}", allowed)
    return Material(k, static, kinetic)


def _shape(r: _Reader, body: RigidBody) -> Shape:
    kind = r.string("shape", "points" if body.point_masses is not None else "point", choices=SHAPES)
    for key in ("radius", "half_extents", "shape_center_body"):
        needed = {"radius": "sphere", "half_extents": "box", "shape_center_body": "box"}[key]
        if r.has(key) and kind != needed:
            raise r.fail(key, f"given for a {kind} shape", f"{key} with shape = \"{needed}\" only")
    if kind == "sphere":
        return Shape("sphere", radius=r.number("radius", positive=True, length=1))
    if kind == "box":
        return Shape("box", half_extents_body=r.vector("half_extents", 3, length=1, positive=True),
                     center_body=r.vector("shape_center_body", 3, [0.0] * 3, length=1))
    if kind == "points":
        if body.point_masses is None:
            raise r.fail("shape", "\"points\" needs the body's [[body.point_mass]] entries",
                         "point, sphere, box; points for a body built from point masses")
        return Shape("points", points_body=body.point_masses.points_body)
    return Shape("point")


_CONTACT_KEYS = _SHAPE + _MATERIAL


def _contact(top: _Reader, readers: list[_Reader], bodies: tuple[RigidBody, ...]) -> Contact | None:
    """The scene's planes and contact parameters, or None when it has no [[plane]]."""
    if not top.has("plane"):
        for key in ("contact",):
            if top.has(key):
                raise top.fail(key, "contact settings without a [[plane]]", "[[plane]] entries to collide with")
        for r in readers:
            for key in _CONTACT_KEYS:
                if r.has(key):
                    raise r.fail(key, "a contact property, but the scene has no [[plane]] to touch",
                                 "[[plane]] entries, or no shape and material keys")
        return None
    planes: list[Plane] = []
    for p in top.array_of_tables("plane", _PLANE, "max_bodies"):
        abcd = p.vector("coefficients", 4)
        length = safe_norm(abcd[:3])
        if not (length > 0 and np.isfinite(length)):
            raise p.fail("coefficients", "the normal (a, b, c) is all zeros", "[a, b, c, d] with (a, b, c) != 0")
        scaled = abcd / np.max(np.abs(abcd[:3]))  # the same plane, its normal's largest entry 1: no overflow
        offset = scaled[3] / float(np.linalg.norm(scaled[:3])) * p.scale  # the plane's distance from the origin
        if not RANGES["position_world"].allows(abs(offset)):
            raise p.fail("coefficients", f"the plane lies {abs(offset):.3g} m from the origin",
                         RANGES["position_world"].text())
        planes.append(Plane(scaled[:3], scaled[3] * p.scale, p.name("name", f"plane{len(planes)}")))
    names = [plane.name for plane in planes]
    if len(set(names)) != len(names):
        raise top.fail("plane", f"the plane name {next(n for i, n in enumerate(names) if n in names[:i])!r} repeats",
                       "distinct names")
    c = top.optional_subtable("contact", _CONTACT) or _Reader(top.source, {}, "contact", _CONTACT, top.scale,
                                                                     top.limits)
    default = _material(c, Material())
    shapes = tuple(_shape(r, body) for r, body in zip(readers, bodies))
    materials = [[_material(r, default)] * len(planes) for r in readers]
    if c.has("pair"):
        for pair in c.array_of_tables("pair", _PAIR, "max_bodies"):
            body = pair.string("body", choices=tuple(b.name for b in bodies))
            plane = pair.string("plane", choices=tuple(names))
            i, j = [b.name for b in bodies].index(body), names.index(plane)
            materials[i][j] = _material(pair, materials[i][j])
    contact = Contact(
        planes=tuple(planes), shapes=shapes, materials=tuple(tuple(row) for row in materials),
        methods=c.strings("methods", CONTACT_METHODS, "no contact method {}") if c.has("methods") else CONTACT_METHODS,
        rest_speed=c.number("rest_speed", 1e-3, positive=True, length=1),
        penalty_stiffness=c.number("penalty_stiffness", 1e5, positive=True),
        penalty_damping=c.number("penalty_damping") if c.has("penalty_damping") else None,
    )
    if contact.penalty_damping is not None and contact.penalty_damping < 0:
        raise c.fail("penalty_damping", "is negative", "numbers >= 0")
    _check_start_outside(top, contact, bodies)
    return contact


def _check_start_outside(top: _Reader, contact: Contact, bodies: tuple[RigidBody, ...]) -> None:
    """Every body starts on the free side of every plane (within :data:`START_INSIDE_TOLERANCE`)."""
    for i, (body, shape) in enumerate(zip(bodies, contact.shapes)):
        rotation = quat_wxyz_to_matrix(body.quat_wxyz)
        vertices = body.position_world + shape.vertices_body() @ rotation.T
        for plane in contact.planes:
            depth = -(float((vertices @ plane.normal_world + plane.offset).min()) - shape.radius)
            if depth > START_INSIDE_TOLERANCE:
                raise top.fail(f"body[{i}].position_world", f"body {body.name!r} starts {depth:.3g} m inside plane "
                               f"{plane.name!r}", "every body on the free side (E >= 0) of every plane at t = 0")


def _dynamics(top: _Reader, head: dict, engines: EngineSet) -> DynamicsScene:
    world = top.optional_subtable("world", ("gravity_world", "air_velocity_world"))
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    air = world.vector("air_velocity_world", 3, length=1) if world and world.has("air_velocity_world") else None
    readers = top.array_of_tables("body", _BODY, "max_bodies")
    bodies = tuple(_body(r) for r in readers)
    per_body = [_body_forces(r, i) for i, r in enumerate(readers)]
    drag = {
        key: np.array([d.get(key, 0.0) for d, _ in per_body]) if any(key in d for d, _ in per_body) else None
        for key in DRAG_KEYS
    }
    if world is not None and air is not None and drag["linear_drag"] is None and drag["quadratic_drag"] is None:
        raise world.fail("air_velocity_world", "wind needs a body with linear_drag or quadratic_drag to act on",
                         "wind with a drag on some body, or no air_velocity_world")
    forces = Forces(gravity_world=gravity, air_velocity_world=air,
                    applied=tuple(a for _, applied in per_body for a in applied), **drag)
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        repeated = next(n for i, n in enumerate(names) if n in names[:i])
        raise top.fail("body", f"the body name {repeated!r} repeats", "distinct names")
    contact = _contact(top, readers, bodies)
    sim = top.subtable("simulation", ("duration", "dt", "rate_hz", "integrators"))
    duration = sim.number("duration", positive=True)
    if sim.has("dt") == sim.has("rate_hz"):
        raise sim.fail("dt", "give exactly one of dt and rate_hz", "dt = [time steps in s] or rate_hz = [steps per s]")
    dts = _ladder(sim, duration, len(bodies))
    integrators = _integrators(sim, engines) if sim.has("integrators") else ()
    return DynamicsScene(bodies=bodies, forces=forces, duration=duration, dts=dts, integrators=integrators,
                         contact=contact, **head)


def _integrators(sim: _Reader, engines: EngineSet) -> tuple[str, ...]:
    """The integrators a scene names, each offered by some engine: a built-in or one of the command's
    ``engines``, else an installed plugin (asked only then)."""
    named, choices = sim.table["integrators"], engines.integrators
    if isinstance(named, list) and any(isinstance(n, str) and n not in choices for n in named):
        choices = engines.installed_integrators
    return sim.strings("integrators", choices, "no engine has an integrator {}")


def _ladder(sim: _Reader, duration: float, n_bodies: int) -> tuple[float, ...]:
    """The time steps [s]: each a whole number of steps of the duration, no two with the same
    number of steps, each within the step limit."""
    key = "dt" if sim.has("dt") else "rate_hz"
    values = sim.numbers(key)
    if len(values) > sim.limits.max_dts:
        raise sim.fail(key, f"{len(values)} time steps", allowed_at_most(sim.limits, "max_dts"))
    dts = values if key == "dt" else tuple(1.0 / h for h in values)
    counts: dict[int, int] = {}
    for i, dt in enumerate(dts):
        steps = duration / dt  # finite: both are inside their ranges
        if dt > duration or abs(steps - round(steps)) > _STEP_COUNT_RTOL * steps:
            raise sim.fail(f"{key}[{i}]", f"duration {duration:g} s is not a whole number of steps of {dt:g} s",
                           "time steps that divide the duration")
        if round(steps) in counts:
            raise sim.fail(f"{key}[{i}]", f"{values[i]:.17g} gives the same {round(steps):,} steps as "
                           f"{key}[{counts[round(steps)]}]", "distinct time steps")
        counts[round(steps)] = i
        if steps * n_bodies > sim.limits.max_steps:
            raise sim.fail(f"{key}[{i}]", f"{steps:,.0f} steps x {n_bodies} bodies = {steps * n_bodies:,.0f} body-steps "
                           f"at {dt:g} s", allowed_at_most(sim.limits, "max_steps", "per time step"))
    return dts


def _joint(r: _Reader, before: tuple[str, ...]) -> Joint:
    """One ``[[chain.joint]]``; ``before``: the names of the joints before it (its branch from the base)."""
    name = r.name("name")
    where = f"joint {name!r} on the branch {' > '.join(('base',) + before + (name,))}"
    kind = r.string("type", choices=JOINT_TYPES)
    length = 1 if kind == "prismatic" else 0
    if r.has("lower") != r.has("upper"):
        raise r.fail("lower" if not r.has("lower") else "upper", "missing: limits need both lower and upper",
                     "both lower and upper, or neither for an unlimited joint")
    lower = r.number("lower", length=length) if r.has("lower") else -np.inf
    upper = r.number("upper", length=length) if r.has("upper") else np.inf
    if lower > upper:  # lower == upper: a joint held at that value where limits act (as in a URDF)
        raise r.fail("upper", f"upper {upper:g} is below lower {lower:g} ({where})", "lower <= upper")
    # damping [N m s/rad = kg m^2/s] or [N s/m = kg/s], armature [kg m^2] or [kg]: length^2 or length^0
    power = 0 if kind == "prismatic" else 2
    damping = r.number("damping", 0.0, length=power) if r.has("damping") else 0.0
    armature = r.number("armature", 0.0, length=power) if r.has("armature") else 0.0
    for key, value in (("damping", damping), ("armature", armature)):
        if value < 0:
            raise r.fail(key, f"{value:g} is negative ({where})", "a number >= 0 (0: none)")
    rpy = r.vector("origin_rpy", 3, [0.0] * 3)
    return Joint(
        name=name, type=kind, axis=r.vector("axis", 3, nonzero=True),
        origin_xyz=r.vector("origin_xyz", 3, [0.0] * 3, length=1), origin_rotation=rpy_to_matrix(rpy),
        lower=lower, upper=upper, link=_link(r, where), damping=damping, armature=armature, origin_rpy=rpy,
    )


def _link(r: _Reader, where: str) -> LinkInertia | None:
    """The mass properties of a ``[[chain.joint]]``'s child link: all of mass, com_xyz, inertia, or none. The same
    rules as a URDF's ``<inertial>`` (:func:`core.urdf.chain_from_urdf`): a mass of 0 with a non-zero inertia loads
    (a rotor's inertia whose mass is counted elsewhere: real URDFs have it, and every engine keeps it as written);
    the tensor's rounding is judged against the link's own scale (:func:`core.dynamics.inertia.link_tensor_problem`).
    ``where`` (the joint's name and branch) ends every message."""
    given = [key for key in _LINK if r.has(key)]
    if not given:
        return None
    if len(given) != len(_LINK):
        missing = next(key for key in _LINK if key not in given)
        raise r.fail(missing, f"missing: {', '.join(given)} given without it ({where})",
                     "all of mass [kg], com_xyz [length] and inertia (3 x 3 about the centre of mass, in the link's "
                     "axes) or none (a chain for kinematics only)")
    massless = r.table.get("mass") == 0  # a massless link, as a URDF link without <inertial> or with mass 0
    mass = 0.0 if massless else r.number("mass", positive=True)
    inertia = r.matrix("inertia", 3, length=2)
    largest, moments = float(np.max(np.abs(inertia))), RANGES["inertia_moment"]
    if largest > moments.high:
        raise r.fail("inertia", f"an entry of {largest:.3g} kg m^2 is outside the physical range ({where})",
                     moments.text())
    com = r.vector("com_xyz", 3, length=1)
    problem = link_tensor_problem(inertia, mass, com)
    if problem:
        raise r.fail("inertia", f"{problem} ({where})", LINK_TENSOR_RULE)
    return LinkInertia(mass, com, inertia)


def _package_root(c: _Reader, prefix: str) -> Path:
    """The folder a prefixed ``urdf`` path is relative to."""
    if prefix == PYBULLET_DATA_PREFIX:
        import pybullet_data  # data files only; ships with pybullet

        return Path(pybullet_data.getDataPath())
    from importlib import metadata

    try:
        robots = metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)
    except metadata.PackageNotFoundError:
        raise c.fail("urdf", "the example-robot-data package is not installed",
                     "pip install example-robot-data, or the path of a URDF file") from None
    return Path(str(robots))


def _urdf_path(c: _Reader) -> Path:
    """The URDF file a scene names: relative to the scene file, absolute, or inside a package."""
    text = c.string("urdf")
    prefix = next((p for p in (PYBULLET_DATA_PREFIX, EXAMPLE_ROBOT_DATA_PREFIX) if text.startswith(p)), None)
    if prefix:
        root = _package_root(c, prefix)
        path = root / text[len(prefix):]
        if not os.path.realpath(path).startswith(os.path.realpath(root) + os.sep):
            raise c.fail("urdf", f"{echo(text)} leaves the {prefix[:-1]} package", _WHERE_URDF)
    else:
        path = Path(os.path.abspath(Path(c.source).parent / text))  # absolute: the same file however the scene was named
    problem = file_problem(path, "URDF file")
    if problem:
        raise c.fail("urdf", f"{problem}: {one_line(path)}", _WHERE_URDF)
    return path


def _urdf_chain(c: _Reader, dynamics: bool) -> Chain:
    """The chain of a ``urdf`` scene; an error in the URDF names the scene file, and the URDF as the scene does."""
    base, tip = (c.name(key) if c.has(key) else None for key in ("base_link", "tip_link"))
    path = _urdf_path(c)
    try:
        return chain_from_urdf(str(path), base_link=base, tip_link=tip, max_joints=c.limits.max_joints,
                               max_bytes=c.limits.max_file_bytes, dynamics=dynamics)
    except SceneError as err:
        raise c.fail("urdf", f"{one_line(c.table['urdf'], 120)}: {err.key}: {err.problem}", err.allowed) from None


def _dh_chain(c: _Reader, name: str) -> Chain:
    dh = c.subtable("dh", _DH)
    convention = dh.string("convention", "standard", choices=("standard", "modified"))
    columns = {key: dh.table.get(key) for key in ("a", "alpha", "d", "theta_offset")}
    size = len(columns["a"]) if isinstance(columns["a"], list) else 0
    if size < 1:
        raise dh.fail("a", "expected a non-empty list of numbers", "one number per joint")
    if size > dh.limits.max_joints:
        raise dh.fail("a", f"{size:,} joints", allowed_at_most(dh.limits, "max_joints"))
    values = {key: dh.vector(key, size, [0.0] * size if key == "theta_offset" else None,
                             length=1 if key in ("a", "d") else 0) for key in columns}
    limits = None
    if dh.has("lower") or dh.has("upper"):
        limits = np.stack([dh.vector("lower", size), dh.vector("upper", size)], axis=1)
        bad = np.flatnonzero(limits[:, 0] > limits[:, 1])
        if bad.size:
            raise dh.fail(f"upper[{bad[0]}]", f"the upper limit of joint {bad[0]} is below its lower limit (branch "
                          f"{' > '.join(f'joint {i}' for i in range(bad[0] + 1))})", "lower <= upper for every joint")
    table = DHTable(convention, **values)  # the numbers as given, for the references (core derives the frames)
    return replace(chain_from_dh(name, convention=convention, limits=limits, **values), dh=table)


def _chain(top: _Reader, name: str, dynamics: bool = False) -> Chain:
    """The scene's ``[chain]``; for ``dynamics``, a URDF's inertia tensors must be physical."""
    c = top.subtable("chain", _CHAIN)
    sources = [key for key in ("joint", "urdf", "dh") if c.has(key)]
    if len(sources) != 1:
        raise c.fail("joint", f"give exactly one chain source, got {sources or 'none'}",
                     "one of [[chain.joint]], urdf, [chain.dh]")
    if sources == ["urdf"]:
        return _urdf_chain(c, dynamics)
    if sources == ["dh"]:
        return _dh_chain(c, c.name("name", name))
    joints: tuple[Joint, ...] = ()
    for r in c.array_of_tables("joint", _JOINT, "max_joints"):
        joints += (_joint(r, tuple(joint.name for joint in joints)),)
    names = [j.name for j in joints]
    end_effector = c.name("end_effector", "end_effector")
    if len(set(names + [end_effector])) != len(names) + 1:
        repeated = next(n for i, n in enumerate(names + [end_effector]) if n in names[:i])
        raise c.fail("joint", f"the name {repeated!r} is given to two frames", "distinct joint and end-effector names")
    tip_rpy = c.vector("end_effector_rpy", 3, [0.0] * 3)
    return Chain(
        name=c.name("name", name), joints=joints, end_effector_name=end_effector,
        end_effector_xyz=c.vector("end_effector_xyz", 3, [0.0] * 3, length=1),
        end_effector_rotation=rpy_to_matrix(tip_rpy), end_effector_rpy=tip_rpy,
    )


def _kinematics(top: _Reader, head: dict) -> KinematicsScene:
    chain = _chain(top, head["name"])
    sampling = top.optional_subtable("sampling", ("configurations", "seed"))
    limit = top.limits.max_samples
    n = sampling.integer("configurations", 100, minimum=1, maximum=limit, why=_SAMPLES_WHY) if sampling else 100
    seed = sampling.integer("seed", 0, maximum=_MAX_SEED) if sampling else 0
    return KinematicsScene(chain=chain, n_configurations=n, seed=seed, **head)


def _joint_dynamics(top: _Reader, head: dict) -> JointDynamicsScene:
    chain = _dynamics_chain(top, head)
    world = top.optional_subtable("world", ("gravity_world",))
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    sampling = top.optional_subtable("sampling", _JOINT_DYNAMICS_SAMPLING)
    limit = top.limits.max_samples
    count = sampling.integer("states", 100, minimum=1, maximum=limit, why=_SAMPLES_WHY) if sampling else 100
    seed = sampling.integer("seed", 0, maximum=_MAX_SEED) if sampling else 0
    velocity, acceleration, torque = (sampling.number(key, 1.0, positive=True) if sampling and sampling.has(key)
                                      else 1.0 for key in _JOINT_DYNAMICS_SAMPLING[2:])
    return JointDynamicsScene(chain=chain, gravity_world=gravity, n_states=count, seed=seed, velocity_scale=velocity,
                              acceleration_scale=acceleration, torque_scale=torque, **head)


def _dynamics_chain(top: _Reader, head: dict) -> Chain:
    """The ``[chain]`` of a joint-dynamics or joint-motion scene: every link with mass properties."""
    chain = _chain(top, head["name"], dynamics=True)
    problem = chain.dynamics_problem()
    if problem:
        raise top.fail("chain", problem, "a chain whose every link has mass properties: a URDF file with <inertial> "
                       "elements or [[chain.joint]] with mass, com_xyz and inertia ([chain.dh] declares none)")
    return chain


def _joint_powers(chain: Chain, revolute: int, prismatic: int) -> np.ndarray:
    """(n,) the power of length in each joint's unit of a quantity (revolute and prismatic joints differ)."""
    return np.array([revolute if j.type == "revolute" else prismatic for j in chain.joints], dtype=float)


def _joint_values(r: _Reader, key: str, chain: Chain, powers: np.ndarray, default: float | None = 0.0) -> np.ndarray:
    """(n,) one number per joint in the scene's length unit (scaled joint by joint by ``powers``)."""
    values = r.vector(key, chain.n_joints, None if default is None else [default] * chain.n_joints) * r.scale ** powers
    return np.array([r._in_range(f"{key}[{i}]", float(v)) for i, v in enumerate(values)])


def _within_limits(r: _Reader, key: str, chain: Chain, q: np.ndarray) -> np.ndarray:
    """``q`` (n,), refused naming ``key`` and the first joint outside its limits."""
    outside = np.flatnonzero((q < chain.lower) | (q > chain.upper))
    if outside.size:
        joint = chain.joints[outside[0]]
        raise r.fail(key, f"joint {joint.name} starts outside its limits",
                     f"values within [{joint.lower:g}, {joint.upper:g}] for {joint.name}")
    return q


def _initial_q(r: _Reader, chain: Chain) -> np.ndarray:
    """(n,) the initial joint values: a list, "zeros" or "random" (uniform within the limits, ``seed``)."""
    value = r.table.get("q", "zeros")
    if value == "zeros":
        q = np.zeros(chain.n_joints)
    elif value == "random":
        q = sample_configurations(chain, 1, r.integer("seed", 0, maximum=_MAX_SEED))[0]
    elif isinstance(value, list):
        q = _joint_values(r, "q", chain, _joint_powers(chain, 0, 1), None)
    else:
        raise r.fail("q", f"{echo(value)} is not allowed", f'"zeros", "random" or a list of {chain.n_joints} numbers')
    return _within_limits(r, "q", chain, q)


def _with_damping(drive: _Reader, chain: Chain) -> Chain:
    """``chain`` with the joint damping ``[drive] damping`` gives: one number for every joint or one per joint
    [N m s/rad = kg m^2/s, or N s/m = kg/s], >= 0."""
    value = drive.table["damping"]
    if not isinstance(value, list):
        drive.table = dict(drive.table, damping=[value] * chain.n_joints)
    damping = _joint_values(drive, "damping", chain, _joint_powers(chain, 2, 0))
    if np.any(damping < 0):
        raise drive.fail("damping", f"a negative damping {float(damping.min()):g}", "numbers >= 0 (N m s/rad or N s/m)")
    return replace(chain, joints=tuple(replace(j, damping=float(d)) for j, d in zip(chain.joints, damping)))


def _joint_motion(top: _Reader, head: dict, engines: EngineSet) -> JointMotionScene:
    chain = _dynamics_chain(top, head)
    world = top.optional_subtable("world", ("gravity_world",))
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    initial = top.optional_subtable("initial", _INITIAL) or _Reader(top.source, {}, "initial", _INITIAL, top.scale,
                                                                    top.limits)
    q0 = _initial_q(initial, chain)
    qdot0 = _joint_values(initial, "qdot", chain, _joint_powers(chain, 0, 1))
    drive = top.optional_subtable("drive", ("torque", "damping"))
    torque = (_joint_values(drive, "torque", chain, _joint_powers(chain, 2, 1)) if drive
              else np.zeros(chain.n_joints))  # N m = kg m^2 / s^2 (mass and time fixed) or N = kg m / s^2
    if drive and drive.has("damping"):  # replaces the chain's own (a URDF's <dynamics damping>)
        chain = _with_damping(drive, chain)
    sim = top.subtable("simulation", _MOTION_SIMULATION)
    duration = sim.number("duration", positive=True)
    dts = _ladder(sim, duration, 1)
    segments = sim.integer("segments", 0, maximum=MAX_SEGMENTS, why="") if sim.has("segments") else 0
    for i, dt in enumerate(dts if segments else ()):  # each segment a whole number of every step
        steps = duration / segments / dt
        if abs(steps - round(steps)) > _STEP_COUNT_RTOL * max(steps, 1.0) or round(steps) < 1:
            raise sim.fail("segments", f"{segments} segments of {duration / segments:g} s are not a whole number of "
                           f"steps of dt[{i}] = {dt:g} s", "a count of segments each a whole number of every dt")
    perturbation = sim.number("perturbation", 0.0) if sim.has("perturbation") else 0.0  # rad (a prismatic joint: m)
    if not 0 <= perturbation <= MAX_PERTURBATION:
        raise sim.fail("perturbation", f"{perturbation:g} is out of range",
                       f"0 (none) to {MAX_PERTURBATION:g} rad: a small change of the start, for predictability")
    integrators = (sim.strings("integrators", engines.joint_motion_integrators, "no engine steps a chain with {}")
                   if sim.has("integrators") else ())
    return JointMotionScene(chain=chain, gravity_world=gravity, q0=q0, qdot0=qdot0, torque=torque,
                            duration=duration, dts=dts, integrators=integrators, segments=segments,
                            perturbation=perturbation, **head)


def _start(t: _Reader, chain: Chain) -> np.ndarray:
    """The start pose: "zeros", "mid-range" (limits' middle, 0 where unlimited) or a list."""
    value = t.table.get("start", "zeros")
    allowed = f'"zeros", "mid-range" or a list of {chain.n_joints} numbers'
    if isinstance(value, list):
        prismatic = np.array([j.type == "prismatic" for j in chain.joints])
        q = t.vector("start", chain.n_joints) * np.where(prismatic, t.scale, 1.0)  # lengths in the scene's unit
    elif value in ("zeros", "mid-range"):
        limited = np.isfinite(chain.lower) & np.isfinite(chain.upper)  # continuous joints: 0, no inf - inf
        middle = 0.5 * np.where(limited, chain.lower, 0.0) + 0.5 * np.where(limited, chain.upper, 0.0)
        q = np.zeros(chain.n_joints) if value == "zeros" else middle
    else:
        raise t.fail("start", f"{echo(value)} is not allowed", allowed)
    return _within_limits(t, "start", chain, q)


def _position_tolerance(t: _Reader, chain: Chain) -> float:
    """[m]; in its physical range and at most :data:`POSITION_TOLERANCE_OF_REACH` of the chain's reach."""
    if not t.has("position_tolerance"):
        return DEFAULT_POSITION_TOLERANCE
    value = t.number("position_tolerance", positive=True, length=1)
    most = POSITION_TOLERANCE_OF_REACH * reach_upper_bound(chain)[1]
    if value > most:
        raise t.fail("position_tolerance", f"{value:.3g} m is more than a tenth of the chain's reach: misses that "
                     "large would count as solved",
                     f"at most {POSITION_TOLERANCE_OF_REACH:g} x the chain's reach = {most:.3g} m")
    return value


def _ik(top: _Reader, head: dict) -> IKScene:
    chain = _chain(top, head["name"])
    t = top.subtable("targets", _TARGETS)
    count = t.integer("count", 100, minimum=1, maximum=t.limits.max_samples, why=_SAMPLES_WHY)
    iterations = t.integer("max_iterations", 200, minimum=1, maximum=t.limits.max_iterations)
    if count * iterations > t.limits.max_steps:
        raise t.fail("max_iterations", f"{count:,} targets x {iterations:,} iterations = {count * iterations:,} solver "
                     "iterations at worst", allowed_at_most(t.limits, "max_steps", "per solver"))
    return IKScene(
        chain=chain, n_targets=count, seed=t.integer("seed", 0, maximum=_MAX_SEED),
        target_kind=t.string("kind", "pose", choices=("pose", "position")), q_start=_start(t, chain),
        position_tolerance=_position_tolerance(t, chain),
        orientation_tolerance=t.number("orientation_tolerance", 1e-6, positive=True),
        max_iterations=iterations, hard_targets=t.strings("hard", HARD_TARGETS, "unknown hard target {}") if t.has("hard") else (), **head,
    )


def _check_reference(top: _Reader, scene, engines: EngineSet) -> None:
    """A reference that cannot do the scene (as its engine's ``supports_*`` says) is an error now, not a run of n/a
    rows; so is core as the reference of a contact scene that does not run its exact method, backup."""
    contact = getattr(scene, "contact", None)
    if scene.reference == "core":
        if contact is not None and "backup" not in contact.methods:
            raise top.fail("scene.reference", "core is the reference, but the scene's contact methods leave out "
                           "backup, its exact one", 'contact.methods with "backup", or another reference')
        return
    from simparity.comparisons.engines.placeholders import UnavailableEngine

    engine = engines.reference(scene.reference)
    if isinstance(engine, UnavailableEngine):  # its library is missing here: the run's rows say so
        return
    if isinstance(scene, DynamicsScene):
        integrators = engine.integrators()
        support = engine.supports_dynamics(scene, integrators[0]) if integrators else Support.no("it offers no integrator")
    elif isinstance(scene, JointMotionScene):
        integrator = motion_reference_integrator(scene, engine)
        support = (engine.supports_joint_motion(scene, integrator) if integrator != NO_INTEGRATOR
                   else Support.no("it steps no chain through time"))
    elif isinstance(scene, JointDynamicsScene):
        methods = engine.joint_dynamics_methods()
        support = (engine.supports_joint_dynamics(scene.chain, methods[0]) if methods
                   else Support.no("it computes no joint-space dynamics"))
    else:
        support = engine.supports_kinematics(scene.chain)
    if not support.ok:
        allowed = ("a reference that can: core (its backup method), mujoco or pybullet for contact" if contact is not None
                   else "a reference that computes joint-space dynamics: pinocchio, mujoco, core, or analytic for a "
                        "planar chain of 1 or 2 joints" if isinstance(scene, JointDynamicsScene)
                   else "a reference that steps chains: pinocchio (its DOP853 solve), or analytic for a pendulum or a "
                        "single damped joint" if isinstance(scene, JointMotionScene)
                   else "a reference that can: core, mujoco, pybullet, pinocchio, or tight for dynamics without a "
                        "closed form")
        raise top.fail("scene.reference", f"{scene.reference} cannot serve this scene: {support.reason}", allowed)


def parse_scene(data: dict, source: str = "<scene>", limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None):
    """Build a scene from parsed TOML ``data``; ``source`` names it in error messages. Data with a ``[sweep]``
    is several scenes: :func:`parse_scenes`."""
    if SWEEP_TABLE in data:
        raise SceneError(source, SWEEP_TABLE, "the file sweeps keys: it is several scenes, not one",
                         "load_scenes or parse_scenes (comparisons.scene_loader), library.load, simparity.load_scenes "
                         "or simparity run FILE, which expand it into its variants")
    try:
        return _parse(data, source, limits, engines or EngineSet())
    except SceneError as err:
        if err.source != "<code>":
            raise
        # raised by the data model itself (core.scene): name the file it came from
        raise SceneError(source, err.key, err.problem, err.allowed) from None


def _parse(data: dict, source: str, limits: Limits, engines: EngineSet):
    top = _Reader(source, data, "", _TOP, 1.0, limits)
    s = top.subtable("scene", _SCENE)
    unit = s.string("length_unit", "m", choices=tuple(LENGTH_UNITS))
    kind = s.string("kind", choices=KINDS)
    head = dict(
        name=s.name("name"), description=s.text("description", ""),
        reference=s.string("reference", choices=ENGINE_NAMES), source=source,
        suites=s.strings("suites", SUITES, "there is no suite {}") if s.has("suites") else ("default",),
    )
    top.scale = LENGTH_UNITS[unit]
    for key in _TOP[1:]:
        if top.has(key) and key not in _PARTS[kind]:
            raise top.fail(key, f"not part of a {kind} scene", ", ".join(("scene",) + _PARTS[kind]))
    scene: Scene
    if kind == "dynamics":
        scene = _dynamics(top, dict(head, length_unit=unit), engines)
    elif kind == "joint_motion":
        scene = _joint_motion(top, head, engines)
    else:
        readers: dict[str, Callable[[_Reader, dict], Scene]] = {"kinematics": _kinematics, "ik": _ik,
                                                                  "joint_dynamics": _joint_dynamics}
        scene = readers[kind](top, head)
    _check_reference(top, scene, engines)
    return scene


def parse_scenes(data: dict, source: str = "<scene>", limits: Limits = DEFAULT_LIMITS,
                 engines: EngineSet | None = None) -> list:
    """The scenes of parsed TOML ``data``: the one it describes, or the variants of its ``[sweep]`` in the
    sweep's order. The file without its ``[sweep]`` must be a valid scene; each variant is checked like a file
    written by hand with its values, and an error in one names the sweep key and value
    (:meth:`comparisons.sweep.Sweep.refusal`)."""
    if SWEEP_TABLE not in data:
        return [parse_scene(data, source, limits, engines)]
    engines = engines or EngineSet()  # one for every variant: a plugin or a reference is asked once
    base_data = {key: value for key, value in data.items() if key != SWEEP_TABLE}
    base = parse_scene(base_data, source, limits, engines)
    sweep = read_sweep(data[SWEEP_TABLE], base_data, source, base.name)
    scenes = []
    for name, variant, point in sweep.variants(base_data):
        try:
            scene = parse_scene(variant, source, limits, engines)
        except SceneError as err:
            raise sweep.refusal(err, point) from None
        scenes.append(replace(scene, name=name, sweep=point))
    return scenes


def load_scenes(path: str | Path, limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None) -> list:
    """Read and check one scene file (a regular file of at most ``limits.max_file_bytes``): its scene, or the
    variants of its ``[sweep]``."""
    source = str(path)
    return parse_scenes(read_toml(source, limits.max_file_bytes, "scene file"), source, limits, engines)


def load_scene(path: str | Path, limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None):
    """Read and check one scene file without a ``[sweep]`` (a file with one: :func:`load_scenes`)."""
    source = str(path)
    return parse_scene(read_toml(source, limits.max_file_bytes, "scene file"), source, limits, engines)
