"""MJCF (MuJoCo's model format) for simparity scenes and chains, built with an XML library.

Every element is built with :mod:`xml.etree.ElementTree`, which escapes attribute values:
no name can close an element or open another (no string templates).

What MuJoCo is given, and why
-----------------------------
- ``<compiler angle="radian">``: MJCF angles default to degrees.
- Every free body gets an explicit ``<inertial>`` with ``fullinertia`` from the scene (no
  inertia from geoms); it has no geom, so nothing can collide, and contact is disabled.
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

from simparity.core.scene import Chain, DynamicsScene
from simparity.references.conventions import PLACEHOLDER_INERTIA, PLACEHOLDER_MASS, fmt, matrix_to_quat_wxyz

INTEGRATORS = {"euler": "Euler", "rk4": "RK4", "implicit": "implicit", "implicitfast": "implicitfast"}
"""simparity integrator name -> MJCF ``option/@integrator``."""


def _text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _model(name: str, flags: dict[str, str], **option: str) -> tuple[ET.Element, ET.Element]:
    """(``<mujoco>``, its ``<worldbody>``) with radians, the options and the disabled flags."""
    root = ET.Element("mujoco", model=name)
    ET.SubElement(root, "compiler", angle="radian")
    ET.SubElement(ET.SubElement(root, "option", **option), "flag", **flags)
    return root, ET.SubElement(root, "worldbody")


def dynamics_mjcf(scene: DynamicsScene, integrator: str, dt: float) -> str:
    """MJCF text of a dynamics scene for one integrator and time step."""
    gravity = scene.forces.gravity_world
    flags = {"contact": "disable"}
    if gravity is None:
        flags["gravity"] = "disable"
    if scene.forces.linear_drag is not None or scene.forces.angular_linear_drag is not None:
        flags["eulerdamp"] = "disable"  # the drag is dof_damping: keep Euler explicit
    root, world = _model(scene.name, flags, timestep=fmt([dt]), integrator=INTEGRATORS[integrator],
                         gravity=fmt(gravity) if gravity is not None else "0 0 0")
    for body in scene.bodies:
        i = body.inertia_body
        element = ET.SubElement(world, "body", name=body.name, pos=fmt(body.position_world), quat=fmt(body.quat_wxyz))
        ET.SubElement(element, "freejoint", name=f"{body.name}_free")
        ET.SubElement(element, "inertial", pos="0 0 0", mass=fmt([body.mass]),
                      fullinertia=fmt([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]))
    return _text(root)


def chain_mjcf(chain: Chain) -> str:
    """MJCF text of a fixed-base chain (kinematics only)."""
    root, parent = _model(chain.name, {"contact": "disable", "gravity": "disable"})
    for joint in chain.joints:
        parent = ET.SubElement(parent, "body", name=joint.name, pos=fmt(joint.origin_xyz),
                               quat=fmt(matrix_to_quat_wxyz(joint.origin_rotation)))
        limits = {"range": fmt([joint.lower, joint.upper])} if joint.limited else {"limited": "false"}
        ET.SubElement(parent, "joint", name=joint.name, type="hinge" if joint.type == "revolute" else "slide",
                      axis=fmt(joint.axis), **limits)
        ET.SubElement(parent, "inertial", pos="0 0 0", mass=fmt([PLACEHOLDER_MASS]),
                      diaginertia=fmt([PLACEHOLDER_INERTIA] * 3))
    ET.SubElement(parent, "site", name=chain.end_effector_name, pos=fmt(chain.end_effector_xyz),
                  quat=fmt(matrix_to_quat_wxyz(chain.end_effector_rotation)))
    return _text(root)
