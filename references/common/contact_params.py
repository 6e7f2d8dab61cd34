"""Contact parameters shared by the MuJoCo and PyBullet adapters: geometry and the restitution mapping.

Neither engine has the scene's contact model (Newton restitution k at the contact point, Coulomb
friction with mu_s and mu_k, a rest speed below which an impact ends in resting contact); each
gets the closest thing it has, chosen here and documented in the adapters. Nothing here comes
from core's contact code (``core/contact/particle.py``): the geometry (plane frames, box corners) and
the restitution mapping are written independently.

Shapes as the engines see them
------------------------------
A "point" touches a plane with the body's COM, which no engine can represent exactly with a
zero-size shape. Both get a sphere of radius :data:`POINT_RADIUS` whose contact is shifted by
that radius, so that contact starts when the CENTRE reaches the plane (exact, no offset):
MuJoCo with a contact ``margin`` of ``-POINT_RADIUS`` on the point's pairs (a contact is active
while distance < margin), PyBullet with ``contactSlop`` = ``POINT_RADIUS`` (its multibody solver
adds the slop to every contact distance) and every collision sphere inflated by the same
radius (:func:`inflated_spheres`). A box touches a plane with its corners; a sphere at
COM - r N; "points" with each point.

Restitution in MuJoCo (no restitution coefficient)
-------------------------------------------------
MuJoCo's contact is a soft constraint whose reference acceleration is a damped spring,
a_ref = -b v - K r (penetration r, normal velocity v). Written in MuJoCo's direct form
``solref = (-K, -b)`` with a constant impedance (``solimp`` d0 = dwidth = d, so K and b are the
spring's own mass-normalised stiffness and damping, and a constraint at impedance d ~ 1 follows
a_ref), a bounce is one half-period of a damped oscillator, after which the normal velocity is
e = exp(-zeta pi / sqrt(1 - zeta^2)) times the one before. Inverting gives the damping ratio
zeta = -ln k / sqrt(pi^2 + ln^2 k) (:func:`damping_ratio`; k = 0 -> 1, critically damped; k = 1 ->
0, no damping). The stiffness is the stiffest MuJoCo's own stability rule allows: its standard
form clamps the time constant to >= 2 dt ("refsafe"), i.e. a natural frequency omega_n <= 1/(2 dt),
so omega_n = 1/(2 dt) here (:func:`natural_frequency`), K = omega_n^2, b = 2 zeta omega_n; a bounce
lasts pi / (omega_n sqrt(1 - zeta^2)) >= 2 pi dt, about 6-7 steps. The standard form
(timeconst, dampratio) cannot express this: its stiffness is 1/(timeconst dampratio)^2, which
grows without bound as zeta -> 0 (k -> 1). The mapping is that of a continuous oscillator;
the time-stepped contact differs by a few percent, which the comparisons MEASURE (0.48-0.57 for
k = 0.5 and 0.78-0.85 for k = 0.8 over dt = 0.001-0.01, tests/references/test_contact_engines.py). MuJoCo's
documentation ("Restitution" and "Solver parameters" in doc/modeling.rst) recommends exactly
the direct form for restitution.
The penetration MuJoCo's soft contact allows: at most about v_impact / omega_n = 2 v dt during
an impact (measured 7 cm at 4.2 m/s and dt = 0.01) and (1 - d) |g| / K = 0.02 |g| dt^2 at rest.
A contact becomes active only once the bodies overlap, by up to v dt, so its spring starts
compressed and can add up to (omega_n dt)^2 = 1/4 of the impact's kinetic energy: a rotating
box or points body hitting at 20 m/s with k = 0 rebounded up to 2.7 m in exploratory runs
(omega_n = 1/(4 dt) still gave 0.9 m; MuJoCo's default solref launches the same box at dt = 0.01).
"""

from __future__ import annotations

import math

import numpy as np

from simparity.core.model.scenes.contact import Contact, Plane, Shape
from simparity.core.model.engine import Support
from simparity.core.model.scenes.joint_motion import JointMotionScene

POINT_RADIUS = 1e-5  # [m]
"""Radius of the sphere standing for a point (a "point" body, each of "points", each box corner
in PyBullet); its contact is shifted by this radius so the centre touches the plane (module
docstring). Small, because in PyBullet it is also the width of the band in which a bouncing
body's contact is taken before it touches (a contact found at distance D < POINT_RADIUS
reduces the rebound by D / dt: at most 0.01 m/s at dt = 1e-3, and only for the few impacts whose
last step ends that close); not smaller, because PyBullet generates a contact only within its
relative contactBreakingThreshold times the shape's bounding radius (sqrt(3) POINT_RADIUS for a
point), and that factor is capped by Bullet's AABB overflow check (see the PyBullet adapter)."""

REFSAFE_STEPS = 2.0
"""MuJoCo's "refsafe" rule: a constraint's time constant is at least 2 time steps; the contact
spring's natural frequency is omega_n = 1 / (REFSAFE_STEPS dt)."""

FRICTION_DAMPING_STEPS = 10.0
"""MuJoCo's frictional rows have a reference tangential acceleration -b_f v_t (their direct
``solreffriction``; only the damping acts on friction). b_f = 1 / (FRICTION_DAMPING_STEPS dt):
large enough that Coulomb friction saturates at mu N while sliding (measured: a block at 2 m/s,
mu = 0.3 stops within 0.8 % of v^2/(2 mu g) at dt = 0.01, Euler), small enough that the
elliptic cone does not turn the friction demand into a normal force that lifts a sliding body
(b_f = 1/dt lifted it 1.6 cm on its first step at 2 m/s; 1/(10 dt) about 0.2 mm at dt = 1e-3)."""

IMPEDANCE = 0.995
"""MuJoCo's constraint impedance d, constant (solimp d0 = dwidth). A constraint follows its reference a_ref
with weight d and the unconstrained motion with 1 - d, so gravity leaks into resting contact as a static
penetration (1 - d) |g| / K = 0.02 |g| dt^2 and into sticking friction as a creep speed (1 - d) a_t / (d b_f)
(0.17 mm/s at dt = 1e-3 on a 20 degree incline); d closer to 1 would shrink both, but with d >= 0.999 the
implicit and implicitfast integrators let a block resting on that incline start slipping after ~0.1 s
(measured 1.8 cm in 1 s at d = 0.9999, dt = 1e-3, where Euler and RK4 hold it to 0.04 mm); at 0.995 every
integrator holds it (0.09 mm)."""

SOLIMP_WIDTH, SOLIMP_MIDPOINT, SOLIMP_POWER = 0.001, 0.5, 2.0
"""MuJoCo's defaults for the rest of solimp; irrelevant when d0 = dwidth (constant impedance)."""


def damping_ratio(restitution: float) -> float:
    """zeta of the damped oscillator whose half-period rebound is ``restitution`` times the impact speed.

    zeta = -ln k / sqrt(pi^2 + ln^2 k); 1 (critically damped) for k = 0, 0 for k = 1.
    """
    if restitution <= 0.0:
        return 1.0
    log_k = math.log(restitution)
    return -log_k / math.sqrt(math.pi**2 + log_k**2)


def natural_frequency(dt: float) -> float:
    """omega_n [rad/s] of MuJoCo's contact spring at time step ``dt`` [s]: 1 / (REFSAFE_STEPS dt)."""
    return 1.0 / (REFSAFE_STEPS * dt)


def mujoco_solref(restitution: float, dt: float) -> tuple[float, float]:
    """MuJoCo's direct-form ``solref`` (-K [1/s^2], -b [1/s]) for restitution k at time step dt [s]."""
    omega = natural_frequency(dt)
    return -(omega**2), -2.0 * damping_ratio(restitution) * omega


def mujoco_solreffriction(dt: float) -> tuple[float, float]:
    """MuJoCo's direct-form ``solreffriction`` (-K, -b_f); only b_f = 1/(FRICTION_DAMPING_STEPS dt) acts."""
    return -(natural_frequency(dt) ** 2), -1.0 / (FRICTION_DAMPING_STEPS * dt)


SOLIMP = (IMPEDANCE, IMPEDANCE, SOLIMP_WIDTH, SOLIMP_MIDPOINT, SOLIMP_POWER)
"""MuJoCo ``solimp`` of every contact pair: constant impedance :data:`IMPEDANCE`."""


def plane_frame(plane: Plane) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,) [m], rotation (3, 3)) of a frame whose xy-plane is the plane and whose z axis is N.

    The origin is -d N, the point of the plane nearest the world origin; the x axis is the
    world x (or y, when N is within ~25 degrees of x) made orthogonal to N.
    """
    normal = np.asarray(plane.normal_world, dtype=float)
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x_axis = helper - (helper @ normal) * normal
    x_axis /= np.linalg.norm(x_axis)
    rotation = np.column_stack([x_axis, np.cross(normal, x_axis), normal])
    return -plane.offset * normal, rotation


def box_corners(shape: Shape) -> np.ndarray:
    """(8, 3) corners of a box shape relative to the COM, body axes [m]: center +- half extents."""
    signs = np.array([[sx, sy, sz] for sx in (-1.0, 1.0) for sy in (-1.0, 1.0) for sz in (-1.0, 1.0)])
    return np.asarray(shape.center_body) + signs * np.asarray(shape.half_extents_body)


def contact_spheres(shape: Shape) -> list[tuple[np.ndarray, float, bool]]:
    """The spheres standing for a shape against planes: (centre (3,) body axes [m], radius [m], is_point).

    A sphere is itself; a point, each of "points" and (for an engine without an exact box) each
    box corner a sphere of :data:`POINT_RADIUS` marked ``is_point`` (its contact is shifted by
    that radius).
    """
    if shape.kind == "sphere":
        return [(np.zeros(3), float(shape.radius), False)]
    if shape.kind == "point":
        return [(np.zeros(3), POINT_RADIUS, True)]
    points = box_corners(shape) if shape.kind == "box" else np.asarray(shape.points_body)
    return [(np.array(p, dtype=float), POINT_RADIUS, True) for p in points]


def inflated_spheres(shape: Shape) -> list[tuple[np.ndarray, float]]:
    """PyBullet's collision spheres of a shape: (centre (3,) body axes [m], radius [m]), every radius
    grown by :data:`POINT_RADIUS` to cancel PyBullet's contact slop of the same size (a box is
    its 8 corners: box-plane contact is at the corners)."""
    return [(centre, (0.0 if is_point else radius) + POINT_RADIUS)
            for centre, radius, is_point in contact_spheres(shape)]


def body_materials(contact: Contact) -> tuple[list[tuple[float, float]] | None, str]:
    """Per body (restitution k, friction mu_k) when each body's material is the same against every plane.

    Returns (values, "") or (None, reason naming the first body whose material differs between
    planes): an engine that combines per-object materials (PyBullet multiplies them) can give
    a body only one value.
    """
    values = []
    for b, row in enumerate(contact.materials):
        first = row[0] if row else None
        for p, material in enumerate(row):
            assert first is not None  # row is not empty here: first is its first material
            if (material.restitution, material.friction_kinetic) != (first.restitution, first.friction_kinetic):
                return None, (f"body {b}'s material differs between planes 0 and {p} (restitution "
                              f"{first.restitution} vs {material.restitution}, friction_kinetic "
                              f"{first.friction_kinetic} vs {material.friction_kinetic})")
        values.append((first.restitution, first.friction_kinetic) if first else (0.0, 0.0))
    return values, ""


def static_friction_note(contact: Contact) -> str:
    """'' when mu_s = mu_k everywhere, else a note that the engine uses mu_k for both."""
    mu_s, mu_k = contact.friction_static, contact.friction_kinetic
    if np.array_equal(mu_s, mu_k):
        return ""
    return (f"mu_s (max {float(np.max(mu_s)):g}) > mu_k: the engine has one friction coefficient and uses "
            "mu_k, so sticking holds only while the tangential force stays within mu_k N")


def plastic_only(scene: JointMotionScene, how: str) -> Support:
    """Whether an engine whose robot contact is plastic (every impulse stops a pushed sphere: restitution 0) can do a
    joint-motion scene's contact: a soft one (its own stiffness), or a rigid one with restitution 0; ``how`` says what
    makes it plastic."""
    contact = scene.contact
    if contact is not None and contact.rigid and contact.restitution != 0:
        return Support.no(f"no restitution on a robot's contact: {how}; the scene asks for restitution "
                          f"{contact.restitution:g}")
    return Support.yes()
