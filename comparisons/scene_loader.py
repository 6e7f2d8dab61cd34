"""Scene files (TOML) -> :class:`core.scene.DynamicsScene` / :class:`core.scene.KinematicsScene`.

Every value is checked; a bad one raises :class:`core.errors.SceneError` naming the file,
the key path, what was wrong and what is allowed. The format is documented in
``docs/scenes.md``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from comparisons.engines import ENGINE_NAMES
from core.errors import SceneError
from core.inertia import inertia_problem
from core.rotations import rpy_to_matrix
from core.scene import Chain, DynamicsScene, Forces, Joint, KinematicsScene, RigidBody

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "ft": 0.3048, "in": 0.0254}
"""Units a scene may declare for lengths, and their size in metres."""

KINDS = ("dynamics", "kinematics")
JOINT_TYPES = ("revolute", "prismatic")

_REQUIRED = object()  # marks a key without a default


class _Reader:
    """Typed access to one table of a scene file, with key paths for error messages."""

    def __init__(self, source: str, table: dict, path: str, allowed: tuple[str, ...], length_scale: float) -> None:
        self.source, self.table, self.path, self.scale = source, table, path, length_scale
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            raise SceneError(source, self._key(unknown[0]), "unknown key", ", ".join(allowed))

    def _key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def fail(self, key: str, problem: str, allowed: str = "") -> SceneError:
        return SceneError(self.source, self._key(key), problem, allowed)

    def has(self, key: str) -> bool:
        return key in self.table

    def _get(self, key: str, default):
        if key in self.table:
            return self.table[key]
        if default is _REQUIRED:
            raise self.fail(key, "missing required key")
        return default

    def string(self, key: str, default=None, choices: tuple[str, ...] | None = None) -> str:
        value = self._get(key, _REQUIRED if default is None else default)
        if not isinstance(value, str) or not value:
            raise self.fail(key, f"expected a non-empty string, got {value!r}")
        if choices and value not in choices:
            raise self.fail(key, f"'{value}' is not allowed", ", ".join(choices))
        return value

    def _checked(self, key: str, value, positive: bool) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"expected a number, got {value!r}")
        if not math.isfinite(value):
            raise self.fail(key, f"{value} is not finite", "finite numbers")
        if positive and value <= 0:
            raise self.fail(key, f"{value} is not positive", "numbers > 0")
        return float(value)

    def number(self, key: str, default=None, *, positive=False, length=0) -> float:
        value = self._get(key, _REQUIRED if default is None else default)
        return self._checked(key, value, positive) * self.scale**length

    def integer(self, key: str, default=None, *, minimum=0) -> int:
        value = self._get(key, _REQUIRED if default is None else default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"expected a whole number, got {value!r}")
        if value < minimum:
            raise self.fail(key, f"{value} is too small", f"whole numbers >= {minimum}")
        return value

    def vector(self, key: str, size: int, default=None, *, length=0, nonzero=False, positive=False) -> np.ndarray:
        value = self._get(key, _REQUIRED if default is None else default)
        if not isinstance(value, list) or len(value) != size:
            got = f"{len(value)} values" if isinstance(value, list) else repr(value)
            raise self.fail(key, f"expected a list of {size} numbers, got {got}")
        out = np.array([self._checked(f"{key}[{i}]", v, positive) for i, v in enumerate(value)])
        out *= self.scale**length
        if nonzero and not np.any(out):
            raise self.fail(key, "is all zeros", "a vector with a non-zero entry")
        return out

    def matrix(self, key: str, size: int, *, length=0) -> np.ndarray:
        rows = self._get(key, _REQUIRED)
        if not isinstance(rows, list) or len(rows) != size:
            raise self.fail(key, f"expected {size} rows of {size} numbers")
        for i, row in enumerate(rows):
            if not isinstance(row, list) or len(row) != size:
                raise self.fail(f"{key}[{i}]", f"expected a list of {size} numbers, got {row!r}")
        values = [[self._checked(f"{key}[{i}][{j}]", v, False) for j, v in enumerate(row)] for i, row in enumerate(rows)]
        return np.array(values) * self.scale**length

    def numbers(self, key: str) -> tuple[float, ...]:
        """A non-empty list of positive numbers."""
        value = self._get(key, _REQUIRED)
        if not isinstance(value, list) or not value:
            raise self.fail(key, f"expected a non-empty list of numbers, got {value!r}")
        return tuple(self._checked(f"{key}[{i}]", v, True) for i, v in enumerate(value))

    def subtable(self, key: str, allowed: tuple[str, ...], required: bool = True) -> "_Reader | None":
        if key not in self.table:
            if required:
                raise self.fail(key, "missing required table")
            return None
        value = self.table[key]
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a table, got {value!r}")
        return _Reader(self.source, value, self._key(key), allowed, self.scale)

    def array_of_tables(self, key: str, allowed: tuple[str, ...]) -> list["_Reader"]:
        value = self._get(key, _REQUIRED)
        if not isinstance(value, list) or not value or not all(isinstance(v, dict) for v in value):
            raise self.fail(key, "expected one or more tables", f"[[{self._key(key)}]] entries")
        return [_Reader(self.source, v, f"{self._key(key)}[{i}]", allowed, self.scale) for i, v in enumerate(value)]



_TOP = ("scene", "world", "body", "simulation", "chain", "sampling")
_SCENE = ("name", "description", "kind", "reference", "length_unit")
_BODY = ("name", "mass", "inertia_body_diagonal", "inertia_body", "position_world", "quat_wxyz",
         "velocity_world", "angular_velocity_world")
_CHAIN = ("name", "joint", "end_effector", "end_effector_xyz", "end_effector_rpy")
_JOINT = ("name", "type", "axis", "origin_xyz", "origin_rpy", "lower", "upper")

# duration / dt may differ from a whole number by this much (rounding of a decimal dt).
_STEP_COUNT_RTOL = 1e-9


def _body(r: _Reader) -> RigidBody:
    if r.has("inertia_body_diagonal") == r.has("inertia_body"):
        raise r.fail("inertia_body_diagonal", "give exactly one of inertia_body_diagonal and inertia_body")
    if r.has("inertia_body"):
        inertia = r.matrix("inertia_body", 3, length=2)
    else:
        inertia = np.diag(r.vector("inertia_body_diagonal", 3, length=2, positive=True))
    problem = inertia_problem(inertia)
    if problem:
        key = "inertia_body" if r.has("inertia_body") else "inertia_body_diagonal"
        raise r.fail(key, problem, "a symmetric positive-definite tensor obeying the triangle inequality")
    return RigidBody(
        name=r.string("name"),
        mass=r.number("mass", positive=True),
        inertia_body=inertia,
        position_world=r.vector("position_world", 3, [0.0] * 3, length=1),
        quat_wxyz=r.vector("quat_wxyz", 4, [1.0, 0.0, 0.0, 0.0], nonzero=True),
        velocity_world=r.vector("velocity_world", 3, [0.0] * 3, length=1),
        angular_velocity_world=r.vector("angular_velocity_world", 3, [0.0] * 3),
    )


def _dynamics(top: _Reader, head: dict) -> DynamicsScene:
    world = top.subtable("world", ("gravity_world",), required=False)
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    bodies = tuple(_body(r) for r in top.array_of_tables("body", _BODY))
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        raise top.fail("body", f"body names repeat: {names}", "distinct names")
    sim = top.subtable("simulation", ("duration", "dt", "rate_hz"))
    duration = sim.number("duration", positive=True)
    if sim.has("dt") == sim.has("rate_hz"):
        raise sim.fail("dt", "give exactly one of dt and rate_hz")
    dts = sim.numbers("dt") if sim.has("dt") else tuple(1.0 / h for h in sim.numbers("rate_hz"))
    for dt in dts:
        steps = duration / dt
        if abs(steps - round(steps)) > _STEP_COUNT_RTOL * steps or round(steps) < 1:
            raise sim.fail("dt" if sim.has("dt") else "rate_hz",
                           f"duration {duration} s is not a whole number of steps of {dt} s",
                           "time steps that divide the duration")
    return DynamicsScene(bodies=bodies, forces=Forces(gravity_world=gravity), duration=duration, dts=dts, **head)


def _joint(r: _Reader) -> Joint:
    kind = r.string("type", choices=JOINT_TYPES)
    length = 1 if kind == "prismatic" else 0
    if r.has("lower") != r.has("upper"):
        raise r.fail("lower" if not r.has("lower") else "upper", "missing: limits need both lower and upper")
    lower = r.number("lower", length=length) if r.has("lower") else -np.inf
    upper = r.number("upper", length=length) if r.has("upper") else np.inf
    if lower >= upper:
        raise r.fail("upper", f"upper {upper} is not above lower {lower}")
    return Joint(
        name=r.string("name"), type=kind, axis=r.vector("axis", 3, nonzero=True),
        origin_xyz=r.vector("origin_xyz", 3, [0.0] * 3, length=1),
        origin_rotation=rpy_to_matrix(r.vector("origin_rpy", 3, [0.0] * 3)),
        lower=lower, upper=upper,
    )


def _kinematics(top: _Reader, head: dict) -> KinematicsScene:
    c = top.subtable("chain", _CHAIN)
    joints = tuple(_joint(r) for r in c.array_of_tables("joint", _JOINT))
    names = [j.name for j in joints]
    end_effector = c.string("end_effector", "end_effector")
    if len(set(names + [end_effector])) != len(names) + 1:
        raise c.fail("joint", f"joint and end-effector names repeat: {names + [end_effector]}", "distinct names")
    chain = Chain(
        name=c.string("name", head["name"]), joints=joints, end_effector_name=end_effector,
        end_effector_xyz=c.vector("end_effector_xyz", 3, [0.0] * 3, length=1),
        end_effector_rotation=rpy_to_matrix(c.vector("end_effector_rpy", 3, [0.0] * 3)),
    )
    sampling = top.subtable("sampling", ("configurations", "seed"), required=False)
    n = sampling.integer("configurations", 100, minimum=1) if sampling else 100
    seed = sampling.integer("seed", 0) if sampling else 0
    return KinematicsScene(chain=chain, n_configurations=n, seed=seed, **head)


def parse_scene(data: dict, source: str = "<scene>"):
    """Build a scene from parsed TOML ``data``; ``source`` names it in error messages."""
    top = _Reader(source, data, "", _TOP, 1.0)
    s = top.subtable("scene", _SCENE)
    unit = s.string("length_unit", "m", choices=tuple(LENGTH_UNITS))
    kind = s.string("kind", choices=KINDS)
    head = dict(
        name=s.string("name"), description=s.string("description", "-"),
        reference=s.string("reference", choices=ENGINE_NAMES), source=source,
    )
    top.scale = LENGTH_UNITS[unit]
    misplaced = ("chain", "sampling") if kind == "dynamics" else ("world", "body", "simulation")
    for key in misplaced:
        if top.has(key):
            raise top.fail(key, f"not part of a {kind} scene", ", ".join(k for k in _TOP if k not in misplaced))
    if kind == "dynamics":
        return _dynamics(top, dict(head, length_unit=unit))
    return _kinematics(top, head)


def load_scene(path: str | Path):
    """Read and check one scene file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise SceneError(str(path), "-", f"cannot read the file: {err.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(str(path), "-", f"not valid TOML: {err}") from None
    return parse_scene(data, str(path))
