"""A robot's contact with the ground: :class:`ContactSphere` on named frames of a chain, :class:`ChainContact`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.contact import Plane


@dataclass(frozen=True)
class ContactSphere:
    """A sphere rigidly attached to one frame of a chain: what touches the ground (a foot, a tip, a corner of a body).

    Real feet are meshes; a sphere is the simplification every engine models alike (a point contact at
    ``centre - radius N`` with the plane's normal N).

    Attributes
    ----------
    frame : str
        The frame it rides on: a chain joint's name (the frame of the link that joint moves, as URDF places it), the
        chain's end effector name, or the base link's name (:meth:`ChainContact.frame_index`).
    centre_xyz : (3,) ndarray
        The sphere's centre in that frame [m].
    radius : float
        [m], > 0.
    """

    frame: str
    centre_xyz: np.ndarray
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre_xyz", readonly(self.centre_xyz, shape=(3,)))
        if not (np.all(np.isfinite(self.centre_xyz)) and np.isfinite(self.radius) and self.radius > 0):
            raise SceneError("<code>", "contact.sphere", f"centre {self.centre_xyz.tolist()}, radius {self.radius}",
                             "a finite centre and a radius > 0 [m]")


@dataclass(frozen=True)
class ChainContact:
    """A chain's spheres against one plane (issue #46, part 1): the plane pushes each sphere along its normal, never
    pulls, and with Coulomb friction (``friction`` mu > 0) resists its slip along the plane within the cone
    |f_t| <= mu f_n; nothing else touches (the spheres do not touch each other, the links have no other collision
    geometry). Without friction (mu = 0, the default) it pushes along its normal only.

    The contact is soft or rigid, as the scene says:

    - soft (``penalty_stiffness`` given): how hard it is belongs to each engine: core's penalty method (the lecture's
      spring-damper at each penetrating sphere, ``penalty_stiffness`` and ``penalty_damping``), MuJoCo's soft
      constraints (its solref and solimp, reported in each row). The truths a scene is held to need none of them.
    - rigid (``restitution`` given): no sphere enters the plane; at an impact the sphere's normal velocity is reversed
      and scaled by the restitution e (Newton's law, the lecture's impulse), except that a rebound slower than
      ``rest_speed`` is plastic (e = 0) and the sphere then rests on the plane while the plane pushes it. A pendulum
      striking the plane has a closed form (:mod:`references.analytic.joint_motion`).

    Attributes
    ----------
    plane : Plane
    spheres : tuple of ContactSphere
        At least one.
    penalty_stiffness : float or None
        k_s [N/m] of core's penalty method, > 0; None for a rigid contact.
    penalty_damping : float or None
        k_d [N s/m] of core's penalty method, >= 0; None for a rigid contact.
    rest_after : float or None
        [s] From this time on the scene's author says the robot is at rest (``rest_acceleration_max`` holds every
        engine to it); None: the scene does not say, and a run that never settles only leaves the rest checks n/a.
    restitution : float or None
        e in [0, 1] of a rigid contact; None for a soft one.
    rest_speed : float
        [m/s] of a rigid contact, > 0: a rebound whose normal speed would be below it is plastic (without it a
        bouncing sphere's impacts accumulate without end, Zeno's bounces).
    friction : float
        mu >= 0, the Coulomb coefficient of every sphere on the plane (one coefficient: static and kinetic alike);
        0 is a frictionless plane. A soft contact's only: a rigid one is frictionless (impacts with friction are part
        2 of the issue).
    stands : bool
        The scene's author says the robot comes to rest by the end of the run (on a slope: its friction holds it), so
        that the rest checks must be measured: a robot not at rest is then an alarm (``not-at-rest``), not n/a. Unlike
        ``rest_after`` it asks nothing of the joints' motion before the end.
    friction_speed : float
        [m/s] > 0, core's penalty friction's regularisation: the slip above which it is the full Coulomb force (below
        it grows linearly; a held foot creeps at ~friction_speed tan / mu). A constant of core's model like
        ``penalty_stiffness``, a scene input so that it changes with the scene's units.
    """

    plane: Plane
    spheres: tuple[ContactSphere, ...]
    penalty_stiffness: float | None
    penalty_damping: float | None
    rest_after: float | None = None
    restitution: float | None = None
    rest_speed: float = 1e-3
    friction: float = 0.0
    friction_speed: float = 1e-2
    stands: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "spheres", tuple(self.spheres))
        if not self.spheres:
            raise SceneError("<code>", "contact.sphere", "no contact sphere", "at least one [[contact.sphere]]")
        if self.rigid:
            self._check_rigid()
        else:
            self._check_soft()
        if not (np.isfinite(self.friction) and self.friction >= 0):
            raise SceneError("<code>", "contact.friction", f"{self.friction}", "a Coulomb coefficient >= 0")
        if not (np.isfinite(self.friction_speed) and self.friction_speed > 0):
            raise SceneError("<code>", "contact.friction_speed", f"{self.friction_speed}", "a speed > 0 [m/s]")
        if self.rigid and self.friction > 0:
            raise SceneError("<code>", "contact.friction", f"{self.friction} on a rigid contact",
                             "friction on a soft contact (penalty_stiffness); a rigid contact is frictionless")
        if self.rest_after is not None and not (np.isfinite(self.rest_after) and self.rest_after > 0):
            raise SceneError("<code>", "contact.rest_after", f"{self.rest_after}", "a time > 0 [s]")

    @property
    def rigid(self) -> bool:
        """True for a rigid contact (impulses, a restitution), False for a soft one (penalty springs)."""
        return self.restitution is not None

    def _check_soft(self) -> None:
        if self.penalty_stiffness is None or not (np.isfinite(self.penalty_stiffness) and self.penalty_stiffness > 0):
            raise SceneError("<code>", "contact.penalty_stiffness", f"{self.penalty_stiffness}", "a number > 0 [N/m]")
        if self.penalty_damping is None or not (np.isfinite(self.penalty_damping) and self.penalty_damping >= 0):
            raise SceneError("<code>", "contact.penalty_damping", f"{self.penalty_damping}", "a number >= 0 [N s/m]")

    def _check_rigid(self) -> None:
        if self.penalty_stiffness is not None or self.penalty_damping is not None:
            raise SceneError("<code>", "contact.penalty_stiffness", "a penalty spring on a rigid contact",
                             "either restitution (rigid) or penalty_stiffness (soft)")
        e = self.restitution
        if not (e is not None and np.isfinite(e) and 0 <= e <= 1):
            raise SceneError("<code>", "contact.restitution", f"{e}", "a number in [0, 1]")
        if not (np.isfinite(self.rest_speed) and self.rest_speed > 0):
            raise SceneError("<code>", "contact.rest_speed", f"{self.rest_speed}", "a speed > 0 [m/s]")

    @property
    def radii(self) -> np.ndarray:
        """(S,) the spheres' radii [m]."""
        return np.array([s.radius for s in self.spheres])

    @property
    def centres_xyz(self) -> np.ndarray:
        """(S, 3) the spheres' centres in their frames [m]."""
        return np.array([s.centre_xyz for s in self.spheres]).reshape(-1, 3)

    def gaps(self, centres_world: np.ndarray) -> np.ndarray:
        """(..., S) each sphere's distance from the plane [m] (negative: penetrating) of centres (..., S, 3) [m]."""
        return self.plane.signed_distance(centres_world) - self.radii


def frame_index(frame: str, joint_names: tuple[str, ...], end_effector: str, base_link: str | None) -> int:
    """Where ``frame`` is among a chain's frames: ``i`` for joint i's frame, ``n`` for the end effector, -1 for the base
    link; ValueError for another name."""
    if frame in joint_names:
        return joint_names.index(frame)
    if frame == end_effector:
        return len(joint_names)
    if base_link is not None and frame == base_link:
        return -1
    raise ValueError(frame)
