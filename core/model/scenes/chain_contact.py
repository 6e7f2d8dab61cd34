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
    """A chain's spheres against one plane, frictionless (issue #46, part 1): the plane pushes each sphere along its
    normal only, never pulls, and nothing else touches (the spheres do not touch each other, the links have no other
    collision geometry).

    How hard the contact is belongs to each engine: core's penalty method (the lecture's spring-damper at each
    penetrating sphere, ``penalty_stiffness`` and ``penalty_damping``), MuJoCo's soft constraints (its solref and
    solimp, reported in each row). The truths a scene is held to need none of them.

    Attributes
    ----------
    plane : Plane
    spheres : tuple of ContactSphere
        At least one.
    penalty_stiffness : float
        k_s [N/m] of core's penalty method, > 0.
    penalty_damping : float
        k_d [N s/m] of core's penalty method, >= 0.
    rest_after : float or None
        [s] From this time on the scene's author says the robot is at rest (``rest_acceleration_max`` holds every
        engine to it); None: the scene does not say, and a run that never settles only leaves the rest checks n/a.
    """

    plane: Plane
    spheres: tuple[ContactSphere, ...]
    penalty_stiffness: float
    penalty_damping: float
    rest_after: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "spheres", tuple(self.spheres))
        if not self.spheres:
            raise SceneError("<code>", "contact.sphere", "no contact sphere", "at least one [[contact.sphere]]")
        if not (np.isfinite(self.penalty_stiffness) and self.penalty_stiffness > 0):
            raise SceneError("<code>", "contact.penalty_stiffness", f"{self.penalty_stiffness}", "a number > 0 [N/m]")
        if not (np.isfinite(self.penalty_damping) and self.penalty_damping >= 0):
            raise SceneError("<code>", "contact.penalty_damping", f"{self.penalty_damping}", "a number >= 0 [N s/m]")
        if self.rest_after is not None and not (np.isfinite(self.rest_after) and self.rest_after > 0):
            raise SceneError("<code>", "contact.rest_after", f"{self.rest_after}", "a time > 0 [s]")

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
