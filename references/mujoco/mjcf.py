"""MJCF (MuJoCo's model format) for simparity scenes and chains, built with an XML library.

Every element is built with :mod:`xml.etree.ElementTree`, which escapes attribute values:
no name can close an element or open another (no string templates).

What MuJoCo is given, and why
-----------------------------
- ``<compiler angle="radian">``: MJCF angles default to degrees.
- Every free body gets an explicit ``<inertial>`` with ``fullinertia`` from the scene (no
  inertia from geoms). A scene without contact has no geom at all and contact disabled.
- A scene with contact (:func:`contact_elements`, parameters from
  :mod:`references.common.contact_params`): ``inertiafromgeom="false"`` (geoms carry no mass: the
  scene's inertia stays exactly the ``<inertial>``), a ``plane`` geom per plane (its frame's z
  axis along N, origin -d N), the body's shape as geoms (sphere; box of the half extents at
  its centre; a sphere of ``POINT_RADIUS`` per point), every geom with ``contype`` =
  ``conaffinity`` = 0 so that MuJoCo generates no contact of its own (no body-body contact),
  and one explicit ``<pair>`` per body geom and plane carrying that pair's material exactly
  (a pair's own attributes override MuJoCo's mixing of geom parameters: max friction,
  solmix-weighted solref). Per pair: ``condim`` 3 with ``friction`` mu_k (MuJoCo has one
  coefficient; condim 1 for a frictionless pair: mu_k = 0), direct-form ``solref`` (-K, -b)
  from the restitution, ``solreffriction``, constant-impedance ``solimp``, ``margin`` -POINT_RADIUS
  for point spheres and 0 otherwise, ``gap`` 0. In MuJoCo 4.0 ``margin`` inflates a surface (a
  contact is active while distance < margin), so a negative one deflates the point's sphere to
  its centre: the contact starts when the centre reaches the plane (pinned by a test).
  ``<option cone="elliptic">``; ``impratio`` 1 and ``noslip_iterations`` 0 stay at their
  defaults. An XML comment before each pair gives its k, damping ratio and mu's.
- Gravity is set only when the scene has gravity; otherwise it is zero AND disabled.
- With drag (given as ``dof_damping`` by the adapter) ``eulerdamp`` is disabled, so the
  Euler integrator applies damping explicitly like every other engine.
- Defaults already zero in MuJoCo (dof damping, armature, frictionloss, wind, density,
  viscosity) are left at zero; tests pin each one.
- Quaternions in MJCF are (w, x, y, z), the project's order: no conversion.
- Chains: nested bodies, one hinge or slide joint at each body origin (the URDF joint
  frame), a site at the end effector. Bodies get a placeholder inertial (mass 1,
  inertia 1e-3) because MuJoCo rejects massless moving bodies; it does not affect
  kinematics.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.contact import Contact
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.references.common import contact_params
from simparity.references.common.conventions import PLACEHOLDER_INERTIA, PLACEHOLDER_MASS, fmt, matrix_to_quat_wxyz

INTEGRATORS = {"euler": "Euler", "rk4": "RK4", "implicit": "implicit", "implicitfast": "implicitfast"}
"""simparity integrator name -> MJCF ``option/@integrator``."""


def _text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


CONE = "elliptic"
"""MuJoCo's friction cone for contact scenes: elliptic, the Coulomb cone |f_t| <= mu f_n itself
(the pyramidal cone approximates it with edges)."""


def _model(name: str, flags: dict[str, str], compiler: dict[str, str] | None = None,
           **option: str) -> tuple[ET.Element, ET.Element]:
    """(``<mujoco>``, its ``<worldbody>``) with radians, the options and the disabled flags."""
    root = ET.Element("mujoco", model=name)
    # Attributes as one dict (same order): a ``**dict`` would also be offered to SubElement's ``attrib``.
    ET.SubElement(root, "compiler", {"angle": "radian", **(compiler or {})})
    ET.SubElement(ET.SubElement(root, "option", option), "flag", flags)
    return root, ET.SubElement(root, "worldbody")


ARENA_BASE_KIB, ARENA_PER_BODY_KIB = 1024, 2
"""``<size memory>`` of a scene without contact: MuJoCo's default arena grows as nv^2 (1.7 GiB at 1,000
free bodies, 13 GiB at 3,000, an allocation failure at 10,000) though such a scene has no constraints;
measured use (``MjData.maxuse_arena``) is 800 bytes per free body, so 2 KiB per body plus 1 MiB."""


def arena_kib(scene: DynamicsScene) -> int | None:
    """The arena a scene without contact is given [KiB]; None for a contact scene (MuJoCo's default)."""
    return None if scene.contact is not None else ARENA_BASE_KIB + ARENA_PER_BODY_KIB * len(scene.bodies)


def dynamics_mjcf(scene: DynamicsScene, integrator: str, dt: float) -> str:
    """MJCF text of a dynamics scene for one integrator and time step."""
    gravity = scene.forces.gravity_world
    contact = scene.contact
    flags = {"contact": "disable"} if contact is None else {}
    if gravity is None:
        flags["gravity"] = "disable"
    if scene.forces.linear_drag is not None or scene.forces.angular_linear_drag is not None:
        flags["eulerdamp"] = "disable"  # the drag is dof_damping: keep Euler explicit
    extra = {} if contact is None else {"cone": CONE}
    root, world = _model(scene.name, flags, None if contact is None else {"inertiafromgeom": "false"},
                         timestep=fmt([dt]), integrator=INTEGRATORS[integrator],
                         gravity=fmt(gravity) if gravity is not None else "0 0 0", **extra)
    bodies = []
    for body in scene.bodies:
        i = body.inertia_body
        element = ET.SubElement(world, "body", name=body.name, pos=fmt(body.position_world), quat=fmt(body.quat_wxyz))
        ET.SubElement(element, "freejoint", name=f"{body.name}_free")
        ET.SubElement(element, "inertial", pos="0 0 0", mass=fmt([body.mass]),
                      fullinertia=fmt([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]))
        bodies.append(element)
    if contact is not None:
        contact_elements(root, world, bodies, contact, dt)
    else:
        ET.SubElement(root, "size", memory=f"{arena_kib(scene)}K")
    return _text(root)


def _body_geoms(element: ET.Element, b: int, shape) -> list[tuple[str, bool]]:
    """Add a body's shape as geoms (no collision of their own); [(geom name, is a point sphere)]."""
    if shape.kind == "box":
        name = f"body{b}_box"
        ET.SubElement(element, "geom", name=name, type="box", size=fmt(shape.half_extents_body),
                      pos=fmt(shape.center_body), contype="0", conaffinity="0")
        return [(name, False)]
    geoms = []
    for v, (centre, radius, is_point) in enumerate(contact_params.contact_spheres(shape)):
        name = f"body{b}_{'point' if is_point else 'sphere'}{v}"
        ET.SubElement(element, "geom", name=name, type="sphere", size=fmt([radius]), pos=fmt(centre),
                      contype="0", conaffinity="0")
        geoms.append((name, is_point))
    return geoms


def contact_elements(root: ET.Element, world: ET.Element, bodies: list[ET.Element], contact: Contact,
                     dt: float) -> None:
    """Planes, the bodies' shape geoms and one ``<pair>`` per body geom and plane (module docstring).

    Geom names are made of indices (``plane{p}``, ``body{b}_box``, ``body{b}_sphere0``,
    ``body{b}_point{v}``) so that no scene name reaches a comment.
    """
    for p, plane in enumerate(contact.planes):
        origin, rotation = contact_params.plane_frame(plane)
        # size 0 0 1: an infinite plane (the first two are only its rendered extent), grid 1 m.
        ET.SubElement(world, "geom", name=f"plane{p}", type="plane", size="0 0 1", pos=fmt(origin),
                      quat=fmt(matrix_to_quat_wxyz(rotation)), contype="0", conaffinity="0")
    pairs = ET.SubElement(root, "contact")
    solreffriction = fmt(contact_params.mujoco_solreffriction(dt))
    solimp = fmt(contact_params.SOLIMP)
    for b, (element, shape) in enumerate(zip(bodies, contact.shapes)):
        for geom, is_point in _body_geoms(element, b, shape):
            for p, material in enumerate(contact.materials[b]):
                k, mu = material.restitution, material.friction_kinetic
                static = material.friction_static
                pairs.append(ET.Comment(
                    f" body {b} vs plane {p}: restitution k = {fmt([k])} -> damping ratio "
                    f"{fmt([contact_params.damping_ratio(k)])} at natural frequency 1/(2 dt) = "
                    f"{fmt([contact_params.natural_frequency(dt)])} rad/s; friction mu_k = {fmt([mu])} (mu_s = "
                    f"{fmt([static])}{'' if mu == static else ', not modelled: one coefficient'}) "))
                ET.SubElement(pairs, "pair", geom1=f"plane{p}", geom2=geom, condim="3" if mu > 0 else "1",
                              friction=fmt([mu, mu, 0.0, 0.0, 0.0]),
                              solref=fmt(contact_params.mujoco_solref(k, dt)), solreffriction=solreffriction,
                              solimp=solimp, margin=fmt([-contact_params.POINT_RADIUS if is_point else 0.0]),
                              gap="0.0")


def chain_mjcf(chain: Chain) -> str:
    """MJCF text of a fixed-base chain (kinematics only)."""
    root, parent = _model(chain.name, {"contact": "disable", "gravity": "disable"})
    for joint in chain.joints:
        parent = ET.SubElement(parent, "body", name=joint.name, pos=fmt(joint.origin_xyz),
                               quat=fmt(matrix_to_quat_wxyz(joint.origin_rotation)))
        limits = {"range": fmt([joint.lower, joint.upper])} if joint.limited else {"limited": "false"}
        ET.SubElement(parent, "joint", {"name": joint.name, "type": "hinge" if joint.type == "revolute" else "slide",
                                        "axis": fmt(joint.axis), **limits})
        ET.SubElement(parent, "inertial", pos="0 0 0", mass=fmt([PLACEHOLDER_MASS]),
                      diaginertia=fmt([PLACEHOLDER_INERTIA] * 3))
    ET.SubElement(parent, "site", name=chain.end_effector_name, pos=fmt(chain.end_effector_xyz),
                  quat=fmt(matrix_to_quat_wxyz(chain.end_effector_rotation)))
    return _text(root)
