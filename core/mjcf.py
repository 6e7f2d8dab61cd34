"""Serial chains from MJCF files (MuJoCo's XML: kinematics and the mass properties dynamics needs), read with the
standard library: core's own reader of the subset robot files use, giving the :class:`~core.model.scenes.chain.Chain`
:func:`core.urdf.chain_from_urdf` gives from a URDF file.

What is read, with MuJoCo 4's semantics: the ``<worldbody>`` tree of ``<body name pos (orientation) childclass>``
(``<frame pos (orientation) childclass>`` elements flattened into their contents); each ``<joint name type pos axis
range limited ref damping armature springdamper class>`` and ``<freejoint>``; each body's ``<inertial pos (orientation)
mass diaginertia|fullinertia>`` or, by ``<compiler inertiafromgeom>``, its ``<geom type size fromto pos (orientation)
mass density group shellinertia class>`` elements; the ``<default>`` classes (nested, ``class`` and ``childclass``) of
those joint and geom attributes; ``<compiler angle eulerseq autolimits inertiafromgeom inertiagrouprange>``; and
``<mujoco model>``, the chain's name. An orientation is one of ``quat`` (w x y z, normalised), ``axisangle``, ``euler``
(the axes of ``eulerseq``: lowercase ones turn with the frame, uppercase ones stay fixed), ``xyaxes`` or ``zaxis``
(the smallest turn of z onto it); angles (``euler``, ``axisangle``, a hinge's ``range`` and ``ref``) are degrees unless
``<compiler angle="radian">``. Sites, cameras, lights, actuators, sensors, tendons, contacts, options and visuals are
not read, nor a joint's ``stiffness``, ``springref`` and ``frictionloss`` or a body's ``gravcomp`` (not modelled: they
load), nor ``alignfree`` (MuJoCo aligns only free bodies without children, never a chain's base).

The chain: the base body (default the worldbody's one child body; ``"world"`` names the worldbody) is fixed at the
world's origin, its frame the world frame (its ``pos`` and orientation ignored; its free joint dropped, its other
joints held), or floats free with ``floating_base``. MuJoCo moves a body with joints k = 1..K as parent frame
``T(pos, R) prod_k [T(p_k) Motion(axis_k, q_k - ref_k) T(-p_k)]`` (``p_k``, ``axis_k``: the joint's ``pos`` and unit
``axis`` in the body frame); core gives each hinge (revolute) or slide (prismatic) joint on the path from the base to
the tip body one :class:`~core.model.scenes.chain.Joint`, its frame at the joint's anchor ``pos`` with the body's axes
turned by ``-ref`` about a hinge's axis (moved by ``-ref`` along a slide's), so that core's q is MuJoCo's qpos (the
file's pose at q = ref). Link k's frame is joint k's moved frame: the body's frame ``T(-p_K)`` from the last joint's
link frame, where the next body's ``pos`` and the end effector are expressed. Several joints in one body are successive
joints with massless links between them; a body on the path without joints is welded (merged into the next joint's
origin, or the end effector). Joint limits follow ``limited`` (``"auto"``: set where ``range`` has lower < upper, with
``<compiler autolimits="true">``), -inf / inf without; ``damping`` (its first coefficient) and ``armature`` are the
chain joint's. ``Chain.held_joints`` are the joints of the base body's subtree not on the chain (but the base's
free joint), in MuJoCo's order (bodies depth first, each body's joints as written): they are welded at the file's pose
(q = ref; a ball or free joint at its identity).

Each chain joint's ``link`` is the last joint's body in its link frame with everything rigid with it: the bodies
welded to it on the path, and every body below it off the path (held joints at the file's pose). A body's mass
properties are its ``<inertial>`` or the sum of its geoms counted by ``inertiagrouprange`` (:mod:`core.mjcf_inertia`:
a geom's ``mass``, or ``density`` (1000) times its volume), by ``inertiafromgeom``: ``"auto"`` the ``<inertial>`` where
there is one, ``"true"`` the geoms where one counts (MuJoCo 4 keeps the ``<inertial>`` of a body without), ``"false"``
the ``<inertial>`` or none (massless). All are combined exactly (total mass, mass-weighted centre of mass, the
parallel-axis theorem), as from a URDF file.

The rules: every number read is a decimal (:data:`core.urdf.DECIMAL`), finite and not subnormal, positions within
:data:`core.model.ranges.RANGES`' ``origin_xyz``, angles within ``origin_rpy``, the norm of a quaternion and of an axis
within :data:`core.model.ranges.NORM_RANGES`; a chain joint's limits and ``ref`` within ``lower``/``upper`` and ``q``,
its ``damping`` and ``armature`` >= 0 within theirs; masses >= 0 (a body's within ``mass``), inertia entries up to the
largest moment, and for ``dynamics`` a physical tensor on every body riding on a chain link
(:func:`core.dynamics.inertia.link_tensor_problem`; recorded as ``Chain.mass_problem`` instead without
``refuse_mass``). Bodies and joints on the path are named after :data:`core.model.names.NAME_RULE`; held joints are
named. Refused with a one-line :class:`~core.errors.SceneError` naming the element, as unsupported by core's reader or
as MuJoCo 4 refuses them: ``<include>``, ``<compiler coordinate="global">``, ``fusestatic``, ``boundmass``,
``boundinertia``, ``settotalmass``, ``balanceinertia``, ``exactmeshinertia``, a ``<frame>`` that scales,
``<replicate>``, ``<attach>``, ``<flexcomp>`` or any element of the tree besides those read and ``<site>``,
``<camera>``, ``<light>``; a ball or free joint on the path, a joint coupled
by an ``<equality><joint>``, polynomial damping, ``springdamper`` (it sets the damping from the inertia); a mesh,
sdf, height-field or plane geom, a geom fitted to a mesh or with ``shellinertia`` whose inertia would be inferred;
several orientations on one element, an ``<inertial>`` without ``pos``, ``mass`` or an inertia, a reversed ``range``
on the chain, unknown or repeated default classes and names; a file with a ``<!DOCTYPE>``, nested deeper than
:data:`core.model.files.MAX_XML_DEPTH`, larger than ``max_bytes``, with more than ``max_joints`` joints or
:data:`MAX_MJCF_BODIES` bodies, :data:`MAX_MJCF_GEOMS` geoms or default classes nested deeper than
:data:`MAX_DEFAULT_DEPTH`. Nothing is guessed.

Over 600 lines: one format's reader (its mass properties apart, in :mod:`core.mjcf_inertia`); every check names its
element, and the chain is assembled from the same parsed tree.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace

import numpy as np
from simparity.core.dynamics.inertia import LINK_TENSOR_RULE
from simparity.core.mjcf_inertia import (ANY, INTEGER, ORIENTATIONS, BodyMass, Layers, combine, counted,
                                         geoms_mass, inertial_mass, z_to)
from simparity.core.model.errors import SceneError, one_line
from simparity.core.model.files import MAX_FILE_BYTES, parse_xml, read_input
from simparity.core.model.names import NAME_RULE, name_problem
from simparity.core.model.ranges import NORM_RANGES, RANGES, SUBNORMAL_RULE, Range, safe_norm, subnormal
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.rotations import quat_wxyz_to_matrix, so3_exp
from simparity.core.urdf import BRANCH_NAMES, DECIMAL, MAX_MOVABLE_JOINTS, MAX_URDF_JOINTS

MAX_MJCF_BODIES = MAX_URDF_JOINTS + 1
"""``<body>`` elements an MJCF file may have: as many as a URDF file's links (:data:`core.urdf.MAX_URDF_JOINTS` + 1)."""

MAX_MJCF_GEOMS = 10 * MAX_MJCF_BODIES
"""``<geom>`` elements an MJCF file may have: a body's inferred mass reads each (200,000 geoms took 22 s and 750 MB);
real robots have tens to hundreds (dm_control's dog: ~300)."""
MAX_DEFAULT_DEPTH = 16
"""``<default>`` classes nested at most this deep: each joint and geom read carries its class's chain of defaults, so
depth times elements is the reader's work and memory (a 145 KB file of 90 nested classes and 20,000 geoms took 37 s and
2 GB); real files nest 2 to 5 deep (dm_control's humanoid_CMU: 3)."""
MJCF_JOINT_TYPES = ("hinge", "slide", "ball", "free")
_CHAIN_TYPES = {"hinge": "revolute", "slide": "prismatic"}
_ON_PATH = "hinge or slide joints (a chain's joints are revolute or prismatic)"
_IGNORED = ("site", "camera", "light")
_LENGTH, _ANGLE = RANGES["origin_xyz"], RANGES["origin_rpy"]
_DIRECTION = Range(NORM_RANGES["axis"].low, NORM_RANGES["axis"].high, "", "a direction (an axis, zaxis, xyaxes) is "
                   "normalised on loading; its norm must survive that")
_COMPILER_OFF = {"boundmass": "bounds every body's mass from below", "boundinertia": "bounds every body's inertia "
                 "from below", "settotalmass": "scales every body's mass"}
"""Compiler attributes that change the masses the file gives when positive, which core does not mirror."""


@dataclass(frozen=True)
class _Settings:
    """``<compiler>``: ``radian`` [rad] per written angle unit, the euler axes, autolimits, inertiafromgeom and the
    geom groups whose inertia counts."""

    radian: float = np.pi / 180
    eulerseq: str = "xyz"
    autolimits: bool = True
    inertiafromgeom: str = "auto"
    groups: tuple[int, int] = (0, 5)


@dataclass(frozen=True)
class _Placed:
    """An element of the tree (a body in its parent, or a joint or geom in its body): its key and defaults class,
    and the frame it sits in (``<frame>`` elements flattened) in its parent body's frame."""

    element: ET.Element
    key: str
    cls: str
    xyz: np.ndarray
    rotation: np.ndarray


@dataclass
class _Body:
    """A body of the tree (index 0: the worldbody): its name ("" without one), key, parent index (-1 for the world),
    placement, child bodies, joints (with their types) and geoms, in the order written."""

    name: str
    key: str
    parent: int
    placed: _Placed | None
    children: list[int] = field(default_factory=list)
    joints: list[_Placed] = field(default_factory=list)
    kinds: list[str] = field(default_factory=list)
    geoms: list[_Placed] = field(default_factory=list)
    inertial: _Placed | None = None


def chain_from_mjcf(
    path_or_text: str | os.PathLike,
    base_body: str | None = None,
    tip_body: str | None = None,
    source: str | None = None,
    max_joints: int = MAX_MOVABLE_JOINTS,
    max_bytes: int = MAX_FILE_BYTES,
    dynamics: bool = False,
    floating_base: bool = False,
    refuse_mass: bool = True,
) -> Chain:
    """Build the serial :class:`~core.scene.Chain` from ``base_body`` to ``tip_body`` of an MJCF file.

    Parameters
    ----------
    path_or_text : str or path-like
        An MJCF file, or the MJCF text itself (a string whose first non-blank character is ``<``).
    base_body : str, optional
        The body whose frame is the world frame; default the worldbody's one child body; ``"world"``: the worldbody.
    tip_body : str, optional
        The body whose frame is the end effector; default the unique leaf body below ``base_body`` (an error when
        there are several).
    source : str, optional
        Name reported in errors; default the file path, or ``"<mjcf text>"``.
    max_joints : int
        Largest number of joints (free ones included) in the file (and so on the chain).
    max_bytes : int
        Largest size of the file accepted [bytes].
    dynamics : bool
        Whether the chain's dynamics will be computed: then a non-physical inertia tensor on a body riding on a chain
        link is refused.
    floating_base : bool
        Whether the base body floats free (:attr:`Chain.floating_base`): its rigid group (the base body, the bodies
        welded to it and the branches off the chain held) is then the chain's ``base_inertia``, held to the physical
        rules as a chain link's.
    refuse_mass : bool
        With ``dynamics``: True refuses a non-physical inertia tensor on a moving body (raises); False loads the file
        as written and records the first one as the chain's ``mass_problem`` (the one-line refusal), as
        :func:`core.urdf.chain_from_urdf` does. A floating base's own rigid group is refused either way.

    Returns
    -------
    Chain
        Named after ``<mujoco model>``; one joint per hinge or slide joint on the path (with its ``link`` mass
        properties, ``damping`` and ``armature``), the end-effector frame named after ``tip_body``; ``mjcf_path`` is
        the file (None for text), ``base_link`` the base body's name, ``held_joints`` the joints below it off the
        chain, in MuJoCo's order, and ``mass_problem`` the first non-physical tensor met without ``refuse_mass``.

    Raises
    ------
    SceneError
        For anything the module docstring refuses; ``key`` names the element, e.g.
        ``mujoco/worldbody//body[@name='thigh']/joint[@name='hip']/@range``.
    """
    text = os.fspath(path_or_text)
    is_text = text.lstrip().startswith("<")
    source = source or ("<mjcf text>" if is_text else text)
    root = parse_xml(text if is_text else read_input(text, max_bytes, "MJCF file"), source, "mujoco")
    reader = _Reader(root, source, max_joints)
    base = reader.pick_base(base_body)
    tip = reader.pick_tip(tip_body, base)
    path = reader.path(base, tip)
    name = root.get("model", "")
    name = "" if name_problem(name) else name  # a label only: a model named outside the rule (with a space) is unnamed
    chain = reader.assemble(name, path, tip)
    on_chain = {joint.name for joint in chain.joints}
    reader.check_couplings(on_chain)
    jointed = [index for index in path if reader.bodies[index].joints]
    problems: list[SceneError] = []  # the non-physical tensors met, when they are recorded rather than raised
    links: list[LinkInertia] = []
    for index, following in zip(jointed, jointed[1:] + [-1]):
        count, anchor = len(reader.bodies[index].joints), reader.anchor(reader.bodies[index].joints[-1])
        links += [LinkInertia.massless()] * (count - 1) + [
            reader.rigid_group(index, following, _PhysicalRule(dynamics, refuse_mass, problems), anchor)]
    base_inertia = None
    if floating_base:
        if base == 0:
            raise SceneError(source, "base_body", "the worldbody cannot float", "a body of the file")
        base_inertia = reader.rigid_group(base, jointed[0], _PhysicalRule(True, True, problems), np.zeros(3),
                                          "the floating base")
    joints = tuple(replace(joint, link=link) for joint, link in zip(chain.joints, links))
    return replace(chain, joints=joints, held_joints=reader.held(base, on_chain), floating_base=floating_base,
                   base_inertia=base_inertia, mjcf_path=None if is_text else text, base_link=reader.bodies[base].name,
                   mass_problem=f"{problems[0].key}: {problems[0].problem}" if problems else "")


@dataclass(frozen=True)
class _PhysicalRule:
    """How a moving body's non-physical inertia tensor is met (as :mod:`core.urdf` meets a link's): ignored (``held``
    False: kinematics), refused (``refuse``), or recorded in ``problems`` (the file loads as written)."""

    held: bool
    refuse: bool
    problems: list[SceneError]


class _Reader:
    """One MJCF file's tree, compiler settings and default classes, and the values read from them (``source``: the
    file's name in errors)."""

    def __init__(self, root: ET.Element, source: str, max_joints: int) -> None:
        self.source = source
        if root.find(".//include") is not None:
            raise SceneError(source, "mujoco//include", "an <include> (core's reader reads one file)",
                             "one file without <include>")
        worlds = root.findall("worldbody")
        self._check_size(worlds, max_joints)
        self.settings = self._compiler(root)
        self.classes: dict[str, Layers] = {}
        self._defaults(root)
        self.bodies = [_Body("world", "mujoco/worldbody", -1, None)]
        for i, world in enumerate(worlds):
            key = "mujoco/worldbody" if len(worlds) == 1 else f"mujoco/worldbody[{i + 1}]"
            self._walk(world, key, 0, "main", np.zeros(3), np.eye(3))
        self._check_names()
        self.root = root
        self._masses: dict[int, BodyMass] = {}

    # --- the file's structure -------------------------------------------------------------------------------------

    def _check_size(self, worlds: list[ET.Element], max_joints: int) -> None:
        """Refuse a file with more joints or bodies than any engine should be given (before reading them)."""
        joints = sum(1 for world in worlds for element in world.iter() if element.tag in ("joint", "freejoint"))
        if joints > max_joints:
            raise SceneError(self.source, "mujoco/worldbody//joint", f"the file has {joints:,} joints",
                             f"at most {max_joints:,}; simparity run --max-joints N raises it")
        bodies = sum(1 for world in worlds for _ in world.iter("body"))
        if bodies > MAX_MJCF_BODIES:
            raise SceneError(self.source, "mujoco/worldbody//body", f"the file has {bodies:,} <body> elements",
                             f"at most {MAX_MJCF_BODIES:,} (a fixed limit)")
        geoms = sum(1 for world in worlds for _ in world.iter("geom"))
        if geoms > MAX_MJCF_GEOMS:
            raise SceneError(self.source, "mujoco/worldbody//geom", f"the file has {geoms:,} <geom> elements",
                             f"at most {MAX_MJCF_GEOMS:,} (a fixed limit)")

    def _compiler(self, root: ET.Element) -> _Settings:
        """The ``<compiler>`` settings core reads (later elements override earlier ones, as in MuJoCo), refusing those
        that change the file's kinematics or masses in ways core does not mirror."""
        settings = _Settings()
        keywords = {"angle": ("degree", "radian"), "autolimits": ("true", "false"), "coordinate": ("local",),
                    "inertiafromgeom": ("true", "false", "auto"), "fusestatic": ("false",),
                    "balanceinertia": ("false",)}
        compilers = root.findall("compiler")
        for i, compiler in enumerate(compilers):
            key = "mujoco/compiler" if len(compilers) == 1 else f"mujoco/compiler[{i + 1}]"
            for attribute, allowed in keywords.items():
                value = compiler.get(attribute)
                if value is not None and value not in allowed:
                    problem = {"global": "global coordinates (MuJoCo 4 refuses them too: 'no longer supported')",
                               "true": "a compiler option that changes the bodies or masses (unsupported by core's "
                                       "reader)"}.get(value, f"unknown value {value!r}")
                    raise SceneError(self.source, f"{key}/@{attribute}", problem, ", ".join(allowed))
            for attribute, what in _COMPILER_OFF.items():
                if (value := compiler.get(attribute)) is not None and self.number(value, f"{key}/@{attribute}",
                                                                                 ANY)[0] > 0:
                    raise SceneError(self.source, f"{key}/@{attribute}", f"a positive value {what} (unsupported by "
                                     "core's reader)", "0 or less (off)")
            if compiler.get("exactmeshinertia") is not None:
                raise SceneError(self.source, f"{key}/@exactmeshinertia", "mesh inertia (unsupported by core's "
                                 "reader; MuJoCo 4 refuses the attribute)", "no exactmeshinertia")
            angle, sequence, groups = compiler.get("angle"), compiler.get("eulerseq"), compiler.get("inertiagrouprange")
            if sequence is not None and (len(sequence) != 3 or any(axis not in "xyzXYZ" for axis in sequence)):
                raise SceneError(self.source, f"{key}/@eulerseq", f"{sequence!r}", "3 of x, y, z (turning with the "
                                 "frame) or X, Y, Z (fixed)")
            if groups is not None and (len(groups.split()) != 2 or not all(map(INTEGER.match, groups.split()))):
                raise SceneError(self.source, f"{key}/@inertiagrouprange", f"malformed {groups!r}", "2 integers")
            limits = compiler.get("autolimits")
            settings = _Settings(
                radian=settings.radian if angle is None else np.pi / 180 if angle == "degree" else 1.0,
                eulerseq=sequence or settings.eulerseq,
                autolimits=settings.autolimits if limits is None else limits == "true",
                inertiafromgeom=compiler.get("inertiafromgeom") or settings.inertiafromgeom,
                groups=settings.groups if groups is None else (int(groups.split()[0]), int(groups.split()[1])))
        return settings

    def _defaults(self, root: ET.Element) -> None:
        """The default classes: name -> the ``<default>`` elements it inherits from, outermost first. A class
        inherits what its parent holds where it is defined: a nested class, the top-level ``<default>`` elements up
        to its own (MuJoCo merges them all into "main")."""
        tops = root.findall("default")
        for i, top in enumerate(tops):
            key = "mujoco/default" if len(tops) == 1 else f"mujoco/default[{i + 1}]"
            if top.get("class", "main") != "main":
                raise SceneError(self.source, f"{key}/@class", "the top-level default class renamed (MuJoCo 4 "
                                 "refuses it)", "main, or no class")
            self._classes(top, key, [(element, f"mujoco/default[{j + 1}]" if len(tops) > 1 else key)
                                     for j, element in enumerate(tops[:i + 1])])
        self.classes["main"] = [(top, f"mujoco/default[{j + 1}]" if len(tops) > 1 else "mujoco/default")
                                for j, top in enumerate(tops)]

    def _classes(self, element: ET.Element, key: str, chain: Layers) -> None:
        if len(chain) > MAX_DEFAULT_DEPTH:
            raise SceneError(self.source, key, f"default classes nested {len(chain)} deep",
                             f"at most {MAX_DEFAULT_DEPTH} (every element read carries its class's chain)")
        for tag in ("joint", "geom"):
            if len(element.findall(tag)) > 1:
                raise SceneError(self.source, f"{key}/{tag}", f"several <{tag}> in one <default>", "at most one")
        for child in element.findall("default"):
            name = child.get("class")
            child_key = f"{key}/default[@class='{one_line(name or '', 80)}']"
            if not name or name == "main" or name in self.classes:
                raise SceneError(self.source, f"{child_key}/@class", "a missing or repeated class name",
                                 "a class name used once, not main")
            self.classes[name] = chain + [(child, child_key)]
            self._classes(child, child_key, chain + [(child, child_key)])

    def _walk(self, element: ET.Element, key: str, body: int, cls: str, xyz: np.ndarray, rotation: np.ndarray) -> None:
        """Read the contents of a body (or frame) ``element`` into :attr:`bodies`: ``cls`` is its childclass, (``xyz``,
        ``rotation``) the frame its contents sit in, in body ``body``'s frame."""
        counts: dict[str, int] = {}
        for child in element:
            tag = child.tag
            counts[tag] = counts.get(tag, 0) + 1
            name = child.get("name")
            child_key = (f"{key}/{tag}[@name='{one_line(name, 80)}']" if name else f"{key}/{tag}"
                         if tag == "inertial" else f"{key}/{tag}[{counts[tag]}]")
            own = child.get("class")
            if own is not None and own not in self.classes:
                raise SceneError(self.source, f"{child_key}/@class", f"no default class {own!r}",
                                 ", ".join(self.classes) or "a class of <default>")
            placed = _Placed(child, child_key, own or cls, xyz, rotation)
            if tag in ("body", "frame"):
                inner = child.get("childclass") or (own if tag == "frame" else None) or cls
                if inner not in self.classes:
                    raise SceneError(self.source, f"{child_key}/@childclass", f"no default class {inner!r}",
                                     ", ".join(self.classes) or "a class of <default>")
                if tag == "frame":
                    for attribute in ("scale", "massscale", "scaling"):
                        if child.get(attribute) is not None:
                            raise SceneError(self.source, f"{child_key}/@{attribute}", "a frame that scales its "
                                             "contents (unsupported by core's reader)", "a frame without it")
                    frame_xyz, frame_rotation = self.pose([(child, child_key)])
                    self._walk(child, child_key, body, inner, xyz + rotation @ frame_xyz, rotation @ frame_rotation)
                    continue
                if name:
                    child_key = (f"mujoco/worldbody{'/' if element.tag == 'worldbody' else '//'}"
                                 f"body[@name='{one_line(name, 80)}']")
                self.bodies.append(_Body(name or "", child_key, body, replace(placed, key=child_key)))
                self.bodies[body].children.append(len(self.bodies) - 1)
                self._walk(child, child_key, len(self.bodies) - 1, inner, np.zeros(3), np.eye(3))
            elif tag in ("joint", "freejoint", "inertial") and body == 0:
                raise SceneError(self.source, child_key, f"a <{tag}> in the worldbody",
                                 "joints and inertials in bodies")
            elif tag in ("joint", "freejoint"):
                kind = "free" if tag == "freejoint" else self.keyword(self.layers("joint", placed), "type", "hinge",
                                                                        MJCF_JOINT_TYPES)
                self.bodies[body].joints.append(placed)
                self.bodies[body].kinds.append(kind)
            elif tag == "geom":
                self.bodies[body].geoms.append(placed)
            elif tag == "inertial":
                if self.bodies[body].inertial is not None:
                    raise SceneError(self.source, child_key, "a second <inertial> in one body", "at most one")
                self.bodies[body].inertial = placed
            elif tag not in _IGNORED:
                raise SceneError(self.source, child_key, f"a <{tag}> element (unsupported by core's reader)",
                                 "body, frame, joint, freejoint, geom, inertial, site, camera, light")

    def _check_names(self) -> None:
        """Body names, and joint names, are unique (MuJoCo refuses a repeat; the worldbody is named "world")."""
        for what, named in (("body", [(b.name, b.key) for b in self.bodies]),
                            ("joint", [(j.element.get("name"), j.key) for b in self.bodies for j in b.joints])):
            seen: set[str] = set()
            for name, key in named:
                if name and name in seen:
                    raise SceneError(self.source, key, f"the {what} name {name!r} is used twice", "unique names")
                seen.add(name or "")

    def check_couplings(self, on_chain: set[str]) -> None:
        """Refuse an ``<equality><joint>`` coupling a chain joint (MJCF's mimic joint: the chain's joints are free)."""
        for i, equality in enumerate(self.root.iter("equality")):
            for coupling in equality.findall("joint"):
                for attribute in ("joint1", "joint2"):
                    if coupling.get(attribute) in on_chain:
                        raise SceneError(self.source, f"mujoco/equality/joint/@{attribute}", f"couples the chain joint "
                                         f"{coupling.get(attribute)!r}", "equality constraints on joints off the chain")

    # --- attributes -------------------------------------------------------------------------------------------------

    def layers(self, tag: str, placed: _Placed) -> Layers:
        """The elements setting a ``<tag>`` element's attributes, weakest first: its default class's ``<tag>`` (and
        those it inherits), then the element itself."""
        layers = [(found, f"{key}/{tag}") for element, key in self.classes[placed.cls]
                  if (found := element.find(tag)) is not None]
        return layers + [(placed.element, placed.key)]

    def text(self, layers: Layers, attribute: str) -> tuple[str, str] | None:
        """(the attribute's text, its key) from the strongest layer that sets it, or None."""
        for element, key in reversed(layers):
            if element.get(attribute) is not None:
                return element.get(attribute, ""), f"{key}/@{attribute}"
        return None

    def keyword(self, layers: Layers, attribute: str, default: str, allowed: tuple) -> str:
        found = self.text(layers, attribute)
        if found is not None and found[0] not in allowed:
            raise SceneError(self.source, found[1], f"unknown value {found[0]!r}", ", ".join(allowed))
        return default if found is None else found[0]

    def number(self, text: str, key: str, allowed: Range, count: tuple[int, int] = (1, 1)) -> np.ndarray:
        """The numbers of ``text`` (between ``count`` of them, separated by white space): :data:`core.urdf.DECIMAL`,
        finite, not subnormal, their magnitudes within ``allowed``."""
        words = text.split()
        if not (count[0] <= len(words) <= count[1] and all(DECIMAL.match(word) for word in words)
                and np.all(np.isfinite(values := np.array([float(word) for word in words])))):
            many = count[0] if count[0] == count[1] else f"{count[0]} to {count[1]}"
            raise SceneError(self.source, key, f"malformed number list {text!r}",
                             f"{many} finite decimal numbers (like -1.5e-3) separated by spaces")
        tiny = next((value for value in values if subnormal(value)), None)
        if tiny is not None:
            raise SceneError(self.source, key, f"{tiny:.3g} is a subnormal number", SUBNORMAL_RULE)
        for value in values:
            if not allowed.allows(abs(value)):
                raise SceneError(self.source, key, f"{value:.6g} is outside the physical range", allowed.text())
        return values

    def vector(self, layers: Layers, attribute: str, default: tuple[float, ...],
               allowed: Range, partial: bool = False) -> np.ndarray:
        """The attribute's ``len(default)`` numbers (``default`` where no layer sets it); ``partial``: a layer may give
        fewer, which replace the first ones (MuJoCo's ``size`` and ``damping``)."""
        values = np.array(default, dtype=float)
        setting = [(element, key) for element, key in layers if element.get(attribute) is not None]
        for element, key in setting if partial else setting[-1:]:
            read = self.number(element.get(attribute, ""), f"{key}/@{attribute}", allowed,
                               (1 if partial else len(default), len(default)))
            values[:len(read)] = read
        return values

    def pose(self, layers: Layers) -> tuple[np.ndarray, np.ndarray]:
        """(``pos`` (3,) [m], rotation (3, 3)) of an element, its orientation from the strongest layer giving one."""
        xyz = self.vector(layers, "pos", (0.0, 0.0, 0.0), _LENGTH)
        for element, key in reversed(layers):
            given = [attribute for attribute in ORIENTATIONS if element.get(attribute) is not None]
            if len(given) > 1:
                raise SceneError(self.source, f"{key}/@{given[1]}", f"several orientations ({', '.join(given)})",
                                 "at most one of quat, axisangle, euler, xyaxes, zaxis (MuJoCo refuses several)")
            if given:
                return xyz, self._rotation(element.get(given[0], ""), given[0], f"{key}/@{given[0]}")
        return xyz, np.eye(3)

    def _rotation(self, text: str, kind: str, key: str) -> np.ndarray:
        """The rotation an orientation attribute gives (MuJoCo's conversions; angles in the compiler's unit)."""
        sizes = {"quat": 4, "axisangle": 4, "euler": 3, "xyaxes": 6, "zaxis": 3}
        values = self.number(text, key, ANY, (sizes[kind], sizes[kind]))
        if kind == "euler":
            angles = values * self.settings.radian
            self.hold(angles, _ANGLE, key)
            rotation = np.eye(3)
            for axis, angle in zip(self.settings.eulerseq, angles):
                turn = so3_exp(angle * np.eye(3)["xyz".index(axis.lower())])
                rotation = rotation @ turn if axis.islower() else turn @ rotation
            return rotation
        if kind == "axisangle":
            self.hold(values[3:] * self.settings.radian, _ANGLE, key)
            return so3_exp(self._unit(values[:3], key) * values[3] * self.settings.radian)
        if kind == "quat":
            return quat_wxyz_to_matrix(values / self._norm(values, NORM_RANGES["quat_wxyz"], key))
        if kind == "zaxis":
            return z_to(self._unit(values, key))
        x = self._unit(values[:3], key)
        y = self._unit(values[3:] - x * (x @ values[3:]), key)
        return np.column_stack([x, y, np.cross(x, y)])

    def _norm(self, vector: np.ndarray, allowed: Range, key: str) -> float:
        norm = safe_norm(vector)
        if not allowed.allows(norm):
            raise SceneError(self.source, key, f"its norm {norm:.3g} is outside the usable range", allowed.text())
        return norm

    def _unit(self, vector: np.ndarray, key: str) -> np.ndarray:
        return vector / self._norm(vector, _DIRECTION, key)

    def hold(self, values: np.ndarray, allowed: Range, key: str) -> None:
        for value in values:
            if not allowed.allows(abs(value)):
                raise SceneError(self.source, key, f"{value:.6g} is outside the physical range", allowed.text())

    def key(self, layers: Layers, attribute: str) -> str:
        """The key of the attribute where the strongest layer sets it (the element's own where none does)."""
        found = self.text(layers, attribute)
        return found[1] if found is not None else f"{layers[-1][1]}/@{attribute}"

    # --- the chain --------------------------------------------------------------------------------------------------

    def pick_base(self, base_body: str | None) -> int:
        if base_body is None:
            tops = self.bodies[0].children
            if len(tops) != 1:
                raise SceneError(self.source, "base_body", f"the worldbody has {len(tops)} child bodies "
                                 f"{[self._label(i) for i in tops]} and no base_body was given",
                                 "one of their names (or world)")
            return tops[0]
        return self._find(base_body, "base_body")

    def pick_tip(self, tip_body: str | None, base: int) -> int:
        if tip_body is not None:
            return self._find(tip_body, "tip_body")
        leaves, stack = [], [base]
        while stack:  # a tree: every body is visited once
            index = stack.pop()
            stack.extend(self.bodies[index].children)
            if not self.bodies[index].children:
                leaves.append(index)
        if len(leaves) != 1:
            raise SceneError(self.source, "tip_body", f"body {self._label(base)!r} has {len(leaves)} leaf bodies "
                             f"below it {sorted(self._label(i) for i in leaves)} and no tip_body was given",
                             "one of the leaf body names")
        return leaves[0]

    def _find(self, name: str, what: str) -> int:
        if problem := name_problem(name):
            raise SceneError(self.source, what, problem, NAME_RULE)
        for index, body in enumerate(self.bodies):
            if body.name == name:
                return index
        raise SceneError(self.source, what, f"no body named {name!r}", ", ".join(b.name for b in self.bodies if b.name))

    def path(self, base: int, tip: int) -> list[int]:
        """The bodies from the base (excluded) to the tip (included)."""
        path, index = [], tip
        while index != base:
            if index <= 0:
                raise SceneError(self.source, "tip_body", f"body {self._label(tip)!r} is not below base body "
                                 f"{self._label(base)!r}", f"a body in the subtree of {self._label(base)!r}")
            path.append(index)
            index = self.bodies[index].parent
        for index in (base, *path):
            body = self.bodies[index]
            if problem := name_problem(body.name):
                raise SceneError(self.source, body.key, f"{problem} ({self._where(index)}, on the chain)", NAME_RULE)
        return path[::-1]

    def assemble(self, name: str, path: list[int], tip: int) -> Chain:
        """The chain's joints and end effector (massless links: :meth:`rigid_group` gives them)."""
        # (position, rotation) of the frame reached so far, in the last chain joint's link frame (or the base's)
        position, rotation = np.zeros(3), np.eye(3)
        joints: list[Joint] = []
        for index in path:
            xyz, turn = self.body_pose(index)
            position, rotation = position + rotation @ xyz, rotation @ turn
            for placed, kind in zip(self.bodies[index].joints, self.bodies[index].kinds):
                where = f"on the chain: {self._where(index)}"
                if kind not in _CHAIN_TYPES:
                    raise SceneError(self.source, self.key(self.layers("joint", placed), "type"),
                                     f"a {kind} joint ({where})", _ON_PATH)
                joint_name = placed.element.get("name", "")
                if problem := name_problem(joint_name):
                    raise SceneError(self.source, placed.key, f"{problem} ({where})", NAME_RULE)
                joints.append(self._joint(placed, kind, joint_name, position, rotation))
                position, rotation = -self.anchor(placed), np.eye(3)
        if not joints:
            raise SceneError(self.source, "tip_body", f"no hinge or slide joint between the base and "
                             f"{self._label(tip)!r}", "a path with at least one hinge or slide joint")
        return Chain(name, tuple(joints), end_effector_name=self.bodies[tip].name, end_effector_xyz=position,
                     end_effector_rotation=rotation)

    def body_pose(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """(position (3,) [m], rotation (3, 3)) of body ``index``'s frame in its parent's, its joints at the file's
        pose."""
        placed = self.bodies[index].placed
        assert placed is not None  # the worldbody is no one's child
        xyz, rotation = self.pose([(placed.element, placed.key)])
        return placed.xyz + placed.rotation @ xyz, placed.rotation @ rotation

    def anchor(self, placed: _Placed) -> np.ndarray:
        """(3,) A joint's ``pos`` in its body's frame [m]."""
        return placed.xyz + placed.rotation @ self.vector(self.layers("joint", placed), "pos", (0.0, 0.0, 0.0), _LENGTH)

    def _joint(self, placed: _Placed, kind: str, name: str, position: np.ndarray, rotation: np.ndarray) -> Joint:
        """The chain joint of a hinge or slide ``placed`` whose body frame is at (``position``, ``rotation``) in the
        previous link's frame: its frame at the anchor, turned (moved) by -ref, so that q = MuJoCo's qpos."""
        layers = self.layers("joint", placed)
        unit = self.settings.radian if kind == "hinge" else 1.0
        axis = placed.rotation @ self._unit(self.vector(layers, "axis", (0.0, 0.0, 1.0), ANY), self.key(layers, "axis"))
        ref = float(self.vector(layers, "ref", (0.0,), ANY)[0]) * unit
        self.hold(np.array([ref]), RANGES["q"], self.key(layers, "ref"))
        origin, turn = position + rotation @ self.anchor(placed), rotation
        if kind == "hinge":
            turn = rotation @ so3_exp(-ref * axis)
        else:
            origin = origin - ref * (rotation @ axis)
        lower, upper = self._limits(layers, unit)
        damping = self.vector(layers, "damping", (0.0, 0.0, 0.0), ANY, partial=True)
        armature = float(self.vector(layers, "armature", (0.0,), ANY)[0])
        for value, what in ((damping[0], "damping"), (armature, "armature")):
            if value < 0:
                raise SceneError(self.source, self.key(layers, what), f"negative {what} {value:g}", f"a {what} >= 0")
            self.hold(np.array([value]), RANGES[what], self.key(layers, what))
        if np.any(damping[1:]):
            raise SceneError(self.source, self.key(layers, "damping"), "polynomial damping (not modelled)",
                             "one coefficient: the viscous damping [N m s/rad or N s/m]")
        if np.all(self.vector(layers, "springdamper", (0.0, 0.0), ANY) > 0):
            raise SceneError(self.source, self.key(layers, "springdamper"), "springdamper sets the damping from the "
                             "model's inertia (unsupported by core's reader)", "no springdamper on a chain joint")
        return Joint(name=name, type=_CHAIN_TYPES[kind], axis=axis, origin_xyz=origin, origin_rotation=turn,
                     lower=lower, upper=upper, damping=float(damping[0]), armature=armature)

    def _limits(self, layers: Layers, unit: float) -> tuple[float, float]:
        """(lower, upper) [rad or m] of a chain joint, -inf / inf when not limited (MuJoCo 4's rules)."""
        limited = self.keyword(layers, "limited", "auto", ("true", "false", "auto"))
        lower, upper = self.vector(layers, "range", (0.0, 0.0), ANY) * unit
        key = self.key(layers, "range")
        if limited == "auto" and not self.settings.autolimits and (lower, upper) != (0, 0):
            raise SceneError(self.source, key, "a range without limited, with <compiler autolimits='false'> (MuJoCo "
                             "refuses it)", "limited='true' or 'false' with a range")
        if limited == "false" or (limited == "auto" and lower == upper):
            return -np.inf, np.inf
        if lower >= upper:
            why = "MuJoCo refuses it" if limited == "true" else "MuJoCo reads no limit: a typo core does not guess at"
            raise SceneError(self.source, key, f"lower {lower:g} is not below upper {upper:g} ({why})", "lower < upper")
        self.hold(np.array([lower, upper]), RANGES["lower"], key)
        return float(lower), float(upper)

    def held(self, base: int, on_chain: set[str]) -> tuple[str, ...]:
        """The joints of the base's subtree off the chain (not the base's free joint), in MuJoCo's order."""
        inside, stack = set(), [base]
        while stack:
            index = stack.pop()
            inside.add(index)
            stack.extend(self.bodies[index].children)
        names = []
        for index in sorted(inside):  # bodies are numbered depth first, as MuJoCo numbers them
            for placed, kind in zip(self.bodies[index].joints, self.bodies[index].kinds):
                name = placed.element.get("name", "")
                if (index == base and kind == "free") or name in on_chain:
                    continue
                if not name:
                    raise SceneError(self.source, placed.key, f"a held joint without a name ({self._where(index)})",
                                     "a name: Chain.held_joints names every joint held")
                names.append(name)
        return tuple(names)

    # --- mass properties ------------------------------------------------------------------------------------------

    def rigid_group(self, index: int, following: int, rule: _PhysicalRule, anchor: np.ndarray,
                    riding: str = "the chain") -> LinkInertia:
        """Body ``index`` and every body below it but the subtree of ``following`` (the next jointed body on the
        path; -1: none), in the frame at ``anchor`` (3,) [m] in the body's with its axes. A non-physical inertia
        tensor among them is met by ``rule``."""
        parts, stack = [], [(index, np.zeros(3), np.eye(3))]
        while stack:
            body, position, rotation = stack.pop()
            own = self.mass(body)
            if own.problem and rule.held:
                refusal = SceneError(self.source, own.key, f"{own.problem} ({self._where(body)}, riding on {riding})",
                                     LINK_TENSOR_RULE)
                if rule.refuse:
                    raise refusal
                rule.problems.append(refusal)
            parts.append((own.mass, position + rotation @ own.com, rotation @ own.inertia @ rotation.T))
            for child in self.bodies[body].children:
                if child != following:
                    xyz, turn = self.body_pose(child)
                    stack.append((child, position + rotation @ xyz, rotation @ turn))
        mass, com, inertia = combine(parts)
        return LinkInertia(mass, com - anchor, inertia)

    def mass(self, index: int) -> BodyMass:
        """Body ``index``'s mass properties in its frame: with ``inertiafromgeom`` "auto", its ``<inertial>`` or else
        its counted geoms'; "true": its counted geoms' if it has any (else its ``<inertial>``, as MuJoCo 4 does);
        "false": its ``<inertial>``, massless without one."""
        if index not in self._masses:
            body, how = self.bodies[index], self.settings.inertiafromgeom
            geoms = []
            for geom in body.geoms:
                layers = self.layers("geom", geom)
                if counted(self, layers, self.settings.groups):
                    geoms.append((layers, geom.xyz, geom.rotation))
            if body.inertial is not None and (how != "true" or not geoms):
                own = inertial_mass(self, body.inertial.element, body.inertial.key)
                turn = body.inertial.rotation
                own = replace(own, com=body.inertial.xyz + turn @ own.com, inertia=turn @ own.inertia @ turn.T)
            elif how == "false":
                own = BodyMass(0.0, np.zeros(3), np.zeros((3, 3)))
            else:
                own = geoms_mass(self, geoms, f"{body.key}/geom")
            self._masses[index] = own
        return self._masses[index]

    # --- messages ---------------------------------------------------------------------------------------------------

    def _label(self, index: int) -> str:
        """The body's name, or its element's key's last step for an unnamed body."""
        return self.bodies[index].name or self.bodies[index].key.rsplit("/", 1)[-1]

    def _where(self, index: int) -> str:
        """'body 'b' on the branch world > ... > b', the middle elided past :data:`core.urdf.BRANCH_NAMES`."""
        names, body = [], index
        while body >= 0:
            names.append(one_line(self._label(body), 40))
            body = self.bodies[body].parent
        names.reverse()
        if len(names) > BRANCH_NAMES:
            names = names[:3] + [f"... {len(names) - 7} more ..."] + names[-4:]
        return f"body {one_line(self._label(index), 40)!r} on the branch {' > '.join(names)}"
