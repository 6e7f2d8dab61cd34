"""The contact of a free-body scene: ``[[plane]]``, ``[contact]`` and its ``[[contact.pair]]``, each body's shape
and material."""

from __future__ import annotations

import numpy as np

from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.core.model.ranges import RANGES, safe_norm
from simparity.core.model.scenes.bodies import RigidBody
from simparity.core.model.scenes.contact import CONTACT_METHODS, SHAPES, Contact, Material, Plane, Shape
from simparity.references.common.conventions import quat_wxyz_to_matrix

_MATERIAL = ("restitution", "friction_static", "friction_kinetic")
_SHAPE = ("shape", "radius", "half_extents", "shape_center_body")
_PLANE = ("name", "coefficients")
_CONTACT = ("methods", "rest_speed", "penalty_stiffness", "penalty_damping", "pair") + _MATERIAL
_PAIR = ("body", "plane") + _MATERIAL
START_INSIDE_TOLERANCE = 1e-9
"""[m] A body may start this far inside a plane (a value typed to 9 digits that puts it on the plane);
deeper is a body that starts inside the plane: an error, not an impact at t = 0."""


def _material(r: TableReader, default: Material) -> Material:
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


def _shape(r: TableReader, body: RigidBody) -> Shape:
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


CONTACT_BODY_KEYS = _SHAPE + _MATERIAL


def read_contact(top: TableReader, readers: list[TableReader], bodies: tuple[RigidBody, ...]) -> Contact | None:
    """The scene's planes and contact parameters, or None when it has no [[plane]]."""
    if not top.has("plane"):
        for key in ("contact",):
            if top.has(key):
                raise top.fail(key, "contact settings without a [[plane]]", "[[plane]] entries to collide with")
        for r in readers:
            for key in CONTACT_BODY_KEYS:
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
    c = top.optional_subtable("contact", _CONTACT) or TableReader(top.source, {}, "contact", _CONTACT, top.scale,
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


def _check_start_outside(top: TableReader, contact: Contact, bodies: tuple[RigidBody, ...]) -> None:
    """Every body starts on the free side of every plane (within :data:`START_INSIDE_TOLERANCE`)."""
    for i, (body, shape) in enumerate(zip(bodies, contact.shapes)):
        rotation = quat_wxyz_to_matrix(body.quat_wxyz)
        vertices = body.position_world + shape.vertices_body() @ rotation.T
        for plane in contact.planes:
            depth = -(float((vertices @ plane.normal_world + plane.offset).min()) - shape.radius)
            if depth > START_INSIDE_TOLERANCE:
                raise top.fail(f"body[{i}].position_world", f"body {body.name!r} starts {depth:.3g} m inside plane "
                               f"{plane.name!r}", "every body on the free side (E >= 0) of every plane at t = 0")
