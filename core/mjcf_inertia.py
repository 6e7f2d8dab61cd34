"""Mass properties for the MJCF reader (:mod:`core.mjcf`): a body's ``<inertial>``, or the mass and inertia MuJoCo
infers from its geoms (``<compiler inertiafromgeom>``), and the exact combination of rigidly attached parts. The
attributes are read by :mod:`core.mjcf`'s reader (:class:`Attributes`: default classes applied, numbers held to its
rules).

The formulas are MuJoCo 4's (a uniform solid of the geom's shape; its ``size`` as the type reads it):

- sphere (radius r): V = 4/3 pi r^3, I = 2/5 m r^2 about every axis;
- capsule (radius r, half-length h of the cylinder part; H = 2h): a cylinder with two hemispherical caps, the mass
  shared by volume; about its centre, the cylinder's m_c (3 r^2 + H^2) / 12 across and m_c r^2 / 2 along its z axis,
  each cap's 2/5 m_s r^2 about its flat face, moved across by the parallel-axis theorem (m_s H (2H + 3r) / 8 for both);
- cylinder (r, h): V = 2 pi r^2 h, I = m (3 r^2 + 4 h^2) / 12 across and m r^2 / 2 along z;
- ellipsoid (radii a, b, c): V = 4/3 pi a b c, I_x = m (b^2 + c^2) / 5 and so on;
- box (half-extents a, b, c): V = 8 a b c, I_x = m (b^2 + c^2) / 3 and so on.

Each was checked against MuJoCo's compiled body inertia (``tests/core/test_mjcf.py``).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from simparity.core.dynamics.inertia import link_tensor_problem
from simparity.core.model.errors import SceneError
from simparity.core.model.ranges import RANGES, Range, safe_norm

Layers = list[tuple[ET.Element, str]]
"""The elements setting an MJCF element's attributes, weakest first (its default classes', then its own), each with its
key (``mujoco/worldbody//body[@name='b']/geom[2]``)."""
ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
"""The attributes that turn an MJCF frame (at most one per element)."""
ANY = Range(0.0, np.inf, "", "any magnitude")
INTEGER = re.compile(r"[+-]?[0-9]+\Z")
_SIZE = Range(0.0, 1e6, "m", "a geom within 1000 km")
_TENSORS = {"diaginertia": 3, "fullinertia": 6}

SOLID_GEOMS = {"sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "box": 3}
"""The geom types whose mass properties core infers, with the number of ``size`` values each reads."""

FROMTO_GEOMS = ("capsule", "cylinder", "ellipsoid", "box")
"""The geom types a ``fromto`` segment may place (MuJoCo refuses it on any other)."""
GEOM_TYPES = ("plane", "hfield", "mesh", "sdf", *SOLID_GEOMS)


class Attributes(Protocol):
    """:mod:`core.mjcf`'s reader of attributes: each refuses a malformed or out-of-range value with a
    :class:`~core.errors.SceneError` naming ``source`` and the attribute's key."""

    source: str

    def text(self, layers: Layers, attribute: str) -> tuple[str, str] | None:
        """(text, key) where the strongest layer sets the attribute, or None."""

    def keyword(self, layers: Layers, attribute: str, default: str, allowed: tuple) -> str:
        """The attribute's keyword, one of ``allowed`` (``default`` where unset)."""

    def key(self, layers: Layers, attribute: str) -> str:
        """The key of the attribute where it is set (the element's own where it is not)."""

    def number(self, text: str, key: str, allowed: Range, count: tuple[int, int] = (1, 1)) -> np.ndarray:
        """The numbers of ``text`` (between ``count`` of them), finite, within ``allowed``."""

    def vector(self, layers: Layers, attribute: str, default: tuple[float, ...], allowed: Range,
               partial: bool = False) -> np.ndarray:
        """The attribute's numbers (``default`` where unset; ``partial``: a layer replaces the first few)."""

    def pose(self, layers: Layers) -> tuple[np.ndarray, np.ndarray]:
        """(``pos`` (3,) [m], rotation (3, 3)) of an element."""

    def hold(self, values: np.ndarray, allowed: Range, key: str) -> None:
        """Refuse a value whose magnitude is outside ``allowed``."""


@dataclass(frozen=True)
class BodyMass:
    """A body's mass properties: mass [kg], centre of mass (3,) [m] and inertia about it (3, 3) [kg m^2] in the
    frame it was read in; ``problem``: why the tensor is not physical ("" if it is), refused where the body rides on a
    chain link (``key``: the tensor's attribute)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray
    key: str = ""
    problem: str = ""


def inertial_mass(values: Attributes, element: ET.Element, key: str) -> BodyMass:
    """An ``<inertial>`` (``key``: its key) in the frame it sits in, held to the physical rules: ``pos`` and ``mass``
    (MuJoCo requires them), one of ``diaginertia`` (in the inertial frame's axes) and ``fullinertia`` (M11 M22 M33
    M12 M13 M23, in the body's axes: MuJoCo refuses an orientation with it); a mass >= 0 within its range, inertia
    entries up to the largest moment."""
    for attribute in ("pos", "mass"):
        if element.get(attribute) is None:
            raise SceneError(values.source, f"{key}/@{attribute}", "missing (MuJoCo requires it)",
                             "<inertial pos mass diaginertia|fullinertia>")
    given = [attribute for attribute in _TENSORS if element.get(attribute) is not None]
    if len(given) != 1:
        raise SceneError(values.source, key, f"{len(given)} of diaginertia and fullinertia", "exactly one")
    tensor_key = f"{key}/@{given[0]}"
    if given[0] == "fullinertia" and any(element.get(attribute) is not None for attribute in ORIENTATIONS):
        raise SceneError(values.source, tensor_key, "fullinertia with an orientation (MuJoCo refuses it)",
                         "a diaginertia in a turned frame, or a fullinertia in the body's axes")
    xyz, rotation = values.pose([(element, key)])
    mass = float(values.number(element.get("mass", ""), f"{key}/@mass", ANY)[0])
    if mass < 0:
        raise SceneError(values.source, f"{key}/@mass", f"negative mass {mass:g}", "a mass >= 0 [kg]")
    if mass != 0:
        values.hold(np.array([mass]), RANGES["mass"], f"{key}/@mass")
    entries = values.number(element.get(given[0], ""), tensor_key, Range(0.0, RANGES["inertia_moment"].high, "kg m^2",
                            "up to a ship's moment"), (_TENSORS[given[0]],) * 2)
    inertia = entries[[0, 3, 4, 3, 1, 5, 4, 5, 2]].reshape(3, 3) if given[0] == "fullinertia" else np.diag(entries)
    return BodyMass(mass, xyz, rotation @ inertia @ rotation.T, tensor_key, link_tensor_problem(inertia, mass, xyz))


def counted(values: Attributes, layers: Layers, groups: tuple[int, int]) -> bool:
    """Whether a geom's inertia counts: its ``group`` (0) is within ``groups`` (``<compiler inertiagrouprange>``)."""
    group = values.text(layers, "group")
    if group is not None and not INTEGER.match(group[0].strip()):
        raise SceneError(values.source, group[1], f"malformed {group[0]!r}", "an integer")
    return groups[0] <= int(group[0] if group else 0) <= groups[1]


def geoms_mass(values: Attributes, geoms: list[tuple[Layers, np.ndarray, np.ndarray]], key: str) -> BodyMass:
    """The mass properties MuJoCo infers for a body from its counted geoms, each (layers, and the position (3,) [m]
    and rotation (3, 3) of the frame it sits in): their total mass held to its range (``key``: the body's geoms)."""
    mass, com, inertia = combine([_geom(values, layers, xyz, rotation) for layers, xyz, rotation in geoms])
    if mass != 0:
        values.hold(np.array([mass]), RANGES["mass"], key)
    if np.max(np.abs(inertia)) > RANGES["inertia_moment"].high:
        raise SceneError(values.source, key, f"the geoms' inertia {np.max(np.abs(inertia)):.6g} kg m^2 is above the "
                         "physical range", RANGES["inertia_moment"].text())
    return BodyMass(mass, com, inertia)


def _geom(values: Attributes, layers: Layers, frame_xyz: np.ndarray,
          frame_rotation: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """A geom's (mass [kg], centre (3,) [m], inertia about it (3, 3) [kg m^2]) in its body's frame, as MuJoCo infers
    them: its ``mass``, else ``density`` (1000) times its volume."""
    kind = values.keyword(layers, "type", "sphere", GEOM_TYPES)
    if kind not in SOLID_GEOMS:
        raise SceneError(values.source, values.key(layers, "type"), f"a {kind} geom whose inertia would be inferred "
                         "(unsupported by core's reader)", f"{', '.join(SOLID_GEOMS)} geoms, or an <inertial>")
    for attribute in ("mesh", "shellinertia"):
        if values.text(layers, attribute) is not None and (
                attribute == "mesh" or values.keyword(layers, attribute, "false", ("true", "false")) == "true"):
            raise SceneError(values.source, values.key(layers, attribute), f"a geom's inertia from its {attribute} "
                             "(unsupported by core's reader)", "a solid primitive geom, or an <inertial>")
    size = values.vector(layers, "size", (0.0, 0.0, 0.0), _SIZE, partial=True)
    size_key, needed = values.key(layers, "size"), SOLID_GEOMS[kind]
    if values.text(layers, "fromto") is not None:
        if kind not in FROMTO_GEOMS:
            raise SceneError(values.source, values.key(layers, "fromto"), f"fromto on a {kind} (MuJoCo refuses it)",
                             ", ".join(FROMTO_GEOMS))
        if np.any(values.vector(layers, "pos", (0.0, 0.0, 0.0), RANGES["origin_xyz"])):
            raise SceneError(values.source, values.key(layers, "pos"), "both pos and fromto (MuJoCo refuses it)",
                             "one of them")
        ends = values.vector(layers, "fromto", (0.0,) * 6, RANGES["origin_xyz"])
        xyz, segment = (ends[:3] + ends[3:]) / 2, ends[3:] - ends[:3]
        half, size_key = safe_norm(segment) / 2, values.key(layers, "fromto")
        rotation = z_to(segment) if half > 0 else np.eye(3)
        size = np.array([size[0], half] if needed == 2 else [size[0], size[0], half])
    else:
        xyz, rotation = values.pose(layers)
        size = size[:needed]
    if not np.all(size > 0):
        raise SceneError(values.source, size_key, f"a {kind} of sizes {size.tolist()}", f"{needed} positive sizes "
                         "(MuJoCo refuses others; a fromto's ends apart)")
    volume, moments = solid_geom(kind, size)
    given = values.text(layers, "mass")
    if given is not None:
        mass = float(values.number(given[0], given[1], ANY)[0])
    else:
        mass = float(values.vector(layers, "density", (1000.0,), ANY)[0]) * volume
    if mass < 0:
        raise SceneError(values.source, given[1] if given else values.key(layers, "density"), "a negative mass or "
                         "density", "a number >= 0")
    turn = frame_rotation @ rotation
    return mass, frame_xyz + frame_rotation @ xyz, turn @ np.diag(mass * moments) @ turn.T


def solid_geom(kind: str, size: np.ndarray) -> tuple[float, np.ndarray]:
    """Volume [m^3] and principal moments per unit mass (3,) [m^2] about the centre, in the geom's own axes, of a
    solid primitive of :data:`SOLID_GEOMS`; ``size`` (its first ``SOLID_GEOMS[kind]`` values are read) [m] > 0."""
    if kind == "sphere":
        r = size[0]
        return 4 / 3 * np.pi * r ** 3, np.full(3, 0.4 * r * r)
    if kind in ("capsule", "cylinder"):
        r, height = size[0], 2 * size[1]
        cylinder = np.pi * r * r * height
        across, along = (3 * r * r + height * height) / 12, r * r / 2
        if kind == "cylinder":
            return cylinder, np.array([across, across, along])
        sphere = 4 / 3 * np.pi * r ** 3
        caps = sphere / (cylinder + sphere)  # the caps' share of the mass
        cap_across = 0.4 * r * r + height * (2 * height + 3 * r) / 8
        across = (1 - caps) * across + caps * cap_across
        return cylinder + sphere, np.array([across, across, (1 - caps) * along + caps * 0.4 * r * r])
    a, b, c = size[0], size[1], size[2]
    squares = np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if kind == "ellipsoid":
        return 4 / 3 * np.pi * a * b * c, squares / 5
    return 8 * a * b * c, squares / 3


def z_to(vector: np.ndarray) -> np.ndarray:
    """(3, 3) The smallest rotation taking (0, 0, 1) to the direction of ``vector`` (3,), as MuJoCo turns a
    ``zaxis`` or ``fromto`` into a frame: about z x vector, or a half turn about x for a vector along -z."""
    axis = np.cross([0.0, 0.0, 1.0], vector)
    sine = float(np.linalg.norm(axis))
    angle = np.arctan2(sine, vector[2])
    axis = axis / sine if sine >= 1e-10 else np.array([1.0, 0.0, 0.0])
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def combine(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[float, np.ndarray, np.ndarray]:
    """The mass properties of rigidly attached parts, each (mass [kg], centre of mass (3,) [m], inertia about it
    (3, 3) [kg m^2]) in one frame: total mass, mass-weighted centre of mass (the origin when massless) and the inertia
    about it by the parallel-axis theorem, symmetrised."""
    mass = float(sum(part[0] for part in parts))
    com = sum((m * c for m, c, _ in parts), np.zeros(3)) / mass if mass > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for m, c, tensor in parts:
        d = c - com  # parallel-axis theorem: m (|d|^2 E - d d^T) about the combined centre of mass
        inertia += tensor + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, 0.5 * (inertia + inertia.T)
