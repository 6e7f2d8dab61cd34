"""Random valid robot descriptions, each written as URDF and as MJCF describing the same rigid-body model, with the
model's own ground truth (tests/references/test_random_robot_files.py runs them through every importer).

A model is drawn as a :class:`RobotSpec` (a tree of links and joints, the numbers, and how each format spells them)
from a seeded ``numpy.random.Generator`` passed in, and rendered (:func:`render`) into a :class:`RandomRobot`: both
texts, the features the model exercises and its truth (every link's mass, centre of mass and inertia in the world frame
at q = 0, every joint's world axis and anchor, and the joint-space mass matrix and bias forces at any state, computed
here from the spec and nothing else). A spec can be shrunk and rendered again (the sweep's minimiser), so every text
always has the truth of what it says.

What is drawn, each with some probability (the feature names in brackets, :func:`features`):

- A tree of 2 to 12 movable joints and up to 4 fixed ones, its longest branch 1 to 8 joints deep [``branching`` or
  ``serial``]: revolute, continuous and prismatic joints (MJCF hinge, hinge without a range, slide) with random unit
  axes, axis-aligned ones (negative too) and the URDF default (1, 0, 0), sometimes with ``<axis>`` left out
  [``default_axis``]; fixed joints (MJCF: a body without a joint) between moving ones [``fixed_mid_chain``] or at
  a leaf [``fixed_leaf``]; origins with random rpy [``origin_rpy``], some at pitch +-pi/2 [``gimbal_rpy``], some
  left out when zero [``omitted_origin``].
- Inertias: boxes, spheres, thin rods (smallest to largest principal moment 6e-8 to 6e-5) [``thin_rod``], thin
  discs (a + b - c = 3e-13 c to 3e-7 c) [``thin_disc``] and point masses (zero inertia) [``point_mass``], their
  principal frames rotated [``rotated_inertia``]; URDF as inertial ``rpy`` with a diagonal tensor or a full tensor
  in the link's axes [``urdf_full_inertia``]; MJCF as ``quat`` + ``diaginertia``, ``euler`` + ``diaginertia``
  [``mjcf_inertial_euler``] or ``fullinertia`` [``mjcf_fullinertia``].
- Massless links [``zero_mass_link``]: URDF without ``<inertial>`` [``no_inertial_element``] or with mass 0 and a
  zero tensor; MJCF without ``<inertial>`` or ``mass="0" diaginertia="0 0 0"``. MuJoCo refuses a moving body
  ("mass and inertia of moving bodies must be larger than mjMINVAL") unless it or a body welded below it (fixed
  joints, recursively) carries mass and rotational inertia (measured with MuJoCo 4.0: a massless moving body with a
  massive welded child or grandchild compiles; with only a moving massive child, or a welded point mass, it is
  refused; a lone moving body whose smallest principal moment is 0 or 1e-16 is refused). So a massless or
  point-mass link is drawn only where its rigid group (:func:`rigid_groups`) keeps a link of mass > 0 and every
  principal moment >= :data:`FULL_RANK_MOMENT` [``zero_mass_moving_link``: the group's moving link is the massless
  one], or on the base's group [``massless_root``]. A link of mass 0 with a non-zero inertia (a rotor whose mass is
  counted elsewhere, like pybullet_data's Panda flange) [``massless_inertia``] rides the same way.
- Mimic joints [``mimic``]: URDF ``<mimic joint multiplier offset>``, MJCF ``<equality><joint joint1=follower
  joint2=leader polycoef="offset multiplier 0 0 0">``; the leader moves and mimics nothing, of the same kind
  (rotational or prismatic).
- Joint damping [``damping``] (URDF ``<dynamics damping>``, MJCF ``damping``), friction [``friction``] (URDF
  ``<dynamics friction>``, MJCF ``frictionloss``), armature [``armature``] (MJCF only: URDF has none, so the two
  files differ by diag(armature) in M, recorded by :meth:`RandomRobot.mass_matrix`'s ``armature``).
- Limits: every revolute and prismatic joint has ``<limit lower upper effort velocity>`` (urdfdom refuses one
  without), MJCF ``range`` with ``limited="true"`` written [``explicit_limited``] or left to ``autolimits``.
- Spelling: MJCF ``<compiler angle="degree">`` [``mjcf_degree``] (hinge ranges and every angle in degrees),
  body orientations as ``quat``, ``euler`` with ``eulerseq`` "XYZ" (URDF's rpy) or "zyx" [``mjcf_euler``], or
  ``axisangle`` [``mjcf_axisangle``]; URDF links and joints in a shuffled order [``shuffled_urdf``]; names with
  ``_ . : / -`` [``punctuated_names``]; the URDF's ``<mujoco><compiler fusestatic="false"/></mujoco>`` left out
  [``fusestatic_default``: MuJoCo then fuses the bodies welded by fixed joints].

Both texts are written with ``xml.etree.ElementTree`` (names are attribute values, never spliced into markup), every
number as Python's shortest round-trip repr of a float64: the URDF's numbers are the spec's exactly, the MJCF's too but
for orientations written as quat or axisangle and angles in degrees, conversions rounded to ~1e-16.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from dataclasses import asdict, dataclass, field, replace
from functools import cached_property

import numpy as np
from scipy.spatial.transform import Rotation

GRAVITY = np.array([0.0, 0.0, -9.81])
"""[m/s^2] MuJoCo's and Pinocchio's default gravity; PyBullet's (0) is set to it."""

MOVABLE = ("revolute", "continuous", "prismatic")
JOINT_TYPES = MOVABLE + ("fixed",)
MJCF_TYPE = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide"}

FULL_RANK_MOMENT = 1e-12
"""[kg m^2] A principal moment this large makes a link's inertia full rank for MuJoCo's rule (its mjMINVAL is 1e-15;
the smallest drawn moment, a 0.05 kg thin rod's, is 2.5e-12)."""

MJCF_MOMENT_SMALLEST = 1e-12
"""[kg m^2] ``fullinertia`` is written only for tensors whose smallest principal moment is at least this: MuJoCo refuses
one without positive eigenvalues ("inertia must have positive eigenvalues", measured on a zero tensor)."""


@dataclass(frozen=True)
class Mimic:
    """URDF ``<mimic>``: q = multiplier * q_leader + offset."""

    leader: str
    multiplier: float
    offset: float


@dataclass(frozen=True)
class LinkSpec:
    """A link: mass [kg], centre of mass ``com`` (3,) in the link frame [m], principal moments (3,) [kg m^2] in the
    inertial frame turned by ``rpy`` from the link frame; how each format writes it (``urdf_inertial``: "rpy",
    "full", "zero" or "none"; ``mjcf_inertial``: "quat", "euler", "full", "zero" or "none") and the shape it was
    drawn as (``shape``: box, sphere, thin_rod, thin_disc, point_mass, massless, massless_inertia)."""

    name: str
    mass: float
    com: tuple[float, float, float]
    rpy: tuple[float, float, float]
    moments: tuple[float, float, float]
    urdf_inertial: str
    mjcf_inertial: str
    shape: str

    @cached_property
    def inertia(self) -> np.ndarray:
        """(3, 3) about the centre of mass in the link's axes."""
        rotation = rpy_matrix(self.rpy)
        return rotation @ np.diag(self.moments) @ rotation.T

    @property
    def full_rank(self) -> bool:
        return self.mass > 0 and min(self.moments) >= FULL_RANK_MOMENT


@dataclass(frozen=True)
class JointSpec:
    """A joint: type (:data:`JOINT_TYPES`), parent and child link, origin ``xyz`` [m] and ``rpy`` [rad] in the parent
    link's frame (the child link's frame at q = 0), unit ``axis`` in the child's frame, limits (revolute and prismatic;
    +-inf otherwise), damping, friction, armature (MJCF only), a mimic; ``write_origin`` / ``write_axis``: whether
    the URDF writes an ``<origin>`` / ``<axis>`` equal to its default."""

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    lower: float = -np.inf
    upper: float = np.inf
    damping: float = 0.0
    friction: float = 0.0
    armature: float = 0.0
    mimic: Mimic | None = None
    write_origin: bool = True
    write_axis: bool = True

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE


@dataclass(frozen=True)
class Style:
    """How the files spell the model: MJCF ``angle`` ("radian" or "degree"), body orientation ("quat", "euler",
    "axisangle"), ``eulerseq`` ("XYZ": URDF's extrinsic rpy, "zyx": the same as intrinsic yaw-pitch-roll; "" for the
    default, unused), ``limited="true"`` written on ranged joints, the URDF's elements shuffled by ``shuffle`` (0: in
    tree order), its ``<mujoco>`` compiler block (fusestatic off) written."""

    angle: str = "radian"
    orientation: str = "quat"
    eulerseq: str = ""
    explicit_limited: bool = False
    shuffle: int = 0
    mujoco_block: bool = True


@dataclass(frozen=True)
class RobotSpec:
    """A tree of links and joints (the root link first, every joint after its parent link's joint) and its spelling."""

    name: str
    links: tuple[LinkSpec, ...]
    joints: tuple[JointSpec, ...]
    style: Style = field(default_factory=Style)

    @property
    def root(self) -> str:
        return self.links[0].name

    def link(self, name: str) -> LinkSpec:
        return next(link for link in self.links if link.name == name)

    def joint(self, name: str) -> JointSpec:
        return next(joint for joint in self.joints if joint.name == name)


@dataclass(frozen=True)
class LinkTruth:
    """A link at q = 0: mass [kg], centre of mass (3,) and inertia about it (3, 3) in the world frame; its frame
    (``origin`` (3,), ``rotation`` (3, 3)); ``group``: the movable joint whose rigid group it rides in ("" for the
    base's)."""

    name: str
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    origin: np.ndarray
    rotation: np.ndarray
    group: str


@dataclass(frozen=True)
class JointTruth:
    """A joint at q = 0: its world axis (unit, (3,)) and anchor (the child link's origin, (3,)), with the spec's
    type, limits, damping, friction, armature and mimic."""

    name: str
    type: str
    parent: str
    child: str
    axis: np.ndarray
    anchor: np.ndarray
    lower: float
    upper: float
    damping: float
    friction: float
    armature: float
    mimic: Mimic | None


@dataclass(frozen=True)
class RandomRobot:
    """One random model: its ``seed``, both texts, the :func:`features` it exercises and its truth.

    Attributes
    ----------
    seed : int
    spec : RobotSpec
        What the texts were rendered from (shrink it and :func:`render` again for a smaller model).
    urdf, mjcf : str
        The same rigid-body model in each format (URDF without armature: :attr:`JointTruth.armature` is MJCF's).
    features : tuple[str, ...]
    links : tuple[LinkTruth, ...]
        Every link, the root first.
    joints : tuple[JointTruth, ...]
        Every joint, fixed ones included, in tree order.
    """

    seed: int
    spec: RobotSpec
    urdf: str
    mjcf: str
    features: tuple[str, ...]
    links: tuple[LinkTruth, ...]
    joints: tuple[JointTruth, ...]

    @property
    def movable(self) -> tuple[str, ...]:
        """The movable joints' names, sorted: the DoF order every comparison uses."""
        return tuple(sorted(joint.name for joint in self.spec.joints if joint.movable))

    @property
    def total_mass(self) -> float:
        return float(sum(link.mass for link in self.links))

    @cached_property
    def _tables(self) -> _Tables:
        return _Tables(self.spec, self.movable)

    @cached_property
    def _memo(self) -> dict:
        return {}

    def mass_matrix(self, q: np.ndarray, armature: bool = False) -> np.ndarray:
        """(n, n) joint-space mass matrix at q (n,) in :attr:`movable` order; with ``armature``, MJCF's armature on
        the diagonal."""
        q = np.asarray(q, dtype=float)
        key = ("M", q.tobytes(), armature)
        if key not in self._memo:
            self._memo[key] = self._mass_matrix(q, armature)
        return self._memo[key]

    def _mass_matrix(self, q: np.ndarray, armature: bool) -> np.ndarray:
        jv, jw, masses, inertias = self._tables.jacobians(q)
        m = np.einsum("k,kin,kim->nm", masses, jv, jv) + np.einsum("kin,kij,kjm->nm", jw, inertias, jw)
        if armature:
            m = m + np.diag([self.spec.joint(name).armature for name in self.movable])
        return 0.5 * (m + m.T)

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray, gravity: np.ndarray = GRAVITY) -> np.ndarray:
        """(n,) h(q, qdot): Coriolis, centrifugal and gravity forces (the joint forces at zero acceleration), by a
        recursive Newton-Euler pass in the world frame."""
        q, qdot, gravity = (np.asarray(x, dtype=float) for x in (q, qdot, gravity))
        key = ("h", q.tobytes(), qdot.tobytes(), gravity.tobytes())
        if key not in self._memo:
            self._memo[key] = self._tables.rnea(q, qdot, gravity)
        return self._memo[key]

    def groups(self) -> dict[str, tuple[float, np.ndarray, np.ndarray]]:
        """Rigid group ("" for the base's, else the movable joint it hangs from) -> its mass, centre of mass (3,)
        and inertia about it (3, 3) in the world frame at q = 0 (:func:`rigid_groups`)."""
        out = {}
        for group in rigid_groups(self.spec):
            members = [link for link in self.links if link.group == group]
            out[group] = combine([(link.mass, link.com, link.inertia) for link in members])
        return out

    def core_path(self) -> tuple[str, tuple[str, ...]] | None:
        """(tip link, movable joints on the path from the root to it) for core's serial-chain reader: the leaf with the
        most movable joints above it and no mimic joint among them (core refuses one on the chain), first by name;
        None when no leaf has such a path."""
        parent = {joint.child: joint for joint in self.spec.joints}
        parents = {joint.parent for joint in self.spec.joints}
        best: tuple[int, str, tuple[str, ...]] | None = None
        for link in sorted(link.name for link in self.spec.links if link.name not in parents):
            path, name = [], link
            while name in parent:
                path.append(parent[name])
                name = parent[name].parent
            if any(joint.mimic is not None for joint in path):
                continue
            moving = tuple(joint.name for joint in reversed(path) if joint.movable)
            if moving and (best is None or len(moving) > best[0]):
                best = (len(moving), link, moving)
        return None if best is None else (best[1], best[2])


def rpy_matrix(rpy) -> np.ndarray:
    """URDF roll-pitch-yaw [rad] as a rotation matrix: Rz(yaw) Ry(pitch) Rx(roll) (SciPy's extrinsic "xyz", written
    out: SciPy's call costs ~50 times more, and the truth makes thousands)."""
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def axis_angle_matrix(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` [rad] about the unit ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array([[c + t * x * x, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, c + t * y * y, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, c + t * z * z]])


def _cross(a, b) -> np.ndarray:
    """a x b of 3-vectors (np.cross costs ~20 times more on one pair)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def combine(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, com, inertia about com) of rigid parts given the same way, all in one frame (parallel axes)."""
    mass = float(sum(m for m, _, _ in parts))
    if mass == 0:
        return 0.0, np.zeros(3), sum((i for _, _, i in parts), np.zeros((3, 3)))
    com = sum(m * c for m, c, _ in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - com
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def rigid_groups(spec: RobotSpec) -> dict[str, list[str]]:
    """Group -> its links: "" for the root and the links welded to it, else a movable joint's name for its child link
    and the links welded below it (fixed joints, recursively)."""
    parent = {joint.child: joint for joint in spec.joints}
    groups: dict[str, list[str]] = {}
    for link in spec.links:
        name = link.name
        while name in parent and not parent[name].movable:
            name = parent[name].parent
        groups.setdefault(parent[name].name if name in parent else "", []).append(link.name)
    return groups


class _Tables:
    """The spec's kinematic tree as arrays, for the truth's M and h at any state."""

    def __init__(self, spec: RobotSpec, movable: tuple[str, ...]) -> None:
        self.spec = spec
        self.index = {name: k for k, name in enumerate(movable)}
        self.n = len(movable)
        self.parent_joint = {joint.child: joint for joint in spec.joints}
        self.order = [spec.root] + [joint.child for joint in spec.joints]  # every joint after its parent's joint
        self.links = {link.name: link for link in spec.links}
        self.origins = {joint.name: (np.array(joint.xyz), rpy_matrix(joint.rpy)) for joint in spec.joints}
        self.axes = {joint.name: np.array(joint.axis) / np.linalg.norm(joint.axis) for joint in spec.joints}
        self.ancestors = {name: self._ancestors(name) for name in self.order}

    def poses(self, q: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Link -> (rotation (3, 3), origin (3,)) in the world at q (in :attr:`index` order)."""
        poses = {self.spec.root: (np.eye(3), np.zeros(3))}
        for joint in self.spec.joints:
            r, p = poses[joint.parent]
            xyz, turn = self.origins[joint.name]
            origin, rotation = p + r @ xyz, r @ turn
            if joint.movable:
                value, axis = q[self.index[joint.name]], self.axes[joint.name]
                if joint.type == "prismatic":
                    origin = origin + rotation @ axis * value
                else:
                    rotation = rotation @ axis_angle_matrix(axis, value)
            poses[joint.child] = (rotation, origin)
        return poses

    def _ancestors(self, link: str) -> list[JointSpec]:
        out = []
        while link in self.parent_joint:
            joint = self.parent_joint[link]
            if joint.movable:
                out.append(joint)
            link = joint.parent
        return out

    def jacobians(self, q: np.ndarray):
        """Per link: the linear Jacobian of its centre of mass and its angular Jacobian (k, 3, n), masses (k,), world
        inertias (k, 3, 3)."""
        poses = self.poses(q)
        k = len(self.order)
        jv, jw = np.zeros((k, 3, self.n)), np.zeros((k, 3, self.n))
        masses, inertias = np.zeros(k), np.zeros((k, 3, 3))
        for i, name in enumerate(self.order):
            link = self.links[name]
            r, p = poses[name]
            com = p + r @ np.array(link.com)
            masses[i], inertias[i] = link.mass, r @ link.inertia @ r.T
            for joint in self.ancestors[name]:
                jr, jp = poses[joint.child]
                axis = jr @ self.axes[joint.name]
                col = self.index[joint.name]
                if joint.type == "prismatic":
                    jv[i, :, col] = axis
                else:
                    jw[i, :, col] = axis
                    jv[i, :, col] = _cross(axis, com - jp)
        return jv, jw, masses, inertias

    def rnea(self, q: np.ndarray, qdot: np.ndarray, gravity: np.ndarray) -> np.ndarray:
        """Joint forces at zero acceleration: world-frame Newton-Euler, the base accelerating at -gravity."""
        poses = self.poses(q)
        state = {self.spec.root: (np.zeros(3), np.zeros(3), -gravity)}  # omega, alpha, origin's acceleration
        wrench = {}
        for name in self.order:
            r, p = poses[name]
            if name in self.parent_joint:
                joint = self.parent_joint[name]
                w_p, a_p, acc_p = state[joint.parent]
                d = p - poses[joint.parent][1]
                acc = acc_p + _cross(a_p, d) + _cross(w_p, _cross(w_p, d))
                w, a = w_p, a_p
                if joint.movable:
                    axis, rate = r @ self.axes[joint.name], qdot[self.index[joint.name]]
                    if joint.type == "prismatic":
                        acc = acc + 2 * _cross(w_p, axis * rate)
                    else:
                        w = w_p + axis * rate
                        a = a_p + _cross(w_p, axis * rate)
                state[name] = (w, a, acc)
            w, a, acc = state[name]
            link = self.links[name]
            c = r @ np.array(link.com)
            inertia = r @ link.inertia @ r.T
            force = link.mass * (acc + _cross(a, c) + _cross(w, _cross(w, c)))
            torque = inertia @ a + _cross(w, inertia @ w) + _cross(c, force)  # about the link origin
            wrench[name] = [force, torque]
        tau = np.zeros(self.n)
        for name in reversed(self.order[1:]):
            joint = self.parent_joint[name]
            force, torque = wrench[name]
            if joint.movable:
                axis = poses[name][0] @ self.axes[joint.name]
                tau[self.index[joint.name]] = axis @ (force if joint.type == "prismatic" else torque)
            d = poses[name][1] - poses[joint.parent][1]
            up = wrench[joint.parent]
            up[0] = up[0] + force
            up[1] = up[1] + torque + _cross(d, force)
        return tau


# ---------------------------------------------------------------------------------------------------------------
# Drawing


LINK_WORDS = ("link", "L", "seg", "Arm", "body", "b")
JOINT_WORDS = ("joint", "j", "J", "hinge", "q", "axis")
PUNCTUATION = ("_", ".", ":", "/", "-")


def _names(rng: np.random.Generator, words: tuple[str, ...], count: int, punctuated: bool) -> list[str]:
    """``count`` distinct names, numbered in a random order (so sorted names are not tree order)."""
    word = words[int(rng.integers(len(words)))]
    numbers = rng.permutation(count) + int(rng.integers(0, 20))
    out = []
    for k in numbers:
        sep = PUNCTUATION[int(rng.integers(len(PUNCTUATION)))] if punctuated else "_"
        out.append(f"{word}{sep}{k}")
    return out


def _unit(rng: np.random.Generator) -> tuple[float, float, float]:
    v = rng.normal(size=3)
    return tuple(float(x) for x in v / np.linalg.norm(v))


def _rpy(rng: np.random.Generator, p_rotated: float, p_gimbal: float = 0.0) -> tuple[float, float, float]:
    if rng.random() >= p_rotated:
        return (0.0, 0.0, 0.0)
    r, p, y = rng.uniform(-np.pi, np.pi, size=3)
    if rng.random() < p_gimbal:
        p = float(rng.choice([-0.5, 0.5])) * np.pi
    return (float(r), float(p), float(y))


def _shape(rng: np.random.Generator, mass: float) -> tuple[str, tuple[float, float, float]]:
    """A body's shape and principal moments [kg m^2] (a + b >= c holds for each)."""
    kind = rng.choice(["box", "box", "box", "sphere", "thin_rod", "thin_disc"])
    if kind == "box":
        a, b, c = np.exp(rng.uniform(np.log(0.02), np.log(0.5), size=3))
        return "box", (mass / 12 * (b * b + c * c), mass / 12 * (a * a + c * c), mass / 12 * (a * a + b * b))
    if kind == "sphere":
        r = rng.uniform(0.02, 0.3)
        return "sphere", (0.4 * mass * r * r,) * 3
    if kind == "thin_rod":  # a solid cylinder of length l and radius r << l: moments ~ (r^2 / 2, l^2 / 12, l^2 / 12)
        length = rng.uniform(0.1, 1.0)
        radius = length * 10 ** rng.uniform(-4.0, -2.5)
        side = mass * (3 * radius * radius + length * length) / 12
        return "thin_rod", (mass * radius * radius / 2, side, side)
    radius = rng.uniform(0.05, 0.4)  # a disc of thickness t << r: a + b - c = m t^2 / 6
    thickness = radius * 10 ** rng.uniform(-6.0, -3.0)
    side = mass * (3 * radius * radius + thickness * thickness) / 12
    return "thin_disc", (side, side, mass * radius * radius / 2)


def _tree(rng: np.random.Generator, n_joints: int, depth: int) -> list[int]:
    """Parent index of links 1..n_joints (link 0 the root): a spine ``depth`` deep, the rest hung anywhere above
    the depth."""
    parents, depths = [], [0]
    for k in range(1, n_joints + 1):
        if k <= depth:
            parent = k - 1
        else:
            choices = [i for i, d in enumerate(depths) if d < depth]
            parent = int(rng.choice(choices))
        parents.append(parent)
        depths.append(depths[parent] + 1)
    return parents


def random_spec(rng: np.random.Generator, name: str = "random_robot") -> RobotSpec:
    """A random valid model (see the module docstring), drawn from ``rng`` only."""
    n_movable = int(rng.integers(2, 13))
    n_fixed = int(rng.choice([0, 0, 1, 1, 2, 3, 4]))
    n_joints = n_movable + n_fixed
    depth = int(rng.integers(1, 9))
    parents = _tree(rng, n_joints, depth)
    punctuated = rng.random() < 0.3
    link_names = _names(rng, LINK_WORDS, n_joints + 1, punctuated)
    joint_names = _names(rng, JOINT_WORDS, n_joints, punctuated)
    fixed = set(rng.choice(n_joints, size=n_fixed, replace=False).tolist()) if n_fixed else set()
    style = Style(
        angle="degree" if rng.random() < 0.3 else "radian",
        orientation=str(rng.choice(["quat", "quat", "euler", "euler", "axisangle"])),
        explicit_limited=bool(rng.random() < 0.5),
        shuffle=int(rng.integers(1, 2**31)) if rng.random() < 0.5 else 0,
        mujoco_block=bool(rng.random() < 0.85),
    )
    if style.orientation == "euler" or rng.random() < 0.3:
        style = replace(style, eulerseq=str(rng.choice(["XYZ", "zyx"])))
    p_rotated_inertia = float(rng.choice([0.0, 0.5, 1.0]))
    armature_model = rng.random() < 0.5

    links = [_draw_link(rng, link_names[0], style, p_rotated_inertia)]
    joints = []
    for k in range(n_joints):
        kind = "fixed" if k in fixed else str(rng.choice(["revolute", "revolute", "continuous", "prismatic"]))
        joints.append(_draw_joint(rng, joint_names[k], kind, link_names[parents[k]], link_names[k + 1],
                                  armature_model))
        links.append(_draw_link(rng, link_names[k + 1], style, p_rotated_inertia))
    spec = RobotSpec(name=f"{name}", links=tuple(links), joints=tuple(joints), style=style)
    spec = _massless(rng, spec)
    spec = _mimics(rng, spec)
    return spec


def _draw_link(rng: np.random.Generator, name: str, style: Style, p_rotated: float) -> LinkSpec:
    mass = float(np.exp(rng.uniform(np.log(0.05), np.log(20.0))))
    shape, moments = _shape(rng, mass)
    rpy = _rpy(rng, p_rotated)
    com = tuple(float(x) for x in rng.uniform(-0.2, 0.2, size=3))
    return LinkSpec(name, mass, com, rpy, tuple(float(m) for m in moments), _urdf_inertial(rng),
                    _mjcf_inertial(rng, style, min(moments)), shape)


def _urdf_inertial(rng: np.random.Generator) -> str:
    return "full" if rng.random() < 0.4 else "rpy"


def _mjcf_inertial(rng: np.random.Generator, style: Style, smallest: float) -> str:
    choices = ["quat", "quat"] + (["euler"] if style.eulerseq else []) + (
        ["full", "full"] if smallest >= MJCF_MOMENT_SMALLEST else [])
    return str(rng.choice(choices))


def _draw_joint(rng: np.random.Generator, name: str, kind: str, parent: str, child: str,
                armature_model: bool) -> JointSpec:
    zero_origin = rng.random() < 0.08
    xyz = (0.0, 0.0, 0.0) if zero_origin else tuple(float(x) for x in rng.uniform(-0.4, 0.4, size=3))
    rpy = (0.0, 0.0, 0.0) if zero_origin else _rpy(rng, 0.6, 0.1)
    joint = JointSpec(name, kind, parent, child, xyz, rpy, write_origin=not zero_origin or rng.random() < 0.5)
    if kind == "fixed":
        return joint
    draw = rng.random()
    if draw < 0.65:
        axis = _unit(rng)
    elif draw < 0.85:
        axis = tuple(float(x) for x in np.eye(3)[int(rng.integers(3))] * rng.choice([-1.0, 1.0]))
    else:
        axis = (1.0, 0.0, 0.0)
    lower, upper = -np.inf, np.inf
    if kind == "revolute":
        lower, upper = float(rng.uniform(-3.0, -0.1)), float(rng.uniform(0.1, 3.0))
    elif kind == "prismatic":
        lower, upper = float(rng.uniform(-0.5, -0.01)), float(rng.uniform(0.01, 0.5))
    return replace(
        joint, axis=axis, lower=lower, upper=upper,
        damping=float(rng.uniform(0.0, 2.0)) if rng.random() < 0.5 else 0.0,
        friction=float(rng.uniform(0.0, 0.5)) if rng.random() < 0.2 else 0.0,
        armature=float(rng.uniform(1e-3, 0.1)) if armature_model and rng.random() < 0.7 else 0.0,
        write_axis=axis != (1.0, 0.0, 0.0) or rng.random() < 0.5)


def _massless(rng: np.random.Generator, spec: RobotSpec) -> RobotSpec:
    """Some links made massless or point masses, then every moving group given a full-rank link (MuJoCo's rule,
    module docstring): its moving link turned into a box where it has none."""
    links = list(spec.links)
    if rng.random() < 0.35:
        for k in rng.choice(len(links), size=min(len(links), int(rng.integers(1, 3))), replace=False):
            none = rng.random() < 0.5
            links[k] = replace(links[k], mass=0.0, com=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0), moments=(0.0, 0.0, 0.0),
                               urdf_inertial="none" if none else "zero",
                               mjcf_inertial="none" if rng.random() < 0.5 else "zero", shape="massless")
    if rng.random() < 0.2:
        k = int(rng.integers(len(links)))
        if links[k].mass > 0:
            links[k] = replace(links[k], moments=(0.0, 0.0, 0.0), shape="point_mass",
                               mjcf_inertial="euler" if links[k].mjcf_inertial == "euler" else "quat")
    if rng.random() < 0.1:  # a rotor whose mass is counted elsewhere (pybullet_data's Panda flange): inertia, no mass
        k = int(rng.integers(len(links)))
        if links[k].mass > 0 and links[k].shape != "point_mass":
            links[k] = replace(links[k], mass=0.0, shape="massless_inertia",
                               mjcf_inertial="euler" if links[k].mjcf_inertial == "euler" else "quat")
    spec = replace(spec, links=tuple(links))
    by_name = {link.name: k for k, link in enumerate(links)}
    for group, members in rigid_groups(spec).items():
        if group and not any(spec.link(name).full_rank for name in members):
            k = by_name[spec.joint(group).child]
            mass = float(np.exp(rng.uniform(np.log(0.05), np.log(20.0))))
            links[k] = replace(links[k], mass=mass, moments=_shape(rng, mass)[1], shape="box",
                               urdf_inertial=_urdf_inertial(rng), mjcf_inertial="quat")
    return replace(spec, links=tuple(links))


def _mimics(rng: np.random.Generator, spec: RobotSpec) -> RobotSpec:
    """One or two mimic joints, each following a movable joint of its kind that mimics nothing."""
    if rng.random() >= 0.25:
        return spec
    joints = list(spec.joints)
    movable = [k for k, joint in enumerate(joints) if joint.movable]
    for _ in range(int(rng.integers(1, 3))):
        follower = int(rng.choice(movable))
        kind = joints[follower].type == "prismatic"
        leaders = [k for k in movable if k != follower and joints[k].mimic is None
                   and (joints[k].type == "prismatic") == kind
                   and not any(j.mimic is not None and j.mimic.leader == joints[follower].name for j in joints)]
        if joints[follower].mimic is not None or not leaders:
            continue
        leader = joints[int(rng.choice(leaders))]
        multiplier = float(rng.uniform(0.3, 2.0) * rng.choice([-1.0, 1.0]))
        offset = float(rng.uniform(-0.2, 0.2)) if rng.random() < 0.5 else 0.0
        joints[follower] = replace(joints[follower], mimic=Mimic(leader.name, multiplier, offset))
    return replace(spec, joints=tuple(joints))


# ---------------------------------------------------------------------------------------------------------------
# Writing


def _num(value: float) -> str:
    return repr(float(value))


def _vec(values) -> str:
    return " ".join(_num(v) for v in values)


def _shuffled(items: list, seed: int) -> list:
    if not seed:
        return items
    order = np.random.default_rng(seed).permutation(len(items))
    return [items[k] for k in order]


def urdf_text(spec: RobotSpec) -> str:
    """The spec as URDF (armature is not written: URDF has none)."""
    robot = ET.Element("robot", name=spec.name)
    elements = []
    for link in spec.links:
        element = ET.Element("link", name=link.name)
        if link.urdf_inertial != "none":
            inertial = ET.SubElement(element, "inertial")
            full = link.urdf_inertial in ("full", "zero")
            ET.SubElement(inertial, "origin", xyz=_vec(link.com), rpy=_vec((0.0, 0.0, 0.0) if full else link.rpy))
            ET.SubElement(inertial, "mass", value=_num(link.mass))
            tensor = link.inertia if full else np.diag(link.moments)
            ET.SubElement(inertial, "inertia", ixx=_num(tensor[0, 0]), ixy=_num(tensor[0, 1]),
                          ixz=_num(tensor[0, 2]), iyy=_num(tensor[1, 1]), iyz=_num(tensor[1, 2]),
                          izz=_num(tensor[2, 2]))
        elements.append(element)
    for joint in spec.joints:
        element = ET.Element("joint", name=joint.name, type=joint.type)
        ET.SubElement(element, "parent", link=joint.parent)
        ET.SubElement(element, "child", link=joint.child)
        if joint.write_origin or any(joint.xyz) or any(joint.rpy):
            ET.SubElement(element, "origin", xyz=_vec(joint.xyz), rpy=_vec(joint.rpy))
        if joint.movable and (joint.write_axis or joint.axis != (1.0, 0.0, 0.0)):
            ET.SubElement(element, "axis", xyz=_vec(joint.axis))
        if joint.type in ("revolute", "prismatic"):
            ET.SubElement(element, "limit", lower=_num(joint.lower), upper=_num(joint.upper), effort="100.0",
                          velocity="10.0")
        if joint.damping or joint.friction:
            ET.SubElement(element, "dynamics", damping=_num(joint.damping), friction=_num(joint.friction))
        if joint.mimic is not None:
            ET.SubElement(element, "mimic", joint=joint.mimic.leader, multiplier=_num(joint.mimic.multiplier),
                          offset=_num(joint.mimic.offset))
        elements.append(element)
    robot.extend(_shuffled(elements, spec.style.shuffle))
    if spec.style.mujoco_block:
        ET.SubElement(ET.SubElement(robot, "mujoco"), "compiler", fusestatic="false", discardvisual="false")
    ET.indent(robot)
    return ET.tostring(robot, encoding="unicode") + "\n"


def _angle(value: float, style: Style) -> float:
    return float(np.degrees(value)) if style.angle == "degree" else float(value)


def _orientation(element: ET.Element, rpy, style: Style, spelling: str) -> None:
    """Write the rotation rpy(rpy) on a body (``spelling`` the style's orientation) or an inertial."""
    if not any(rpy):
        return
    if spelling == "euler":
        values = rpy if style.eulerseq == "XYZ" else rpy[::-1]  # zyx intrinsic = XYZ extrinsic, angles reversed
        element.set("euler", _vec(_angle(v, style) for v in values))
    elif spelling == "axisangle":
        rotvec = Rotation.from_euler("xyz", rpy).as_rotvec()
        angle = float(np.linalg.norm(rotvec))
        element.set("axisangle", _vec(list(rotvec / angle) + [_angle(angle, style)]))
    else:
        element.set("quat", _vec(Rotation.from_euler("xyz", rpy).as_quat(scalar_first=True)))


def mjcf_text(spec: RobotSpec) -> str:
    """The spec as MJCF: every inertial explicit (``inertiafromgeom="false"``), no geometry."""
    style = spec.style
    root = ET.Element("mujoco", model=spec.name)
    compiler = ET.SubElement(root, "compiler", angle=style.angle, inertiafromgeom="false")
    if style.eulerseq:
        compiler.set("eulerseq", style.eulerseq)
    world = ET.SubElement(root, "worldbody")
    bodies = {spec.root: _body(world, spec.link(spec.root), style)}
    for joint in spec.joints:
        body = _body(bodies[joint.parent], spec.link(joint.child), style, joint)
        bodies[joint.child] = body
    mimics = [joint for joint in spec.joints if joint.mimic is not None]
    if mimics:
        equality = ET.SubElement(root, "equality")
        for joint in mimics:
            ET.SubElement(equality, "joint", joint1=joint.name, joint2=joint.mimic.leader,
                          polycoef=_vec((joint.mimic.offset, joint.mimic.multiplier, 0.0, 0.0, 0.0)))
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


def _body(parent: ET.Element, link: LinkSpec, style: Style, joint: JointSpec | None = None) -> ET.Element:
    body = ET.SubElement(parent, "body", name=link.name)
    if joint is not None:
        if any(joint.xyz):
            body.set("pos", _vec(joint.xyz))
        _orientation(body, joint.rpy, style, style.orientation)
    if link.mjcf_inertial == "zero":
        ET.SubElement(body, "inertial", pos="0.0 0.0 0.0", mass="0.0", diaginertia="0.0 0.0 0.0")
    elif link.mjcf_inertial != "none":
        inertial = ET.SubElement(body, "inertial", pos=_vec(link.com), mass=_num(link.mass))
        if link.mjcf_inertial == "full":
            t = link.inertia
            inertial.set("fullinertia", _vec((t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2])))
        else:
            _orientation(inertial, link.rpy, style, link.mjcf_inertial)
            inertial.set("diaginertia", _vec(link.moments))
    if joint is not None and joint.movable:
        element = ET.SubElement(body, "joint", name=joint.name, type=MJCF_TYPE[joint.type], axis=_vec(joint.axis))
        if joint.type != "continuous":
            scale = (lambda v: _angle(v, style)) if joint.type == "revolute" else float
            element.set("range", _vec((scale(joint.lower), scale(joint.upper))))
            if style.explicit_limited:
                element.set("limited", "true")
        if joint.damping:
            element.set("damping", _num(joint.damping))
        if joint.friction:
            element.set("frictionloss", _num(joint.friction))
        if joint.armature:
            element.set("armature", _num(joint.armature))
    return body


# ---------------------------------------------------------------------------------------------------------------
# The model's truth, and the public API


FEATURES = ("branching", "serial", "revolute", "continuous", "prismatic", "fixed", "fixed_mid_chain", "fixed_leaf",
            "origin_rpy", "gimbal_rpy", "omitted_origin", "default_axis", "damping", "friction", "armature", "mimic",
            "thin_rod", "thin_disc", "point_mass", "massless_inertia", "rotated_inertia", "urdf_full_inertia",
            "mjcf_fullinertia", "mjcf_inertial_euler", "zero_mass_link", "no_inertial_element",
            "zero_mass_moving_link", "massless_root", "mjcf_degree", "mjcf_euler", "mjcf_axisangle",
            "explicit_limited", "shuffled_urdf", "fusestatic_default", "punctuated_names")
"""Every feature :func:`features` names (the module docstring says what each is)."""


def features(spec: RobotSpec) -> tuple[str, ...]:
    """The features (module docstring) the spec exercises, sorted."""
    found = set()
    children: dict[str, int] = {}
    for joint in spec.joints:
        children[joint.parent] = children.get(joint.parent, 0) + 1
    found.add("branching" if any(c > 1 for c in children.values()) else "serial")
    below_movable = _has_movable_below(spec)
    for joint in spec.joints:
        found.add(joint.type)
        if joint.type == "fixed":
            found.add("fixed_mid_chain" if below_movable[joint.child] else "fixed_leaf")
        if any(joint.rpy):
            found.add("origin_rpy")
            if abs(abs(joint.rpy[1]) - np.pi / 2) < 1e-12:
                found.add("gimbal_rpy")
        if not joint.write_origin and not any(joint.xyz) and not any(joint.rpy):
            found.add("omitted_origin")
        if joint.movable and not joint.write_axis and joint.axis == (1.0, 0.0, 0.0):
            found.add("default_axis")
        for attribute in ("damping", "friction", "armature", "mimic"):
            if getattr(joint, attribute):
                found.add(attribute)
    groups = rigid_groups(spec)
    moving_link = {spec.joint(g).child for g in groups if g}
    for link in spec.links:
        if link.shape in ("thin_rod", "thin_disc", "point_mass", "massless_inertia"):
            found.add(link.shape)
        if link.mass > 0 and any(link.rpy) and link.shape != "point_mass":
            found.add("rotated_inertia")
        if link.mass > 0 and link.urdf_inertial == "full" and np.count_nonzero(link.inertia - np.diag(np.diag(
                link.inertia))):
            found.add("urdf_full_inertia")
        if link.mass > 0 and link.mjcf_inertial == "full":
            found.add("mjcf_fullinertia")
        if link.mass > 0 and link.mjcf_inertial == "euler" and any(link.rpy):
            found.add("mjcf_inertial_euler")
        if link.mass == 0 and link.shape != "massless_inertia":
            found.add("zero_mass_link")
            if link.urdf_inertial == "none":
                found.add("no_inertial_element")
            if link.name in moving_link:
                found.add("zero_mass_moving_link")
    if all(spec.link(name).mass == 0 and not any(spec.link(name).moments) for name in groups[""]):
        found.add("massless_root")
    style = spec.style
    if style.angle == "degree":
        found.add("mjcf_degree")
    if any(any(j.rpy) for j in spec.joints):
        if style.orientation == "euler":
            found.add("mjcf_euler")
        elif style.orientation == "axisangle":
            found.add("mjcf_axisangle")
    if style.explicit_limited and any(j.type in ("revolute", "prismatic") for j in spec.joints):
        found.add("explicit_limited")
    if style.shuffle:
        found.add("shuffled_urdf")
    if not style.mujoco_block:
        found.add("fusestatic_default")
    if any(c in name for name in [link.name for link in spec.links] + [j.name for j in spec.joints]
           for c in PUNCTUATION[1:]):
        found.add("punctuated_names")
    return tuple(sorted(found))


def _has_movable_below(spec: RobotSpec) -> dict[str, bool]:
    """Link -> whether a movable joint hangs anywhere below it."""
    below = {link.name: False for link in spec.links}
    for joint in reversed(spec.joints):  # children after parents in spec order: walk up
        below[joint.parent] = below[joint.parent] or joint.movable or below[joint.child]
    return below


def render(spec: RobotSpec, seed: int = -1) -> RandomRobot:
    """Both texts, the features and the truth of ``spec`` (``seed``: what it was drawn with, -1 for a shrunk spec)."""
    movable = tuple(sorted(joint.name for joint in spec.joints if joint.movable))
    poses = _Tables(spec, movable).poses(np.zeros(len(movable)))
    group_of = {name: group for group, names in rigid_groups(spec).items() for name in names}
    links = []
    for link in spec.links:
        r, p = poses[link.name]
        links.append(LinkTruth(link.name, link.mass, p + r @ np.array(link.com), r @ link.inertia @ r.T, p, r,
                               group_of[link.name]))
    joints = []
    for joint in spec.joints:
        r, p = poses[joint.child]
        joints.append(JointTruth(joint.name, joint.type, joint.parent, joint.child, r @ np.array(joint.axis), p,
                                 joint.lower, joint.upper, joint.damping, joint.friction, joint.armature, joint.mimic))
    return RandomRobot(seed, spec, urdf_text(spec), mjcf_text(spec), features(spec), tuple(links), tuple(joints))


def random_robot(rng: np.random.Generator, seed: int) -> RandomRobot:
    """One random model drawn from ``rng`` (``seed``: the seed ``rng`` was made from, kept on the model)."""
    return render(random_spec(rng, name=f"random_robot_{seed}"), seed)


def random_robots(count: int, seed: int) -> list[RandomRobot]:
    """``count`` models, the k-th drawn from ``np.random.default_rng([seed, k])`` (so each is reproducible alone, and
    carries the seed ``[seed, k]`` as ``seed * 100_000 + k``)."""
    return [random_robot(np.random.default_rng([seed, k]), seed * 100_000 + k) for k in range(count)]


def robot_from_seed(seed: int) -> RandomRobot:
    """The model :func:`random_robots` made as ``seed`` (``seed * 100_000 + k``)."""
    base, k = divmod(seed, 100_000)
    return random_robot(np.random.default_rng([base, k]), seed)


def spec_to_json(spec: RobotSpec) -> str:
    """The spec as compact JSON (a minimised model is stored so: :func:`spec_from_json` reads it back exactly)."""

    def plain(value):
        if isinstance(value, float) and not math.isfinite(value):
            return repr(value)  # inf / -inf, which JSON has no spelling for
        return value

    data = asdict(spec)
    for joint in data["joints"]:
        joint["lower"], joint["upper"] = plain(joint["lower"]), plain(joint["upper"])
    return json.dumps(data, separators=(",", ":"))


def spec_from_json(text: str) -> RobotSpec:
    """The spec :func:`spec_to_json` wrote."""
    data = json.loads(text)
    links = tuple(LinkSpec(**{**link, "com": tuple(link["com"]), "rpy": tuple(link["rpy"]),
                              "moments": tuple(link["moments"])}) for link in data["links"])
    joints = []
    for joint in data["joints"]:
        mimic = Mimic(**joint["mimic"]) if joint["mimic"] else None
        joints.append(JointSpec(**{**joint, "xyz": tuple(joint["xyz"]), "rpy": tuple(joint["rpy"]),
                                   "axis": tuple(joint["axis"]), "lower": float(joint["lower"]),
                                   "upper": float(joint["upper"]), "mimic": mimic}))
    return RobotSpec(data["name"], links, tuple(joints), Style(**data["style"]))
