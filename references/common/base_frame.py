"""A chain's base frame inside an engine's model.

A chain read from a URDF file starts at its ``base_link``, whose frame is the chain's
world frame; the engines load the WHOLE file, whose world frame is the root link's. When
the base link is not the root, every pose and Jacobian an engine returns is re-expressed
in the base link's frame here, and IK targets (given in the base frame) are moved into the
engine's world. Joints off the chain stay at 0, so the base link does not move.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class BaseFrame:
    """Pose of the chain's base link in the engine's world.

    Attributes
    ----------
    position_world : (3,) ndarray
        [m].
    rotation_world : (3, 3) ndarray
        Base link frame to the engine's world frame.
    """

    position_world: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation_world: np.ndarray = field(default_factory=lambda: np.eye(3))

    def frames(self, position_world: np.ndarray, rotation_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Engine-world frames (..., 3), (..., 3, 3) -> the same frames in the base frame."""
        rt = self.rotation_world.T
        return (position_world - self.position_world) @ rt.T, rt @ rotation_world

    def jacobian(self, jacobian_world: np.ndarray) -> np.ndarray:
        """(B, 6, n) linear and angular rows in engine-world axes -> in base axes."""
        rt = self.rotation_world.T
        return np.concatenate([rt @ jacobian_world[:, :3], rt @ jacobian_world[:, 3:]], axis=1)

    def targets_to_world(self, position: np.ndarray, rotation: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
        """Targets (B, 3) [m] and (B, 3, 3) or None in the base frame -> in the engine's world."""
        world = position @ self.rotation_world.T + self.position_world
        return world, None if rotation is None else self.rotation_world @ rotation
