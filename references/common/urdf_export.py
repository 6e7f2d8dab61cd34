"""URDF for simparity scenes and chains, built with an XML library.

Every element is built (or rewritten) with :mod:`xml.etree.ElementTree`, which escapes
attribute values: no name can close an element or open another (no string templates).

What the engines are given, and why
-----------------------------------
- A free body is one link whose ``<inertial>`` carries the scene's mass and inertia in
  PRINCIPAL axes (``origin rpy`` = the principal frame, off-diagonal terms zero): PyBullet
  keeps only a diagonal inertia and reports the base pose in this inertial frame, so the
  adapters convert with the same rotation (:func:`references.common.conventions.principal_axes`).
  No ``<collision>`` or ``<visual>``: nothing collides. In a scene with contact, PyBullet's
  body gets its contact spheres as ``<collision>`` elements (``spheres``, centres in the body
  frame, which is the link frame); loaded with ``URDF_USE_INERTIA_FROM_FILE`` they add no mass.
- A chain read from a URDF file: the ORIGINAL file, parsed (its XML declaration's encoding
  honoured) with every link's ``<visual>`` and ``<collision>`` removed. Kinematics and IK
  need no geometry ("model only what a scene needs"), so no engine opens a mesh: not one
  named by ``package://``, not one missing, and not one anywhere else on disk.
- Other chains: ``base`` link, then one link per joint named after the joint, and a fixed
  joint to a link named after the end effector. Their frames are the ones the references derive from the
  scene file's numbers (roll-pitch-yaw, a DH table: :mod:`references.common.scene_inputs`, through which every
  reference engine is given its chains), never core's. Revolute joints without limits become
  ``continuous``. Links get the chain's declared mass properties (base and end effector massless) when it
  declares them; otherwise a placeholder inertial (mass 1, inertia 1e-3; PyBullet would otherwise invent mass 1,
  inertia 1), which kinematics does not see and dynamics never gets (it refuses such a chain).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING, cast

from simparity.core.model.engine import Support
from simparity.core.model.files import parse_xml
from simparity.core.model.scenes.bodies import RigidBody
from simparity.core.model.scenes.chain import Chain, LinkInertia
from simparity.references.common.conventions import (
    PLACEHOLDER_INERTIA,
    PLACEHOLDER_MASS,
    fmt,
    matrix_to_rpy,
    principal_axes,
)

GEOMETRY = ("visual", "collision")
"""Link elements left out of a chain's URDF: kinematics and IK need no geometry."""


def _text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _inertial(link: ET.Element, mass: float, moments, rpy) -> None:
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz="0 0 0", rpy=fmt(rpy))
    ET.SubElement(inertial, "mass", value=fmt([mass]))
    ixx, iyy, izz = moments
    ET.SubElement(inertial, "inertia", ixx=fmt([ixx]), ixy="0", ixz="0", iyy=fmt([iyy]), iyz="0", izz=fmt([izz]))


def body_urdf(body: RigidBody, spheres=()) -> str:
    """URDF text of one free rigid body (a single link, inertia in principal axes).

    ``spheres``: collision spheres ((centre (3,) in the body frame [m], radius [m]), ...); none by default.
    """
    moments, axes = principal_axes(body.inertia_body)
    root = ET.Element("robot", name=body.name)
    link = ET.SubElement(root, "link", name=body.name)
    _inertial(link, body.mass, moments, matrix_to_rpy(axes))
    for centre, radius in spheres:
        collision = ET.SubElement(link, "collision")
        ET.SubElement(collision, "origin", xyz=fmt(centre), rpy="0 0 0")
        ET.SubElement(ET.SubElement(collision, "geometry"), "sphere", radius=fmt([radius]))
    return _text(root)


def urdf_support(chain: Chain) -> Support:
    """Whether the chain can be written as URDF: a prismatic joint needs limits there."""
    for joint in chain.joints:
        if joint.type == "prismatic" and not joint.limited:
            return Support.no(f"URDF cannot express the unlimited prismatic joint '{joint.name}'")
    return Support.yes()


if TYPE_CHECKING:  # the mixin's super() is the Engine it is mixed into
    from simparity.core.model.engine import Engine as _MixinBase
else:
    _MixinBase = object


class UrdfChains(_MixinBase):
    """Support rules of an engine that receives chains as URDF (a mixin for Engine subclasses)."""

    def supports_kinematics(self, chain: Chain) -> Support:
        return urdf_support(chain) if chain.urdf_path is None else Support.yes()

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        named = super().supports_ik(chain, solver, position_only)
        return named if not named.ok else self.supports_kinematics(chain)


def _placeholder_link(root: ET.Element, name: str) -> None:
    _inertial(ET.SubElement(root, "link", name=name), PLACEHOLDER_MASS, [PLACEHOLDER_INERTIA] * 3, [0, 0, 0])


def zero_inertial(link: ET.Element) -> None:
    """An explicit massless ``<inertial>`` (a URDF link without one is massless; PyBullet would invent 1 kg)."""
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz="0 0 0", rpy="0 0 0")
    ET.SubElement(inertial, "mass", value="0")
    ET.SubElement(inertial, "inertia", ixx="0", ixy="0", ixz="0", iyy="0", iyz="0", izz="0")


def _declared_link(root: ET.Element, name: str, inertia: LinkInertia | None) -> None:
    """A link with the chain's declared mass properties (None: massless): the centre of mass as the inertial
    origin, the full tensor in the link's axes."""
    link = ET.SubElement(root, "link", name=name)
    if inertia is None:
        zero_inertial(link)
        return
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz=fmt(inertia.com_xyz), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=fmt([inertia.mass]))
    i = inertia.inertia_com
    ET.SubElement(inertial, "inertia", ixx=fmt([i[0, 0]]), ixy=fmt([i[0, 1]]), ixz=fmt([i[0, 2]]),
                  iyy=fmt([i[1, 1]]), iyz=fmt([i[1, 2]]), izz=fmt([i[2, 2]]))


def _joint(root: ET.Element, name: str, kind: str, parent: str, child: str, xyz, rotation) -> ET.Element:
    joint = ET.SubElement(root, "joint", name=name, type=kind)
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)
    ET.SubElement(joint, "origin", xyz=fmt(xyz), rpy=fmt(matrix_to_rpy(rotation)))
    return joint


def exported_chain_urdf(chain: Chain) -> str:
    """URDF text written for a chain that has no URDF file (joints inline or from DH): with the chain's declared
    mass properties when it has them (base and end-effector links massless), else placeholder inertials, which
    kinematics does not see (dynamics refuses such a chain: :meth:`Chain.dynamics_problem`)."""
    declared = not chain.dynamics_problem()

    def link(name: str, inertia: LinkInertia | None) -> None:
        _declared_link(root, name, inertia) if declared else _placeholder_link(root, name)

    root = ET.Element("robot", name=chain.name)
    link("base", None)
    parent = "base"
    for joint in chain.joints:
        kind = joint.type if joint.limited or joint.type == "prismatic" else "continuous"
        link(joint.name, joint.link)
        element = _joint(root, joint.name, kind, parent, joint.name, joint.origin_xyz, joint.origin_rotation)
        ET.SubElement(element, "axis", xyz=fmt(joint.axis))
        if joint.limited:
            ET.SubElement(element, "limit", lower=fmt([joint.lower]), upper=fmt([joint.upper]), effort="0", velocity="0")
        parent = joint.name
    link(chain.end_effector_name, None)
    _joint(root, f"{chain.end_effector_name}_fixed", "fixed", parent, chain.end_effector_name,
           chain.end_effector_xyz, chain.end_effector_rotation)
    return _text(root)


def _parsed(urdf_path: str) -> ET.Element:
    """The ``<robot>`` element of a URDF file, parsed as the loader parsed it (no DOCTYPE, bounded nesting:
    :func:`core.model.files.parse_xml`), so a file changed since it was loaded is refused, never recursed into."""
    with open(urdf_path, "rb") as handle:
        return parse_xml(handle.read(), urdf_path, "robot")


def original_without_geometry(urdf_path: str) -> str:
    """The URDF file's text with every link's visual and collision elements removed."""
    root = _parsed(urdf_path)
    for link in root.findall("link"):
        for tag in GEOMETRY:
            for element in link.findall(tag):
                link.remove(element)
    return _text(root)


def movable_joints_above_base(chain: Chain) -> list[str]:
    """Names of the URDF file's non-fixed joints between its root link and the chain's base link."""
    if chain.urdf_path is None:
        return []
    # The file is one load_urdf read: every joint has a name and <parent link=...>, <child link=...>.
    parent_joint = {cast(ET.Element, j.find("child")).get("link"): j
                    for j in _parsed(chain.urdf_path).findall("joint")}
    names: list[str] = []
    link = chain.base_link
    while link in parent_joint:
        joint = parent_joint[link]
        if joint.get("type") != "fixed":
            names.append(cast(str, joint.get("name")))
        link = cast(ET.Element, joint.find("parent")).get("link")
    return names[::-1]


def chain_urdf(chain: Chain) -> str:
    """The URDF text engines are given for a chain: its file without geometry, or the export."""
    return exported_chain_urdf(chain) if chain.urdf_path is None else original_without_geometry(chain.urdf_path)


def chain_source(chain: Chain) -> str:
    """Where a chain's model comes from, for the rows' detail and ``simparity export``."""
    if chain.urdf_path is None:
        return "the adapter's URDF export"
    return f"{chain.urdf_path} without visual and collision geometry (base link {chain.base_link})"


def chain_export(chain: Chain, how: str) -> str:
    """The URDF an engine gets for a chain, headed by where it comes from and how it is loaded."""
    header = ET.Comment(f" {chain_source(chain)}; loaded by {how} ")
    return ET.tostring(header, encoding="unicode") + "\n" + chain_urdf(chain)
