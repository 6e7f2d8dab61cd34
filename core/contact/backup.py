"""Backing up time to the first instant of contact (lecture, "Bodies in Contact"), for rigid bodies.

Each step of each body is cut at its contact events. From the start of a sub-step the body flies
freely (RK4, quaternion orientation: exact for translation under constant gravity) and the first
instant a contact point reaches a plane is found (:mod:`core.contact.roots`): exactly for a body whose
contact points move on parabolas (a point or a sphere, or a body that does not turn, under gravity
alone), else by a bracketed root finder along the free flight, vectorised over bodies with per-body
sub-steps, which also catches a corner dipping in and out within one step.

The body is advanced to that instant and responds (:func:`core.contact.bodies.impulse_response` at the patch
of touching points, :func:`core.contact.bodies.patch_lever`), then flies the rest of the step; several events
within one step are handled in time order, at most :data:`MAX_EVENTS_PER_STEP` per body (one exceeding
it is put at rest). Each round works only on the bodies that still have time left.

Slow contacts: where the rebound normal speed would be below ``rest_speed`` the impulse is plastic
(friction included), and then

- if the points touching the plane support the COM (:func:`core.contact.bodies.supported`: always for a point
  or a sphere, a box lying on a face) the body rests on the plane: normal velocity and spin removed,
  lowest point on the plane. A resting body does not turn; the plane supports it (normal force -F.N)
  and Coulomb friction acts on it: sliding with slip direction s, a = (F_t - mu_k |F.N| s) / m, constant
  under gravity, and time is backed up to the instant the slip speed reaches zero, after which the body
  sticks while |F_t| <= mu_s |F.N| (else slides along F_t). Exact for a block sliding on a level plane
  or along the line of steepest slope. It leaves the plane when F.N >= 0 or at an impact elsewhere;
- otherwise (a box on an edge or a corner) the body pivots: it flies to the end of the step and its
  contacts are resolved after the fact (:func:`core.contact.act_after.resolve_after`, plastic on that
  plane), a first-order treatment under which it topples.

Known limits: the friction direction is frozen over a sub-step, so a slip not along F_t is stopped in
pieces; under forces that are not constant (drag) the stop time is estimated from the forces at the
sub-step's start (a slip reversed within the sub-step is stopped at its end); resting bodies do not
roll; a pivoting body gains up to m |g.N| |g| dt^2 / 2 of energy per step from being pushed out; a body
wedged between two planes (it rests on one, slides into the other, rests there ...) is put at rest after
:data:`MAX_RESTS_PER_STEP`.
"""

from __future__ import annotations

import numpy as np

from simparity.core.contact.bodies import (FLIGHT_SCHEME, RESTING_GAP, Bodies, EventLog, contact_lever, impulse_response, put_state, supported,
                                    take_state)
from simparity.core.contact.act_after import resolve_after
from simparity.core.contact.roots import distances, exact_contact, root_contact
from simparity.core.dynamics.quaternion_integrators import make_packed_step, pack, unpack
from simparity.core.dynamics.rigid_body import State, velocities
from simparity.core.rotations import cross

MAX_EVENTS_PER_STEP = 100
"""Contact events one body may have in one step; past it the body is put at rest (a ball dropped from 1 m
with k = 0.8 bounces 38 times before it rests, the last ~20 of them within one 0.1 s step)."""

MAX_RESTS_PER_STEP = 4
"""Times one body may come to rest in one step; past it the body is wedged between planes (it rests on one,
slides into the other, rests there and slides back) and is put at rest."""

FREE = -1
"""``resting`` value of a body in free flight."""


class _Flight:
    """Free flight of n bodies, with the support and friction of those resting on a plane (no torque).

    ``normal`` (n, 3) is the resting plane's N (0 in free flight), ``slide`` the frozen slip direction,
    ``stuck`` (n,) bodies held by static friction, ``mu_k`` (n,).
    """

    def __init__(self, bodies: Bodies, normal, slide, stuck, mu_k) -> None:
        self.bodies, self.normal, self.slide, self.stuck, self.mu_k = bodies, normal, slide, stuck, mu_k
        self._external = bodies.external
        self._step = make_packed_step(FLIGHT_SCHEME, bodies.props, self.wrench)

    def take(self, idx: np.ndarray) -> "_Flight":
        """The flight of the bodies ``idx`` (itself if that is all of them)."""
        if len(idx) == len(self.mu_k):
            return self
        return _Flight(self.bodies.take(idx), self.normal[idx], self.slide[idx], self.stuck[idx], self.mu_k[idx])

    def wrench(self, t, x, rotation, v, omega, step_start=None):
        force, torque = self._external(t, x, rotation, v, omega, step_start)
        resting = np.any(self.normal != 0.0, axis=1)
        if not resting.any():
            return force, torque
        along = np.sum(force * self.normal, axis=1)[:, None]
        friction = np.where(self.stuck[:, None], along * self.normal - force,
                            self.mu_k[:, None] * np.minimum(along, 0.0) * self.slide)
        held = force - np.minimum(along, 0.0) * self.normal + friction
        return np.where(resting[:, None], held, force), np.where(resting[:, None], 0.0, torque)

    def __call__(self, t: float, state: State, duration: np.ndarray) -> State:
        """Every body flown for its own duration (n,) [s] (0: unchanged)."""
        new = unpack(self._step(t, pack(state), duration))
        moved = duration[:, None] > 0.0
        return State(*(np.where(moved, a, b) for a, b in zip(
            (new.position_world, new.orientation, new.momentum_world, new.angular_momentum_world),
            (state.position_world, state.orientation, state.momentum_world, state.angular_momentum_world))))


def _support(bodies: Bodies, t: float, state: State, resting: np.ndarray):
    """The flight of a sub-step from ``state``: (flight, resting (bodies pulled off leave), time to stop (n,) [s]).

    A sliding resting body stops when its slip speed reaches zero: at slip / (mu_k |F.N| - F_t . s) m.
    """
    model, mass = bodies.model, bodies.props.mass
    rotation = state.rotation_world
    v, omega = velocities(state, bodies.props, rotation)
    force, _ = bodies.external(t, state.position_world, rotation, v, omega)
    plane = np.maximum(resting, 0)
    normal = np.where((resting >= 0)[:, None], model.normals[plane], 0.0)
    f_n = np.sum(force * normal, axis=1)
    on = (resting >= 0) & (f_n < 0.0)
    resting = np.where(on, resting, FREE)
    normal = np.where(on[:, None], normal, 0.0)
    body = np.arange(len(resting))
    mu_s, mu_k = (np.where(on, table[body, plane], 0.0) for table in (model.friction_static, model.friction_kinetic))
    pull = force - f_n[:, None] * normal
    slip_v = v - np.sum(v * normal, axis=1)[:, None] * normal
    slip = np.linalg.norm(slip_v, axis=1)
    stuck = on & (slip == 0.0) & (np.linalg.norm(pull, axis=1) <= mu_s * np.abs(f_n))
    direction = np.where((slip > 0.0)[:, None], slip_v, pull)
    size = np.linalg.norm(direction, axis=1)
    slide = direction / np.where(size > 0.0, size, 1.0)[:, None]
    along = (np.sum(pull * slide, axis=1) - mu_k * np.abs(f_n)) / mass
    stopping = on & ~stuck & (slip > 0.0) & (along < 0.0)
    stop = np.where(stopping, slip / np.where(stopping, -along, 1.0), np.inf)
    return _Flight(bodies, normal, slide, stuck, mu_k), resting, stop


def _hold(model, state: State, resting: np.ndarray, stopped: np.ndarray) -> State:
    """Resting bodies: no normal velocity, lowest point on the plane; ``stopped`` ones: no velocity at all."""
    on = resting >= 0
    if not on.any():
        return state
    plane = np.maximum(resting, 0)
    normal = np.where(on[:, None], model.normals[plane], 0.0)
    lowest = model.points(state.position_world, state.rotation_world)[1][np.arange(len(on)), plane].min(axis=1)
    p = state.momentum_world
    p = np.where(stopped[:, None], 0.0, p - np.sum(p * normal, axis=1)[:, None] * normal)
    return State(state.position_world - np.where(on, lowest, 0.0)[:, None] * normal, state.orientation, p,
                 state.angular_momentum_world)


def _settling_gap(bodies: Bodies, state: State, normal: np.ndarray, dt: float) -> np.ndarray:
    """RESTING_GAP + |a.N| dt^2 [m] (n,): how far from flat a slow body may settle
    (:data:`core.contact.bodies.RESTING_GAP`)."""
    rotation = state.rotation_world
    v, omega = velocities(state, bodies.props, rotation)
    force, _ = bodies.external(0.0, state.position_world, rotation, v, omega)
    return RESTING_GAP + np.abs(np.sum(force * normal, axis=1)) / bodies.props.mass * dt * dt


def _respond(bodies: Bodies, state: State, resting: np.ndarray, dt: float, clock: np.ndarray, ids: np.ndarray,
             log: EventLog):
    """The response of bodies that have just reached a plane: (state, resting, pivot plane (n,) or FREE).

    A bounce (impulse with restitution k), or where the rebound would be slower than ``rest_speed`` a
    plastic impulse; then the body rests on the plane if that supports its COM, else it pivots about the
    contact for the rest of the step (resolved after the fact, :func:`core.contact.act_after.resolve_after`).
    """
    model, mass = bodies.model, bodies.props.mass
    lever, distance, speed = distances(bodies, state, resting)
    n = len(resting)
    plane = distance.reshape(n, -1).argmin(axis=1) // distance.shape[2]
    body = np.arange(n)
    normal = model.normals[plane]
    rotation = state.rotation_world
    inertia_inv = bodies.props.inertia_world_inv(rotation)
    velocity, omega = velocities(state, bodies.props, rotation)
    k = model.restitution[body, plane]
    approach = np.maximum(-np.sum(velocity * normal, axis=1), 0.0)
    r, tips = contact_lever(lever[body, plane], distance[body, plane], speed[body, plane], model.weights, normal, velocity,
                      omega, np.where(k * approach < model.rest_speed, 0.0, k), model.friction_static[body, plane],
                      model.friction_kinetic[body, plane], model.rest_speed)

    def normal_speed(p, l):
        return np.sum((p / mass[:, None] + cross(np.einsum("nij,nj->ni", inertia_inv, l), r)) * normal, axis=1)

    before = normal_speed(state.momentum_world, state.angular_momentum_world)
    slow = (k * np.maximum(-before, 0.0) < model.rest_speed) & (before <= model.rest_speed)
    rest = slow & ~tips & supported(lever[body, plane], distance[body, plane], normal, model.weights, _settling_gap(
        bodies, state, normal, dt))
    p, l, _ = impulse_response(mass, inertia_inv, state.momentum_world, state.angular_momentum_world, r, normal,
                               np.where(slow, 0.0, k), model.friction_static[body, plane],
                               model.friction_kinetic[body, plane])
    p = np.where(rest[:, None], p - np.sum(p * normal, axis=1)[:, None] * normal, p)
    l = np.where(rest[:, None], 0.0, l)
    after = normal_speed(p, l)
    depth = distance[body, plane].min(axis=1)
    x = state.position_world - np.where(rest, depth, np.minimum(depth, 0.0))[:, None] * normal
    for kind, chosen in (("impact", ~slow), ("rest", rest), ("pivot", slow & ~rest)):
        log.add(clock[chosen], ids[chosen], plane[chosen], kind, before[chosen], after[chosen])
    return State(x, state.orientation, p, l), np.where(rest, plane, FREE), np.where(slow & ~rest, plane, FREE)


class BackupStepper:
    """One step of the backup method: ``step(t, state, resting, dt, log) -> (state, resting)``.

    ``resting`` (B,) int is the plane each body rests on, :data:`FREE` if none; the step's events are
    appended to ``log`` (:class:`core.contact.bodies.EventLog`).
    """

    def __init__(self, bodies: Bodies) -> None:
        self._bodies = bodies
        self._constant_force = set(bodies.forces.names()) <= {"gravity"}

    def _round(self, bodies: Bodies, t, dt, state, resting, pivot, remaining, clock, ids, log):
        """One sub-step of the bodies with time left: up to their first event or the end of the step (a
        pivoting body flies to the end of the step). Returns (state, resting, pivot, duration (n,) [s],
        event (n,) bool).
        """
        flight, resting, stop = _support(bodies, t, state, resting)
        horizon = np.minimum(remaining, stop)
        _, distance, speed = distances(bodies, state, resting)
        still = np.all(state.angular_momentum_world == 0.0, axis=1)
        exact = self._constant_force & (bodies.model.rotation_free | still)
        hit_time = np.full(len(resting), np.inf)
        idx = np.flatnonzero(exact & (pivot == FREE))
        if len(idx):
            hit_time[idx] = exact_contact(flight.take(idx), t, take_state(state, idx), distance[idx], horizon[idx])
        idx = np.flatnonzero(~exact & (pivot == FREE))
        if len(idx):
            hit_time[idx] = root_contact(flight.take(idx), t, take_state(state, idx), resting[idx], distance[idx],
                                          speed[idx], horizon[idx])
        hit = hit_time <= horizon
        duration = np.where(hit, hit_time, horizon)
        state = flight(t, state, duration)
        sliding = (resting >= 0) & ~flight.stuck
        overshot = sliding & (np.sum(state.momentum_world * flight.slide, axis=1) < 0.0)  # forces not constant
        stopped = (~hit & (stop <= remaining)) | overshot
        state = _hold(bodies.model, state, resting, stopped)
        log.add(clock[stopped] + duration[stopped], ids[stopped], resting[stopped], "stop")
        idx = np.flatnonzero(hit)
        if len(idx):
            part, resting[idx], pivot[idx] = _respond(bodies.take(idx), take_state(state, idx), resting[idx], dt,
                                                      clock[idx] + duration[idx], ids[idx], log)
            state = put_state(state, idx, part)
        return state, resting, pivot, duration, hit | stopped, hit & (resting >= 0)

    def step(self, t: float, state: State, resting: np.ndarray, dt: float, log: EventLog):
        """Advance every body by dt [s] from time t."""
        n = len(resting)
        resting, remaining = resting.copy(), np.full(n, float(dt))
        events, rests = np.zeros(n, dtype=int), np.zeros(n, dtype=int)
        pivot = np.full(n, FREE)
        for _ in range(MAX_EVENTS_PER_STEP + 1):
            idx = np.flatnonzero(remaining > 0.0)
            if not len(idx):
                break
            bodies = self._bodies if len(idx) == n else self._bodies.take(idx)
            part, resting[idx], pivot[idx], duration, event, rest = self._round(
                bodies, t, dt, take_state(state, idx), resting[idx], pivot[idx], remaining[idx],
                t + dt - remaining[idx], idx, log)
            state = put_state(state, idx, part)
            remaining[idx] = np.where(event, remaining[idx] - duration, 0.0)
            events[idx] += event
            rests[idx] += rest
            full = (events >= MAX_EVENTS_PER_STEP) | (rests >= MAX_RESTS_PER_STEP)
            capped = np.flatnonzero(full & (remaining > 0.0))
            if len(capped):
                state, resting = self._cap(state, resting, capped, t + dt - remaining[capped], log)
                remaining[capped], pivot[capped] = 0.0, FREE
        idx = np.flatnonzero(pivot != FREE)
        if len(idx):
            touched = np.arange(len(self._bodies.model.normals))[None, :] == pivot[idx, None]
            state = put_state(state, idx, resolve_after(self._bodies.take(idx), take_state(state, idx), touched))
        return state, resting

    def _cap(self, state: State, resting: np.ndarray, capped: np.ndarray, clock: np.ndarray, log: EventLog):
        """Put bodies with too many events (or rests) in one step at rest on their nearest plane."""
        model = self._bodies.model.take(capped)
        part = take_state(state, capped)
        nearest = model.points(part.position_world, part.rotation_world)[1].min(axis=2).argmin(axis=1)
        part = State(part.position_world, part.orientation, np.zeros_like(part.momentum_world),
                     np.zeros_like(part.angular_momentum_world))
        resting = resting.copy()
        resting[capped] = nearest
        log.add(clock, capped, nearest, "cap")
        return put_state(state, capped, _hold(model, part, nearest, np.ones(len(capped), dtype=bool))), resting
