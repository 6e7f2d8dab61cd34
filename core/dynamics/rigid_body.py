"""The lecture's rigid-body state S = (x, R, P, L) and its time derivative.

dS/dt = (v, omega* R, F, tau), with v = P / M, I(t) = R I_body R^T and omega = I(t)^-1 L
("Summing up all together"). Everything is batched over B independent bodies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from simparity.core.rotations import quat_wxyz_to_matrix
from simparity.core.model.scenes.bodies import RigidBody

class Wrench(Protocol):
    """f(t, x, R, v, omega, step_start=None) -> (force_world (B, 3) [N], torque_world about the COM (B, 3) [N m]).

    ``t`` [s] is the stage's time, a float, or (B,) one per body when a packed step is given one dt per body;
    ``step_start`` [s] (same shape) the start of the step the stage belongs to (None: ``t`` is a step's start),
    which decides what a held load is (:mod:`core.dynamics.time_loads`)."""

    def __call__(self, t: float | np.ndarray, x: np.ndarray, rotation: np.ndarray, v: np.ndarray, omega: np.ndarray,
                 step_start: float | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]: ...


@dataclass(frozen=True)
class MassProperties:
    """Constant mass properties of B bodies.

    Attributes
    ----------
    mass : (B,) ndarray  [kg]
    inertia_body : (B, 3, 3) ndarray  [kg m^2] about the COM, body axes
    inertia_body_inv : (B, 3, 3) ndarray
    """

    mass: np.ndarray
    inertia_body: np.ndarray
    inertia_body_inv: np.ndarray

    @classmethod
    def of(cls, bodies: tuple[RigidBody, ...]) -> "MassProperties":
        inertia = np.stack([b.inertia_body for b in bodies])
        return cls(np.array([b.mass for b in bodies]), inertia, np.linalg.inv(inertia))

    def inertia_world_inv(self, rotation: np.ndarray) -> np.ndarray:
        """I(t)^-1 = R I_body^-1 R^T. (B, 3, 3) -> (B, 3, 3)."""
        return rotation @ self.inertia_body_inv @ np.swapaxes(rotation, -1, -2)

    def inertia_world(self, rotation: np.ndarray) -> np.ndarray:
        """I(t) = R I_body R^T. (B, 3, 3) -> (B, 3, 3)."""
        return rotation @ self.inertia_body @ np.swapaxes(rotation, -1, -2)


@dataclass(frozen=True)
class State:
    """S = (x, orientation, P, L) of B bodies.

    Attributes
    ----------
    position_world : (B, 3) ndarray
        Centre of mass x [m].
    orientation : (B, 3, 3) or (B, 4) ndarray
        Rotation matrix R or quaternion (w, x, y, z), body to world.
    momentum_world : (B, 3) ndarray
        Linear momentum P [kg m/s].
    angular_momentum_world : (B, 3) ndarray
        Angular momentum L about the COM [kg m^2/s].
    """

    position_world: np.ndarray
    orientation: np.ndarray
    momentum_world: np.ndarray
    angular_momentum_world: np.ndarray

    @property
    def rotation_world(self) -> np.ndarray:
        """(B, 3, 3) rotation matrix of the orientation (normalised if a quaternion)."""
        if self.orientation.shape[-1] == 4:
            return quat_wxyz_to_matrix(self.orientation)
        return self.orientation


def initial_state(bodies: tuple[RigidBody, ...], props: MassProperties, quaternion: bool) -> State:
    """State at t = 0 of scene bodies, orientation as quaternion or matrix."""
    rotation = quat_wxyz_to_matrix(np.stack([b.quat_wxyz for b in bodies]))
    omega = np.stack([b.angular_velocity_world for b in bodies])
    orientation = np.stack([b.quat_wxyz for b in bodies]) if quaternion else rotation
    return State(
        np.stack([b.position_world for b in bodies]),
        orientation,
        props.mass[:, None] * np.stack([b.velocity_world for b in bodies]),
        np.einsum("bij,bj->bi", props.inertia_world(rotation), omega),
    )


def velocities(state: State, props: MassProperties, rotation: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(v = P / M, omega = I(t)^-1 L), each (..., B, 3), in world axes.

    The state may have leading axes before the B bodies (e.g. samples in time); ``rotation``
    (..., B, 3, 3) is the state's rotation matrix when the caller already has it.
    """
    rotation = state.rotation_world if rotation is None else rotation
    omega = (props.inertia_world_inv(rotation) @ state.angular_momentum_world[..., None])[..., 0]
    return state.momentum_world / props.mass[:, None], omega
