"""Serial chains from URDF files (kinematics only), read with the standard library.

Only what fixes the kinematics is read: each ``<link name>`` and each ``<joint>``'s type,
``<parent>``, ``<child>``, ``<origin xyz rpy>``, ``<axis xyz>`` and ``<limit lower upper>``.
Visual, collision, inertial, dynamics, transmission and other elements are ignored.
Values follow the URDF specification: a missing ``<origin>`` is the identity, a missing
``<axis>`` is (1, 0, 0), a missing ``lower`` / ``upper`` attribute of ``<limit>`` is 0,
``rpy`` is roll-pitch-yaw Rz(yaw) Ry(pitch) Rx(roll) (:func:`core.rotations.rpy_to_matrix`).

Two sets of rules, because every engine loads the whole file but only the chain is compared:

- The whole file must be what the engines' URDF importers accept: a well-formed tree (unique
  names, every referenced link present, one parent per link, one root), finite numbers, a
  non-zero axis on every moving joint, a ``<limit>`` on every revolute and prismatic joint with
  lower <= upper (urdfdom, hence Pinocchio, refuses a file with a revolute joint without one),
  at most :data:`MAX_MOVABLE_JOINTS` movable and :data:`MAX_URDF_JOINTS` joints in all.
- The chain is the path from ``base_link`` to ``tip_link``; joints on that path must be
  revolute, continuous (an unlimited revolute joint) or prismatic, or fixed (merged into the
  next movable joint's origin, or into the end-effector transform after the last movable
  joint). A revolute or prismatic joint on the path must be able to move: lower < upper (a
  ``<limit>`` without bounds is lower = upper = 0: use ``type='fixed'`` for a joint that does
  not move, as in scene files). Names on the path (and the robot's) follow
  :data:`core.names.NAME_RULE`, numbers on the path the physical ranges of :mod:`core.ranges`
  (origins, angles, joint limits, axis norms). Joints off the path may be of any URDF type,
  mimic ones included, and their names and magnitudes are not held to those rules.

Anything else is rejected with a :class:`~core.errors.SceneError` naming the element; nothing is
guessed. A file with a ``<!DOCTYPE>`` (hence any entity declaration) or elements nested deeper than
:data:`core.model.files.MAX_XML_DEPTH` is refused before anything is read from it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import replace
from typing import Any

import numpy as np

from simparity.core.model.errors import SceneError
from simparity.core.model.files import MAX_FILE_BYTES, parse_xml, read_input
from simparity.core.model.names import NAME_RULE, name_problem
from simparity.core.model.ranges import NORM_RANGES, RANGES, safe_norm
from simparity.core.rotations import rpy_to_matrix
from simparity.core.model.scene import Chain, Joint

URDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
_CHAIN_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed")
_ALLOWED_ON_PATH = "revolute, continuous, prismatic or fixed joints without <mimic>"
MAX_MOVABLE_JOINTS = 128
"""Movable (not fixed) joints a URDF file or a chain may have: every engine loads the whole file,
and Pinocchio's data grows steeply with them (measured: 100 MB for 128 joints, 1.2 GB for 256,
24 GB wanted for 1,000; 5,000 crashed it). Real robots have 6 to ~100 (TIAGo dual: 101)."""

MAX_URDF_JOINTS = 1024
"""``<joint>`` elements (fixed ones included) a URDF file may have, and ``<link>`` elements one
more: the largest real descriptions have ~130 joints; PyBullet crashes on 5,000."""


def chain_from_urdf(
    path_or_text: str | os.PathLike,
    base_link: str | None = None,
    tip_link: str | None = None,
    source: str | None = None,
    max_joints: int = MAX_MOVABLE_JOINTS,
    max_bytes: int = MAX_FILE_BYTES,
) -> Chain:
    """Build the serial :class:`~core.scene.Chain` from ``base_link`` to ``tip_link``.

    Parameters
    ----------
    path_or_text : str or path-like
        A URDF file, or the URDF text itself (a string whose first non-blank character
        is ``<``).
    base_link : str, optional
        The link whose frame is the world frame; default the tree's root link.
    tip_link : str, optional
        The link whose frame is the end effector; default the unique leaf below
        ``base_link`` (an error when there are several).
    source : str, optional
        Name reported in errors; default the file path, or ``"<urdf text>"``.
    max_joints : int
        Largest number of movable joints in the file (and so on the chain).
    max_bytes : int
        Largest size of the file accepted [bytes].

    Returns
    -------
    Chain
        Named after ``<robot name>``; one joint per movable joint on the path, the
        end-effector frame named after ``tip_link``; ``urdf_path`` is the file (None for
        text) and ``base_link`` the base link's name.

    Raises
    ------
    SceneError
        For malformed XML or numbers, a ``<!DOCTYPE>`` (DTDs and entities are refused), elements
        nested deeper than :data:`core.model.files.MAX_XML_DEPTH`, missing links, a link with two parents, several
        roots, an unknown or missing base/tip link, several leaves without ``tip_link``,
        a mimic, floating or planar joint on the path, a joint on the path that cannot move
        (lower == upper), a name on the path outside :data:`core.names.NAME_RULE`, a number on the
        path outside its physical range (:mod:`core.ranges`), or a file that is too large, has too
        many joints or is not a regular file. ``key`` names the element, e.g.
        ``robot/joint[@name='j3']/mimic``.
    """
    root, source = _parse(path_or_text, source, max_bytes)
    _check_size(root, source, max_joints)
    links = _links(root, source)
    joints = _joints(root, source, links)
    parent_joint = _parent_joints(joints, source)
    roots = [name for name in links if name not in parent_joint]
    if len(roots) != 1:
        raise SceneError(source, "robot/link", f"the tree has {len(roots)} root links {roots}",
                         "exactly one link that is no joint's child")
    _check_tree(roots[0], links, joints, source)
    base = _pick_base(base_link, roots[0], links, source)
    tip = _pick_tip(tip_link, base, links, joints, source)
    path = _path(base, tip, parent_joint, source)
    robot = root.get("name", "")
    if robot and (problem := name_problem(robot)):
        raise SceneError(source, "robot/@name", problem, NAME_RULE)
    chain = _assemble(robot, path, tip, source)
    is_file = not os.fspath(path_or_text).lstrip().startswith("<")
    return replace(chain, urdf_path=os.fspath(path_or_text) if is_file else None, base_link=base)


def _parse(path_or_text: str | os.PathLike, source: str | None, max_bytes: int) -> tuple[ET.Element, str]:
    """The root ``<robot>`` element (:func:`core.model.files.parse_xml`: no DOCTYPE, bounded nesting); a file
    is read as bytes, so its XML declaration's encoding is honoured."""
    text = os.fspath(path_or_text)
    is_text = text.lstrip().startswith("<")
    source = source or ("<urdf text>" if is_text else text)
    data = text if is_text else read_input(text, max_bytes, "URDF file")
    return parse_xml(data, source, "robot"), source


def _check_size(root: ET.Element, source: str, max_joints: int) -> None:
    """Refuse a file with more joints or links than any engine should be given (before reading them)."""
    joints = root.findall("joint")
    movable = sum(1 for joint in joints if joint.get("type") != "fixed")
    if movable > max_joints:
        raise SceneError(source, "robot/joint", f"the file has {movable:,} movable joints",
                         f"at most {max_joints:,}; simparity run --max-joints N raises it")
    for tag, most in (("joint", MAX_URDF_JOINTS), ("link", MAX_URDF_JOINTS + 1)):
        count = len(root.findall(tag))
        if count > most:
            raise SceneError(source, f"robot/{tag}", f"the file has {count:,} <{tag}> elements",
                             f"at most {most:,} (a fixed limit)")


def _links(root: ET.Element, source: str) -> list[str]:
    names: dict[str, None] = {}  # ordered, with O(1) lookups
    for i, link in enumerate(root.findall("link")):
        name = link.get("name")
        if not name:
            raise SceneError(source, f"robot/link[{i + 1}]/@name", "missing", "a non-empty link name")
        if name in names:
            raise SceneError(source, f"robot/link[@name='{name}']", "the link name is used twice", "unique names")
        names[name] = None
    return list(names)


def _joints(root: ET.Element, source: str, links: list[str]) -> list[dict]:
    joints: list[dict] = []
    seen, known_links = set(), set(links)
    for i, element in enumerate(root.findall("joint")):
        name = element.get("name")
        if not name:
            raise SceneError(source, f"robot/joint[{i + 1}]/@name", "missing", "a non-empty joint name")
        key = f"robot/joint[@name='{name}']"
        if name in seen:
            raise SceneError(source, key, "the joint name is used twice", "unique names")
        seen.add(name)
        kind = element.get("type")
        if kind not in URDF_JOINT_TYPES:
            raise SceneError(source, f"{key}/@type", f"unknown joint type {kind!r}", ", ".join(URDF_JOINT_TYPES))
        joint: dict[str, Any] = {"name": name, "key": key, "type": kind, "element": element}
        for end in ("parent", "child"):
            link = element.find(end)
            if link is None or not link.get("link"):
                raise SceneError(source, f"{key}/{end}", "missing", f"<{end} link='...'/>")
            if link.get("link") not in known_links:
                raise SceneError(source, f"{key}/{end}/@link", f"link {link.get('link')!r} is not defined",
                                 "the name of a <link> in the file")
            joint[end] = link.get("link")
        origin = element.find("origin")
        joint["xyz"] = _numbers(origin, "xyz", (0.0, 0.0, 0.0), f"{key}/origin", source)
        joint["rpy"] = _numbers(origin, "rpy", (0.0, 0.0, 0.0), f"{key}/origin", source)
        joint["axis"] = _numbers(element.find("axis"), "xyz", (1.0, 0.0, 0.0), f"{key}/axis", source)
        if kind in ("revolute", "continuous", "prismatic") and not np.any(joint["axis"]):
            raise SceneError(source, f"{key}/axis/@xyz", "the axis is zero", "a non-zero vector")
        joint["limits"] = _limits(element, kind, key, source)
        joints.append(joint)
    return joints


def _numbers(element: ET.Element | None, attribute: str, default: tuple[float, ...], key: str,
             source: str) -> np.ndarray:
    text = None if element is None else element.get(attribute)
    if text is None:
        return np.array(default)
    try:
        values = np.array([float(word) for word in text.split()])
    except ValueError:
        values = np.array([np.nan])
    if values.shape != (len(default),) or not np.all(np.isfinite(values)):
        raise SceneError(source, f"{key}/@{attribute}", f"malformed number list {text!r}",
                         f"{len(default)} finite numbers separated by spaces")
    return values


def _limits(element: ET.Element, kind: str, key: str, source: str) -> tuple[float, float]:
    if kind in ("continuous", "fixed", "floating", "planar"):
        return -np.inf, np.inf
    limit = element.find("limit")
    if limit is None:
        raise SceneError(source, f"{key}/limit", f"a {kind} joint has no <limit>",
                         "<limit lower='...' upper='...'/> (use type='continuous' for an unlimited joint)")
    lower, upper = (_numbers(limit, bound, (0.0,), f"{key}/limit", source)[0] for bound in ("lower", "upper"))
    if lower > upper:
        raise SceneError(source, f"{key}/limit", f"lower {lower} is above upper {upper}", "lower <= upper")
    return lower, upper


def _parent_joints(joints: list[dict], source: str) -> dict[str, dict]:
    parent_joint: dict[str, dict] = {}
    for joint in joints:
        child = joint["child"]
        if child in parent_joint:
            raise SceneError(source, f"robot/link[@name='{child}']",
                             f"the link is the child of two joints, '{parent_joint[child]['name']}' and "
                             f"'{joint['name']}' (a closed loop)", "a tree: one parent joint per link")
        parent_joint[child] = joint
    return parent_joint


def _children(joints: list[dict]) -> dict[str, list[str]]:
    """Parent link -> its child links."""
    children: dict[str, list[str]] = {}
    for joint in joints:
        children.setdefault(joint["parent"], []).append(joint["child"])
    return children


def _check_tree(root_link: str, links: list[str], joints: list[dict], source: str) -> None:
    """Every link hangs below the root: a link outside its subtree is on a closed loop."""
    children = _children(joints)
    reached, stack = {root_link}, [root_link]
    while stack:
        for child in children.get(stack.pop(), []):
            if child not in reached:  # one parent per link: each is reached once
                reached.add(child)
                stack.append(child)
    cut_off = next((link for link in links if link not in reached), None)
    if cut_off is not None:
        raise SceneError(source, f"robot/link[@name='{cut_off}']", "the link is not below the root link "
                         f"{root_link!r}: it is on a closed loop", "a tree: every link below the one root link")


def _pick_base(base_link: str | None, root_link: str, links: list[str], source: str) -> str:
    if base_link is None:
        return root_link
    if problem := name_problem(base_link):
        raise SceneError(source, "base_link", problem, NAME_RULE)
    if base_link not in set(links):
        raise SceneError(source, "base_link", f"no link named {base_link!r}", ", ".join(links))
    return base_link


def _pick_tip(tip_link: str | None, base: str, links: list[str], joints: list[dict], source: str) -> str:
    if tip_link is not None:
        if problem := name_problem(tip_link):
            raise SceneError(source, "tip_link", problem, NAME_RULE)
        if tip_link not in set(links):
            raise SceneError(source, "tip_link", f"no link named {tip_link!r}", ", ".join(links))
        return tip_link
    children = _children(joints)
    leaves, stack = [], [base]
    while stack:  # a tree (checked by _check_tree): every link is visited once
        link = stack.pop()
        stack.extend(children.get(link, []))
        if link not in children:
            leaves.append(link)
    if len(leaves) != 1:
        raise SceneError(source, "tip_link", f"link {base!r} has {len(leaves)} leaf links below it "
                         f"{sorted(leaves)} and no tip_link was given", "one of the leaf link names")
    return leaves[0]


def _path(base: str, tip: str, parent_joint: dict[str, dict], source: str) -> list[dict]:
    path: list[dict] = []
    link = tip
    while link != base:
        if link not in parent_joint:
            raise SceneError(source, "tip_link", f"link {tip!r} is not below base link {base!r}",
                             f"a link in the subtree of {base!r}")
        if any(joint["child"] == link for joint in path):
            raise SceneError(source, f"robot/link[@name='{link}']", "the link is its own ancestor (a closed loop)",
                             "a tree")
        path.append(parent_joint[link])
        link = parent_joint[link]["parent"]
    return path[::-1]


_MAGNITUDES = (("xyz", "origin_xyz", "origin/@xyz"), ("rpy", "origin_rpy", "origin/@rpy"))


def _check_magnitudes(joint: dict, source: str) -> None:
    """Hold a joint on the chain to the physical ranges of :mod:`core.ranges`."""
    key = joint["key"]
    for field, range_key, where in _MAGNITUDES:
        allowed = RANGES[range_key]
        for value in joint[field]:
            if not allowed.allows(abs(value)):
                raise SceneError(source, f"{key}/{where}", f"on the chain: {value:.6g} is outside the physical range",
                                 allowed.text())
    if joint["type"] == "fixed":
        return
    norm, allowed = safe_norm(joint["axis"]), NORM_RANGES["axis"]
    if not allowed.allows(norm):
        raise SceneError(source, f"{key}/axis/@xyz", f"on the chain: its norm {norm:.3g} is outside the usable range",
                         allowed.text())
    for bound, value in zip(("lower", "upper"), joint["limits"]):
        if np.isfinite(value) and not RANGES[bound].allows(abs(value)):
            raise SceneError(source, f"{key}/limit/@{bound}", f"on the chain: {value:.6g} is outside the physical range",
                             RANGES[bound].text())


def _assemble(robot_name: str, path: list[dict], tip: str, source: str) -> Chain:
    # (position, rotation) of the frame reached so far, in the last movable joint's
    # child-link frame (or the base frame before the first movable joint).
    position, rotation = np.zeros(3), np.eye(3)
    chain_joints: list[Joint] = []
    for joint in path:
        key = joint["key"]
        if joint["type"] not in _CHAIN_JOINT_TYPES:
            raise SceneError(source, f"{key}/@type", f"a {joint['type']} joint on the chain", _ALLOWED_ON_PATH)
        if joint["element"].find("mimic") is not None:
            raise SceneError(source, f"{key}/mimic", "a mimic joint on the chain", _ALLOWED_ON_PATH)
        for name in (joint["name"], joint["child"]):
            if name_problem(name):
                raise SceneError(source, key, f"on the chain: {name_problem(name)}", NAME_RULE)
        _check_magnitudes(joint, source)
        position = position + rotation @ joint["xyz"]
        rotation = rotation @ rpy_to_matrix(joint["rpy"])
        if joint["type"] == "fixed":
            continue
        lower, upper = joint["limits"]
        if not lower < upper:
            raise SceneError(source, f"{key}/limit", f"on the chain with lower {lower:g} == upper {upper:g}: it cannot move",
                             "lower < upper, or type='fixed' for a joint that does not move (as in scene files)")
        chain_joints.append(Joint(
            name=joint["name"],
            type="prismatic" if joint["type"] == "prismatic" else "revolute",
            axis=joint["axis"],
            origin_xyz=position,
            origin_rotation=rotation,
            lower=lower,
            upper=upper,
        ))
        position, rotation = np.zeros(3), np.eye(3)
    if problem := name_problem(tip):
        raise SceneError(source, f"robot/link[@name='{tip}']", problem, NAME_RULE)
    if not chain_joints:
        raise SceneError(source, "tip_link", f"no movable joint between the base and {tip!r}",
                         "a path with at least one revolute, continuous or prismatic joint")
    return Chain(robot_name, tuple(chain_joints), end_effector_name=tip,
                 end_effector_xyz=position, end_effector_rotation=rotation)
