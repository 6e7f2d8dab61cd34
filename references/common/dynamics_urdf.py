"""The URDF every engine reads for a chain's joint-space dynamics: the model only the scene asks for.

A chain read from a URDF file reaches every engine as that ORIGINAL file, read by the engine's own URDF parser
(never core's parse re-exported: a bug in core's parser then shows as a disagreement, not as agreement), with
only these changes, each made with :mod:`xml.etree.ElementTree` on the parsed file:

- Only the base link's subtree is kept, the base link its root: the base is fixed to the world, and links
  above it (or beside it) are not part of the model.
- Every ``<visual>`` and ``<collision>`` is removed: no engine opens a mesh, and no engine recomputes an
  inertia from collision shapes (PyBullet does without ``URDF_USE_INERTIA_FROM_FILE``).
- Every ``<dynamics>`` is removed: MuJoCo would turn ``friction`` into Coulomb ``frictionloss`` and read
  ``damping``, PyBullet would damp while stepping, Pinocchio keeps both and its ``aba`` ignores them. Each adapter
  sets the chain's damping (and armature) itself.
- Every movable joint not on the chain (``Chain.held_joints``: fingers, branches, joints past the tip, mimic
  joints) becomes a fixed joint at its zero position (its ``<origin>``), so its links ride on the chain link they
  hang from in every engine alike.
- A link without ``<inertial>`` is massless (the URDF specification) and gets an explicit zero one: PyBullet
  would otherwise give it 1 kg and a unit inertia.
- The base link and every link welded to it by fixed joints never move: their ``<inertial>`` is replaced by the
  explicit zero (a placeholder tensor there, as ANYmal's base has, made MuJoCo refuse the whole model).

``<inertial>`` elements of links that move are never touched. A chain without a URDF file (inline joints in a scene) is written with
its declared mass properties (centre of mass as the inertial origin, the full tensor in the link's axes).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import cast

from simparity.core.model.errors import SimparityError
from simparity.core.model.files import parse_xml
from simparity.core.model.scene import Chain
from simparity.references.common.urdf_export import exported_chain_urdf, zero_inertial

REMOVED_FROM_LINKS = ("visual", "collision")
"""Link elements no engine is given for dynamics."""

HELD_JOINT_CHILDREN = ("axis", "limit", "mimic", "dynamics", "calibration", "safety_controller")
"""What a held joint loses when it becomes fixed."""


def _text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _subtree(root: ET.Element, base: str) -> tuple[set[str], set[str]]:
    """(links, joints) below ``base``, ``base`` included among the links."""
    children: dict[str, list[ET.Element]] = {}
    for joint in root.findall("joint"):
        children.setdefault(cast(str, cast(ET.Element, joint.find("parent")).get("link")), []).append(joint)
    links, joints, stack = {base}, set(), [base]
    while stack:
        for joint in children.get(stack.pop(), []):
            child = cast(str, cast(ET.Element, joint.find("child")).get("link"))
            joints.add(cast(str, joint.get("name")))
            if child not in links:
                links.add(child)
                stack.append(child)
    return links, joints


def original_for_dynamics(chain: Chain) -> str:
    """The chain's URDF file as every engine reads it for dynamics (see the module docstring)."""
    path = cast(str, chain.urdf_path)
    with open(path, "rb") as handle:
        root = parse_xml(handle.read(), path, "robot")
    links, joints = _subtree(root, cast(str, chain.base_link))
    held = set(chain.held_joints)
    for element in list(root):
        kept = links if element.tag == "link" else joints if element.tag == "joint" else None
        if kept is not None and element.get("name") not in kept:
            root.remove(element)
    for joint in root.findall("joint"):
        for element in joint.findall("dynamics"):
            joint.remove(element)
        if joint.get("name") in held:
            joint.set("type", "fixed")
            for tag in HELD_JOINT_CHILDREN:
                for element in joint.findall(tag):
                    joint.remove(element)
    welded = _welded_to_base(root, cast(str, chain.base_link))
    for link in root.findall("link"):
        for tag in REMOVED_FROM_LINKS:
            for element in link.findall(tag):
                link.remove(element)
        if link.get("name") in welded:  # never moves: not part of the dynamics (a placeholder there is harmless)
            for element in link.findall("inertial"):
                link.remove(element)
        if link.find("inertial") is None:
            zero_inertial(link)
    return _text(root)


def _welded_to_base(root: ET.Element, base: str) -> set[str]:
    """The base link and every link joined to it by fixed joints only: they never move."""
    fixed: dict[str, list[str]] = {}
    for joint in root.findall("joint"):
        if joint.get("type") == "fixed":
            parent = cast(str, cast(ET.Element, joint.find("parent")).get("link"))
            fixed.setdefault(parent, []).append(cast(str, cast(ET.Element, joint.find("child")).get("link")))
    welded, stack = {base}, [base]
    while stack:
        for child in fixed.get(stack.pop(), []):
            if child not in welded:
                welded.add(child)
                stack.append(child)
    return welded


def declared_for_dynamics(chain: Chain) -> str:
    """URDF text of a chain without a URDF file, with its declared mass properties (the adapters' export,
    :func:`urdf_export.exported_chain_urdf`). Raises :class:`SimparityError` for a chain without them."""
    problem = chain.dynamics_problem()
    if problem:
        raise SimparityError(f"chain {chain.name!r} has no dynamics: {problem}")
    return exported_chain_urdf(chain)


def dynamics_urdf(chain: Chain) -> str:
    """The URDF text every engine reads for ``chain``'s dynamics: its file changed only as the module docstring
    says, or its declared mass properties written out."""
    return declared_for_dynamics(chain) if chain.urdf_path is None else original_for_dynamics(chain)


def dynamics_source(chain: Chain) -> str:
    """Where an engine's dynamics model of ``chain`` comes from, for the rows' detail."""
    if chain.urdf_path is None:
        return "the chain's declared mass properties written as URDF"
    held = f"; held at 0: {', '.join(chain.held_joints)}" if chain.held_joints else ""
    return (f"{chain.urdf_path} below {chain.base_link}, inertials untouched, without geometry and <dynamics>, "
            f"links without <inertial> massless{held}")
