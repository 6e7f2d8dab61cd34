"""Serial chains from URDF files (kinematics and the mass properties dynamics needs), read with the
standard library.

What is read: each ``<link name>`` and each ``<joint>``'s type, ``<parent>``, ``<child>``,
``<origin xyz rpy>``, ``<axis xyz>`` and ``<limit lower upper>`` (the kinematics); each link's
``<inertial>`` (``<origin xyz rpy>``: the inertial frame in the link frame, ``<mass value>``,
``<inertia ixx ixy ixz iyy iyz izz>`` about the centre of mass in the inertial frame's axes), for
links in the base link's subtree only; and the ``damping`` of ``<dynamics>`` on the chain's joints
(its ``friction``, Coulomb friction, is not modelled). Visual, collision, transmission and other
elements are ignored. Values follow the URDF specification: a missing ``<origin>`` is the identity,
a missing ``<axis>`` is (1, 0, 0), a missing ``lower`` / ``upper`` attribute of ``<limit>`` is 0, a
missing ``damping`` is 0, a link without ``<inertial>`` is massless (mass and inertia 0), ``rpy`` is
roll-pitch-yaw Rz(yaw) Ry(pitch) Rx(roll) (:func:`core.rotations.rpy_to_matrix`).

Each chain joint's ``link`` (:class:`~core.model.scenes.chain.LinkInertia`) is everything rigidly attached
to the joint's child link, in that link's frame: its own inertial, the links hanging from it by
fixed joints (those on the path up to the next chain joint, and any beyond the tip link: a payload),
and every branch off the chain below it, its movable joints held at 0 (their transform is their
origin). The inertials are combined exactly: total mass, mass-weighted centre of mass, and the
inertia about that centre by the parallel-axis theorem (``R I R^T`` for a rotated inertial frame).
The held joints (the file's movable joints below the base link that are not on the chain, in file
order) are ``Chain.held_joints``. A chain whose links are all massless loads (kinematics needs no
mass); :meth:`core.model.scenes.chain.Chain.dynamics_problem` refuses it for dynamics.

The rules, stricter on the chain because every engine loads the whole file but only the chain is compared:

- The whole file must be what the engines' URDF importers accept: a well-formed tree (unique
  names, every referenced link present, one parent per link, one root), finite numbers, a
  non-zero axis on every moving joint, a ``<limit>`` on every revolute and prismatic joint with
  lower <= upper (urdfdom, hence Pinocchio, refuses a file with a revolute joint without one),
  at most :data:`MAX_MOVABLE_JOINTS` movable and :data:`MAX_URDF_JOINTS` joints in all; no element of
  :data:`SINGLE_CHILDREN` twice in its parent (MuJoCo refuses a repeat, PyBullet and urdfdom take the first);
  the numbers the engines read and core does not model finite (:data:`READ_BY_ENGINES`: ``<limit effort
  velocity>``, ``<dynamics friction>`` and ``<mimic multiplier offset>`` among them; effort, velocity and friction
  >= 0, as Pinocchio requires); every ``<mimic>`` naming another joint of
  the file; no number subnormal (:data:`core.model.ranges.SMALLEST_NORMAL`).
- The chain is the path from ``base_link`` to ``tip_link``; joints on that path must be
  revolute, continuous (an unlimited revolute joint) or prismatic, or fixed (merged into the
  next movable joint's origin, or into the end-effector transform after the last movable
  joint). A revolute or prismatic joint with lower == upper (a ``<limit>`` without bounds is
  lower = upper = 0; real files have such knees and wheels) loads: no limit acts in joint dynamics
  or motion, and where limits act (sampled configurations, IK) it is held at that value. Names
  on the path (and the robot's) follow
  :data:`core.model.names.NAME_RULE`, numbers on the path the physical ranges of :mod:`core.model.ranges`
  (origins, angles, joint limits, axis norms). Joints off the path may be of any URDF type,
  mimic ones included, and their names and magnitudes are not held to those rules.
- The inertials of links in the base link's subtree must be a complete ``<inertial>`` (``<mass
  value>`` and all six ``<inertia>`` attributes, as urdfdom requires) of finite numbers: a mass of 0
  or within its physical range, inertial origins within theirs, inertia entries no larger than the
  range of moments (tiny ones only as rounding of the link's scale: real files have 1e-35). A mass
  of 0 with a non-zero inertia loads (a rotor's inertia whose mass is counted elsewhere: pybullet_data's Panda flange),
  as it does from a scene file. A link that rides on a chain link must have a physical inertia
  tensor, symmetric with principal moments a <= b <= c, a + b >= c (hence positive semidefinite), judged
  against the link's own scale (:func:`core.dynamics.inertia.link_tensor_problem`: the written
  decimals' rounding and floating point's on the link's inertia about its frame origin); links
  fixed to the base never move and are not held to it (real files have placeholder tensors there).
  A chain joint's ``damping`` is >= 0 and within its physical range. Links outside the base link's
  subtree are not read for mass.

Every refusal about a link or a joint names it and its branch from the tree's root, e.g. ``(link
'head' on the branch root_link > torso_1 > ... > head)``, the middle elided past
:data:`BRANCH_NAMES` links.

Anything else is rejected with a :class:`~core.errors.SceneError` naming the element; nothing is
guessed. A file with a ``<!DOCTYPE>`` (hence any entity declaration) or elements nested deeper than
:data:`core.model.files.MAX_XML_DEPTH` is refused before anything is read from it.

Over 600 lines: one format's reader. Every check (each naming the element and its branch) and the chain
assembled from the file work on the same parsed joints and links.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from simparity.core.dynamics.inertia import LINK_TENSOR_RULE, link_tensor_problem
from simparity.core.model.errors import SceneError, one_line
from simparity.core.model.files import MAX_FILE_BYTES, parse_xml, read_input
from simparity.core.model.names import NAME_RULE, name_problem
from simparity.core.model.ranges import NORM_RANGES, RANGES, SUBNORMAL_RULE, Range, safe_norm, subnormal
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.rotations import rpy_to_matrix

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
    dynamics: bool = False,
    floating_base: bool = False,
    refuse_mass: bool = True,
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
    dynamics : bool
        Whether the chain's dynamics will be computed: then a non-physical inertia tensor on a link riding on a
        chain link is refused (real URDFs have such placeholders, e.g. pybullet_data's xarm6, which kinematics never
        sees: a kinematics or IK scene loads them as before).
    floating_base : bool
        Whether the base link floats free (:attr:`Chain.floating_base`): its rigid group (the base link, the links
        welded to it and the branches off the chain held at 0) is then the chain's ``base_inertia``, held to the
        physical rules as a chain link's (a fixed base's placeholder tensor moves now).
    refuse_mass : bool
        With ``dynamics``: True refuses a non-physical inertia tensor on a moving link (raises); False loads the file
        as written and records the first one as the chain's ``mass_problem`` (the one-line refusal), for a run in
        which the engines that accept the file compute with it and core declines (issue #45: a file is refused
        only where every reader refuses it). A floating base's own rigid group is refused either way: the scene chose
        to float it, and no free body has a non-physical tensor.

    Returns
    -------
    Chain
        Named after ``<robot name>``; one joint per movable joint on the path (with its
        ``link`` mass properties and ``damping``), the end-effector frame named after
        ``tip_link``; ``urdf_path`` is the file (None for text), ``base_link`` the base link's
        name and ``held_joints`` the movable joints below it off the chain, in file order.

    Raises
    ------
    SceneError
        For malformed XML or numbers, a ``<!DOCTYPE>`` (DTDs and entities are refused), elements
        nested deeper than :data:`core.model.files.MAX_XML_DEPTH`, missing links, a link with two parents, several
        roots, an unknown or missing base/tip link, several leaves without ``tip_link``,
        a mimic, floating or planar joint on the path, a joint with lower > upper, a name on the
        path outside :data:`core.model.names.NAME_RULE`, a number on the
        path outside its physical range (:mod:`core.model.ranges`), an incomplete or malformed
        ``<inertial>`` below the base link, a negative mass or damping, a mass, inertia entry or
        inertial origin outside its physical range, a non-physical inertia tensor on a link riding
        on a chain link, or a file that is too large, has too many joints or is not a regular
        file. ``key`` names the element, e.g. ``robot/joint[@name='j3']/mimic`` or
        ``robot/link[@name='l2']/inertial/mass/@value``.
    """
    root, source = _parse(path_or_text, source, max_bytes)
    _check_size(root, source, max_joints)
    _check_single(root, source)
    links = _links(root, source)
    joints = _joints(root, source, links)
    _check_mimics(joints, source)
    parent_joint = _parent_joints(joints, source)
    roots = [name for name in links if name not in parent_joint]
    if len(roots) != 1:
        raise SceneError(source, "robot/link", f"the tree has {len(roots)} root links {roots}",
                         "exactly one link that is no joint's child")
    _check_tree(roots[0], links, joints, source)
    _check_limits(joints, parent_joint, source)
    base = _pick_base(base_link, roots[0], links, source)
    tip = _pick_tip(tip_link, base, links, joints, source)
    path = _path(base, tip, parent_joint, source)
    robot = root.get("name", "")
    if robot and (problem := name_problem(robot)):
        raise SceneError(source, "robot/@name", problem, NAME_RULE)
    chain = _assemble(robot, path, tip, parent_joint, source)
    child_joints = _child_joints(joints)
    inertials = _modelled_inertials(base, links, child_joints, parent_joint, source)
    movable = [joint for joint in path if joint["type"] != "fixed"]
    problems: list[SceneError] = []  # the non-physical tensors met, when they are recorded rather than raised
    held_to = _PhysicalRule(dynamics, refuse_mass, problems)
    chain_joints = tuple(
        replace(chain_joint, link=_rigid_body(joint, following, inertials, child_joints, source, held_to),
                damping=_damping(joint, parent_joint, source))
        for chain_joint, joint, following in zip(chain.joints, movable, movable[1:] + [None]))
    on_path = {joint["name"] for joint in path}
    held = tuple(joint["name"] for joint in joints
                 if joint["type"] != "fixed" and joint["name"] not in on_path and joint["parent"] in inertials)
    is_file = not os.fspath(path_or_text).lstrip().startswith("<")
    base_inertia = (_rigid_body({"child": base}, movable[0], inertials, child_joints, source,
                                _PhysicalRule(True, True, problems), "the floating base")
                    if floating_base else None)
    return replace(chain, joints=chain_joints, held_joints=held, floating_base=floating_base,
                   base_inertia=base_inertia, urdf_path=os.fspath(path_or_text) if is_file else None, base_link=base,
                   mass_problem=f"{problems[0].key}: {problems[0].problem}" if problems else "")


@dataclass(frozen=True)
class _PhysicalRule:
    """How a moving link's non-physical inertia tensor is met: ignored (``held`` False: kinematics), refused
    (``refuse``), or recorded in ``problems`` (the file loads as written)."""

    held: bool
    refuse: bool
    problems: list[SceneError]


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


SINGLE_CHILDREN = {"link": ("inertial",), "inertial": ("origin", "mass", "inertia"),
                   "joint": ("parent", "child", "origin", "axis", "limit", "dynamics", "mimic")}
"""Elements that may appear at most once in their parent element. The engines disagree on a repeat: MuJoCo's URDF
importer refuses the file ("repeated element"), PyBullet's and urdfdom's (Pinocchio's) take the first and ignore the
rest (tried with each: two <inertial>, <origin>, <mass>, <inertia>, <axis>, <limit>, <dynamics>, <mimic>, <parent>,
<child>). A repeat is refused wherever it is in the file, since every engine loads the whole file. ``<visual>`` and
``<collision>`` repeat by design; ``<calibration>`` and ``<safety_controller>`` repeat in every importer."""


def _check_single(root: ET.Element, source: str) -> None:
    """Refuse an element of :data:`SINGLE_CHILDREN` given twice in its parent, naming it and the rule."""
    for kind in ("link", "joint"):
        for i, element in enumerate(root.findall(kind)):
            where = f"robot/{kind}[@name='{one_line(element.get('name') or f'#{i + 1}', 80)}']"
            _single_children(element, SINGLE_CHILDREN[kind], where, source)
            for inertial in element.findall("inertial"):  # a link's one <inertial>, checked above
                _single_children(inertial, SINGLE_CHILDREN["inertial"], f"{where}/inertial", source)


def _single_children(element: ET.Element, tags: tuple[str, ...], where: str, source: str) -> None:
    for tag in tags:
        count = len(element.findall(tag))
        if count > 1:
            raise SceneError(source, f"{where}/{tag}", f"{count} <{tag}> elements in one <{element.tag}> (MuJoCo "
                             "refuses the file, PyBullet and Pinocchio take the first)",
                             f"at most one <{tag}> per <{element.tag}>")


def _links(root: ET.Element, source: str) -> dict[str, ET.Element]:
    """Link name -> its ``<link>`` element, in file order."""
    names: dict[str, ET.Element] = {}
    for i, link in enumerate(root.findall("link")):
        name = link.get("name")
        if not name:
            raise SceneError(source, f"robot/link[{i + 1}]/@name", "missing", "a non-empty link name")
        if name in names:
            raise SceneError(source, f"robot/link[@name='{name}']", "the link name is used twice", "unique names")
        names[name] = link
    return names


def _joints(root: ET.Element, source: str, links: dict[str, ET.Element]) -> list[dict]:
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
        _check_read_by_engines(element, key, source)
        joints.append(joint)
    return joints


READ_BY_ENGINES = {"limit": ("effort", "velocity"), "dynamics": ("damping", "friction"),
                   "mimic": ("multiplier", "offset"), "calibration": ("rising", "falling"),
                   "safety_controller": ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity")}
"""Joint attributes core does not model but the engines' importers read: each must be a finite number (urdfdom, hence
Pinocchio, refuses a file where one is nan, inf or text; MuJoCo refuses text)."""

NON_NEGATIVE = (("limit", "effort"), ("limit", "velocity"), ("dynamics", "friction"))
"""Of those, the ones Pinocchio refuses a file for when negative ("min_effort greater than max_effort")."""

REQUIRED = (("safety_controller", "k_velocity"),)
"""Attributes urdfdom refuses a file without when their element is there."""


def _check_read_by_engines(element: ET.Element, key: str, source: str) -> None:
    """The joint ``element``'s numbers of :data:`READ_BY_ENGINES` as its importers need them (``key``: the joint)."""
    for tag, attributes in READ_BY_ENGINES.items():
        child = element.find(tag)
        for attribute in attributes:
            value = float(_numbers(child, attribute, (0.0,), f"{key}/{tag}", source)[0])
            if (tag, attribute) in NON_NEGATIVE and value < 0:
                raise SceneError(source, f"{key}/{tag}/@{attribute}", f"{value:g} is negative", "a number >= 0")
            if child is not None and (tag, attribute) in REQUIRED and child.get(attribute) is None:
                raise SceneError(source, f"{key}/{tag}/@{attribute}", "missing", f"<{tag} {attribute}='...'> "
                                 "(urdfdom refuses the file without it)")


def _check_mimics(joints: list[dict], source: str) -> None:
    """Every ``<mimic>`` names another joint of the file that moves and mimics none (MuJoCo and urdfdom refuse a mimic
    without a name, MuJoCo one naming its own joint; Pinocchio's mimic model refuses one naming no joint, a fixed joint
    or another mimic, chains and cycles of mimics included; no installed robot file has any of them); its multiplier
    and offset are finite (:data:`READ_BY_ENGINES`). A mimic joint is held at 0 off the chain and refused on it
    (:func:`_assemble`); a fixed joint with a ``<mimic>`` loads (real grippers have it: every importer ignores it)."""
    by_name = {joint["name"]: joint for joint in joints}
    for joint in joints:
        mimic = joint["element"].find("mimic")
        problem = "" if mimic is None else _mimic_problem(joint, mimic.get("joint"), by_name)
        if problem:
            raise SceneError(source, f"{joint['key']}/mimic/@joint", problem,
                             "the name of another revolute, continuous or prismatic <joint> of the file, not a mimic")


def _mimic_problem(joint: dict, name: str | None, by_name: dict[str, dict]) -> str:
    """What is wrong with ``joint``'s ``<mimic joint=name>`` ("" if nothing)."""
    if not name:
        return "names no joint"
    target, shown = by_name.get(name), repr(one_line(name, 80))
    if target is None:
        return f"names joint {shown}, which the file does not have"
    if target is joint:
        return f"names its own joint {shown}"
    if target["type"] not in ("revolute", "continuous", "prismatic"):
        return f"names the {target['type']} joint {shown}, which does not move"
    if target["element"].find("mimic") is not None:
        return f"names joint {shown}, itself a mimic"
    return ""


DECIMAL = re.compile(r"[+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?\Z")
"""A number as every engine's URDF importer reads it alike: ASCII decimal digits, an optional point and exponent.
Python's ``float`` reads more than the engines do, differently: ``1_0`` is 10 to it (MuJoCo refuses it, Pinocchio
reads 0), ``0x10`` is 16 to MuJoCo (Pinocchio: 0), ``infinity`` inf to MuJoCo (Pinocchio: 0), Arabic-Indic digits are
digits to Python only, and a single number followed by a space is 0 to Pinocchio. Numbers of a vector are separated
by spaces (Pinocchio refuses tabs); no installed robot file writes a number any other way."""


def _numbers(element: ET.Element | None, attribute: str, default: tuple[float, ...], key: str,
             source: str) -> np.ndarray:
    """The attribute's numbers (``default`` without it): ``len(default)`` :data:`DECIMAL` numbers, finite, none
    subnormal; a single number without spaces around it."""
    text = None if element is None else element.get(attribute)
    if text is None:
        return np.array(default)
    words = [word for word in text.split(" ") if word]
    if (len(words) != len(default) or not all(DECIMAL.match(word) for word in words)
            or (len(default) == 1 and text != words[0])
            or not np.all(np.isfinite(values := np.array([float(word) for word in words])))):
        raise SceneError(source, f"{key}/@{attribute}", f"malformed number list {text!r}",
                         f"{len(default)} finite decimal numbers (like -1.5e-3) separated by spaces")
    tiny = next((value for value in values if subnormal(value)), None)
    if tiny is not None:
        raise SceneError(source, f"{key}/@{attribute}", f"{tiny:.3g} is a subnormal number", SUBNORMAL_RULE)
    return values


def _limits(element: ET.Element, kind: str, key: str, source: str) -> tuple[float, float]:
    if kind in ("continuous", "fixed", "floating", "planar"):
        return -np.inf, np.inf
    limit = element.find("limit")
    if limit is None:
        raise SceneError(source, f"{key}/limit", f"a {kind} joint has no <limit>",
                         "<limit lower='...' upper='...'/> (use type='continuous' for an unlimited joint)")
    lower, upper = (_numbers(limit, bound, (0.0,), f"{key}/limit", source)[0] for bound in ("lower", "upper"))
    return lower, upper


def _check_limits(joints: list[dict], parent_joint: dict[str, dict], source: str) -> None:
    """Refuse a joint whose lower limit is above its upper one (lower == upper is a joint held at that value where
    limits act: it loads)."""
    for joint in joints:
        lower, upper = joint["limits"]
        if lower > upper:
            raise SceneError(source, f"{joint['key']}/limit", f"lower {lower:g} is above upper {upper:g} "
                             f"({_where(joint, parent_joint)})", "lower <= upper")


BRANCH_NAMES = 8
"""Links a message lists on a branch before eliding its middle: a humanoid's finger is ~15 links from the root,
and a message stays one readable line."""


def _branch(link: str, parent_joint: dict[str, dict]) -> str:
    """The links from the tree's root to ``link`` ('root > a > b'), the middle elided past :data:`BRANCH_NAMES`."""
    names = [link]
    while names[-1] in parent_joint:  # a tree (checked by _check_tree): the walk ends at the root
        names.append(parent_joint[names[-1]]["parent"])
    names = [one_line(name, 40) for name in reversed(names)]
    if len(names) > BRANCH_NAMES:
        names = names[:3] + [f"... {len(names) - 7} more ..."] + names[-4:]
    return " > ".join(names)


def _where(joint: dict, parent_joint: dict[str, dict]) -> str:
    """'joint 'j' on the branch root > ... > its child link', for messages."""
    return f"joint {one_line(joint['name'], 40)!r} on the branch {_branch(joint['child'], parent_joint)}"


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


def _check_tree(root_link: str, links: dict[str, ET.Element], joints: list[dict], source: str) -> None:
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


def _pick_base(base_link: str | None, root_link: str, links: dict[str, ET.Element], source: str) -> str:
    if base_link is None:
        return root_link
    if problem := name_problem(base_link):
        raise SceneError(source, "base_link", problem, NAME_RULE)
    if base_link not in set(links):
        raise SceneError(source, "base_link", f"no link named {base_link!r}", ", ".join(links))
    return base_link


def _pick_tip(tip_link: str | None, base: str, links: dict[str, ET.Element], joints: list[dict], source: str) -> str:
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


def _check_magnitudes(joint: dict, where: str, source: str) -> None:
    """Hold a joint on the chain (``where``: its name and branch, for messages) to the physical ranges of
    :mod:`core.model.ranges`."""
    key = joint["key"]
    for field, range_key, element in _MAGNITUDES:
        allowed = RANGES[range_key]
        for value in joint[field]:
            if not allowed.allows(abs(value)):
                raise SceneError(source, f"{key}/{element}", f"{value:.6g} is outside the physical range ({where})",
                                 allowed.text())
    if joint["type"] == "fixed":
        return
    norm, allowed = safe_norm(joint["axis"]), NORM_RANGES["axis"]
    if not allowed.allows(norm):
        raise SceneError(source, f"{key}/axis/@xyz", f"its norm {norm:.3g} is outside the usable range ({where})",
                         allowed.text())
    for bound, value in zip(("lower", "upper"), joint["limits"]):
        if np.isfinite(value) and not RANGES[bound].allows(abs(value)):
            raise SceneError(source, f"{key}/limit/@{bound}", f"{value:.6g} is outside the physical range ({where})",
                             RANGES[bound].text())


def _assemble(robot_name: str, path: list[dict], tip: str, parent_joint: dict[str, dict], source: str) -> Chain:
    # (position, rotation) of the frame reached so far, in the last movable joint's
    # child-link frame (or the base frame before the first movable joint).
    position, rotation = np.zeros(3), np.eye(3)
    chain_joints: list[Joint] = []
    for joint in path:
        key, where = joint["key"], f"on the chain: {_where(joint, parent_joint)}"
        if joint["type"] not in _CHAIN_JOINT_TYPES:
            raise SceneError(source, f"{key}/@type", f"a {joint['type']} joint ({where})", _ALLOWED_ON_PATH)
        if joint["element"].find("mimic") is not None:
            raise SceneError(source, f"{key}/mimic", f"a mimic joint ({where})", _ALLOWED_ON_PATH)
        for name in (joint["name"], joint["child"]):
            if name_problem(name):
                raise SceneError(source, key, f"{name_problem(name)} ({where})", NAME_RULE)
        _check_magnitudes(joint, where, source)
        position = position + rotation @ joint["xyz"]
        rotation = rotation @ rpy_to_matrix(joint["rpy"])
        if joint["type"] == "fixed":
            continue
        lower, upper = joint["limits"]  # lower == upper: a joint held at that value where limits act (IK, sampling)
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


_INERTIA_ENTRIES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_INERTIA_INDEX = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


@dataclass(frozen=True)
class _Inertial:
    """A link's ``<inertial>`` in the link frame: mass [kg], centre of mass (3,) [m] and inertia (3, 3)
    about it in the link frame's axes [kg m^2] (``R I R^T`` of the inertial frame's); ``problem``: why the
    tensor is not physical ("" if it is), refused only when the link rides on a chain link (``key``: its
    ``<inertia>`` element; ``where``: the link's name and branch)."""

    mass: float
    com_xyz: np.ndarray
    inertia_com: np.ndarray
    key: str = ""
    problem: str = ""
    where: str = ""


def _modelled_inertials(base: str, links: dict[str, ET.Element], children: dict[str, list[dict]],
                        parent_joint: dict[str, dict], source: str) -> dict[str, _Inertial]:
    """Link name -> its checked inertial, for the base link and every link below it (the model)."""
    inertials: dict[str, _Inertial] = {}
    stack = [base]
    while stack:  # a tree (checked by _check_tree): every link is visited once
        link = stack.pop()
        where = f"link {one_line(link, 40)!r} on the branch {_branch(link, parent_joint)}"
        inertials[link] = _inertial(links[link], f"robot/link[@name='{link}']/inertial", where, source)
        stack.extend(joint["child"] for joint in children.get(link, []))
    return inertials


def _child_joints(joints: list[dict]) -> dict[str, list[dict]]:
    """Parent link -> the joints it is the parent of."""
    children: dict[str, list[dict]] = {}
    for joint in joints:
        children.setdefault(joint["parent"], []).append(joint)
    return children


def _inertial(link: ET.Element, key: str, where: str, source: str) -> _Inertial:
    """The link's ``<inertial>`` (massless without one), held to the physical rules; ``where`` (the link's name and
    branch) ends every message. A mass of 0 with a non-zero inertia loads: real files have it (pybullet_data's
    Panda flange, Bolt's feet) and every engine keeps the rotational inertia as written."""
    element = link.find("inertial")
    if element is None:
        return _Inertial(0.0, np.zeros(3), np.zeros((3, 3)))
    origin = element.find("origin")
    xyz = _numbers(origin, "xyz", (0.0, 0.0, 0.0), f"{key}/origin", source)
    rpy = _numbers(origin, "rpy", (0.0, 0.0, 0.0), f"{key}/origin", source)
    for values, attribute, range_key in ((xyz, "xyz", "origin_xyz"), (rpy, "rpy", "origin_rpy")):
        _hold(values, RANGES[range_key], f"{key}/origin/@{attribute}", where, source)
    mass = _required_number(element.find("mass"), "value", f"{key}/mass", where, source)
    if mass < 0:
        raise SceneError(source, f"{key}/mass/@value", f"negative mass {mass:g} ({where})", "a mass >= 0 [kg]")
    if mass != 0:
        _hold(np.array([mass]), RANGES["mass"], f"{key}/mass/@value", where, source)
    inertia, largest = np.zeros((3, 3)), RANGES["inertia_moment"]
    for name, (row, column) in zip(_INERTIA_ENTRIES, _INERTIA_INDEX):
        value = _required_number(element.find("inertia"), name, f"{key}/inertia", where, source)
        if abs(value) > largest.high:  # tiny entries: only as rounding of the link's scale (link_tensor_problem)
            raise SceneError(source, f"{key}/inertia/@{name}", f"{value:.6g} is above the physical range ({where})",
                             largest.text())
        inertia[row, column] = inertia[column, row] = value
    rotation = rpy_to_matrix(rpy)
    return _Inertial(mass, xyz, rotation @ inertia @ rotation.T, f"{key}/inertia",
                     link_tensor_problem(inertia, mass, xyz), where)


def _required_number(element: ET.Element | None, attribute: str, key: str, where: str, source: str) -> float:
    """One finite number that the URDF specification requires (urdfdom refuses a file without it)."""
    if element is None or element.get(attribute) is None:
        missing = key if element is None else f"{key}/@{attribute}"
        raise SceneError(source, missing, f"missing ({where})", "a complete <inertial>: <mass value> and all six "
                         "<inertia> attributes (leave <inertial> out for a massless link)")
    return float(_numbers(element, attribute, (0.0,), key, source)[0])


def _hold(values: np.ndarray, allowed: Range, key: str, where: str, source: str) -> None:
    """Refuse a value whose magnitude is outside ``allowed`` (a :class:`core.model.ranges.Range`)."""
    for value in values:
        if not allowed.allows(abs(value)):
            raise SceneError(source, key, f"{value:.6g} is outside the physical range ({where})", allowed.text())


def _rigid_body(joint: dict, following: dict | None, inertials: dict[str, _Inertial],
                children: dict[str, list[dict]], source: str, rule: _PhysicalRule,
                riding: str = "the chain") -> LinkInertia:
    """Everything rigidly attached to ``joint``'s child link, in its frame: the links below it except the
    subtree of the next chain joint ``following``; every other joint at its zero position (its origin).
    A non-physical inertia tensor among them is met by ``rule``."""
    parts: list[tuple[_Inertial, np.ndarray, np.ndarray]] = []  # (inertial, position, rotation of its link)
    stack = [(joint["child"], np.zeros(3), np.eye(3))]
    while stack:
        link, position, rotation = stack.pop()
        inertial = inertials[link]
        if inertial.problem and rule.held:
            refusal = SceneError(source, inertial.key, f"{inertial.problem} ({inertial.where}, riding on {riding})",
                                 LINK_TENSOR_RULE)
            if rule.refuse:
                raise refusal
            rule.problems.append(refusal)
        parts.append((inertial, position, rotation))
        for child in children.get(link, []):
            if child is not following:
                stack.append((child["child"], position + rotation @ child["xyz"],
                              rotation @ rpy_to_matrix(child["rpy"])))
    mass = float(sum(inertial.mass for inertial, _, _ in parts))
    coms = [position + rotation @ inertial.com_xyz for inertial, position, rotation in parts]
    com = sum((inertial.mass * c for (inertial, _, _), c in zip(parts, coms)), np.zeros(3)) / mass \
        if mass > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for (inertial, _, rotation), c in zip(parts, coms):
        d = c - com  # parallel-axis theorem: m (|d|^2 E - d d^T) about the combined centre of mass
        inertia += rotation @ inertial.inertia_com @ rotation.T + inertial.mass * (d @ d * np.eye(3) - np.outer(d, d))
    return LinkInertia(mass, com, 0.5 * (inertia + inertia.T))


def _damping(joint: dict, parent_joint: dict[str, dict], source: str) -> float:
    """The chain joint's ``<dynamics damping>`` [N m s/rad or N s/m], 0 without one; >= 0 and within its physical
    range (:data:`core.model.ranges.RANGES`)."""
    key = f"{joint['key']}/dynamics"
    damping = float(_numbers(joint["element"].find("dynamics"), "damping", (0.0,), key, source)[0])
    if damping < 0:
        raise SceneError(source, f"{key}/@damping", f"negative damping {damping:g} ({_where(joint, parent_joint)})",
                         "a damping >= 0")
    _hold(np.array([damping]), RANGES["damping"], f"{key}/@damping", _where(joint, parent_joint), source)
    return damping
