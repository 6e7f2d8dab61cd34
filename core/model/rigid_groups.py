"""What an engine compiled from a chain's robot file, joint by joint: :class:`RigidGroups`.

A chain's joint moves a *rigid group*: its child link and every link welded to it by fixed joints (or by joints held
at their zero position, :attr:`core.model.scenes.chain.Chain.held_joints`), up to the next moving joint. Engines
merge those links differently: Pinocchio always, MuJoCo under ``fusestatic``, PyBullet never. Compared group by
group, as a mass, a centre of mass and a rotational inertia about it in one frame (so that a tensor diagonalised in
its own principal frame compares equal), with the joint's axis and origin, at the same configurations, every
engine's reading of the same file is comparable field by field before any dynamics are
(:mod:`comparisons.measure.model_parity`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.arrays import readonly

FIELDS = ("mass", "com_world", "inertia_world", "axis_world", "origin_world")
"""The fields of :class:`RigidGroups`, in the order they are compared."""


@dataclass(frozen=True)
class RigidGroups:
    """Each chain joint's rigid group as one engine compiled it, in the chain's base frame, at B configurations.

    Attributes
    ----------
    mass : (B, n) ndarray
        The group's mass [kg] (the same at every configuration).
    com_world : (B, n, 3) ndarray
        Its centre of mass [m].
    inertia_world : (B, n, 3, 3) ndarray
        Its rotational inertia about its centre of mass, in base-frame axes [kg m^2].
    axis_world : (B, n, 3) ndarray
        The joint's unit axis, in base-frame axes.
    origin_world : (B, n, 3) ndarray
        The joint frame's origin (the child link's frame) [m].
    """

    mass: np.ndarray
    com_world: np.ndarray
    inertia_world: np.ndarray
    axis_world: np.ndarray
    origin_world: np.ndarray

    def __post_init__(self) -> None:
        mass = np.asarray(self.mass, dtype=float)
        b, n = mass.shape
        for name, tail in zip(FIELDS, ((), (3,), (3, 3), (3,), (3,))):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float),
                                                    shape=(b, n) + tail))


@dataclass(frozen=True)
class CompiledJoints:
    """Each chain joint as one engine compiled it, configuration aside: its type and limits.

    Attributes
    ----------
    prismatic : (n,) bool ndarray
        True for a prismatic (slide) joint, False for a revolute (hinge) one.
    lower, upper : (n,) ndarray
        Its position limits [rad or m] as the engine holds them, -inf / inf where it holds none (each engine's own way
        of saying "unlimited" read by its adapter: MuJoCo's ``jnt_limited``, Pinocchio's unbounded joint types,
        PyBullet's upper < lower).
    """

    prismatic: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    def __post_init__(self) -> None:
        prismatic = np.asarray(self.prismatic, dtype=bool)
        object.__setattr__(self, "prismatic", readonly(prismatic, shape=prismatic.shape))
        for name in ("lower", "upper"):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float),
                                                    shape=prismatic.shape))
