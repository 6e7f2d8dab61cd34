"""Forces that no engine models natively, computed by the references themselves.

Written independently of ``core.dynamics.forces`` (a reference must not borrow the code it checks):
a sign error in core's drag or torque then shows up as a disagreement with every engine.

- Drag acts on the velocity relative to the air, u = v - w (w: wind, zero in still air):
  F = -b u - c |u| u per body.
- Angular drag: tau = -k omega - k_q |omega| omega per body (world axes, about the COM).
- Applied forces are constant world-frame forces at points fixed in a body; each engine
  applies them at the point's WORLD position with its own API (MuJoCo ``mj_applyFT``,
  PyBullet ``applyExternalForce``, Pinocchio ``SE3.act`` on an ``aba`` external force), so
  the torque about the COM is the engine's. Only the tight solve needs the torque here.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.bodies import Forces

DETAIL = "drag and wind computed by the references (independently of core) from the state at each step's start"
"""What the rows' detail says of the forces computed here."""


def has_drag(forces: Forces) -> bool:
    """True when the scene has a linear or quadratic drag (with or without wind)."""
    return forces.linear_drag is not None or forces.quadratic_drag is not None


def has_angular_drag(forces: Forces) -> bool:
    """True when the scene has a linear or quadratic angular drag."""
    return forces.angular_linear_drag is not None or forces.angular_quadratic_drag is not None


def drag_force_world(forces: Forces, velocity_world: np.ndarray) -> np.ndarray:
    """F = -b u - c |u| u with u = v - w. (B, 3) [m/s] -> (B, 3) [N]."""
    wind = np.zeros(3) if forces.air_velocity_world is None else forces.air_velocity_world
    relative = np.asarray(velocity_world, dtype=float) - wind
    force = np.zeros_like(relative)
    if forces.linear_drag is not None:
        force -= forces.linear_drag[:, None] * relative
    if forces.quadratic_drag is not None:
        speed = np.sqrt(np.sum(relative * relative, axis=1))
        force -= (forces.quadratic_drag * speed)[:, None] * relative
    return force


def drag_torque_world(forces: Forces, angular_velocity_world: np.ndarray) -> np.ndarray:
    """tau = -k omega - k_q |omega| omega. (B, 3) [rad/s] -> (B, 3) [N m]."""
    omega = np.asarray(angular_velocity_world, dtype=float)
    torque = np.zeros_like(omega)
    if forces.angular_linear_drag is not None:
        torque -= forces.angular_linear_drag[:, None] * omega
    if forces.angular_quadratic_drag is not None:
        spin = np.sqrt(np.sum(omega * omega, axis=1))
        torque -= (forces.angular_quadratic_drag * spin)[:, None] * omega
    return torque


def applied_wrench_world(forces: Forces, rotation_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Total applied force (B, 3) [N] and its torque about each COM (B, 3) [N m].

    A force f at the body point p (body axes, from the COM) has the lever r = R p in world
    axes and the torque r x f. ``rotation_world`` (B, 3, 3) is body to world.
    """
    rotation = np.asarray(rotation_world, dtype=float)
    force, torque = np.zeros((len(rotation), 3)), np.zeros((len(rotation), 3))
    for applied in forces.applied:
        lever = rotation[applied.body] @ applied.point_body
        force[applied.body] += applied.force_world
        torque[applied.body] += np.cross(lever, applied.force_world)
    return force, torque
