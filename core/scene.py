"""Scenes: the problem every engine is given, in the project's conventions.

SI units, float64, quaternions (w, x, y, z), velocities in the world frame. A body's
frame has its origin at the centre of mass; its inertia tensor is about the centre of
mass, in body axes. A scene carries only what it needs: ``gravity_world`` is ``None``
when the scene has no gravity, and adapters then give the engines none.

Scenes are built by the loader in ``comparisons.scene_loader`` (which checks every value
and reports the file and key of a bad one) or directly in code (tests, benchmarks).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from core.rotations import quat_wxyz_to_matrix


def _frozen(a, shape: tuple[int, ...]) -> np.ndarray:
    out = np.array(a, dtype=float).reshape(shape)
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class RigidBody:
    """One free rigid body and its initial state.

    Attributes
    ----------
    name : str
    mass : float
        [kg], > 0.
    inertia_body : (3, 3) ndarray
        Inertia tensor about the centre of mass in body axes [kg m^2]; symmetric
        positive definite, off-diagonal entries are the physical -sum(m x y).
    position_world : (3,) ndarray
        Centre of mass [m].
    quat_wxyz : (4,) ndarray
        Orientation, body to world, unit norm.
    velocity_world : (3,) ndarray
        Centre-of-mass velocity [m/s].
    angular_velocity_world : (3,) ndarray
        [rad/s].
    """

    name: str
    mass: float
    inertia_body: np.ndarray
    position_world: np.ndarray
    quat_wxyz: np.ndarray
    velocity_world: np.ndarray
    angular_velocity_world: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia_body", _frozen(self.inertia_body, (3, 3)))
        object.__setattr__(self, "position_world", _frozen(self.position_world, (3,)))
        q = np.asarray(self.quat_wxyz, dtype=float).reshape(4)
        object.__setattr__(self, "quat_wxyz", _frozen(q / np.linalg.norm(q), (4,)))
        object.__setattr__(self, "velocity_world", _frozen(self.velocity_world, (3,)))
        object.__setattr__(
            self, "angular_velocity_world", _frozen(self.angular_velocity_world, (3,))
        )

    @property
    def rotation_world(self) -> np.ndarray:
        """(3, 3) initial rotation matrix, body to world."""
        return quat_wxyz_to_matrix(self.quat_wxyz)


@dataclass(frozen=True)
class Forces:
    """External forces a dynamics scene asks for; absent ones are ``None``.

    Attributes
    ----------
    gravity_world : (3,) ndarray or None
        Gravitational acceleration [m/s^2].
    """

    gravity_world: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.gravity_world is not None:
            object.__setattr__(self, "gravity_world", _frozen(self.gravity_world, (3,)))

    def names(self) -> tuple[str, ...]:
        """Names of the forces present, e.g. ``("gravity",)``."""
        return tuple(n for n, v in (("gravity", self.gravity_world),) if v is not None)


@dataclass(frozen=True)
class DynamicsScene:
    """Free rigid bodies under external forces, simulated from t = 0 to ``duration``.

    Attributes
    ----------
    name, description : str
    reference : str
        Engine whose trajectory the others are measured against (e.g. ``"analytic"``).
    bodies : tuple of RigidBody
        Independent bodies (no body-body interaction).
    forces : Forces
    duration : float
        [s].
    dts : tuple of float
        Time steps [s] to run; each divides ``duration`` into a whole number of steps.
    length_unit : str
        The unit the scene file was written in (values here are already in metres).
    source : str
        File the scene came from, or ``"<code>"``.
    """

    name: str
    description: str
    reference: str
    bodies: tuple[RigidBody, ...]
    forces: Forces
    duration: float
    dts: tuple[float, ...]
    length_unit: str = "m"
    source: str = "<code>"
    kind: str = field(default="dynamics", init=False)

    def n_steps(self, dt: float) -> int:
        """Number of steps of size ``dt`` that cover ``duration``."""
        return int(round(self.duration / dt))


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
    """

    name: str
    type: str
    axis: np.ndarray
    origin_xyz: np.ndarray
    origin_rotation: np.ndarray
    lower: float = -np.inf
    upper: float = np.inf

    def __post_init__(self) -> None:
        axis = np.asarray(self.axis, dtype=float).reshape(3)
        object.__setattr__(self, "axis", _frozen(axis / np.linalg.norm(axis), (3,)))
        object.__setattr__(self, "origin_xyz", _frozen(self.origin_xyz, (3,)))
        object.__setattr__(self, "origin_rotation", _frozen(self.origin_rotation, (3, 3)))

    @property
    def limited(self) -> bool:
        return bool(np.isfinite(self.lower) and np.isfinite(self.upper))


@dataclass(frozen=True)
class Chain:
    """A fixed-base serial chain of joints ending in an end-effector frame.

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
    """

    name: str
    joints: tuple[Joint, ...]
    end_effector_name: str = "end_effector"
    end_effector_xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))
    end_effector_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "end_effector_xyz", _frozen(self.end_effector_xyz, (3,)))
        object.__setattr__(
            self, "end_effector_rotation", _frozen(self.end_effector_rotation, (3, 3))
        )

    @property
    def n_joints(self) -> int:
        return len(self.joints)

    @property
    def lower(self) -> np.ndarray:
        """(n,) lower joint limits, -inf when unlimited."""
        return np.array([j.lower for j in self.joints])

    @property
    def upper(self) -> np.ndarray:
        """(n,) upper joint limits, inf when unlimited."""
        return np.array([j.upper for j in self.joints])

    def frame_names(self) -> tuple[str, ...]:
        """Names of the frames FK returns: one per joint (its child link), then the end effector."""
        return tuple(j.name for j in self.joints) + (self.end_effector_name,)


@dataclass(frozen=True)
class KinematicsScene:
    """A chain whose FK and Jacobian are compared at seeded random configurations.

    Attributes
    ----------
    name, description, reference : str
    chain : Chain
    n_configurations : int
    seed : int
        Seed of the configuration sampler (uniform within limits, [-pi, pi] or
        [-1, 1] m where unlimited).
    source : str
    """

    name: str
    description: str
    reference: str
    chain: Chain
    n_configurations: int
    seed: int
    source: str = "<code>"
    kind: str = field(default="kinematics", init=False)

    def configurations(self) -> np.ndarray:
        """(n_configurations, n_joints) seeded random joint values within the limits."""
        rng = np.random.default_rng(self.seed)
        default = np.array([np.pi if j.type == "revolute" else 1.0 for j in self.chain.joints])
        lo = np.where(np.isfinite(self.chain.lower), self.chain.lower, -default)
        hi = np.where(np.isfinite(self.chain.upper), self.chain.upper, default)
        return rng.uniform(lo, hi, size=(self.n_configurations, self.chain.n_joints))


Scene = DynamicsScene | KinematicsScene
