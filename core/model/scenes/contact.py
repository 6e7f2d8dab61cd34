"""Contact of free bodies with planes: :class:`Plane`, :class:`Shape`, :class:`Material`, :class:`Contact`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError


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

