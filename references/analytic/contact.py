"""Closed-form, event-driven ground truth of bodies bouncing, resting and sliding on planes.

A body qualifies when it only translates (zero angular velocity, and nothing that would
turn it): a ``point``, a ``sphere``, or a ``box`` / ``points`` body that touches the plane
with a whole face whose support polygon holds the centre of pressure (the COM's
projection, shifted by friction's torque: ``h |F_t| / F_n`` toward the slip, h the COM's
height above the face). Forces: gravity (or none); no drag, no applied force. The body
touches ONE plane (with several planes, the one it touches; n/a when it would touch two).

Between events the motion has constant acceleration, so each piece is exact:

- free flight: x0 + v0 t + g t^2 / 2 (a parabola);
- impact (support distance E = 0, normal velocity v_n < 0): v_n -> k |v_n| (Newton
  restitution k), or 0 when k |v_n| < ``rest_speed`` (resting contact from then on). With
  friction (point, box, points) the normal impulse per mass is j_n = |v_n| + v_n_after
  (= (1 + k)|v_n| for a bounce); the tangential impulse |v_t| that stops the slip is taken
  when |v_t| <= mu_s j_n (stick: v_t = 0), else v_t shrinks by mu_k j_n along the slip;
- resting contact (E = 0, v_n = 0, gravity pushing in, g_n < 0): the plane carries g_n;
  sliding with speed > 0 accelerates by g_t - mu_k |g_n| s (s the slip direction), exact
  while s stays fixed (v_t parallel to g_t, or g_t = 0, or mu_k = 0); it stops at the
  exact root of the linear velocity, then sticks if |g_t| <= mu_s |g_n|, else slides down
  with (|g_t| - mu_k |g_n|) g_t / |g_t| from rest.

Event times are the exact roots of E(t) = E0 + v_n t + g_n t^2 / 2 in the cancellation-free
forms t = 2 E0 / (|v_n| + sqrt(D)) (approaching) and t = (v_n + sqrt(D)) / |g_n| (receding,
falling back), D = v_n^2 - 2 g_n E0, and the normal speed at impact is sqrt(D). The events
are computed once per body (in plane coordinates: E along N, two tangent axes), then every
sample time is evaluated at once with ``searchsorted`` over the piece start times.

Public: :func:`supports`, :func:`contact_events` (the exact event sequence, for the
comparisons), :class:`ContactEvents`, :class:`ContactSimulation`.
Rotations are SciPy's (:mod:`simparity.references.common.conventions`); the geometry (vertices,
support distance, face, support polygon) is this module's own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from simparity.core.model.engine import Simulation, Support
from simparity.core.model.errors import SimparityError
from simparity.core.model.scenes.contact import Plane, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.references.common.conventions import quat_wxyz_to_matrix

ON_PLANE_TOL = 1e-12
"""[m] A body whose support distance is within this of 0 starts on the plane (the scene put it
there; float64 placement rounds). Below -ON_PLANE_TOL it starts inside: n/a."""

_RTOL = 1e-12
"""Relative tolerance of the decisions that are exact in the scene and off only by rounding:
a normal velocity or tangential gravity that is zero, a slip parallel to the tangential
gravity, vertices of one face at one height, a centre of pressure on its polygon's edge."""

MAX_IMPACTS = 100_000
"""Impacts per body beyond which the event list is refused (a rest_speed of 0 gives an
accumulating, Zeno, sequence; elastic bounces over a very long duration)."""

KINDS = ("impact", "rest", "stop", "slide")
"""Event kinds of :class:`ContactEvents`."""


class NoClosedForm(SimparityError):
    """The scene (a body of it) has no closed form here; the message says why."""


@dataclass(frozen=True)
class ContactEvents:
    """The exact contact events of one body, in time order.

    Kinds: ``impact`` (an impact: normal velocity before < 0, after = k |before| or 0),
    ``rest`` (resting contact begins: normal velocity 0 from then on; the body may still
    slide along the plane), ``stop`` (a slide stops: tangential velocity reaches 0),
    ``slide`` (the body starts to slide from rest: static friction cannot hold it).
    ``rest`` follows an impact at the same time when that impact ends the bouncing; at
    t = 0 it marks a body that starts on the plane.

    Attributes
    ----------
    plane : str
        Name of the plane the body touches ("" if it touches none).
    times : (E,) ndarray
        [s].
    kinds : tuple of str
        (E,) from :data:`KINDS`.
    normal_velocity_before, normal_velocity_after : (E,) ndarray
        N . v of the COM just before and after the event [m/s] (equal except at impacts).
    position_world : (E, 3) ndarray
        COM at the event [m].
    """

    plane: str
    times: np.ndarray
    kinds: tuple[str, ...]
    normal_velocity_before: np.ndarray
    normal_velocity_after: np.ndarray
    position_world: np.ndarray

    def __len__(self) -> int:
        return len(self.times)


@dataclass(frozen=True)
class _Pieces:
    """Constant-acceleration pieces of one body's motion (world frame).

    starts (S,) [s], position/velocity/acceleration (S, 3) at each piece's start; piece i
    holds on [starts[i], starts[i + 1]) and the last one for ever after.
    """

    starts: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray

    def evaluate(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(position (T, 3), velocity (T, 3)) at ``times`` (T,) [s], vectorised."""
        i = np.clip(np.searchsorted(self.starts, times, side="right") - 1, 0, len(self.starts) - 1)
        i[times <= self.starts[0]] = 0  # t = 0 is the initial state, even before an impact at t = 0
        tau = (times - self.starts[i])[:, None]
        a = self.acceleration[i]
        return self.position[i] + tau * (self.velocity[i] + 0.5 * a * tau), self.velocity[i] + a * tau


# ---------------------------------------------------------------------------------------------
# Geometry of a shape against a plane (the module's own; no core geometry is used).


def _vertices_body(shape: Shape) -> np.ndarray:
    """(V, 3) points of the shape relative to the COM that can touch a plane [m] (a sphere:
    its centre, the radius is added separately)."""
    if shape.kind == "box":
        signs = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
        return np.asarray(shape.center_body) + signs * np.asarray(shape.half_extents_body)
    if shape.kind == "points":
        return np.asarray(shape.points_body, dtype=float).reshape(-1, 3)
    return np.zeros((1, 3))


def _basis(normal: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangent axes (e1, e2) with (e1, e2, N) right-handed; e1 along gravity's tangential part
    when it has one."""
    g_t = g - (g @ normal) * normal
    if np.linalg.norm(g_t) > _RTOL * np.linalg.norm(g):
        e1 = g_t / np.linalg.norm(g_t)
    else:
        axis = np.zeros(3)
        axis[int(np.argmin(np.abs(normal)))] = 1.0
        e1 = np.cross(normal, axis)
        e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


@dataclass
class _Motion:
    """One body against one plane, in plane coordinates (E along N, tangent axes e1, e2)."""

    name: str
    kind: str
    plane: Plane
    x0: np.ndarray
    v0: np.ndarray
    g: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    low: float  # min over the shape of N . (point - COM) [m] (-radius for a sphere)
    offsets_t: np.ndarray  # (V, 2) tangential coordinates of the lowest vertices [m]
    restitution: float
    mu_s: float
    mu_k: float
    rest_speed: float

    @property
    def friction(self) -> bool:
        return self.mu_s > 0 or self.mu_k > 0

    def label(self) -> str:
        return f"{self.kind} '{self.name}' on plane '{self.plane.name}'"

    def support_distance(self, position: np.ndarray) -> np.ndarray:
        """E of the shape's lowest point at COM positions (..., 3) [m]."""
        return position @ self.plane.normal_world + self.plane.offset + self.low


def _motion(scene: DynamicsScene, k: int, p: int) -> _Motion:
    body, contact = scene.bodies[k], scene.contact
    assert contact is not None  # called for contact scenes only (supports and callers check scene.contact)
    shape, plane = contact.shapes[k], contact.planes[p]
    n = np.asarray(plane.normal_world, dtype=float)
    g = np.zeros(3) if scene.forces.gravity_world is None else np.asarray(scene.forces.gravity_world, dtype=float)
    e1, e2 = _basis(n, g)
    rotation = quat_wxyz_to_matrix(np.asarray(body.quat_wxyz))
    offsets = _vertices_body(shape) @ rotation.T  # (V, 3) world offsets from the COM
    if not len(offsets):
        raise NoClosedForm(f"body '{body.name}' has a 'points' shape without points")
    heights = offsets @ n
    scale = float(np.max(np.linalg.norm(offsets, axis=1)))
    lowest = offsets[heights <= heights.min() + _RTOL * scale]
    radius = shape.radius if shape.kind == "sphere" else 0.0
    material = contact.materials[k][p]
    return _Motion(body.name, shape.kind, plane, np.asarray(body.position_world, dtype=float),
                   np.asarray(body.velocity_world, dtype=float), g, e1, e2, float(heights.min()) - radius,
                   np.stack([lowest @ e1, lowest @ e2], axis=1), material.restitution, material.friction_static,
                   material.friction_kinetic, contact.rest_speed)


def _check_support(m: _Motion, ratio: float, slip: tuple[float, float]) -> None:
    """Raise unless a box / points body rests on a face whose polygon holds the centre of pressure.

    ``ratio`` = |F_t| / F_n of the friction the plane exerts, ``slip`` the unit tangential direction
    (e1, e2 coordinates) the friction opposes: its torque about the COM moves the centre of
    pressure by h * ratio along ``slip`` (h the COM's height above the face)."""
    if m.kind in ("point", "sphere"):
        return
    q = m.offsets_t
    scale = max(float(np.max(np.abs(q))), -m.low, 1e-300)
    centred = q - q.mean(axis=0)
    singular = np.linalg.svd(centred, compute_uv=False) if len(q) > 1 else np.zeros(2)
    if len(q) < 3 or singular[1] <= _RTOL * scale:
        feature = "a vertex" if len(q) == 1 or singular[0] <= _RTOL * scale else "an edge"
        raise NoClosedForm(f"no closed form for {m.label()} landing on {feature}: it starts to turn")
    h = -m.low
    centre = h * ratio * np.asarray(slip)
    hull = ConvexHull(q)
    outside = float(np.max(hull.equations[:, :2] @ centre + hull.equations[:, 2]))
    if outside > _RTOL * scale:
        cause = ("its centre of mass is not above the face" if ratio == 0 else
                 f"friction (|F_t|/F_n = {ratio:.6g}) moves the centre of pressure {h * ratio:.6g} m, out of the face")
        raise NoClosedForm(f"no closed form for {m.label()}: it would tip over ({cause})")


# ---------------------------------------------------------------------------------------------
# The event loop, in plane coordinates: z = E (support distance), (p1, p2) tangential position,
# (vn, v1, v2) velocity; gravity (gn, g1, g2).


def _flight_time(z: float, vn: float, gn: float) -> float | None:
    """Time until E = 0 is reached approaching (exact root, cancellation-free); None if never.
    A start within ON_PLANE_TOL below the plane counts as on it (z clamped to 0)."""
    z = max(z, 0.0)
    if vn < 0:
        disc = vn * vn - 2.0 * gn * z
        if disc <= 0:  # a receding-gravity graze (g_n > 0): it turns before the plane
            return None
        return max(2.0 * z / (math.sqrt(disc) - vn), 0.0)
    if gn < 0:
        return (vn + math.sqrt(vn * vn - 2.0 * gn * z)) / -gn
    return None


def _solve(m: _Motion, t_end: float) -> tuple[_Pieces, ContactEvents]:
    """The pieces and events of a body against its plane up to ``t_end`` [s]; NoClosedForm if none."""
    n = np.asarray(m.plane.normal_world, dtype=float)
    g_norm = float(np.linalg.norm(m.g))
    gn, g1, g2 = float(m.g @ n), float(m.g @ m.e1), float(m.g @ m.e2)
    if abs(gn) <= _RTOL * g_norm:
        gn = 0.0
    if math.hypot(g1, g2) <= _RTOL * g_norm:
        g1 = 0.0
    g2 = 0.0  # e1 is along g_t (or g_t = 0): g2 is zero but for rounding
    z0 = float(m.support_distance(m.x0))
    if z0 < -ON_PLANE_TOL:
        raise NoClosedForm(f"{m.label()} starts inside the plane (E = {z0:.6g} m)")
    p10, p20 = float(m.x0 @ m.e1), float(m.x0 @ m.e2)
    vn, v1, v2 = float(m.v0 @ n), float(m.v0 @ m.e1), float(m.v0 @ m.e2)
    if abs(vn) <= _RTOL * float(np.linalg.norm(m.v0)):
        vn = 0.0
    t, z, p1, p2 = 0.0, z0, p10, p20
    pieces: list[tuple] = []  # (t, z, p1, p2, vn, v1, v2, an, a1, a2, flight)
    events: list[tuple] = []  # (t, kind, vn_before, vn_after, z, p1, p2)
    impacts = 0
    on_plane = z0 <= ON_PLANE_TOL
    contact = on_plane and vn == 0.0 and gn < 0
    if contact:
        events.append((0.0, "rest", 0.0, 0.0, z, p1, p2))
    checked = False

    def face(ratio: float = 0.0, slip=(1.0, 0.0)) -> None:
        nonlocal checked
        if ratio > 0 or not checked:
            _check_support(m, ratio, slip)
            checked = True

    while True:
        if not contact:
            tau = _flight_time(z, vn, gn)
            pieces.append((t, z, p1, p2, vn, v1, v2, gn, g1, g2, True))
            if tau is None or t + tau > t_end:
                break
            p1 += tau * (v1 + 0.5 * g1 * tau)
            p2 += tau * (v2 + 0.5 * g2 * tau)
            v1 += g1 * tau
            v2 += g2 * tau
            before = -math.sqrt(max(vn * vn - 2.0 * gn * max(z, 0.0), 0.0))  # the speed sqrt(D) at E = 0
            t, z = t + tau, 0.0
            impacts += 1
            if impacts > MAX_IMPACTS:
                raise NoClosedForm(f"more than {MAX_IMPACTS} impacts of {m.label()} by t = {t:.6g} s: "
                                   f"rest_speed {m.rest_speed:g} m/s is too small for an event list")
            face()
            rebound = m.restitution * -before
            after = rebound if rebound >= m.rest_speed and rebound > 0 else 0.0
            speed = math.hypot(v1, v2)
            if m.friction and speed > _RTOL * math.hypot(speed, before):
                if m.kind == "sphere":
                    raise NoClosedForm(f"no closed form for {m.label()}: a sphere with friction and tangential "
                                       f"velocity at an impact (it would roll)")
                jn = after - before  # normal impulse per unit mass
                s1, s2 = v1 / speed, v2 / speed
                if speed <= m.mu_s * jn:
                    face(speed / jn, (s1, s2))
                    v1 = v2 = 0.0
                else:
                    face(m.mu_k, (s1, s2))
                    v1, v2 = v1 - m.mu_k * jn * s1, v2 - m.mu_k * jn * s2
            elif speed <= _RTOL * math.hypot(speed, before):
                v1 = v2 = 0.0
            events.append((t, "impact", before, after, z, p1, p2))
            vn = after
            if after == 0.0 and gn < 0:
                events.append((t, "rest", 0.0, 0.0, z, p1, p2))
                contact = True
            continue
        # Resting contact: E = z (0 after an impact), vn = 0, gn < 0.
        face()
        speed = math.hypot(v1, v2)
        g_t = abs(g1)
        if speed == 0.0:
            if m.kind == "sphere" and m.friction and g_t > 0:
                raise NoClosedForm(f"no closed form for {m.label()}: a sphere with friction on an incline "
                                   f"(it would roll)")
            if g_t <= m.mu_s * -gn:
                if g_t > 0:
                    face(g_t / -gn, (1.0, 0.0))
                pieces.append((t, z, p1, p2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False))
                break
            # The incline is steeper than the friction angle: it slides down from rest, for ever.
            if m.mu_k > 0:
                face(m.mu_k, (1.0, 0.0))
            events.append((t, "slide", 0.0, 0.0, z, p1, p2))
            pieces.append((t, z, p1, p2, 0.0, 0.0, 0.0, 0.0, g_t - m.mu_k * -gn, 0.0, False))
            break
        if m.kind == "sphere" and m.mu_k > 0:
            raise NoClosedForm(f"no closed form for {m.label()}: a sphere sliding with friction (it would roll)")
        if g_t == 0.0:
            parallel = True  # no tangential gravity: a straight slide in any direction
        elif abs(v2) <= _RTOL * speed:
            parallel, v2, speed = True, 0.0, abs(v1)  # along the slope, up or down (off by rounding only)
        else:
            parallel = False
        if not parallel and m.mu_k > 0:
            raise NoClosedForm(f"no closed form for {m.label()}: its slip is not along the slope "
                               f"(curved slide on an incline has no closed form here)")
        s1, s2 = v1 / speed, v2 / speed
        a1, a2 = g1 - m.mu_k * -gn * s1, g2 - m.mu_k * -gn * s2
        if m.mu_k > 0:
            face(m.mu_k, (s1, s2))
        along = a1 * s1 + a2 * s2
        if not (parallel and along < 0):
            pieces.append((t, z, p1, p2, 0.0, v1, v2, 0.0, a1, a2, False))
            break
        tau = speed / -along
        pieces.append((t, z, p1, p2, 0.0, v1, v2, 0.0, a1, a2, False))
        if t + tau > t_end:
            break
        p1 += tau * (v1 + 0.5 * a1 * tau)
        p2 += tau * (v2 + 0.5 * a2 * tau)
        t, v1, v2 = t + tau, 0.0, 0.0
        events.append((t, "stop", 0.0, 0.0, z, p1, p2))

    rows = np.array([piece[:10] for piece in pieces], dtype=float)
    starts, z_, q1, q2, wn, w1, w2, an, b1, b2 = rows.T
    flight = np.array([piece[10] for piece in pieces])
    position = m.x0 + np.outer(z_ - z0, n) + np.outer(q1 - p10, m.e1) + np.outer(q2 - p20, m.e2)
    velocity = np.outer(wn, n) + np.outer(w1, m.e1) + np.outer(w2, m.e2)
    acceleration = np.outer(an, n) + np.outer(b1, m.e1) + np.outer(b2, m.e2)
    acceleration[flight] = m.g  # exactly gravity in flight
    if flight[0]:
        velocity[0] = m.v0  # the initial state as given
    if events:
        t_e, kinds, speeds_before, speeds_after, ze, r1, r2 = zip(*events)
        at = m.x0 + np.outer(np.array(ze) - z0, n) + np.outer(np.array(r1) - p10, m.e1) + np.outer(
            np.array(r2) - p20, m.e2)
        record = ContactEvents(m.plane.name, np.array(t_e), tuple(kinds), np.array(speeds_before),
                               np.array(speeds_after), at)
    else:
        record = ContactEvents(m.plane.name, np.zeros(0), (), np.zeros(0), np.zeros(0), np.zeros((0, 3)))
    return _Pieces(starts, position, velocity, acceleration), record


# ---------------------------------------------------------------------------------------------
# Per body: the scene checks, the plane it touches.


def _scene_checks(scene: DynamicsScene, k: int) -> None:
    body, forces = scene.bodies[k], scene.forces
    if np.any(np.asarray(body.angular_velocity_world) != 0):
        raise NoClosedForm(f"no closed form for body '{body.name}': an initial angular velocity in a contact scene")
    if any(a.body == k for a in forces.applied):
        raise NoClosedForm(f"no closed form for body '{body.name}': an applied force in a contact scene")
    for name in ("linear_drag", "quadratic_drag", "angular_linear_drag", "angular_quadratic_drag"):
        values = getattr(forces, name)
        if values is not None and values[k] != 0:
            raise NoClosedForm(f"no closed form for body '{body.name}': drag with contact ({name})")


def _min_over_pieces(pieces: _Pieces, t_end: float, normal: np.ndarray, offset: float) -> float:
    """min over [0, t_end] of N . x(t) + offset along the pieces (each a quadratic in time) [m]."""
    ends = np.append(pieces.starts[1:], max(t_end, pieces.starts[-1]))
    length = ends - pieces.starts
    c = pieces.position @ normal + offset
    b = pieces.velocity @ normal
    a = 0.5 * pieces.acceleration @ normal
    values = [c, c + length * (b + a * length)]
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(a > 0, -b / (2 * a), -1.0)
    inside = (vertex > 0) & (vertex < length)
    values.append(np.where(inside, c + vertex * (b + a * vertex), np.inf))
    return float(np.min(values))


@dataclass(frozen=True)
class _Plan:
    pieces: _Pieces
    events: ContactEvents
    detail: str


def _plan(scene: DynamicsScene, k: int, t_end: float) -> _Plan:
    """Body k's closed form up to ``t_end`` [s]; NoClosedForm with the reason when it has none."""
    _scene_checks(scene, k)
    contact = scene.contact
    assert contact is not None  # called for contact scenes only (supports and callers check scene.contact)
    touching = []
    for p in range(len(contact.planes)):
        m = _motion(scene, k, p)
        pieces, events = _solve(m, t_end)
        others = [q for q in range(len(contact.planes)) if q != p]
        touched = []
        for q in others:
            other = _motion(scene, k, q)
            normal = np.asarray(other.plane.normal_world)
            lowest = _min_over_pieces(pieces, t_end, normal, other.plane.offset + other.low)
            if lowest <= ON_PLANE_TOL:
                touched.append(other.plane.name)
        if not touched:
            friction = (f"Coulomb friction mu_s={m.mu_s:g} mu_k={m.mu_k:g}" if m.friction else "frictionless")
            detail = f"plane '{m.plane.name}': Newton restitution k={m.restitution:g}, {friction}"
            return _Plan(pieces, events, detail)
        touching.append((m.plane.name, touched))
    names = sorted({name for plane, rest in touching for name in [plane, *rest]})
    raise NoClosedForm(f"no closed form for body '{scene.bodies[k].name}': it touches more than one plane "
                       f"({', '.join(repr(n) for n in names)})")


def _t_end(scene: DynamicsScene) -> float:
    """The last sample time any of the scene's time steps reaches [s]."""
    return max([scene.duration] + [scene.n_steps(dt) * dt for dt in scene.dts])


def supports(scene: DynamicsScene) -> Support:
    """Whether every body of a contact scene has a closed form over the scene's duration."""
    if scene.contact is None:
        return Support.no("not a contact scene")
    t_end = _t_end(scene)
    for k in range(len(scene.bodies)):
        try:
            _plan(scene, k, t_end)
        except NoClosedForm as error:
            return Support.no(str(error))
    return Support.yes()


def contact_events(scene: DynamicsScene, body_index: int, t_end: float) -> ContactEvents:
    """The exact contact events of body ``body_index`` on [0, ``t_end``] [s].

    Raises NoClosedForm (a SimparityError) with the reason when the body has no closed form.
    """
    if scene.contact is None:
        raise NoClosedForm("not a contact scene")
    return _plan(scene, body_index, t_end).events


class ContactSimulation(Simulation):
    """The piecewise closed form of a contact scene at the samples t = i dt.

    Events are found when built (not timed), up to the scene's last sample time; ``run``
    evaluates every sample at once. Orientation stays the initial one, angular velocity 0.
    """

    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        self._scene, self._dt = scene, dt
        self._t_end = max(_t_end(scene), scene.n_steps(dt) * dt)
        self._plans = [_plan(scene, k, self._t_end) for k in range(len(scene.bodies))]
        planes = "; ".join(dict.fromkeys(plan.detail for plan in self._plans))
        assert scene.contact is not None  # built for contact scenes only (the engine checks scene.contact)
        self.detail = f"closed form: ballistic flight; {planes}; rest below {scene.contact.rest_speed:g} m/s"

    def run(self, n_steps: int) -> Trajectory:
        times = np.arange(n_steps + 1) * self._dt
        if times[-1] > self._t_end:
            self._t_end = float(times[-1])
            self._plans = [_plan(self._scene, k, self._t_end) for k in range(len(self._scene.bodies))]
        positions, velocities = zip(*(plan.pieces.evaluate(times) for plan in self._plans))
        quat = np.stack([np.broadcast_to(np.asarray(b.quat_wxyz), (len(times), 4)) for b in self._scene.bodies], axis=1)
        return Trajectory(times, np.stack(positions, axis=1), quat, np.stack(velocities, axis=1),
                          np.zeros((len(times), len(self._scene.bodies), 3)))
