"""The lecture's kinematic response "after it happened", for rigid bodies against planes.

Every body flies the whole step (RK4, quaternion orientation). Then, where a contact point has
E <= 0, the body is translated back along N by the penetration depth and the impulse of
:func:`core.contact.bodies.impulse_response` is applied at the deepest touching point moving into the plane
(at the centre of the patch of points touching with it, :func:`core.contact.bodies.patch_lever`): for a
particle exactly v - (1 + k)(v . N) N, the tangential part by Coulomb friction. A few Gauss-Seidel
passes repeat this for the points still moving in, so that a box landing flat does not tip and a body
in a corner leaves both planes.

The impulse is plastic (k = 0) where the rebound would be slower than ``rest_speed``, and where the body
already rested on that plane at the start of the step (touching it without moving into it faster than
``rest_speed``; a body that starts on a plane striking it bounces): the step cannot resolve a flight shorter than
itself, and the normal speed it gathered in the plane is what the plane's support would have removed
(a resting body then sits on the plane at every sample, and a sliding one loses mu_k |g_n| dt of speed
per step). First order in dt: the bounce starts from where the body was found, up to |v| dt inside.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from simparity.core.contact.bodies import CONTACT_TOLERANCE, FLIGHT_SCHEME, Bodies, contact_lever, impulse_response, put_state, take_state
from simparity.core.dynamics.integrators import make_step
from simparity.core.dynamics.rigid_body import State, velocities
from simparity.core.rotations import cross

GAUSS_SEIDEL_PASSES = 8
"""Passes of push-out and impulse after each step: one per touching point of a box face in the worst case
(a landing on a corner, then the rest of the face), with a margin for a body in a corner of two planes."""


def _push_out(model, state: State) -> State:
    """Translate each body out of every plane it penetrates, along that plane's normal."""
    x, rotation = state.position_world, state.rotation_world
    for p, normal in enumerate(model.normals):
        depth = model.points(x, rotation)[1][:, p].min(axis=1)
        x = x - np.minimum(depth, 0.0)[:, None] * normal
    return State(x, state.orientation, state.momentum_world, state.angular_momentum_world)


def resolve_after(bodies: Bodies, state: State, touched: np.ndarray) -> State:
    """Push-out and impulses after the fact (:data:`GAUSS_SEIDEL_PASSES` passes) for n bodies.

    ``touched`` (n, P) bool marks the planes each body touched at the start of its step: their
    impulses are plastic. Returns the state with no point inside a plane.
    """
    close = bodies.model.points(state.position_world, state.rotation_world)[1] <= CONTACT_TOLERANCE
    near = np.flatnonzero(close.any(axis=(1, 2)))
    if len(near) < len(touched):
        if len(near):
            part = resolve_after(bodies.take(near), take_state(state, near), touched[near])
            state = put_state(state, near, part)
        return state
    model, m = bodies.model, bodies.props
    for _ in range(GAUSS_SEIDEL_PASSES):
        state = _push_out(model, state)
        rotation = state.rotation_world
        lever, distance = model.points(state.position_world, rotation)
        v, omega = velocities(state, m, rotation)
        speed = model.normal_speeds(v, omega, lever)
        moving_in = (distance <= CONTACT_TOLERANCE) & (speed < 0.0)
        idx = np.flatnonzero(moving_in.any(axis=(1, 2)))
        if not len(idx):
            break
        depth = np.where(moving_in[idx], distance[idx], np.inf).reshape(len(idx), -1)
        plane = depth.argmin(axis=1) // distance.shape[2]
        normal = model.normals[plane]
        k_com = model.restitution[idx, plane]
        approach = np.maximum(-np.sum(v[idx] * normal, axis=1), 0.0)
        k_com = np.where(touched[idx, plane] | (k_com * approach < model.rest_speed), 0.0, k_com)
        r, _ = contact_lever(lever[idx, plane], distance[idx, plane], speed[idx, plane], model.weights[idx], normal,
                          v[idx], omega[idx], k_com, model.friction_static[idx, plane],
                          model.friction_kinetic[idx, plane], model.rest_speed)
        arrival = np.sum((v[idx] + cross(omega[idx], r)) * normal, axis=1)
        k = model.restitution[idx, plane]
        plastic = touched[idx, plane] | (k * np.maximum(-arrival, 0.0) < model.rest_speed)
        turn = rotation[idx] @ m.inertia_body_inv[idx] @ np.swapaxes(rotation[idx], -1, -2)
        p, l, _ = impulse_response(m.mass[idx], turn, state.momentum_world[idx], state.angular_momentum_world[idx],
                                   r, normal, np.where(plastic, 0.0, k), model.friction_static[idx, plane],
                                   model.friction_kinetic[idx, plane])
        momentum, angular = state.momentum_world.copy(), state.angular_momentum_world.copy()
        momentum[idx], angular[idx] = p, l
        state = State(state.position_world, state.orientation, momentum, angular)
    return state


class ActAfterStepper:
    """One step of the act-after method for B bodies: ``step(t, state, dt) -> state``."""

    def __init__(self, bodies: Bodies) -> None:
        self._bodies = bodies
        self._flight = make_step(FLIGHT_SCHEME, "quaternion", bodies.props, bodies.external)

    def step(self, t: float, state: State, dt: float) -> State:
        """Advance every body by dt [s] from time t."""
        model = self._bodies.model
        rotation = state.rotation_world
        lever, distance = model.points(state.position_world, rotation)
        v, omega = velocities(state, self._bodies.props, rotation)
        touching = distance <= CONTACT_TOLERANCE
        striking = touching & (model.normal_speeds(v, omega, lever) < -model.rest_speed)
        # Resting on a plane at the step's start (touching, not striking it): that plane's impulse is plastic.
        # (B, P, V) reduced over V: a (B, P) array, never the scalar numpy's stubs also allow
        touched = cast(np.ndarray, touching.any(axis=2) & ~striking.any(axis=2))
        return resolve_after(self._bodies, self._flight(t, state, dt), touched)
