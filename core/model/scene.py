"""Scenes: the problem every engine is given, in the project's conventions.

SI units, float64, quaternions (w, x, y, z), velocities in the world frame. A body's
frame has its origin at the centre of mass; its inertia tensor is about the centre of
mass, in body axes. A scene carries only what it needs: ``gravity_world`` is ``None``
when the scene has no gravity, and adapters then give the engines none.

Scenes are built by the loader in ``comparisons.scenes.loader`` (which checks every value
and reports the file and key of a bad one) or directly in code (tests, benchmarks).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError
from simparity.core.model.ranges import INERTIA_RTOL

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


def _symmetric(tensor: np.ndarray, what: str) -> None:
    """SceneError unless the (3, 3) ``tensor`` is symmetric to :data:`~core.model.ranges.INERTIA_RTOL` of its largest
    entry (a rotated tensor, R I R^T, is symmetric to rounding): engines read one triangle or the other."""
    largest = float(np.max(np.abs(tensor)))
    asymmetry = float(np.max(np.abs(tensor / largest - tensor.T / largest))) if largest > 0 else 0.0
    if asymmetry > INERTIA_RTOL:
        raise SceneError("<code>", what, f"not symmetric: max |I - I^T| = {asymmetry * largest:.3g} kg m^2",
                         f"a symmetric tensor (to {INERTIA_RTOL:g} of its largest entry)")


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
    point_masses : PointMasses or None
        When the body was built from point masses: them (mass, COM and tensor above were
        computed from them).
    """

    name: str
    mass: float
    inertia_body: np.ndarray
    position_world: np.ndarray
    quat_wxyz: np.ndarray
    velocity_world: np.ndarray
    angular_velocity_world: np.ndarray
    point_masses: "PointMasses | None" = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia_body", readonly(self.inertia_body, shape=(3, 3)))
        if np.all(np.isfinite(self.inertia_body)):
            _symmetric(self.inertia_body, f"{self.name}.inertia_body")
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


SHAPES = ("point", "sphere", "box", "points")
"""Collision shapes of a body (:class:`Shape`)."""

CONTACT_METHODS = ("backup", "act_after", "penalty")
"""The lecture's three ways of handling contact, which core runs (:class:`Contact`):

- ``backup``: back up time to the first instant of contact, respond there (an impulse with
  restitution and Coulomb friction), integrate the rest of the step; contacts within one step
  in time order;
- ``act_after``: the kinematic response after the fact: contact detected at the end of a step
  (E(p) <= 0), the velocity reflected v - (1 + k)(v . N) N (an impulse for a rigid body) and
  the body projected back out of the plane;
- ``penalty``: a spring-damper force on penetration (``penalty_stiffness``, ``penalty_damping``)
  integrated by a time integrator; it makes the system stiff."""

PENALTY_PREFIX = "penalty_"
"""Integrator names of the penalty method: this prefix and the time integrator (``penalty_rk4``).
Each has its stability limit measured on the scene (``comparisons.measure.stability``)."""


@dataclass(frozen=True)
class Plane:
    """The plane E(p) = N . p + d = 0 with unit normal N, free side E > 0.

    Built from the lecture's coefficients: ``Plane((a, b, c), d)``; (a, b, c) is normalised
    and d divided by the same length, so that E is a signed distance [m].

    Attributes
    ----------
    normal_world : (3,) ndarray
        Unit normal N, pointing to the free side.
    offset : float
        d [m]: the plane passes through -d N.
    name : str
    """

    normal_world: np.ndarray
    offset: float
    name: str = "plane"

    def __post_init__(self) -> None:
        abc = np.asarray(self.normal_world, dtype=float).reshape(3)
        with np.errstate(over="ignore", invalid="ignore"):
            length = float(np.linalg.norm(abc))
        if not np.isfinite(length) or length == 0.0:
            raise ValueError(f"{ZERO_NORMAL}, got {abc.tolist()}")
        if not np.isfinite(self.offset):
            raise ValueError(f"the plane's offset d must be finite, got {self.offset}")
        object.__setattr__(self, "normal_world", readonly(abc / length, shape=(3,)))
        object.__setattr__(self, "offset", float(self.offset) / length)

    def signed_distance(self, position_world: np.ndarray) -> np.ndarray:
        """E(p) = N . p + d [m] of points (..., 3) [m]; (...,), negative inside the plane."""
        return np.asarray(position_world) @ self.normal_world + self.offset


ZERO_NORMAL = "the plane's normal (a, b, c) must be finite and non-zero"


@dataclass(frozen=True)
class Shape:
    """A body's collision shape, in body axes about its centre of mass.

    Attributes
    ----------
    kind : str
        ``"point"`` (a particle at the COM), ``"sphere"`` (``radius`` about the COM), ``"box"``
        (``half_extents_body`` about ``center_body``: 8 vertices, 6 faces) or ``"points"``
        (the vertices ``points_body``: a body built from point masses touches with its points).
    radius : float
        Sphere radius [m]; 0 otherwise.
    half_extents_body : (3,) ndarray
        Box half sizes along the body axes [m]; zeros otherwise.
    center_body : (3,) ndarray
        Box centre relative to the COM, body axes [m].
    points_body : (V, 3) ndarray
        ``points``: the contact points relative to the COM, body axes [m]; (0, 3) otherwise.
    """

    kind: str = "point"
    radius: float = 0.0
    half_extents_body: np.ndarray = field(default_factory=lambda: np.zeros(3))
    center_body: np.ndarray = field(default_factory=lambda: np.zeros(3))
    points_body: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __post_init__(self) -> None:
        if self.kind not in SHAPES:
            raise SceneError("<code>", "shape", f"unknown shape {self.kind!r}", ", ".join(SHAPES))
        object.__setattr__(self, "half_extents_body", readonly(self.half_extents_body, shape=(3,)))
        object.__setattr__(self, "center_body", readonly(self.center_body, shape=(3,)))
        object.__setattr__(self, "points_body", readonly(self.points_body, shape=(-1, 3)))

    def vertices_body(self) -> np.ndarray:
        """(V, 3) points of the shape that can touch a plane first, relative to the COM [m]:
        the COM for a point, the 8 corners of a box, the points of ``points``. A sphere has none
        (it touches at -radius N); (1, 3) zeros, its centre, is returned for it."""
        if self.kind == "box":
            signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
            return self.center_body + signs * self.half_extents_body
        if self.kind == "points":
            return np.array(self.points_body)
        return np.zeros((1, 3))


@dataclass(frozen=True)
class Material:
    """Contact parameters of one body against one plane.

    Attributes
    ----------
    restitution : float
        k in [0, 1]: the normal velocity after an impact is -k times the one before.
    friction_static, friction_kinetic : float
        Coulomb coefficients mu_s >= mu_k >= 0: a contact sticks while the tangential force
        needed stays within mu_s N, and slides with mu_k N otherwise.
    """

    restitution: float = 0.0
    friction_static: float = 0.0
    friction_kinetic: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.restitution <= 1.0:
            raise SceneError("<code>", "restitution", f"{self.restitution} is outside [0, 1]", "0 <= k <= 1")
        if not 0.0 <= self.friction_kinetic <= self.friction_static < np.inf:
            raise SceneError("<code>", "friction_kinetic", f"mu_k = {self.friction_kinetic}, mu_s = "
                             f"{self.friction_static}", "0 <= friction_kinetic <= friction_static, finite")


@dataclass(frozen=True)
class Contact:
    """Planes a scene's bodies collide with, and how (bodies do not collide with each other).

    Attributes
    ----------
    planes : tuple of Plane
    shapes : tuple of Shape
        One per body.
    materials : tuple of tuple of Material
        ``materials[body][plane]``.
    methods : tuple of str
        Core's response methods to run (:data:`CONTACT_METHODS`).
    rest_speed : float
        [m/s] An impact whose rebound (normal speed after it) would be slower than this ends in
        resting contact instead: the normal velocity is removed, the body stays on the plane.
        Every engine given the scene applies the same rule where it can (PyBullet's restitution
        velocity threshold); the analytic reference applies it too.
    penalty_stiffness : float
        k_s [N/m] of the penalty method.
    penalty_damping : float or None
        k_d [N s/m] of the penalty method; None: per body and plane, the damping that gives the linear
        spring-damper on the body's mass the pair's restitution k, c = 2 zeta sqrt(k_s m) with
        zeta = -ln k / sqrt(pi^2 + ln^2 k) (critical for k = 0, none for k = 1).
    """

    planes: tuple[Plane, ...]
    shapes: tuple[Shape, ...]
    materials: tuple[tuple[Material, ...], ...]
    methods: tuple[str, ...] = CONTACT_METHODS
    rest_speed: float = 1e-3
    penalty_stiffness: float = 1e5
    penalty_damping: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "planes", tuple(self.planes))
        object.__setattr__(self, "shapes", tuple(self.shapes))
        object.__setattr__(self, "materials", tuple(tuple(row) for row in self.materials))
        if any(len(row) != len(self.planes) for row in self.materials) or len(self.materials) != len(self.shapes):
            raise SceneError("<code>", "contact", "materials must be one row per body, one entry per plane",
                             "materials[body][plane]")
        unknown = [m for m in self.methods if m not in CONTACT_METHODS]
        if unknown or not self.methods:
            raise SceneError("<code>", "contact.methods", f"{unknown or 'none'}", ", ".join(CONTACT_METHODS))

    def _table(self, name: str) -> np.ndarray:
        return readonly([[getattr(m, name) for m in row] for row in self.materials], shape=(len(self.shapes), -1))

    @property
    def restitution(self) -> np.ndarray:
        """(B, P) k of every body against every plane."""
        return self._table("restitution")

    @property
    def friction_static(self) -> np.ndarray:
        """(B, P) mu_s."""
        return self._table("friction_static")

    @property
    def friction_kinetic(self) -> np.ndarray:
        """(B, P) mu_k."""
        return self._table("friction_kinetic")


@dataclass(frozen=True)
class PointMasses:
    """A body built from point masses (the lecture's "Center of Mass" and "Inertia Tensor").

    Attributes
    ----------
    masses : (N,) ndarray
        [kg].
    points_body : (N, 3) ndarray
        Positions relative to the centre of mass, body axes [m] (the loader subtracts the COM).
    center_of_mass_given : (3,) ndarray
        The COM sum m_i q_i / M in the frame the points were given in [m].
    positions_given : (N, 3) ndarray or None
        The points as the scene file gave them, in its frame [m]: the raw numbers ``points_body``, the COM and
        the body's mass and tensor were computed from (by core, in the loader), kept so that every reference
        computes them again with its own code (``references.common.scene_inputs``). None for a body built in code.
    frame_position_world : (3,) ndarray or None
        Where the file's ``position_world`` put the frame the points were given in [m] (the body's
        ``position_world`` is this plus its rotation times the COM); None with ``positions_given``. Code that moves
        such a body moves this too (``comparisons.invariance.transforms``, ``comparisons.invariance.perturb``).
    """

    masses: np.ndarray
    points_body: np.ndarray
    center_of_mass_given: np.ndarray
    positions_given: np.ndarray | None = None
    frame_position_world: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "masses", readonly(self.masses, shape=(-1,)))
        object.__setattr__(self, "points_body", readonly(self.points_body, shape=(-1, 3)))
        object.__setattr__(self, "center_of_mass_given", readonly(self.center_of_mass_given, shape=(3,)))
        if (self.positions_given is None) != (self.frame_position_world is None):
            raise SceneError("<code>", "point_mass", "positions_given without frame_position_world or the reverse",
                             "both (a body read from a scene file) or neither (a body built in code)")
        if self.positions_given is not None:
            object.__setattr__(self, "positions_given", readonly(self.positions_given, shape=self.points_body.shape))
            object.__setattr__(self, "frame_position_world", readonly(self.frame_position_world, shape=(3,)))


@dataclass(frozen=True)
class SweepPoint:
    """Where a scene sits in the ``[sweep]`` of its file: one variant of the scene the file declares
    (``docs/scenes.md``, "Sweeps").

    Attributes
    ----------
    base : str
        The name the file gives the scene (``[scene] name``); the variant's own name is derived from it
        and the values, for display only.
    values : tuple of (str, int or float)
        Each swept key (its path as the ``[sweep]`` table writes it, e.g. ``"body[ball].restitution"``)
        with this variant's value, in the sweep's order. A value is the number written into the file, in
        the file's ``length_unit``: an int for whole-number keys (seeds, counts), else a float.
    index : int
        The variant's position in the sweep's order, from 0.
    count : int
        Variants the file expands into.
    """

    base: str
    values: tuple[tuple[str, int | float], ...]
    index: int
    count: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", tuple((str(k), v) for k, v in self.values))
        if not 0 <= self.index < self.count:
            raise SceneError("<code>", "sweep", f"variant index {self.index} of {self.count} variants",
                             "an index from 0 to count - 1")

    @property
    def keys(self) -> tuple[str, ...]:
        """The swept keys, in the sweep's order."""
        return tuple(key for key, _ in self.values)


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
        File the scene came from, or ``"<code>"``: where, not what; not part of the scene's equality or
        content hash.
    suites : tuple of str
        The built-in suites (:data:`SUITES`) the scene belongs to.
    contact : Contact or None
        Planes the bodies collide with; None: no contact (no engine is given any).
    sweep : SweepPoint or None
        For a variant of a file with a ``[sweep]``: its base scene and swept values; None otherwise.
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
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    contact: Contact | None = None
    sweep: SweepPoint | None = None
    kind: str = field(default="dynamics", init=False)

    def n_steps(self, dt: float) -> int:
        """Number of steps of size ``dt`` that cover ``duration``."""
        return int(round(self.duration / dt))

    def replicated(self, copies: int) -> DynamicsScene:
        """The scene ``copies`` times over, as one scene of ``copies * N`` bodies: copy c's body k is body
        ``c * N + k``, with its forces (per-body arrays tiled, applied forces re-indexed) and its contact shape and
        materials. Bodies never interact, so every copy moves as the scene does: an engine batched over bodies
        steps all copies together."""
        n, forces = len(self.bodies), self.forces

        def tiled(values: np.ndarray | None) -> np.ndarray | None:
            return None if values is None else np.tile(values, copies)

        applied = tuple(replace(a, body=a.body + c * n) for c in range(copies) for a in forces.applied)
        forces = replace(forces, linear_drag=tiled(forces.linear_drag), quadratic_drag=tiled(forces.quadratic_drag),
                         angular_linear_drag=tiled(forces.angular_linear_drag),
                         angular_quadratic_drag=tiled(forces.angular_quadratic_drag), applied=applied)
        contact = None if self.contact is None else replace(self.contact, shapes=self.contact.shapes * copies,
                                                            materials=self.contact.materials * copies)
        return replace(self, bodies=self.bodies * copies, forces=forces, contact=contact)


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
        _symmetric(self.inertia_com, "inertia")

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
        object.__setattr__(self, "axis", readonly(_unit(self.axis, 3, f"{self.name}.axis"), shape=(3,)))
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

    def __post_init__(self) -> None:
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

    def dynamics_problem(self) -> str:
        """Why the chain has no joint-space dynamics ("" when it has): a link without declared mass
        properties, or a joint that moves no mass (its link and everything beyond it massless: the mass
        matrix would be singular)."""
        missing = [j.name for j in self.joints if j.link is None]
        if missing:
            return (f"joint {missing[0]!r}'s link declares no mass properties (mass, com_xyz, inertia): "
                    "dynamics needs every link's; a URDF file's <inertial> or [[chain.joint]] mass keys give them")
        carried = 0.0
        for joint in reversed(self.joints):
            link = joint.link
            assert link is not None  # every link checked above
            carried += link.mass + float(np.trace(link.inertia_com))
            if carried <= 0 and joint.armature <= 0:
                return f"joint {joint.name!r} moves no mass (its link and all beyond it are massless)"
        return ""


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
    sweep : SweepPoint or None
        For a variant of a file with a ``[sweep]``: its base scene and swept values; None otherwise.
    """

    name: str
    description: str
    reference: str
    chain: Chain
    n_configurations: int
    seed: int
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="kinematics", init=False)

    def configurations(self) -> np.ndarray:
        """(n_configurations, n_joints) seeded random joint values within the limits."""
        return sample_configurations(self.chain, self.n_configurations, self.seed)


SUITES = ("default", "hard", "contact", "bench", "articulated")
"""Named groups of built-in scenes (``simparity run --suite``): ``default`` is what ``simparity
run`` runs; ``hard`` gathers the numerical-stability cases, each with the verdict it must earn
in the shipped tolerances; ``contact`` every scene with planes; ``bench`` the real arms whose IK
``simparity bench`` times (10,000 targets each); ``articulated`` the joint-space dynamics of real robot arms and
the crafted arm. A scene may be in several."""

HARD_TARGETS = ("stretched", "beyond_reach", "at_base", "near_limits", "beyond_limits", "orientation_in_place",
                "wrist_flip")
"""Hard IK targets a scene may ask for (see ``comparisons.execute.ik_targets``)."""


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
    sweep : SweepPoint or None
        For a variant of a file with a ``[sweep]``: its base scene and swept values; None otherwise.
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
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="ik", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "q_start", readonly(self.q_start, shape=(self.chain.n_joints,)))

    def configurations(self) -> np.ndarray:
        """(n_targets, n) seeded random configurations within the limits (as KinematicsScene)."""
        return sample_configurations(self.chain, self.n_targets, self.seed)


@dataclass(frozen=True)
class JointDynamicsScene:
    """A chain's joint-space dynamics (mass matrix, bias forces, inverse and forward dynamics) compared at
    seeded random states: instant by instant, no time stepping.

    The chain's base link is fixed in the world and its frame is the world frame.

    Attributes
    ----------
    name, description, reference : str
    chain : Chain
        With mass properties on every link (:meth:`Chain.dynamics_problem` is "").
    gravity_world : (3,) ndarray or None
        [m/s^2] in the base frame; None: no gravity.
    n_states : int
        Seeded random states (q, qdot, qddot, tau).
    seed : int
    velocity_scale, acceleration_scale, torque_scale : float or (n,) ndarray
        qdot, qddot and tau are uniform in [-scale, scale] per joint [rad/s or m/s, rad/s^2 or m/s^2,
        N m or N]; q is uniform within the limits (:func:`sample_configurations`). One number serves every joint;
        stored as one per joint, (n,), so that a change of units can scale a revolute and a prismatic joint's
        differently.
    source : str
    suites : tuple of str
    sweep : SweepPoint or None
    """

    name: str
    description: str
    reference: str
    chain: Chain
    gravity_world: np.ndarray | None
    n_states: int
    seed: int
    velocity_scale: float | np.ndarray = 1.0
    acceleration_scale: float | np.ndarray = 1.0
    torque_scale: float | np.ndarray = 1.0
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="joint_dynamics", init=False)

    def __post_init__(self) -> None:
        problem = self.chain.dynamics_problem()
        if problem:
            raise SceneError(self.source, "chain", problem, "a chain with mass properties on every link")
        if self.gravity_world is not None:
            object.__setattr__(self, "gravity_world", readonly(self.gravity_world, shape=(3,)))
        for key in ("velocity_scale", "acceleration_scale", "torque_scale"):
            scale = np.broadcast_to(np.asarray(getattr(self, key), dtype=float), (self.chain.n_joints,))
            if not np.all(np.isfinite(scale) & (scale > 0)):
                raise SceneError(self.source, key, f"{scale.tolist()}", "finite numbers > 0, one or one per joint")
            object.__setattr__(self, key, readonly(scale, shape=(self.chain.n_joints,)))

    def states(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(q, qdot, qddot, tau), each (n_states, n): seeded, q within the limits."""
        rng = np.random.default_rng(self.seed)
        q = sample_configurations(self.chain, self.n_states, rng)
        shape = (self.n_states, self.chain.n_joints)
        qd, qdd, tau = (scale * rng.uniform(-1.0, 1.0, size=shape)
                        for scale in (self.velocity_scale, self.acceleration_scale, self.torque_scale))
        return q, qd, qdd, tau


@dataclass(frozen=True)
class JointMotionScene:
    """A chain's motion through time: its joints stepped from an initial state under gravity, its joints' damping
    and constant joint forces, for ``duration`` at each time step of ``dts``.

    The chain's base link is fixed in the world and its frame is the world frame. Every engine is given the same
    model; the applied joint forces are constant in time, so an engine that holds them over a step (MuJoCo holds
    ``qfrc_applied`` over an RK4 step) and one that evaluates them at every stage see the same forces.

    Attributes
    ----------
    name, description, reference : str
        ``reference`` is ``engine`` or ``engine:integrator`` (the integrator defaults to the engine's first).
    chain : Chain
        With mass properties on every link (:meth:`Chain.dynamics_problem` is ""); its joints' ``damping`` and
        ``armature`` are part of the motion.
    gravity_world : (3,) ndarray or None
        [m/s^2] in the base frame; None: no gravity.
    q0, qdot0 : (B, n) ndarray
        Initial joint values and velocities of B copies [rad or m, rad/s or m/s] (one copy: B = 1).
    torque : (n,) ndarray
        Constant applied joint forces [N m or N].
    duration : float
        [s].
    dts : tuple of float
        The time-step ladder [s], largest first or in any order.
    integrators : tuple of str
        The integrators to run (empty: every one each engine offers for joint motion).
    perturbation : float
        > 0: every case also runs from q0 + perturbation on every joint [rad or m] and reports when its two runs part,
        beside when it parts from the reference (predictability, Chung and Pollard 2016); 0: not run.
    segments : int
        0: every engine against the reference. k > 0: accuracy as self-consistency (Erez, Tassa and Todorov
        2015): the motion is cut into k segments starting on the reference's trajectory, and each engine's
        state at a segment's end is compared with the same engine and integrator at a much smaller step from
        the same start, averaged over segments, so that a chaotic chain's divergence is not counted as error.
    source : str
    suites : tuple of str
    sweep : SweepPoint or None
    """

    name: str
    description: str
    reference: str
    chain: Chain
    gravity_world: np.ndarray | None
    q0: np.ndarray
    qdot0: np.ndarray
    torque: np.ndarray
    duration: float
    dts: tuple[float, ...]
    integrators: tuple[str, ...] = ()
    segments: int = 0
    perturbation: float = 0.0
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="joint_motion", init=False)

    def __post_init__(self) -> None:
        problem = self.chain.dynamics_problem()
        if problem:
            raise SceneError(self.source, "chain", problem, "a chain with mass properties on every link")
        n = self.chain.n_joints
        if self.gravity_world is not None:
            object.__setattr__(self, "gravity_world", readonly(self.gravity_world, shape=(3,)))
        for key in ("q0", "qdot0"):
            value = np.asarray(getattr(self, key), dtype=float)
            value = value.reshape(1, n) if value.ndim == 1 else value
            if value.ndim != 2 or value.shape[1] != n or not np.all(np.isfinite(value)):
                raise SceneError(self.source, key, f"shape {value.shape}", f"finite numbers, (B, {n}) or ({n},)")
            object.__setattr__(self, key, readonly(value))
        if self.q0.shape != self.qdot0.shape:
            raise SceneError(self.source, "qdot0", f"{self.qdot0.shape[0]} copies, q0 has {self.q0.shape[0]}",
                             "as many initial velocities as initial joint values")
        object.__setattr__(self, "torque", readonly(np.asarray(self.torque, dtype=float), shape=(n,)))
        if not (np.isfinite(self.duration) and self.duration > 0):
            raise SceneError(self.source, "duration", f"{self.duration}", "a finite number of seconds > 0")
        if not self.dts or not all(np.isfinite(dt) and 0 < dt <= self.duration for dt in self.dts):
            raise SceneError(self.source, "dt", f"{list(self.dts)}", "time steps > 0 and at most the duration")
        if self.segments < 0:
            raise SceneError(self.source, "segments", f"{self.segments}", "0 (against the reference) or more")
        if not (np.isfinite(self.perturbation) and self.perturbation >= 0):
            raise SceneError(self.source, "perturbation", f"{self.perturbation}", "a finite number >= 0 (0: none)")

    @property
    def copies(self) -> int:
        """B, the copies stepped together."""
        return self.q0.shape[0]

    def n_steps(self, dt: float) -> int:
        """Number of steps of size ``dt`` that cover ``duration`` (at least one)."""
        return max(1, int(round(self.duration / dt)))

    def starting_from(self, q0: np.ndarray, qdot0: np.ndarray, duration: float) -> "JointMotionScene":
        """The same chain and forces from other initial states ((B, n) each) for ``duration`` [s]."""
        return replace(self, q0=q0, qdot0=qdot0, duration=duration, dts=tuple(min(dt, duration) for dt in self.dts))


def sample_configurations(chain: Chain, count: int, seed: int | np.random.Generator) -> np.ndarray:
    """(count, n) uniform joint values within the limits; [-pi, pi] rad or [-1, 1] m where unlimited.

    ``seed`` is a seed or a generator to draw from.
    """
    rng = np.random.default_rng(seed)
    default = np.array([np.pi if j.type == "revolute" else 1.0 for j in chain.joints])
    lo = np.where(np.isfinite(chain.lower), chain.lower, -default)
    hi = np.where(np.isfinite(chain.upper), chain.upper, default)
    return rng.uniform(lo, hi, size=(count, chain.n_joints))


Scene = DynamicsScene | KinematicsScene | IKScene | JointDynamicsScene | JointMotionScene
