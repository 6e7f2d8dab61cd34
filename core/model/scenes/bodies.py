"""Free rigid bodies and the forces on them: :class:`RigidBody` (built in code or from
:class:`PointMasses`), :class:`AppliedForce`, :class:`Forces`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.checks import check_symmetric, unit_vector
from simparity.core.model.scenes.time_functions import TimedLoad


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
            check_symmetric(self.inertia_body, f"{self.name}.inertia_body")
        object.__setattr__(self, "position_world", readonly(self.position_world, shape=(3,)))
        object.__setattr__(self, "quat_wxyz", readonly(unit_vector(self.quat_wxyz, 4, f"{self.name}.quat_wxyz"), shape=(4,)))
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
    timed : tuple of TimedLoad
        Forces and torques that change with time (:mod:`core.model.scenes.time_functions`).
    """

    gravity_world: np.ndarray | None = None
    air_velocity_world: np.ndarray | None = None
    linear_drag: np.ndarray | None = None
    quadratic_drag: np.ndarray | None = None
    angular_linear_drag: np.ndarray | None = None
    angular_quadratic_drag: np.ndarray | None = None
    applied: tuple[AppliedForce, ...] = ()
    timed: tuple[TimedLoad, ...] = ()

    def __post_init__(self) -> None:
        for name in ("gravity_world", "air_velocity_world"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, readonly(getattr(self, name), shape=(3,)))
        for name in ("linear_drag", "quadratic_drag", "angular_linear_drag", "angular_quadratic_drag"):
            object.__setattr__(self, name, _per_body(getattr(self, name)))
        object.__setattr__(self, "applied", tuple(self.applied))
        object.__setattr__(self, "timed", tuple(self.timed))

    def names(self) -> tuple[str, ...]:
        """Names of the forces present, e.g. ``("gravity", "linear_drag")``."""
        present = [
            ("gravity", self.gravity_world), ("wind", self.air_velocity_world),
            ("linear_drag", self.linear_drag), ("quadratic_drag", self.quadratic_drag),
            ("angular_linear_drag", self.angular_linear_drag),
            ("angular_quadratic_drag", self.angular_quadratic_drag),
            ("applied_force", self.applied or None),
            ("timed_load", self.timed or None),
        ]
        return tuple(name for name, value in present if value is not None)

    @property
    def exerts_torque(self) -> bool:
        """True when some force has a torque about a body's COM (angular drag, applied forces, timed loads)."""
        return bool({"angular_linear_drag", "angular_quadratic_drag", "applied_force", "timed_load"}
                    & set(self.names()))

    @property
    def conserves_energy(self) -> bool:
        """True when kinetic plus gravitational potential energy is conserved (no drag, no applied or timed load)."""
        return set(self.names()) <= {"gravity"}

    @property
    def conserves_angular_momentum(self) -> bool:
        """True when each body's angular momentum about its COM is conserved (no torque)."""
        return not self.exerts_torque



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

