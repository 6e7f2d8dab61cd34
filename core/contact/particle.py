"""The lecture's particle-plane collision handling ("Bodies in Contact").

The plane is E(p) = a x + b y + c z + d = 0, with E(p) > 0 on the free side; a particle
has collided when E(p(t_i)) <= 0. The lecture lists three ways to handle it, all here:

- kinematic response: v <- v - (1 + k) (v . N) N  (:func:`reflect_velocity`);
- "take actions after the collision occurs (the penalty method)": a spring-damper force
  pushing the particle back out (:func:`penalty_force`);
- "back up time to the first instant the collision occurs and determine the appropriate
  response" (:func:`time_of_impact`, and ``method="backup"`` of :func:`step_particles`).

Arrays are float64 in the world frame and SI units, batched over B particles. The rigid-body
methods the engine runs on scenes with contact (:mod:`core.contact` and the modules it names) build
on :func:`penalty_force` and :func:`entry_time`; the particle steppers here are the lecture's
recipes as written, checked against closed forms in ``tests/core/contact/test_particle.py``.
"""

from __future__ import annotations

import numpy as np

from simparity.core.dynamics.point_mass import average_velocity_step
from simparity.core.model.scenes.contact import Plane
from simparity.core.rotations import vector_lengths

FRICTION_REGULARISATION_SPEED = 1e-2
"""[m/s] The penalty method's Coulomb friction grows linearly from 0 up to mu_k F_n over this slip speed
(a discontinuous force would chatter in any explicit scheme). It adds a damping rate mu_k g / v_reg
(~300 1/s for mu_k = 0.3), comparable to the contact spring's omega = sqrt(k_s / m) ~ 300 rad/s of the
default stiffness, so it does not make the system stiffer than the spring does; a body held by
friction creeps at ~v_reg |g_t| / (mu_k |g_n|)."""


def sliding_friction(normal_force: np.ndarray, velocity: np.ndarray, normal: np.ndarray,
                     mu: float | np.ndarray, speed: float = FRICTION_REGULARISATION_SPEED) -> np.ndarray:
    """The penalty method's regularised Coulomb friction, negated: mu |F_n| u_t / max(|u_t|, v_reg), v_reg the
    regularisation ``speed`` [m/s] (:data:`FRICTION_REGULARISATION_SPEED` by default), u_t the tangential part of
    ``velocity`` (..., 3) [m/s] along the plane
    of unit ``normal`` (3,), ``normal_force`` F_n (..., 3) [N], ``mu`` broadcasting against them. The friction force is
    minus this [N]: opposite the slip, on the cone |f_t| = mu |F_n| once the slip is faster than v_reg, inside it
    below."""
    u_t = velocity - (velocity @ normal)[..., None] * normal
    slip = np.maximum(vector_lengths(u_t), speed)
    return mu * vector_lengths(normal_force) * u_t / slip


METHODS = ("backup", "detect_and_reflect")
"""Collision handling offered by :func:`step_particles`."""

BAD_RESTITUTION = "restitution must lie in [0, 1]"
UNKNOWN_METHOD = "unknown collision method"


def reflect_velocity(velocity_world: np.ndarray, unit_normal_world: np.ndarray, restitution: float) -> np.ndarray:
    """The lecture's kinematic response v - (1 + k) (v . N) N.

    The normal component is removed once and subtracted again scaled by k. It is applied
    only where the particle moves into the plane (v . N < 0); a particle already moving
    away is returned unchanged. The lecture writes the damping factor as 0 < k < 1;
    k = 1 (elastic) reverses the normal component and keeps the speed, k = 0 (perfectly
    plastic) removes it and leaves the particle sliding along the plane.

    Parameters
    ----------
    velocity_world : (B, 3) ndarray
        v [m/s].
    unit_normal_world : (3,) ndarray
        N, unit length (as :attr:`Plane.normal_world`).
    restitution : float
        k in [0, 1].

    Returns
    -------
    (B, 3) ndarray
        Velocity after the response [m/s]; the tangential component is unchanged.
    """
    if not 0.0 <= restitution <= 1.0:
        raise ValueError(f"{BAD_RESTITUTION}, got {restitution}")
    normal_speed = np.minimum(velocity_world @ unit_normal_world, 0.0)
    return velocity_world - (1.0 + restitution) * normal_speed[..., None] * unit_normal_world


def penalty_force(
    position_world: np.ndarray,
    velocity_world: np.ndarray,
    plane: Plane,
    stiffness: float | np.ndarray,
    damping: float | np.ndarray,
) -> np.ndarray:
    """The penalty method: "take actions after the collision occurs".

    F = (-k_s E(p) - k_d (v . N)) N where the particle has penetrated (E(p) < 0), else 0.
    The normal force is clipped at zero so the plane never pulls the particle in (a fast
    separation would otherwise make the damping term attractive).

    Parameters
    ----------
    position_world, velocity_world : (B, 3) ndarray
        p [m] and v [m/s].
    plane : Plane
    stiffness : float or (B,) ndarray
        k_s [N/m].
    damping : float or (B,) ndarray
        k_d [N s/m].

    Returns
    -------
    (B, 3) ndarray
        Force on each particle [N].
    """
    depth = plane.signed_distance(position_world)
    push = -stiffness * depth - damping * (velocity_world @ plane.normal_world)
    magnitude = np.where(depth < 0.0, np.maximum(push, 0.0), 0.0)
    return magnitude[..., None] * plane.normal_world


def time_of_impact(start_world: np.ndarray, end_world: np.ndarray, plane: Plane) -> np.ndarray:
    """Backing up time: the fraction of a constant-velocity step at which the plane is hit.

    Along p(s) = p0 + s (p1 - p0), E is linear in s, so s = E(p0) / (E(p0) - E(p1)) is
    exact for the lecture's constant-velocity segment.

    Parameters
    ----------
    start_world, end_world : (B, 3) ndarray
        p0 and p1 [m], the positions at the start and end of the step.
    plane : Plane

    Returns
    -------
    (B,) ndarray
        s in [0, 1] where the particle entered the plane (E(p0) >= 0 > E(p1)), else 1.
    """
    e0, e1 = plane.signed_distance(start_world), plane.signed_distance(end_world)
    crossed = (e0 >= 0.0) & (e1 < 0.0)
    return np.where(crossed, e0 / np.where(crossed, e0 - e1, 1.0), 1.0)


def entry_time(e0: np.ndarray, normal_speed: np.ndarray, half_normal_gravity, dt):
    """First root s in [0, dt] where E(s) = e0 + u s + a s^2 crosses zero going in (E' <= 0).

    Shared with the rigid-body backup method (:mod:`core.contact.backup`), whose bodies that do not
    turn move their contact points on such parabolas. Arguments broadcast against each other.

    Of the two roots (-u -+ sqrt(u^2 - 4 a e0)) / (2 a), the entering one is always the
    '-' root (E' = -sqrt(.) there); it is taken in the cancellation-free form. Returns
    (hit (B,) bool, s (B,) [s], with s = dt where there is no hit).
    """
    u, a = normal_speed, half_normal_gravity
    disc = u * u - 4.0 * a * e0
    root = np.sqrt(np.maximum(disc, 0.0))
    numerator = np.where(u <= 0.0, 2.0 * e0, -u - root)
    denominator = np.where(u <= 0.0, root - u, 2.0 * a)
    s = numerator / np.where(denominator != 0.0, denominator, 1.0)
    hit = (disc >= 0.0) & (denominator != 0.0) & (s >= 0.0) & (s <= dt)
    return hit, np.where(hit, s, dt)


def _backed_up_flight(p, v, gravity_world, dt, plane, restitution):
    """Fly to the entry time, reflect there, fly the rest of the step ((B, 3) each)."""
    normal = plane.normal_world
    hit, s = entry_time(plane.signed_distance(p), v @ normal, gravity_world @ normal / 2.0, dt)
    p, v = average_velocity_step(p, v, gravity_world, s[:, None])
    v = np.where(hit[:, None], reflect_velocity(v, normal, restitution), v)
    return average_velocity_step(p, v, gravity_world, (dt - s)[:, None])


def step_particles(
    position_world: np.ndarray,
    velocity_world: np.ndarray,
    gravity_world: np.ndarray,
    dt: float,
    plane: Plane,
    restitution: float,
    method: str = "backup",
) -> tuple[np.ndarray, np.ndarray]:
    """One step of B particles falling under gravity onto a plane.

    Free flight uses the lecture's average-velocity rule (exact for constant gravity).

    ``"detect_and_reflect"``: the lecture's kinematic response as written. The particle
    flies the whole step; where E(p(t_i)) <= 0 its velocity is reflected. The position is
    left as computed, i.e. possibly inside the plane, so the bounce starts up to |v| dt
    below it: first-order accurate in dt.

    ``"backup"``: back up time to the first instant of collision. The entry time s is the
    first root of E(p(s)) = 0 in [0, dt] (a quadratic under constant gravity, solved
    exactly); the particle flies to p(s), is reflected there and flies the rest of the step.
    Exact for constant gravity, with at most one backed-up bounce per step. When the
    rebound is shorter than the rest of the step (the tail of a bouncing ball's sequence,
    and resting contact), the second impact is caught at the end of the step by the
    detection rule instead; the particle is then also moved back along N onto the plane,
    so that it rests on the plane, jittering by O(|g| dt^2), instead of sinking into it
    (the kinematic response alone loses (1 - k) |g| dt of normal speed every step).

    Parameters
    ----------
    position_world, velocity_world : (B, 3) ndarray
        p(t_i) [m] and v(t_i) [m/s].
    gravity_world : (3,) ndarray
        g [m/s^2].
    dt : float
        Step [s].
    plane : Plane
    restitution : float
        k in [0, 1], see :func:`reflect_velocity`.
    method : {"backup", "detect_and_reflect"}

    Returns
    -------
    position_world, velocity_world : (B, 3) ndarray
        p(t_{i+1}) [m] and v(t_{i+1}) [m/s].
    """
    if method not in METHODS:
        raise ValueError(f"{UNKNOWN_METHOD} {method!r} (known: {', '.join(METHODS)})")
    if method == "backup":
        p, v = _backed_up_flight(position_world, velocity_world, gravity_world, dt, plane, restitution)
    else:
        p, v = average_velocity_step(position_world, velocity_world, gravity_world, dt)
    distance = plane.signed_distance(p)
    v = np.where((distance <= 0.0)[:, None], reflect_velocity(v, plane.normal_world, restitution), v)
    if method == "backup":  # a second impact fell within the step: put the particle back on the plane
        p = p - np.minimum(distance, 0.0)[:, None] * plane.normal_world
    return p, v


def simulate_bouncing(
    position_world: np.ndarray,
    velocity_world: np.ndarray,
    gravity_world: np.ndarray,
    dt: float,
    n_steps: int,
    plane: Plane,
    restitution: float,
    method: str = "backup",
) -> tuple[np.ndarray, np.ndarray]:
    """``n_steps`` of :func:`step_particles` from the initial state (B, 3), (B, 3).

    Returns
    -------
    position_world, velocity_world : (n_steps + 1, B, 3) ndarray
        [m] and [m/s] at t = 0, dt, ..., n_steps dt (the initial state included).
    """
    p = np.array(position_world, dtype=float).reshape(-1, 3)
    v = np.array(velocity_world, dtype=float).reshape(-1, 3)
    gravity = np.asarray(gravity_world, dtype=float).reshape(3)
    positions, velocities = [p], [v]
    for _ in range(n_steps):
        p, v = step_particles(p, v, gravity, dt, plane, restitution, method)
        positions.append(p)
        velocities.append(v)
    return np.stack(positions), np.stack(velocities)
