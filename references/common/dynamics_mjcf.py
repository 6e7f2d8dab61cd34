"""The MJCF every engine reads for a chain from an MJCF file (issue #45): the model only the scene asks for.

A chain read from an MJCF file reaches every engine as that ORIGINAL file, read by the engine's own MJCF importer
(MuJoCo's ``MjSpec.from_string``, Pinocchio's ``buildModelFromMJCF``, PyBullet's ``loadMJCF``), never core's parse,
with only these changes, each made with :mod:`xml.etree.ElementTree` on the parsed file and named in the rows' detail
(:func:`mjcf_source`):

- Only the base body's subtree is kept: the base body becomes ``<worldbody>``'s one child, at the world's origin
  unturned (its ``pos`` and orientation dropped); every other child of ``<worldbody>`` (floors, lights, other robots)
  is left out. Its free joint is removed (a floating base is each engine's own free joint, added by its adapter), and
  for a fixed base its other joints too (held). A base named ``world`` (:data:`WORLD`) is the worldbody itself: the
  chain's root body (the tip's top ancestor) is kept where the file puts it, with its joints (a cart's slider).
- Every joint off the chain (fingers, branches, joints past the tip) is removed: its body is welded to its parent at
  the file's pose (MuJoCo's q = ref), so its bodies ride on the chain body they hang from in every engine alike. The
  chain is the file's path from the scene's base body to its tip body, walked here (:func:`mjcf_joint_names`), never
  taken from core's parse.
- ``<actuator>``, ``<tendon>``, ``<equality>``, ``<sensor>``, ``<contact>`` and ``<keyframe>`` are removed: they name
  joints, bodies or state sizes that are gone, and none of them is rigid-body dynamics (constraints are off in every
  model, and no scene drives an actuator).
- Paths the file gives relative to itself (``<include file>``, ``<compiler meshdir texturedir assetdir>``) are made
  absolute: the text is read from elsewhere.

Geoms are kept: where a body has no ``<inertial>``, MJCF infers its mass properties from its geoms, and each engine
does so as its importer does (a difference there is an importer difference, shown by the model-parity rows). Joint
damping, armature, springs and friction loss are each adapter's to set or switch off, as for a URDF file.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import cast

from simparity.core.model.errors import SimparityError
from simparity.core.model.files import parse_xml
from simparity.core.model.scenes.chain import Chain

REMOVED_SECTIONS = ("actuator", "tendon", "equality", "sensor", "contact", "keyframe")
"""Top-level MJCF sections no engine is given for a chain's dynamics."""
ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
"""The attributes that turn a body in its parent (one at most)."""
PATH_ATTRIBUTES = ("meshdir", "texturedir", "assetdir")
"""``<compiler>`` folders relative to the file."""
MOVING_TYPES = ("hinge", "slide")
"""Joint types a chain is made of."""


def _text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _file(chain: Chain) -> ET.Element:
    """The chain's MJCF file, parsed (the references' own reading: ElementTree)."""
    path = cast(str, chain.mjcf_path)
    with open(path, "rb") as handle:
        return parse_xml(handle.read(), path, "mujoco")


@dataclass(frozen=True)
class _Tree:
    """The file's bodies: each body's parent body (None under ``<worldbody>``) and its own joints (``<joint>`` and
    ``<freejoint>``, those inside its ``<frame>`` elements included), by body element; the joint types resolved
    through the ``<default>`` classes."""

    parent: dict[ET.Element, ET.Element | None]
    joints: dict[ET.Element, list[ET.Element]]
    types: dict[ET.Element, str]


def _default_types(root: ET.Element) -> dict[str, tuple[str | None, str | None]]:
    """Default class -> (its parent class, the joint ``type`` it sets or None); the root ``<default>`` is "main"."""
    classes: dict[str, tuple[str | None, str | None]] = {}

    def walk(element: ET.Element, parent: str | None) -> None:
        name = element.get("class", "main")
        joint = element.find("joint")
        classes[name] = (parent, None if joint is None else joint.get("type"))
        for child in element.findall("default"):
            walk(child, name)

    for top in root.findall("default"):
        walk(top, None)
    return classes


def _joint_type(joint: ET.Element, cls: str, classes: dict[str, tuple[str | None, str | None]]) -> str:
    """A joint's type: its own, else its class's (up the class tree), else MJCF's default, hinge."""
    if joint.tag == "freejoint":
        return "free"
    if joint.get("type"):
        return cast(str, joint.get("type"))
    name: str | None = joint.get("class", cls)
    while name is not None and name in classes:
        parent, kind = classes[name]
        if kind:
            return kind
        name = parent
    return "hinge"


def _tree(root: ET.Element) -> _Tree:
    worlds = root.findall("worldbody")
    if not worlds:
        raise SimparityError("the MJCF file has no <worldbody>")
    classes = _default_types(root)
    parent: dict[ET.Element, ET.Element | None] = {}
    joints: dict[ET.Element, list[ET.Element]] = {}
    types: dict[ET.Element, str] = {}

    def walk(element: ET.Element, body: ET.Element | None, cls: str) -> None:
        for child in element:
            if child.tag == "body":
                parent[child] = body
                joints[child] = []
                walk(child, child, child.get("childclass", cls))
            elif child.tag == "frame":
                walk(child, body, child.get("childclass", cls))
            elif child.tag in ("joint", "freejoint") and body is not None:
                joints[body].append(child)
                types[child] = _joint_type(child, cls, classes)

    for world in worlds:
        walk(world, None, "main")
    return _Tree(parent, joints, types)


WORLD = "world"
"""The base body's name that means ``<worldbody>`` itself (unless a body has that name): the chain starts at the
world, its root body's joints on it."""


def _body(tree: _Tree, name: str) -> ET.Element:
    found = [body for body in tree.parent if body.get("name") == name]
    if len(found) != 1:
        raise SimparityError(f"the MJCF file has {len(found)} bodies named {name!r}")
    return found[0]


def _base(tree: _Tree, name: str) -> ET.Element | None:
    """The base body named ``name``; None for the worldbody (:data:`WORLD`)."""
    if name == WORLD and not any(body.get("name") == WORLD for body in tree.parent):
        return None
    return _body(tree, name)


def _path(tree: _Tree, base: ET.Element | None, tip: ET.Element) -> list[ET.Element]:
    """The bodies below ``base`` (None: the worldbody) down to ``tip``, in order (``base`` excluded)."""
    path: list[ET.Element] = []
    body: ET.Element | None = tip
    while body is not base:
        if body is None:
            raise SimparityError(f"body {tip.get('name')!r} is not below base body {cast(ET.Element, base).get('name')!r}")
        path.append(body)
        body = tree.parent[body]
    return path[::-1]


def mjcf_joint_names(chain: Chain) -> tuple[str, ...]:
    """The chain's joints as the references select them: the hinge and slide joints of the bodies on the file's own
    path from the base body to the tip body (the scene's ``base_link`` and ``tip_link``), in the file's order, found by
    the references' own walk of the file, never from core's parse."""
    return _chain_joints(_tree(_file(chain)), chain)


def _chain_joints(tree: _Tree, chain: Chain) -> tuple[str, ...]:
    """:func:`mjcf_joint_names` in a file already walked."""
    path = _path(tree, _base(tree, cast(str, chain.base_link)), _body(tree, chain.end_effector_name))
    return tuple(cast(str, joint.get("name")) for body in path for joint in tree.joints[body]
                 if tree.types[joint] in MOVING_TYPES)


@dataclass(frozen=True)
class MjcfChanges:
    """What :func:`dynamics_mjcf` changes in a chain's MJCF file, for the rows' detail and ``simparity show``.

    Attributes
    ----------
    left_out : tuple of str
        ``<worldbody>``'s other children, by tag and name.
    held : tuple of str
        Joints off the chain removed (their bodies welded at the file's pose), named ("(unnamed)" without a name).
    sections : tuple of str
        Top-level sections removed.
    """

    left_out: tuple[str, ...] = ()
    held: tuple[str, ...] = ()
    sections: tuple[str, ...] = ()

    def sentences(self, base: str) -> list[str]:
        said = [(self.held, "joints off the chain removed (their bodies welded at the file's pose, q = ref)"),
                (self.sections, "sections naming joints or state left out"),
                (self.left_out, f"<worldbody>'s children besides the base body {base} left out")]
        return [f"{what}: {', '.join(names)}" for names, what in said if names]


def _changed(chain: Chain) -> tuple[ET.Element, MjcfChanges]:
    root = _file(chain)
    folder = os.path.dirname(os.path.abspath(cast(str, chain.mjcf_path)))
    tree = _tree(root)
    base = _base(tree, cast(str, chain.base_link))
    on_chain = set(_chain_joints(tree, chain))  # the file walked once
    # the world as the base: the chain's root body (the tip's top ancestor) stays where the file puts it
    top = base if base is not None else _path(tree, None, _body(tree, chain.end_effector_name))[0]
    subtree = [body for body in tree.parent if body is top or _below(tree, body, top)]
    held = []
    for body in subtree:
        for joint in tree.joints[body]:
            if joint.get("name") not in on_chain or body is base:
                if tree.types[joint] != "free":
                    held.append(joint.get("name") or "(unnamed)")
                _remove(body, joint)
    holder = {child: parent for parent in root.iter() for child in parent}
    around = [top]  # top and the <frame> elements it sits in, up to its <worldbody>
    while holder[around[-1]].tag != "worldbody":
        around.append(holder[around[-1]])
    world = holder[around[-1]]
    left_out = []

    def leave_out(parent: ET.Element, child: ET.Element) -> None:
        left_out.append(f"{child.tag} {child.get('name')!r}" if child.get("name") else child.tag)
        parent.remove(child)

    for other in root.findall("worldbody"):  # a file may write several; MuJoCo merges them
        if other is not world:
            for child in list(other):
                leave_out(other, child)
            root.remove(other)
    if base is not None:  # the base at the world's origin, out of any frame, the class it inherited kept
        inherited = next((element.get("childclass") for element in around[1:] if element.get("childclass")), None)
        if top.get("childclass") is None and inherited is not None:
            top.set("childclass", inherited)
        for child in list(world):
            if child is not around[-1]:
                leave_out(world, child)
        if top is not around[-1]:
            world.remove(around[-1])
            world.append(top)
        for attribute in ("pos",) + ORIENTATIONS:
            top.attrib.pop(attribute, None)
    else:  # the world as the base: the frames around the root body kept with their poses, all beside them left out
        for parent, kept in zip([world] + around[:0:-1], around[::-1]):
            for child in list(parent):
                if child is not kept:
                    leave_out(parent, child)
    sections = []
    for element in list(root):
        if element.tag in REMOVED_SECTIONS:
            sections.append(f"<{element.tag}>")
            root.remove(element)
    for include in root.iter("include"):
        include.set("file", os.path.join(folder, cast(str, include.get("file"))))
    for compiler in root.findall("compiler"):
        for attribute in PATH_ATTRIBUTES:
            if compiler.get(attribute) is not None:
                compiler.set(attribute, os.path.join(folder, cast(str, compiler.get(attribute))))
    if not any(compiler.get("meshdir") or compiler.get("assetdir") for compiler in root.findall("compiler")):
        first = root.find("compiler")
        if first is None:
            first = ET.Element("compiler")
            root.insert(0, first)
        first.set("assetdir", folder)
    return root, MjcfChanges(tuple(left_out), tuple(held), tuple(sections))


def _below(tree: _Tree, body: ET.Element, base: ET.Element) -> bool:
    parent = tree.parent[body]
    while parent is not None:
        if parent is base:
            return True
        parent = tree.parent[parent]
    return False


def _remove(body: ET.Element, joint: ET.Element) -> None:
    """Remove ``joint`` from its body (or from the ``<frame>`` inside it that holds it)."""
    for holder in [body] + list(body.iter("frame")):
        if joint in list(holder):
            holder.remove(joint)
            return


def dynamics_mjcf(chain: Chain) -> str:
    """The MJCF text every engine reads for a chain from an MJCF file (the module docstring)."""
    return _text(_changed(chain)[0])


def mjcf_changes(chain: Chain) -> MjcfChanges:
    """What every engine's model of ``chain``'s MJCF file changes."""
    return _changed(chain)[1]


def mjcf_source(chain: Chain) -> str:
    """Where an engine's dynamics model of an MJCF chain comes from, for the rows' detail."""
    changes = mjcf_changes(chain).sentences(str(chain.base_link))
    return (f"{chain.mjcf_path} below {chain.base_link}, geoms kept (an MJCF body without <inertial> takes its mass "
            f"from them); " + ("; ".join(changes) if changes else "nothing else changed"))
