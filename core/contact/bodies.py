"""Rigid bodies against planes: contact points, the impulse response and the penalty force.

The lecture's "Bodies in Contact" for the full rigid-body state S = (x, R, P, L), batched over
B bodies and P planes (bodies never touch each other). The three methods that use these pieces
are :mod:`core.contact.backup` (back up time), :mod:`core.contact.act_after` (respond after the
fact) and the penalty force of :func:`penalty_wrench` integrated by any of core's schemes.

Contact points: a body's shape vertices (:meth:`Shape.vertices_body`) rotated and translated;
a sphere touches plane p at its centre - r N_p. The lever r of a point is its offset from the
COM in world axes; the point moves with u = v + omega x r.

Impulse response (:func:`impulse_response`) at a point r with normal N: where u.N < 0,
j_n = -(1 + k) u.N / (1/m + N.((I^-1 (r x N)) x r)); then the friction impulse that would stop
the tangential velocity along its direction t, j_stop = |u_t| / (1/m + t.((I^-1 (r x t)) x r)),
is applied if j_stop <= mu_s j_n (stick), else mu_k j_n (slide). Each of the two is a 1-D
impulse within [0, 2x] of the one that stops the point along its direction, so neither can add
kinetic energy.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from simparity.core.contact.particle import penalty_force, sliding_friction
from simparity.core.dynamics.forces import make_wrench
from simparity.core.dynamics.rigid_body import MassProperties, State, Wrench
from simparity.core.rotations import cross
from simparity.core.model.scenes.bodies import AppliedForce, Forces
from simparity.core.model.scenes.contact import Contact, Plane

CONTACT_TOLERANCE = 1e-9
"""[m] Points within this distance of a plane (and of the deepest point) touch it together: an edge or
a face landing flat puts several vertices on the plane at once, equal up to roundoff (~1e-16 m on
metre-sized positions); a tilt small enough to hide within 1e-9 m changes no bounce measurably."""

RESTING_GAP = 1e-6
"""[m] Points this close to a plane count as its support when a slow body settles (:func:`supported`), on top
of what the step itself leaves unresolved (the backup method adds |a.N| dt^2, the distance a point falls in a
step, for a body whose contact was resolved after the fact): a box rocking on a face at the rest speed
1e-3 m/s lifts an edge by ~u^2 / 2g ~ 5e-8 m. A body settling that tilted stays so."""

SUPPORT_ANGLE_MARGIN = 1e-6
"""[rad] A COM above the line through two support points (a box balanced on an edge) is not supported: the
largest angle between support points seen from the COM must be below pi by this much."""

FLIGHT_SCHEME = "rk4"
"""The scheme the backup and act_after methods fly bodies by between contacts (quaternion orientation)."""

PENALTY_SCHEMES = ("explicit_euler", "semi_implicit_euler", "midpoint", "average_velocity", "rk4")
"""Core's schemes the penalty method is run with (``penalty_<scheme>``)."""

_UNDAMPED_LIMIT = {
    "explicit_euler": 0.0,  # |1 + i w dt| > 1: grows at any dt
    "semi_implicit_euler": 2.0,  # symplectic Euler: stable for w dt < 2
    "midpoint": 0.0,  # |1 + z + z^2 / 2| = sqrt(1 + (w dt)^4 / 4) > 1 on the imaginary axis: grows slowly
    "average_velocity": 0.0,  # the same stability polynomial as midpoint
    "rk4": 2.0 * np.sqrt(2.0),  # RK4's region reaches the imaginary axis up to 2 sqrt 2 (2.785 is the real axis)
}


def penalty_stability_limit(scheme: str, stiffness: float, mass: np.ndarray) -> np.ndarray:
    """Theoretical largest stable dt [s] of ``scheme`` on the undamped contact spring, per body.

    The linear oscillator x'' = -omega^2 x, omega = sqrt(k_s / m) [rad/s], has eigenvalues +-i omega;
    dt_max = c / omega with c = 0 for explicit Euler, midpoint and average velocity (their stability
    regions touch the imaginary axis only at 0: energy grows at any dt, slowly for the second-order
    ones), 2 for semi-implicit Euler, 2 sqrt 2 for RK4. For the documentation: the comparison measures
    the limit. mass (B,) [kg] -> (B,) [s].
    """
    return _UNDAMPED_LIMIT[scheme] / np.sqrt(stiffness / np.asarray(mass, dtype=float))


def penalty_damping(contact: Contact, mass: np.ndarray) -> np.ndarray:
    """(B, P) penalty damping k_d [N s/m]: the scene's, or where it gives none the damping ratio
    zeta = -ln k / sqrt(pi^2 + ln^2 k) of a linear spring-damper that rebounds at the pair's k,
    c = 2 zeta sqrt(k_s m). mass (B,) [kg]."""
    k = np.asarray(contact.restitution, dtype=float)
    if contact.penalty_damping is not None:
        return np.full(k.shape, float(contact.penalty_damping))
    log_k = np.log(np.where(k > 0.0, k, 1.0))
    zeta = np.where(k > 0.0, -log_k / np.sqrt(np.pi**2 + log_k**2), 1.0)
    return 2.0 * zeta * np.sqrt(contact.penalty_stiffness * np.asarray(mass, dtype=float))[:, None]


@dataclass(frozen=True)
class ContactModel:
    """A scene's :class:`Contact` as arrays over B bodies, P planes and V vertices.

    Attributes
    ----------
    normals : (P, 3) ndarray
        Unit plane normals N, pointing to the free side.
    offsets : (P,) ndarray
        d [m]: E(p) = N . p + d.
    vertices_body : (B, V, 3) ndarray
        Contact vertices relative to the COM, body axes [m]; bodies with fewer vertices repeat
        their first one.
    weights : (B, V) ndarray
        1 for a body's own vertices, 0 for the repeats.
    radius : (B,) ndarray
        Sphere radius [m], 0 for the other shapes.
    restitution, friction_static, friction_kinetic : (B, P) ndarray
    rest_speed : float
        [m/s]
    stiffness : float
        Penalty k_s [N/m].
    damping : (B, P) ndarray
        Penalty k_d [N s/m] per body and plane (:attr:`core.scene.Contact.penalty_damping`).
    """

    normals: np.ndarray
    offsets: np.ndarray
    vertices_body: np.ndarray
    weights: np.ndarray
    radius: np.ndarray
    restitution: np.ndarray
    friction_static: np.ndarray
    friction_kinetic: np.ndarray
    rest_speed: float
    stiffness: float
    damping: np.ndarray

    @classmethod
    def of(cls, contact: Contact, mass: np.ndarray) -> "ContactModel":
        """The model of ``contact`` for bodies of ``mass`` (B,) [kg] (the penalty damping may depend on it)."""
        vertices = [s.vertices_body() for s in contact.shapes]
        count = max(len(v) for v in vertices)
        padded = np.stack([np.concatenate([v, np.repeat(v[:1], count - len(v), axis=0)]) for v in vertices])
        weights = np.array([[1.0] * len(v) + [0.0] * (count - len(v)) for v in vertices])
        return cls(
            np.stack([p.normal_world for p in contact.planes]), np.array([p.offset for p in contact.planes]),
            padded, weights, np.array([s.radius for s in contact.shapes]), np.array(contact.restitution),
            np.array(contact.friction_static), np.array(contact.friction_kinetic), float(contact.rest_speed),
            float(contact.penalty_stiffness), penalty_damping(contact, mass),
        )

    def take(self, idx: np.ndarray) -> "ContactModel":
        """The model of the bodies ``idx`` (planes unchanged)."""
        return replace(self, vertices_body=self.vertices_body[idx], weights=self.weights[idx], radius=self.radius[idx],
                       restitution=self.restitution[idx], friction_static=self.friction_static[idx],
                       friction_kinetic=self.friction_kinetic[idx], damping=self.damping[idx])

    @property
    def rotation_free(self) -> np.ndarray:
        """(B,) True where the contact points do not depend on the orientation (point, sphere)."""
        return np.all(self.vertices_body == 0.0, axis=(1, 2))

    def levers(self, rotation_world: np.ndarray) -> np.ndarray:
        """Levers r (B, P, V, 3) [m]: contact point minus COM, world axes."""
        lever = np.einsum("bij,bvj->bvi", rotation_world, self.vertices_body)[:, None]
        return lever - self.radius[:, None, None, None] * self.normals[None, :, None, :]

    def points(self, position_world: np.ndarray, rotation_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Levers r (B, P, V, 3) [m] (:meth:`levers`) and distances E (B, P, V) [m]."""
        lever = self.levers(rotation_world)
        distance = np.einsum("bpvi,pi->bpv", position_world[:, None, None, :] + lever, self.normals)
        return lever, distance + self.offsets[None, :, None]

    def normal_speeds(self, velocity_world: np.ndarray, omega_world: np.ndarray, lever: np.ndarray) -> np.ndarray:
        """u . N_p of every contact point (B, P, V) [m/s], u = v + omega x r."""
        u = velocity_world[:, None, None, :] + cross(omega_world[:, None, None, :], lever)
        return np.einsum("bpvi,pi->bpv", u, self.normals)


@dataclass(frozen=True)
class Bodies:
    """What a contact method needs of B bodies: mass properties, contact model, external forces."""

    props: MassProperties
    model: ContactModel
    forces: Forces

    @cached_property
    def size(self) -> np.ndarray:
        """(B,) each body's size [m]: its contact shape's reach from the COM (vertices and sphere radius), or its
        radius of gyration sqrt(tr I / (2 m)) where that is larger (a point has no reach)."""
        model = self.model
        reach = np.max(np.linalg.norm(model.vertices_body, axis=-1), axis=1) + model.radius
        gyration = np.sqrt(np.trace(self.props.inertia_body, axis1=1, axis2=2) / (2 * self.props.mass))
        return np.maximum(reach, gyration)

    @cached_property
    def external(self) -> Wrench:
        """The scene's forces on these bodies (:func:`core.dynamics.forces.make_wrench`), built once per batch."""
        return make_wrench(self.forces, self.props)

    def take(self, idx: np.ndarray) -> "Bodies":
        """The bodies ``idx`` (n,) as a batch of their own (an applied force follows its body)."""
        if len(idx) == len(self.props.mass) and np.all(idx == np.arange(len(idx))):
            return self
        props = MassProperties(self.props.mass[idx], self.props.inertia_body[idx], self.props.inertia_body_inv[idx])
        f = self.forces
        drags = ("linear_drag", "quadratic_drag", "angular_linear_drag", "angular_quadratic_drag")
        kept = [a for a in f.applied if np.any(idx == a.body)]
        forces = replace(f, **{name: getattr(f, name)[idx] for name in drags if getattr(f, name) is not None},
                         applied=tuple(AppliedForce(int(np.flatnonzero(idx == a.body)[0]), a.force_world, a.point_body)
                                       for a in kept))
        return Bodies(props, self.model.take(idx), forces)


def take_state(state: State, idx: np.ndarray) -> State:
    """The state of the bodies ``idx``."""
    return State(state.position_world[idx], state.orientation[idx], state.momentum_world[idx],
                 state.angular_momentum_world[idx])


def put_state(state: State, idx: np.ndarray, part: State) -> State:
    """``state`` with the bodies ``idx`` replaced by ``part``."""
    arrays = []
    for whole, new in zip((state.position_world, state.orientation, state.momentum_world, state.angular_momentum_world),
                          (part.position_world, part.orientation, part.momentum_world, part.angular_momentum_world)):
        whole = whole.copy()
        whole[idx] = new
        arrays.append(whole)
    return State(*arrays)


def _touching(distance: np.ndarray, weights: np.ndarray, gap) -> np.ndarray:
    """(n, V) bool: a body's own points within ``gap`` [m] (scalar or (n,)) of its lowest one."""
    gap = np.reshape(gap, (-1, 1)) if np.ndim(gap) else gap
    return (distance <= distance.min(axis=1, keepdims=True) + gap) & (weights > 0.0)


def patch_lever(lever: np.ndarray, distance: np.ndarray, speed: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Where a body touches one plane: the mean lever of its touching points (n, 3) [m].

    The touching points are those within :data:`CONTACT_TOLERANCE` of the deepest one that move into
    the plane (all touching points if none does): an edge landing acts at the edge's middle, a face
    landing flat at the face's centre, so that the impulse has the symmetry of the contact.
    lever (n, V, 3), distance (n, V) [m], speed (n, V) [m/s] (u . N), weights (n, V).
    """
    touching = _touching(distance, weights, CONTACT_TOLERANCE)
    moving_in = touching & (speed < 0.0)
    members = np.where(moving_in.any(axis=1, keepdims=True), moving_in, touching).astype(float)
    return np.einsum("nv,nvi->ni", members, lever) / members.sum(axis=1)[:, None]


def supported(lever: np.ndarray, distance: np.ndarray, normal: np.ndarray, weights: np.ndarray,
              gap: np.ndarray) -> np.ndarray:
    """Whether the COM lies above the support polygon of the points touching a plane (n,) bool.

    The support points are those within ``gap`` (n,) [m] of the lowest one; the COM's projection on the
    plane is inside their convex hull when, seen from it, no angle between consecutive support points
    reaches pi (less :data:`SUPPORT_ANGLE_MARGIN`), or when it coincides with one of them.
    lever (n, V, 3) [m], distance (n, V) [m], normal (n, 3), weights (n, V).
    """
    touching = _touching(distance, weights, gap)
    flat = lever - np.sum(lever * normal[:, None, :], axis=-1, keepdims=True) * normal[:, None, :]
    first = cross(normal, np.where(np.abs(normal[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
    first /= np.linalg.norm(first, axis=1, keepdims=True)
    second = cross(normal, first)
    angle = np.arctan2(np.sum(flat * second[:, None], axis=-1), np.sum(flat * first[:, None], axis=-1))
    angle = np.sort(np.where(touching, angle, 4.0 * np.pi), axis=1)  # the others sorted last, then ignored
    count = touching.sum(axis=1)
    gaps = np.diff(angle, axis=1)
    gaps = np.where(np.arange(gaps.shape[1])[None, :] < count[:, None] - 1, gaps, 0.0).max(axis=1, initial=0.0)
    wrap = angle[:, 0] + 2.0 * np.pi - angle[np.arange(len(count)), count - 1]
    on_point = np.any(touching & (np.linalg.norm(flat, axis=-1) <= CONTACT_TOLERANCE), axis=1)
    return on_point | (np.maximum(gaps, wrap) < np.pi - SUPPORT_ANGLE_MARGIN)


FACE_POINTS = 3
"""Touching points that make a face: fewer (a sphere's or a corner's one point, an edge's two) leave the friction's
moment unbalanced, and the body turns."""


def contact_lever(lever: np.ndarray, distance: np.ndarray, speed: np.ndarray, weights: np.ndarray,
                  normal: np.ndarray, velocity: np.ndarray, omega: np.ndarray, restitution: np.ndarray,
                  friction_static: np.ndarray, friction_kinetic: np.ndarray,
                  rest_speed: float) -> tuple[np.ndarray, np.ndarray]:
    """(where the impulse of a body touching one plane acts, relative to its COM (n, 3) [m]; whether it tips (n,)).

    The patch's middle (:func:`patch_lever`), except for a body landing flat: one that does not turn (its
    points move by rotation slower than ``rest_speed`` [m/s]) and touches with a face of at least
    :data:`FACE_POINTS` points. Over a face the normal impulses spread so that their moment cancels the
    friction's: the centre of pressure moves ahead of the COM's projection by rho h along the slip (h the
    COM's height above the face, rho = j_t / j_n the friction impulse over the normal one: the slip speed
    over (1 + k) times the approach speed while that sticks within mu_s, else mu_k). While that point stays
    inside the face, the impulse acts as if at the COM and the body does not start to spin; past the face's
    edge the body tips (it must not be put at rest), and the impulse acts at the patch's middle, which sets it
    turning.
    lever (n, V, 3) [m], distance (n, V) [m], speed (n, V) [m/s], weights (n, V), normal (n, 3), velocity (n, 3)
    [m/s] (the COM's), omega (n, 3) [rad/s], restitution, friction_static, friction_kinetic (n,) (k as the
    impact will use it).
    """
    middle = patch_lever(lever, distance, speed, weights)
    still = np.linalg.norm(omega, axis=1) * np.linalg.norm(lever, axis=-1).max(axis=1) <= rest_speed
    touching = _touching(distance, weights, CONTACT_TOLERANCE)
    face = touching.sum(axis=1) >= FACE_POINTS
    approach = np.maximum(-np.sum(velocity * normal, axis=1), 0.0)
    slip = velocity - np.sum(velocity * normal, axis=1, keepdims=True) * normal
    slip_speed = np.linalg.norm(slip, axis=1)
    impact = (1.0 + restitution) * approach
    needed = np.divide(slip_speed, impact, out=np.full_like(slip_speed, np.inf), where=impact > 0.0)
    ratio = np.where(needed <= friction_static, needed, friction_kinetic)
    height = np.max(np.where(touching, -np.sum(lever * normal[:, None, :], axis=-1), 0.0), axis=1)
    ahead = (ratio * height / np.maximum(slip_speed, np.finfo(float).tiny))[:, None] * slip
    holds = supported(lever - ahead[:, None, :], distance, normal, weights, np.full(len(normal), CONTACT_TOLERANCE))
    flat = still & face & holds
    return np.where(flat[:, None], 0.0, middle), still & face & ~holds


def _effective_inverse_mass(inverse_mass, inertia_inv, lever, direction):
    """1/m + d.((I^-1 (r x d)) x r) [1/kg]: the velocity change along d of the point r per unit impulse along d.
    inverse_mass (n,) [1/kg], inertia_inv (n, 3, 3) [1/(kg m^2)], lever (n, 3) [m], direction (n, 3) unit -> (n,)."""
    turn = np.einsum("nij,nj->ni", inertia_inv, cross(lever, direction))
    return inverse_mass + np.sum(direction * cross(turn, lever), axis=-1)


def impulse_response(
    mass: np.ndarray, inertia_world_inv: np.ndarray, momentum: np.ndarray, angular_momentum: np.ndarray,
    lever: np.ndarray, normal: np.ndarray, restitution: np.ndarray, friction_static: np.ndarray,
    friction_kinetic: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Newton restitution and Coulomb friction at one contact point of each of n bodies.

    Parameters
    ----------
    mass : (n,) ndarray  [kg]
    inertia_world_inv : (n, 3, 3) ndarray  I(t)^-1 [1/(kg m^2)]
    momentum, angular_momentum : (n, 3) ndarray  P [kg m/s], L about the COM [kg m^2/s]
    lever : (n, 3) ndarray  r, contact point minus COM, world axes [m]
    normal : (n, 3) ndarray  unit N of the plane
    restitution, friction_static, friction_kinetic : (n,) ndarray  k, mu_s, mu_k

    Returns
    -------
    momentum, angular_momentum : (n, 3) ndarray
        After the impulse; unchanged where the point does not move into the plane.
    normal_impulse : (n,) ndarray
        j_n [N s] (0 where there was no impact).
    """
    inverse_mass = 1.0 / mass

    def point_velocity(p, l):
        return p * inverse_mass[:, None] + cross(np.einsum("nij,nj->ni", inertia_world_inv, l), lever)

    def apply(p, l, impulse):
        return p + impulse, l + cross(lever, impulse)

    speed_n = np.sum(point_velocity(momentum, angular_momentum) * normal, axis=-1)
    j_n = np.where(speed_n < 0.0, -(1.0 + restitution) * speed_n, 0.0) / _effective_inverse_mass(
        inverse_mass, inertia_world_inv, lever, normal)
    momentum, angular_momentum = apply(momentum, angular_momentum, j_n[:, None] * normal)
    u = point_velocity(momentum, angular_momentum)
    u_t = u - np.sum(u * normal, axis=-1, keepdims=True) * normal
    slip = np.linalg.norm(u_t, axis=-1)
    direction = u_t / np.where(slip > 0.0, slip, 1.0)[:, None]
    j_stop = slip / _effective_inverse_mass(inverse_mass, inertia_world_inv, lever, direction)
    j_t = np.where(j_stop <= friction_static * j_n, j_stop, friction_kinetic * j_n)
    momentum, angular_momentum = apply(momentum, angular_momentum, -j_t[:, None] * direction)
    return momentum, angular_momentum, j_n


def penalty_wrench(model: ContactModel, props: MassProperties, external: Wrench) -> Wrench:
    """The external wrench plus the penalty contact force of every penetrating point.

    At each point with E < 0: F_n = (-k_s E - k_d u.N)^+ N (:func:`core.contact.particle.penalty_force`)
    and regularised Coulomb friction -mu_k |F_n| u_t / max(|u_t|, v_reg)
    (:data:`core.contact.particle.FRICTION_REGULARISATION_SPEED`); torque r x F about the COM. Returns
    f(t, x, R, v, omega, step_start) -> (force (B, 3) [N], torque (B, 3) [N m]).
    """
    # per plane, what its terms read (sliced once, not at every call): the plane, k_d (B, 1), mu_k (B, 1, 1)
    planes = [(p, Plane(n, d), model.damping[:, p, None], model.friction_kinetic[:, p, None, None])
              for p, (n, d) in enumerate(zip(model.normals, model.offsets))]
    weights = model.weights[..., None]

    def wrench(t, x, rotation, v, omega, step_start=None):
        force, torque = external(t, x, rotation, v, omega, step_start)
        lever = model.levers(rotation)
        for p, plane, damping, friction in planes:
            r = lever[:, p]
            u = v[:, None, :] + cross(omega[:, None, :], r)
            f_n = penalty_force(x[:, None, :] + r, u, plane, model.stiffness, damping)
            f = (f_n - sliding_friction(f_n, u, plane.normal_world, friction)) * weights
            force = force + f.sum(axis=1)
            torque = torque + cross(r, f).sum(axis=1)
        return force, torque

    return wrench


@dataclass
class EventLog:
    """Contact events of a run, one entry per event (filled by the backup method).

    Attributes
    ----------
    time : list of float  [s]
    body, plane : list of int
    kind : list of str
        ``"impact"`` (a bounce), ``"rest"`` (an impact ending in resting contact), ``"stop"``
        (a sliding body's slip reached zero), ``"cap"`` (too many events in one step: put at rest).
    speed_before, speed_after : list of float
        Normal speed u . N of the contact point before and after [m/s] (0 for "stop" and "cap").
    """

    time: list = field(default_factory=list)
    body: list = field(default_factory=list)
    plane: list = field(default_factory=list)
    kind: list = field(default_factory=list)
    speed_before: list = field(default_factory=list)
    speed_after: list = field(default_factory=list)

    def add(self, time, body, plane, kind: str, speed_before=0.0, speed_after=0.0) -> None:
        """Append the events of several bodies at once (arrays broadcast to ``body``'s length)."""
        body = np.atleast_1d(body)
        if not len(body):
            return
        for name, values in (("time", time), ("body", body), ("plane", plane), ("speed_before", speed_before),
                             ("speed_after", speed_after)):
            getattr(self, name).extend(np.broadcast_to(values, body.shape).tolist())
        self.kind.extend([kind] * len(body))

    def of(self, body: int, kind: str = "impact") -> np.ndarray:
        """(n, 3) [time, speed_before, speed_after] of one body's events of one kind, in time order."""
        rows = [(t, a, b) for t, i, k, a, b in zip(self.time, self.body, self.kind, self.speed_before,
                                                    self.speed_after) if i == body and k == kind]
        return np.array(sorted(rows)).reshape(-1, 3)
