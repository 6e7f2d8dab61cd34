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
- Every movable joint not on the chain (fingers, branches, joints past the tip, mimic
  joints) becomes a fixed joint at its zero position (its ``<origin>``), so its links ride on the chain link they
  hang from in every engine alike. The chain is the file's path from the scene's base link to its tip link, walked
  here (:func:`chain_joint_names`), never taken from core's parse: each adapter finds its joints by these names.
- A link without ``<inertial>`` is massless (the URDF specification) and gets an explicit zero one: PyBullet
  would otherwise give it 1 kg and a unit inertia.
- For a fixed base, the base link and every link welded to it by fixed joints never move: their ``<inertial>`` is
  replaced by the explicit zero (a placeholder tensor there, as ANYmal's base has, made MuJoCo refuse the whole
  model). A floating base moves: its links keep theirs.

``<inertial>`` elements of links that move are never touched (one of mass 0 with a non-zero inertia included: every
engine keeps its rotational inertia). :class:`ModelChanges` names each change link by link (joint by joint) for the
rows' detail (:func:`dynamics_source`) and ``simparity show``.

A chain without a URDF file (inline joints in a scene) is written with
its declared mass properties (centre of mass as the inertial origin, the full tensor in the link's axes).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import cast

import numpy as np

from simparity.core.model.errors import SimparityError
from simparity.core.model.files import parse_xml
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.dynamics_mjcf import mjcf_joint_names, mjcf_source
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


@dataclass(frozen=True)
class ModelChanges:
    """What :func:`original_for_dynamics` changes in a chain's file to make it mean the same in every engine, named
    link by link and joint by joint (file order), for the rows' detail and ``simparity show``.

    Attributes
    ----------
    removed : tuple of str
        Links not below the base link, left out.
    held : tuple of str
        Movable joints off the chain, made fixed at their zero position.
    welded : tuple of str
        Links welded to the fixed base (the base included): they never move, and get the explicit zero
        ``<inertial>`` in place of theirs.
    no_inertial : tuple of str
        Moving links without ``<inertial>``: given the explicit zero one (PyBullet's default would be 1 kg).
    friction : tuple of str
        Joints whose ``<dynamics friction>`` (Coulomb) no engine is given.
    massless_with_inertia : tuple of str
        Moving links of mass 0 with a non-zero inertia: kept as written (not a change; every engine keeps the
        rotational inertia, a rotor's whose mass is counted elsewhere).
    """

    removed: tuple[str, ...] = ()
    held: tuple[str, ...] = ()
    welded: tuple[str, ...] = ()
    no_inertial: tuple[str, ...] = ()
    friction: tuple[str, ...] = ()
    massless_with_inertia: tuple[str, ...] = ()

    def sentences(self, base: str) -> list[str]:
        """One sentence per kind of change that names its links or joints (none: an empty list)."""
        said = [
            (self.no_inertial, "links without <inertial> given an explicit massless one (the URDF's meaning, where "
                               "PyBullet's default would be 1 kg and a unit inertia)"),
            (self.welded, "links welded to the fixed base (they never move) given the explicit massless <inertial> "
                          "(in place of theirs where they have one)"),
            (self.held, "joints off the chain held at 0 as fixed joints (their links ride on the chain)"),
            (self.friction, "<dynamics friction> (Coulomb) not modelled, no engine is given it"),
            (self.massless_with_inertia, "links of mass 0 with a rotational inertia, kept as written in every engine "
                                         "(a rotor's inertia whose mass is counted elsewhere)"),
            (self.removed, f"links not below the base link {base} left out"),
        ]
        return [f"{what}: {', '.join(names)}" for names, what in said if names]


def _file(chain: Chain) -> ET.Element:
    """The chain's URDF file, parsed (the references' own reading: ElementTree)."""
    path = cast(str, chain.urdf_path)
    with open(path, "rb") as handle:
        return parse_xml(handle.read(), path, "robot")


def _path_joints(root: ET.Element, base: str, tip: str) -> list[ET.Element]:
    """The joints from ``base`` down to ``tip`` in file order along the path (fixed ones included), walked up from the
    tip by each link's parent joint; a tip not below the base is a SimparityError."""
    parent = {cast(str, cast(ET.Element, j.find("child")).get("link")): j for j in root.findall("joint")}
    path, link = [], tip
    while link != base:
        if link not in parent:
            raise SimparityError(f"link {tip!r} is not below base link {base!r} in {root.get('name', 'the file')}")
        path.append(parent[link])
        link = cast(str, cast(ET.Element, parent[link].find("parent")).get("link"))
    return path[::-1]


def chain_joint_names(chain: Chain) -> tuple[str, ...]:
    """The chain's joints as the references select them: for a chain from an MJCF file, :func:`mjcf_joint_names`; for
    a chain from a URDF file, the movable joints on the
    file's own path from the base link to the tip link (the scene's ``base_link`` and ``tip_link``), found by the
    references' own walk of the file, never from core's parse (a path core chose wrongly then shows as a
    disagreement); for a chain without a file, its joints."""
    if chain.mjcf_path is not None:
        return mjcf_joint_names(chain)
    if chain.urdf_path is None:
        return tuple(j.name for j in chain.joints)
    path = _path_joints(_file(chain), cast(str, chain.base_link), chain.end_effector_name)
    return tuple(cast(str, j.get("name")) for j in path if j.get("type") != "fixed")


def _changed(chain: Chain) -> tuple[ET.Element, ModelChanges]:
    """The chain's file as every engine reads it for dynamics (see the module docstring), and what was changed."""
    root = _file(chain)
    base = cast(str, chain.base_link)
    links, joints = _subtree(root, base)
    on_path = {j.get("name") for j in _path_joints(root, base, chain.end_effector_name)}
    held_in_order = tuple(cast(str, j.get("name")) for j in root.findall("joint")
                          if j.get("name") in joints and j.get("type") != "fixed" and j.get("name") not in on_path)
    held = set(held_in_order)
    removed = tuple(cast(str, element.get("name")) for element in root.findall("link")
                    if element.get("name") not in links)
    for element in list(root):
        kept = links if element.tag == "link" else joints if element.tag == "joint" else None
        if kept is not None and element.get("name") not in kept:
            root.remove(element)
    friction = tuple(cast(str, joint.get("name")) for joint in root.findall("joint")
                     if any(float(d.get("friction", "0")) != 0 for d in joint.findall("dynamics")))
    for joint in root.findall("joint"):
        for element in joint.findall("dynamics"):
            joint.remove(element)
        if joint.get("name") in held:
            joint.set("type", "fixed")
            for tag in HELD_JOINT_CHILDREN:
                for element in joint.findall(tag):
                    joint.remove(element)
    welded = set() if chain.floating_base else _welded_to_base(root, cast(str, chain.base_link))
    no_inertial, massless_with_inertia = [], []
    for link in root.findall("link"):
        name = cast(str, link.get("name"))
        for tag in REMOVED_FROM_LINKS:
            for element in link.findall(tag):
                link.remove(element)
        if name in welded:  # never moves: not part of the dynamics (a placeholder there is harmless)
            for element in link.findall("inertial"):
                link.remove(element)
        elif link.find("inertial") is None:
            no_inertial.append(name)
        elif _massless_with_inertia(cast(ET.Element, link.find("inertial"))):
            massless_with_inertia.append(name)
        if link.find("inertial") is None:
            zero_inertial(link)
    order = [cast(str, link.get("name")) for link in root.findall("link")]
    return root, ModelChanges(removed, held_in_order, tuple(n for n in order if n in welded),
                              tuple(no_inertial), friction, tuple(massless_with_inertia))


def _massless_with_inertia(inertial: ET.Element) -> bool:
    """Whether an ``<inertial>`` has mass 0 and a non-zero ``<inertia>`` entry (the file loaded: numbers are valid)."""
    mass, inertia = inertial.find("mass"), inertial.find("inertia")
    if mass is None or inertia is None or float(mass.get("value", "0")) != 0:
        return False
    return any(float(inertia.get(entry, "0")) != 0 for entry in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))


def original_for_dynamics(chain: Chain) -> str:
    """The chain's URDF file as every engine reads it for dynamics (see the module docstring)."""
    return _text(_changed(chain)[0])


def model_changes(chain: Chain) -> ModelChanges:
    """What every engine's model of ``chain``'s file changes, link by link; for a chain without a file (its links
    written after its joints), only its links of mass 0 with an inertia, named after their joints."""
    if chain.urdf_path is not None:
        return _changed(chain)[1]
    return ModelChanges(massless_with_inertia=tuple(
        joint.name for joint in chain.joints
        if joint.link is not None and joint.link.mass == 0 and bool(np.any(joint.link.inertia_com))))


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
    if chain.mjcf_path is not None:
        return mjcf_source(chain)
    changes = model_changes(chain).sentences(str(chain.base_link))
    if chain.urdf_path is None:
        return "; ".join(["the chain's declared mass properties written as URDF"] + changes)
    return (f"{chain.urdf_path} below {chain.base_link}, without geometry and <dynamics>, moving links' inertials "
            f"untouched; " + ("; ".join(changes) if changes else "nothing else changed"))
