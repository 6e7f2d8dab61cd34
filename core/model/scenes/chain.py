"""A serial chain (its base fixed or floating), what every chain scene is built on: :class:`Chain` of :class:`Joint` with
:class:`LinkInertia`, the :class:`DHTable` a file may give it as, and :func:`sample_configurations`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.checks import check_symmetric, unit_vector


@dataclass(frozen=True)
class LinkInertia:
    """The mass properties of one link of a chain, in the link's frame (the frame its joint moves).

    Everything rigidly attached to the link is included: links hanging from it by fixed joints, and (for a
    chain read from a URDF file) every branch off the chain below it, its joints held at 0.

    Attributes
    ----------
    mass : float
        [kg], >= 0 (0: a massless link, as a URDF link without ``<inertial>``).
    com_xyz : (3,) ndarray
        Centre of mass in the link frame [m].
    inertia_com : (3, 3) ndarray
        Inertia tensor about the centre of mass, in the link frame's axes [kg m^2]; symmetric.
    """

    mass: float
    com_xyz: np.ndarray
    inertia_com: np.ndarray

    def __post_init__(self) -> None:
        if not (np.isfinite(self.mass) and self.mass >= 0):
            raise SceneError("<code>", "mass", f"{self.mass}", "a finite mass >= 0 [kg]")
        object.__setattr__(self, "mass", float(self.mass))
        object.__setattr__(self, "com_xyz", readonly(self.com_xyz, shape=(3,)))
        object.__setattr__(self, "inertia_com", readonly(self.inertia_com, shape=(3, 3)))
        if not np.all(np.isfinite(self.com_xyz)) or not np.all(np.isfinite(self.inertia_com)):
            raise SceneError("<code>", "inertia", "a non-finite centre of mass or inertia", "finite numbers")
        check_symmetric(self.inertia_com, "inertia")

    @classmethod
    def massless(cls) -> "LinkInertia":
        """A link with no mass (a URDF link without ``<inertial>``)."""
        return cls(0.0, np.zeros(3), np.zeros((3, 3)))


@dataclass(frozen=True)
class DHTable:
    """A Denavit-Hartenberg table as a scene file gave it (``[chain.dh]``), lengths in metres: the raw numbers a
    chain's joint frames were computed from (by core, in the loader: ``core.dh``), kept so that every reference
    builds the frames again with its own code (``references.common.dh_frames``). Conventions as ``core.dh``'s:
    ``"standard"`` rows T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), ``"modified"`` (Craig) rows
    Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); every joint revolute about its z axis.

    Attributes
    ----------
    convention : str
        ``"standard"`` or ``"modified"``.
    a, alpha, d, theta_offset : (n,) ndarray
        [m, rad, m, rad], the table at q = 0.
    base_xyz : (3,) ndarray
        [m] The table's base frame in the chain's base frame: zero as a file writes it; a transformed scene
        (``comparisons.invariance.transforms``) places the table there.
    base_rotation : (3, 3) ndarray
        Table base frame to chain base frame: the identity as a file writes it.
    """

    convention: str
    a: np.ndarray
    alpha: np.ndarray
    d: np.ndarray
    theta_offset: np.ndarray
    base_xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))
    base_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        if self.convention not in ("standard", "modified"):
            raise SceneError("<code>", "dh.convention", f"{self.convention!r}", "standard, modified")
        for key in ("a", "alpha", "d", "theta_offset"):
            object.__setattr__(self, key, readonly(getattr(self, key), shape=(-1,)))
        if len({len(self.a), len(self.alpha), len(self.d), len(self.theta_offset)}) != 1:
            raise SceneError("<code>", "dh", "columns of different lengths", "a, alpha, d, theta_offset of one length")
        object.__setattr__(self, "base_xyz", readonly(self.base_xyz, shape=(3,)))
        object.__setattr__(self, "base_rotation", readonly(self.base_rotation, shape=(3, 3)))


@dataclass(frozen=True)
class Joint:
    """One joint of a serial chain (URDF semantics).

    The joint frame sits at ``origin_xyz`` / ``origin_rotation`` in the parent link's
    frame; the joint moves its child link about (revolute) or along (prismatic) ``axis``
    given in the joint frame.

    Attributes
    ----------
    name : str
    type : str
        ``"revolute"`` or ``"prismatic"``.
    axis : (3,) ndarray
        Unit axis in the joint frame.
    origin_xyz : (3,) ndarray
        [m].
    origin_rotation : (3, 3) ndarray
        Parent link frame to joint frame.
    lower, upper : float
        Limits [rad or m]; ``-inf`` / ``inf`` when unlimited.
    link : LinkInertia or None
        Mass properties of the child link (and all it carries), in the child link's frame; None when the
        chain declares none (kinematics only: such a chain is refused for dynamics).
    damping : float
        Viscous joint damping [N m s/rad or N s/m], >= 0: the joint force -damping * qdot.
    armature : float
        Rotor inertia added to the joint's diagonal of the mass matrix [kg m^2 or kg], >= 0.
    origin_rpy : (3,) ndarray or None
        The roll-pitch-yaw [rad] a scene file gave ``origin_rotation`` as (URDF order: Rz(yaw) Ry(pitch)
        Rx(roll)): the raw numbers core turned into the matrix, kept so that every reference turns them with its
        own code (``references.common.scene_inputs``). None when the rotation was given as a matrix (in code,
        from a URDF file or a DH table). Code that changes ``origin_rotation`` changes this with it
        (``comparisons.invariance.transforms``), or sets it to None.
    """

    name: str
    type: str
    axis: np.ndarray
    origin_xyz: np.ndarray
    origin_rotation: np.ndarray
    lower: float = -np.inf
    upper: float = np.inf
    link: LinkInertia | None = None
    damping: float = 0.0
    armature: float = 0.0
    origin_rpy: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "axis", readonly(unit_vector(self.axis, 3, f"{self.name}.axis"), shape=(3,)))
        if self.origin_rpy is not None:
            object.__setattr__(self, "origin_rpy", readonly(self.origin_rpy, shape=(3,)))
        if np.isnan(self.lower) or np.isnan(self.upper) or self.lower > self.upper:
            raise SceneError("<code>", f"{self.name}.lower", f"limits ({self.lower}, {self.upper})",
                             "lower <= upper, -inf / inf for none")
        for key in ("damping", "armature"):
            value = getattr(self, key)
            if not (np.isfinite(value) and value >= 0):
                raise SceneError("<code>", f"{self.name}.{key}", f"{value}", "a finite number >= 0")
            object.__setattr__(self, key, float(value))
        object.__setattr__(self, "origin_xyz", readonly(self.origin_xyz, shape=(3,)))
        object.__setattr__(self, "origin_rotation", readonly(self.origin_rotation, shape=(3, 3)))

    @property
    def limited(self) -> bool:
        return bool(np.isfinite(self.lower) and np.isfinite(self.upper))


@dataclass(frozen=True)
class Chain:
    """A serial chain of joints ending in an end-effector frame, its base fixed in the world or floating free.

    Attributes
    ----------
    name : str
    joints : tuple of Joint
        Base to tip; link i is the child of joint i.
    end_effector_name : str
    end_effector_xyz : (3,) ndarray
        End-effector frame origin in the last link's frame [m].
    end_effector_rotation : (3, 3) ndarray
        Last link frame to end-effector frame.
    urdf_path : str or None
        The URDF file the chain was read from; engines then load that file themselves (the
        end effector is its link of the same name). None for chains defined otherwise,
        which engines receive as the adapters' export.
    mjcf_path : str or None
        The MJCF file the chain was read from (``core.mjcf``); engines then load that file themselves, each with
        its own MJCF importer (the end effector is its body of the same name). None otherwise; at most one of
        ``urdf_path`` and ``mjcf_path`` is set.
    base_link : str or None
        For a chain read from a URDF file: the link whose frame is the world frame (the
        file's root link unless the scene chose another); engines express every pose in
        it. For one read from an MJCF file: that body (the worldbody's one child unless the scene chose another).
        None otherwise.
    held_joints : tuple of str
        For a chain read from a URDF file: the file's movable joints below the base link that are not on the
        chain (fingers, branches, joints past the tip), held at 0 in the dynamics model (their links ride on
        the chain link they hang from). Empty otherwise.
    end_effector_rpy : (3,) ndarray or None
        The roll-pitch-yaw [rad] a scene file gave ``end_effector_rotation`` as (see :attr:`Joint.origin_rpy`);
        None when the rotation was given as a matrix.
    dh : DHTable or None
        For a chain a scene file gave as a DH table: the table, from which every joint origin and the end
        effector were computed (by core); None otherwise.
    floating_base : bool
        False: the base link is fixed in the world, its frame the world frame. True: the base link floats
        free (a 6-DOF root joint), and the state starts with its pose and velocity: configurations
        (:attr:`nq` = 7 + n) are (base origin position in the world [m] (3), base orientation quat_wxyz (4),
        joint values (n)); velocities, accelerations and generalized forces (:attr:`nv` = 6 + n) are
        (base origin linear velocity in world axes [m/s] (3), base angular velocity in world axes [rad/s] (3),
        joint rates (n)), their time derivatives, and (a force on the base in world axes [N] (3), a torque about
        the base origin in world axes [N m] (3), joint forces (n)).
    mass_problem : str
        For a chain read from a robot file: why its mass properties are physically meaningless (the first
        non-physical inertia tensor on a moving link, as one line naming the element; "" when every one is physical).
        The engines that accept such a file compute with it as written; core declines it (issue #45: a file is
        refused only where every reader refuses it). Not part of :meth:`dynamics_problem`, which says why no engine
        can compute.
    base_inertia : LinkInertia or None
        For a floating base: the mass properties of the base link and everything rigidly attached to it (links
        welded to it, branches off the chain held at 0), in the base link's frame. None for a fixed base (its
        mass never matters) or when not declared (refused for dynamics).
    """

    name: str
    joints: tuple[Joint, ...]
    end_effector_name: str = "end_effector"
    end_effector_xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))
    end_effector_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    urdf_path: str | None = None
    base_link: str | None = None
    held_joints: tuple[str, ...] = ()
    end_effector_rpy: np.ndarray | None = None
    dh: DHTable | None = None
    floating_base: bool = False
    base_inertia: LinkInertia | None = None
    mjcf_path: str | None = None
    mass_problem: str = ""

    def __post_init__(self) -> None:
        if self.urdf_path is not None and self.mjcf_path is not None:
            raise SceneError("<code>", "chain", "a chain read from both a URDF and an MJCF file", "at most one file")
        object.__setattr__(self, "end_effector_xyz", readonly(self.end_effector_xyz, shape=(3,)))
        object.__setattr__(
            self, "end_effector_rotation", readonly(self.end_effector_rotation, shape=(3, 3))
        )
        if self.end_effector_rpy is not None:
            object.__setattr__(self, "end_effector_rpy", readonly(self.end_effector_rpy, shape=(3,)))
        if self.dh is not None and len(self.dh.a) != len(self.joints):
            raise SceneError("<code>", "dh", f"{len(self.dh.a)} rows for {len(self.joints)} joints",
                             "one row per joint")

    @property
    def robot_file(self) -> str | None:
        """The robot file the chain was read from (:attr:`urdf_path` or :attr:`mjcf_path`); None for a chain defined
        otherwise."""
        return self.urdf_path if self.urdf_path is not None else self.mjcf_path

    @property
    def n_joints(self) -> int:
        return len(self.joints)

    @property
    def base_dofs(self) -> int:
        """The base's velocity components: 6 for a floating base, 0 for a fixed one."""
        return 6 if self.floating_base else 0

    @property
    def nq(self) -> int:
        """The configuration's length: n, or 7 + n with a floating base (:attr:`floating_base`)."""
        return self.n_joints + (7 if self.floating_base else 0)

    @property
    def nv(self) -> int:
        """The velocity's (acceleration's, generalized force's) length: n, or 6 + n with a floating base."""
        return self.n_joints + self.base_dofs

    @property
    def mass(self) -> float:
        """[kg] the whole robot's mass as declared: a floating base's rigid group (its :attr:`base_inertia`), then every
        joint's link (0 for a link without mass properties; a fixed base's own mass never matters and is not counted)."""
        base = self.base_inertia.mass if self.base_inertia is not None else 0.0
        return base + sum(j.link.mass for j in self.joints if j.link is not None)

    @property
    def lower(self) -> np.ndarray:
        """(n,) lower joint limits, -inf when unlimited."""
        return np.array([j.lower for j in self.joints])

    @property
    def upper(self) -> np.ndarray:
        """(n,) upper joint limits, inf when unlimited."""
        return np.array([j.upper for j in self.joints])

    def joint_values(self, q: np.ndarray) -> np.ndarray:
        """(B, n): the joints' part of configurations q (B, nq) (a floating base's pose dropped)."""
        return np.asarray(q)[:, self.nq - self.n_joints:]

    @property
    def length_powers(self) -> np.ndarray:
        """(nv,) int: the power of length in each velocity component's unit (m/s or rad/s): a floating base's linear
        velocity 1 and angular 0 first, then 1 for a prismatic joint and 0 for a revolute one."""
        base = [1, 1, 1, 0, 0, 0] if self.floating_base else []
        return np.array(base + [1 if j.type == "prismatic" else 0 for j in self.joints], dtype=int)

    @property
    def configuration_length_powers(self) -> np.ndarray:
        """(nq,) int: the power of length in each configuration component's unit: a floating base's position 1 and
        quaternion 0 first, then 1 for a prismatic joint and 0 for a revolute one."""
        base = [1, 1, 1, 0, 0, 0, 0] if self.floating_base else []
        return np.array(base + [1 if j.type == "prismatic" else 0 for j in self.joints], dtype=int)

    def frame_names(self) -> tuple[str, ...]:
        """Names of the frames FK returns: one per joint (its child link), then the end effector."""
        return tuple(j.name for j in self.joints) + (self.end_effector_name,)

    def dynamics_problem(self) -> str:
        """Why the chain has no joint-space dynamics ("" when it has): a link without declared mass
        properties, or a joint that moves no mass (its link and everything beyond it massless: the mass
        matrix would be singular)."""
        if self.floating_base and self.base_inertia is None:
            return ("the floating base link declares no mass properties: a floating base needs the base link's "
                    "(a URDF file's <inertial>)")
        missing = [j.name for j in self.joints if j.link is None]
        if missing:
            return (f"joint {missing[0]!r}'s link declares no mass properties (mass, com_xyz, inertia): "
                    "dynamics needs every link's; a URDF file's <inertial> or [[chain.joint]] mass keys give them")
        if self.floating_base and self.base_inertia is not None and (problem := _free_body_problem(self.base_inertia)):
            return (f"the floating base {self.base_link or 'link'!r} (with everything welded to it) {problem}: a free "
                    "body needs a mass and a rotational inertia about every axis, else its motion is undefined (M is "
                    "singular)")
        carried = 0.0
        for joint in reversed(self.joints):
            link = joint.link
            assert link is not None  # every link checked above
            carried += link.mass + float(np.trace(link.inertia_com))
            if carried <= 0 and joint.armature <= 0:
                return f"joint {joint.name!r} moves no mass (its link and all beyond it are massless)"
        return ""



FREE_BODY_ROUNDING = 64 * float(np.finfo(float).eps)
"""A principal moment at most this fraction of the inertia's trace is rounding of zero (the tensor's own entries are
summed and turned with ~10 roundings of the trace each)."""


def _free_body_problem(link: LinkInertia) -> str:
    """Why a floating base's rigid group is no free body ("" when it is): no mass, or a principal moment of inertia
    about its centre of mass that is zero up to rounding (a point mass, a thin rod)."""
    if link.mass <= 0:
        return "has no mass"
    moments = np.linalg.eigvalsh(link.inertia_com)
    if moments[0] <= FREE_BODY_ROUNDING * max(float(np.trace(link.inertia_com)), 0.0):
        return (f"has no rotational inertia about some axis (principal moments "
                f"{', '.join(f'{m:.3g}' for m in moments)} kg m^2)")
    return ""


def sample_configurations(chain: Chain, count: int, seed: int | np.random.Generator) -> np.ndarray:
    """(count, n) uniform joint values within the limits; [-pi, pi] rad or [-1, 1] m where unlimited.

    ``seed`` is a seed or a generator to draw from.
    """
    rng = np.random.default_rng(seed)
    default = np.array([np.pi if j.type == "revolute" else 1.0 for j in chain.joints])
    lo = np.where(np.isfinite(chain.lower), chain.lower, -default)
    hi = np.where(np.isfinite(chain.upper), chain.upper, default)
    return rng.uniform(lo, hi, size=(count, chain.n_joints))

