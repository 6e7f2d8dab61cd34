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

from simparity.core.arrays import readonly
from simparity.core.errors import SceneError

_SAFE_NORM = (1e-150, 1e150)
"""Norms whose square neither under- nor overflows in float64; outside, a vector is first scaled
by its largest entry (which keeps the direction exact to rounding)."""


def _unit(vector, size: int, what: str) -> np.ndarray:
    """``vector`` normalised without overflow or underflow; SceneError if it has no direction."""
    v = np.asarray(vector, dtype=float).reshape(size)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        norm = float(np.linalg.norm(v))
    if not _SAFE_NORM[0] < norm < _SAFE_NORM[1]:
        largest = float(np.max(np.abs(v)))
        if not (np.isfinite(largest) and largest > 0):
            raise SceneError("<code>", what, f"{v.tolist()} has no direction", "a finite non-zero vector")
        v = v / largest
        norm = float(np.linalg.norm(v))
    return v / norm


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
        object.__setattr__(self, "inertia_body", readonly(self.inertia_body, shape=(3, 3)))
        object.__setattr__(self, "position_world", readonly(self.position_world, shape=(3,)))
        object.__setattr__(self, "quat_wxyz", readonly(_unit(self.quat_wxyz, 4, f"{self.name}.quat_wxyz"), shape=(4,)))
        object.__setattr__(self, "velocity_world", readonly(self.velocity_world, shape=(3,)))
        object.__setattr__(
            self, "angular_velocity_world", readonly(self.angular_velocity_world, shape=(3,))
        )


@dataclass(frozen=True)
class AppliedForce:
    """A constant world-frame force applied at a point fixed in a body (lecture: "Forces").

    Attributes
    ----------
    body : int
        Index of the body in the scene.
    force_world : (3,) ndarray
        [N].
    point_body : (3,) ndarray
        Point of application relative to the COM, in body axes [m]; its torque about the
        COM is (R point_body) x force_world.
    """

    body: int
    force_world: np.ndarray
    point_body: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "force_world", readonly(self.force_world, shape=(3,)))
        object.__setattr__(self, "point_body", readonly(self.point_body, shape=(3,)))


def _per_body(values) -> np.ndarray | None:
    return None if values is None else readonly(values, shape=(-1,))


@dataclass(frozen=True)
class Forces:
    """External forces a dynamics scene asks for; absent ones are ``None`` (or empty).

    Drag acts on the velocity relative to the air, v - air_velocity_world (wind).

    Attributes
    ----------
    gravity_world : (3,) ndarray or None
        Gravitational acceleration [m/s^2].
    air_velocity_world : (3,) ndarray or None
        Wind [m/s]; None means still air.
    linear_drag : (B,) ndarray or None
        F = -b (v - w) [N s/m].
    quadratic_drag : (B,) ndarray or None
        F = -c |v - w| (v - w) [N s^2/m^2].
    angular_linear_drag : (B,) ndarray or None
        tau = -k omega [N m s].
    angular_quadratic_drag : (B,) ndarray or None
        tau = -k |omega| omega [N m s^2].
    applied : tuple of AppliedForce
    """

    gravity_world: np.ndarray | None = None
    air_velocity_world: np.ndarray | None = None
    linear_drag: np.ndarray | None = None
    quadratic_drag: np.ndarray | None = None
    angular_linear_drag: np.ndarray | None = None
    angular_quadratic_drag: np.ndarray | None = None
    applied: tuple[AppliedForce, ...] = ()

    def __post_init__(self) -> None:
        for name in ("gravity_world", "air_velocity_world"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, readonly(getattr(self, name), shape=(3,)))
        for name in ("linear_drag", "quadratic_drag", "angular_linear_drag", "angular_quadratic_drag"):
            object.__setattr__(self, name, _per_body(getattr(self, name)))
        object.__setattr__(self, "applied", tuple(self.applied))

    def names(self) -> tuple[str, ...]:
        """Names of the forces present, e.g. ``("gravity", "linear_drag")``."""
        present = [
            ("gravity", self.gravity_world), ("wind", self.air_velocity_world),
            ("linear_drag", self.linear_drag), ("quadratic_drag", self.quadratic_drag),
            ("angular_linear_drag", self.angular_linear_drag),
            ("angular_quadratic_drag", self.angular_quadratic_drag),
            ("applied_force", self.applied or None),
        ]
        return tuple(name for name, value in present if value is not None)

    @property
    def exerts_torque(self) -> bool:
        """True when some force has a torque about a body's COM (angular drag, applied forces)."""
        return bool({"angular_linear_drag", "angular_quadratic_drag", "applied_force"} & set(self.names()))

    @property
    def conserves_energy(self) -> bool:
        """True when kinetic plus gravitational potential energy is conserved (no drag, no applied force)."""
        return set(self.names()) <= {"gravity"}

    @property
    def conserves_angular_momentum(self) -> bool:
        """True when each body's angular momentum about its COM is conserved (no torque)."""
        return not self.exerts_torque


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
    integrators : tuple of str
        Integrator names to run (every engine runs those it has); empty means all.
    length_unit : str
        The unit the scene file was written in (values here are already in metres).
    source : str
        File the scene came from, or ``"<code>"``.
    suites : tuple of str
        The built-in suites (:data:`SUITES`) the scene belongs to.
    """

    name: str
    description: str
    reference: str
    bodies: tuple[RigidBody, ...]
    forces: Forces
    duration: float
    dts: tuple[float, ...]
    integrators: tuple[str, ...] = ()
    length_unit: str = "m"
    source: str = "<code>"
    suites: tuple[str, ...] = ("default",)
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
        object.__setattr__(self, "axis", readonly(_unit(self.axis, 3, f"{self.name}.axis"), shape=(3,)))
        if np.isnan(self.lower) or np.isnan(self.upper) or self.lower > self.upper:
            raise SceneError("<code>", f"{self.name}.lower", f"limits ({self.lower}, {self.upper})",
                             "lower <= upper, -inf / inf for none")
        object.__setattr__(self, "origin_xyz", readonly(self.origin_xyz, shape=(3,)))
        object.__setattr__(self, "origin_rotation", readonly(self.origin_rotation, shape=(3, 3)))

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
    urdf_path : str or None
        The URDF file the chain was read from; engines then load that file themselves (the
        end effector is its link of the same name). None for chains defined otherwise,
        which engines receive as the adapters' export.
    base_link : str or None
        For a chain read from a URDF file: the link whose frame is the world frame (the
        file's root link unless the scene chose another); engines express every pose in
        it. None otherwise.
    """

    name: str
    joints: tuple[Joint, ...]
    end_effector_name: str = "end_effector"
    end_effector_xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))
    end_effector_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    urdf_path: str | None = None
    base_link: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "end_effector_xyz", readonly(self.end_effector_xyz, shape=(3,)))
        object.__setattr__(
            self, "end_effector_rotation", readonly(self.end_effector_rotation, shape=(3, 3))
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
    suites : tuple of str
        The built-in suites (:data:`SUITES`) the scene belongs to.
    """

    name: str
    description: str
    reference: str
    chain: Chain
    n_configurations: int
    seed: int
    source: str = "<code>"
    suites: tuple[str, ...] = ("default",)
    kind: str = field(default="kinematics", init=False)

    def configurations(self) -> np.ndarray:
        """(n_configurations, n_joints) seeded random joint values within the limits."""
        return sample_configurations(self.chain, self.n_configurations, self.seed)


SUITES = ("default", "hard")
"""Named groups of built-in scenes (``simparity run --suite``): ``default`` is what ``simparity
run`` runs; ``hard`` gathers the numerical-stability cases, each with the verdict it must earn
in the shipped tolerances. A scene may be in several."""

HARD_TARGETS = ("stretched", "beyond_reach", "at_base", "near_limits", "beyond_limits", "orientation_in_place",
                "wrist_flip")
"""Hard IK targets a scene may ask for (see ``comparisons.ik_targets``)."""


@dataclass(frozen=True)
class IKScene:
    """A chain, seeded random reachable targets and hard targets for every IK solver.

    Attributes
    ----------
    name, description : str
    reference : str
        Engine whose forward kinematics generates the targets and judges cross-evaluation.
    chain : Chain
    n_targets : int
        Random reachable targets: the end-effector poses of seeded random configurations.
    seed : int
    target_kind : str
        ``"pose"`` (position and orientation) or ``"position"``.
    q_start : (n,) ndarray
        The one start configuration of every solve [rad or m] (also the rest pose).
    position_tolerance : float
        [m].
    orientation_tolerance : float
        [rad].
    max_iterations : int
    hard_targets : tuple of str
        Names from :data:`HARD_TARGETS`.
    source : str
    suites : tuple of str
        The built-in suites (:data:`SUITES`) the scene belongs to.
    """

    name: str
    description: str
    reference: str
    chain: Chain
    n_targets: int
    seed: int
    target_kind: str
    q_start: np.ndarray
    position_tolerance: float
    orientation_tolerance: float
    max_iterations: int
    hard_targets: tuple[str, ...] = ()
    source: str = "<code>"
    suites: tuple[str, ...] = ("default",)
    kind: str = field(default="ik", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "q_start", readonly(self.q_start, shape=(self.chain.n_joints,)))

    def configurations(self) -> np.ndarray:
        """(n_targets, n) seeded random configurations within the limits (as KinematicsScene)."""
        return sample_configurations(self.chain, self.n_targets, self.seed)


def sample_configurations(chain: Chain, count: int, seed: int) -> np.ndarray:
    """(count, n) uniform joint values within the limits; [-pi, pi] rad or [-1, 1] m where unlimited."""
    rng = np.random.default_rng(seed)
    default = np.array([np.pi if j.type == "revolute" else 1.0 for j in chain.joints])
    lo = np.where(np.isfinite(chain.lower), chain.lower, -default)
    hi = np.where(np.isfinite(chain.upper), chain.upper, default)
    return rng.uniform(lo, hi, size=(count, chain.n_joints))


Scene = DynamicsScene | KinematicsScene | IKScene
