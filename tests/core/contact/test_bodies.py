"""Core's contact methods for rigid bodies against planes: backup, act_after and penalty.

Expected values are closed forms written out here (bouncing ball, sliding block, block on an incline)
or single impulses computed by hand; nothing is taken from the code under test.
"""

import math

import numpy as np
import pytest

from simparity.core.contact.bodies import ContactModel, impulse_response, penalty_stability_limit
from simparity.core.inhouse import CONTACT_INTEGRATORS, InHouseEngine, integrator_names
from simparity.core.rotations import quat_wxyz_to_matrix
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.contact import Contact, Material, Plane, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene

G = 9.81  # [m/s^2]
SEED = 20261123
FLOOR = Plane((0.0, 0.0, 1.0), 0.0, "floor")
ENGINE = InHouseEngine()

# Backing up time is exact for these scenes: what is left is the roundoff of a few hundred float64
# operations on O(1) numbers per bounce (measured ~1e-14 relative after 10 bounces at dt = 0.001).
EXACT_RTOL = 1e-9
# The brief's bound on a stopping distance and on a sliding block: exact piecewise-constant motion
# leaves roundoff only (measured ~1e-15 m).
STOP_TOL = 1e-6  # [m]
SLIDE_TOL = 1e-9  # [m]
# A resting body is held exactly; roundoff of one projection per step is ~1e-17 m.
REST_TOL = 1e-12  # [m]
# After a response the body is pushed back out of the plane: what may remain is the roundoff of that
# projection (~1e-16 m on O(1) positions).
INSIDE_TOL = 1e-12  # [m]
# Hand values (a few roundings of O(1) numbers).
ROUNDOFF = 1e-12
# RK4 integrates the spinning box's rotation with an angle error ~(omega dt)^5 / 120 ~ 1e-4 rad at
# omega dt = 0.6: the dip's contact instant moves by ~1e-4 / omega.
DIP_TIME_TOL = 1e-3  # [s]
# act_after's first-apex error / dt is constant up to O(dt) terms: a few per cent at 20-80 steps to impact.
FIRST_ORDER_RTOL = 0.05
# Semi-implicit Euler on the undamped contact spring well inside its stability limit: energy error
# O(omega dt) per contact, omega dt = 0.2 here, but it returns when the contact ends (symplectic):
# measured +1 % at worst out of contact.
BOUNDED_ENERGY_RTOL = 0.05
# Energy gained per impact: none, up to roundoff of the kinetic energy's sums.
ENERGY_RTOL = 1e-12
# RK4 (the free flight) on a box tumbling at up to ~10 rad/s, dt = 0.01: its energy drifts by ~1e-9
# relative before the first impact (measured 7e-10).
TUMBLING_ENERGY_RTOL = 1e-8
# Penalty friction is regularised below 1e-2 m/s: the stopping distance moves by ~1e-4 relative.
PENALTY_FRICTION_RTOL = 1e-3
# Velocities of a few m/s after a handful of exact impulses round at ~1e-15 m/s; 1e-9 leaves margin and still
# tells any first-order error (g dt ~ 0.1 m/s) apart.
VELOCITY_ROUNDOFF = 1e-9
# The expected dampings in N s/m are written by hand to two decimals.
HAND_DIGITS = 0.01


def _ball(position, velocity=(0.0, 0.0, 0.0), mass=1.0, inertia=None, quat=(1.0, 0.0, 0.0, 0.0),
          omega=(0.0, 0.0, 0.0)):
    inertia = np.eye(3) * 0.004 * mass if inertia is None else inertia
    return RigidBody("body", mass, np.asarray(inertia, dtype=float), np.array(position, dtype=float),
                     np.array(quat, dtype=float), np.array(velocity, dtype=float), np.array(omega, dtype=float))


def _box_inertia(mass, half):
    a, b, c = half
    return mass / 3.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def _scene(bodies, shapes, materials, planes=(FLOOR,), dt=0.01, duration=1.0, gravity=(0.0, 0.0, -G),
           rest_speed=1e-3, stiffness=1e5, damping=0.0, methods=("backup", "act_after", "penalty")):
    forces = Forces(gravity_world=None if gravity is None else np.array(gravity, dtype=float))
    contact = Contact(tuple(planes), tuple(shapes), tuple(tuple(row) for row in materials), methods, rest_speed,
                      stiffness, damping)
    return DynamicsScene("contact", "-", "analytic", tuple(bodies), forces, duration, (dt,), contact=contact)


def _run(scene, integrator):
    dt = scene.dts[0]
    simulation = ENGINE.build_dynamics(scene, integrator, dt)
    return simulation.run(scene.n_steps(dt)), simulation


def _impact_times(height, restitution, count):
    """t_1 = sqrt(2h/g), t_{n+1} = t_n + 2 k^n sqrt(2gh) / g."""
    times = [math.sqrt(2.0 * height / G)]
    for n in range(1, count):
        times.append(times[-1] + 2.0 * restitution**n * math.sqrt(2.0 * G * height) / G)
    return np.array(times)


def _corner_heights(trajectory, half, planes=(FLOOR,)):
    """E of every box corner at every sample, (planes, T, B, 8)."""
    corners = Shape("box", half_extents_body=np.array(half)).vertices_body()
    rotation = quat_wxyz_to_matrix(trajectory.quat_wxyz)
    points = np.einsum("tbij,vj->tbvi", rotation, corners) + trajectory.position_world[:, :, None, :]
    return np.stack([points @ p.normal_world + p.offset for p in planes])


# --- the engine interface -------------------------------------------------------------------------------------


def test_engine_runs_contact_methods_only_on_scenes_with_contact():
    """Contact names are listed, chosen by the scene's methods, and refused on the wrong kind of scene."""
    penalties = tuple(f"penalty_{s}" for s in ("explicit_euler", "semi_implicit_euler", "midpoint",
                                               "average_velocity", "rk4"))
    assert set(("backup", "act_after") + penalties) <= set(ENGINE.integrators())
    assert not any("+" in name for name in CONTACT_INTEGRATORS)
    contact = _scene([_ball((0, 0, 1))], [Shape("point")], [[Material(0.5)]], methods=("backup", "penalty"))
    free = DynamicsScene("free", "-", "analytic", (_ball((0, 0, 1)),), Forces(), 1.0, (0.1,))
    assert ENGINE.scene_integrators(contact) == ("backup",) + penalties
    assert ENGINE.scene_integrators(free) == integrator_names()
    assert not set(CONTACT_INTEGRATORS) & set(ENGINE.scene_integrators(free))
    refused = ENGINE.supports_dynamics(free, "backup")
    assert not refused.ok and "no contact planes" in refused.reason
    refused = ENGINE.supports_dynamics(contact, "rk4")
    assert not refused.ok and "contact planes" in refused.reason
    assert ENGINE.supports_dynamics(contact, "act_after").ok
    for name in CONTACT_INTEGRATORS:
        assert ENGINE.theoretical_order(name) is None
        assert ENGINE.integrator_variant(name) == (name, "")
    assert "rest_speed 0.001" in ENGINE.build_dynamics(contact, "backup", 0.01).detail
    detail = ENGINE.build_dynamics(contact, "penalty_midpoint", 0.01).detail
    assert "k_s 100000" in detail and "midpoint" in detail


# --- impulses -------------------------------------------------------------------------------------------------


def test_impulses_never_add_energy():
    """Seeded random bodies, contacts and materials: kinetic energy after <= before; frictionless: -k u.N."""
    rng = np.random.default_rng(SEED)
    n = 2000
    mass = rng.uniform(0.1, 10.0, n)
    root = rng.normal(size=(n, 3, 3))
    inertia_body = root @ np.swapaxes(root, 1, 2) + 0.01 * np.eye(3)
    quat = rng.normal(size=(n, 4))
    rotation = quat_wxyz_to_matrix(quat)
    inertia = rotation @ inertia_body @ np.swapaxes(rotation, 1, 2)
    inertia_inv = np.linalg.inv(inertia)
    lever = 0.5 * rng.normal(size=(n, 3))
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    momentum, angular = mass[:, None] * rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    k = rng.uniform(0.0, 1.0, n)
    mu_s = rng.uniform(0.0, 1.0, n)
    mu_k = mu_s * rng.uniform(0.0, 1.0, n)
    frictionless = np.arange(n) % 4 == 0
    mu_s, mu_k = np.where(frictionless, 0.0, mu_s), np.where(frictionless, 0.0, mu_k)

    def energy(p, l):
        return 0.5 * np.sum(p * p, axis=1) / mass + 0.5 * np.einsum("ni,nij,nj->n", l, inertia_inv, l)

    def normal_speed(p, l):
        return np.sum((p / mass[:, None] + np.cross(np.einsum("nij,nj->ni", inertia_inv, l), lever)) * normal, axis=1)

    p, l, j_n = impulse_response(mass, inertia_inv, momentum, angular, lever, normal, k, mu_s, mu_k)
    before = energy(momentum, angular)
    assert np.all(energy(p, l) <= before * (1.0 + ENERGY_RTOL))
    approaching = normal_speed(momentum, angular) < 0.0
    assert 0.3 * n < approaching.sum() < 0.7 * n
    np.testing.assert_array_equal(j_n[~approaching], 0.0)
    np.testing.assert_array_equal(p[~approaching], momentum[~approaching])
    check = frictionless & approaching
    np.testing.assert_allclose(normal_speed(p, l)[check], -k[check] * normal_speed(momentum, angular)[check],
                               rtol=EXACT_RTOL, atol=ROUNDOFF)


def test_impulse_on_a_particle_is_the_lectures_reflection_plus_coulomb():
    """r = 0: v - (1 + k)(v.N) N, then the tangential speed stops (mu_s j_n enough) or loses mu_k j_n / m."""
    mass, k = np.array([2.0, 2.0]), np.array([0.5, 0.5])
    v = np.array([[1.0, 0.0, -4.0], [3.0, 0.0, -4.0]])
    zero, normal = np.zeros((2, 3)), np.array([[0.0, 0.0, 1.0]] * 2)
    p, l, j_n = impulse_response(mass, np.stack([np.eye(3)] * 2), mass[:, None] * v, zero, zero, normal, k,
                                 np.array([0.2, 0.2]), np.array([0.1, 0.1]))
    np.testing.assert_allclose(j_n, [12.0, 12.0], rtol=0, atol=ROUNDOFF)  # (1 + k) m |v.N|
    # stick: j_stop = m |v_t| = 2 <= mu_s j_n = 2.4; slide: 6 > 2.4, so |v_t| -= mu_k j_n / m = 0.6
    np.testing.assert_allclose(p / mass[:, None], [[0.0, 0.0, 2.0], [2.4, 0.0, 2.0]], rtol=0, atol=ROUNDOFF)
    np.testing.assert_array_equal(l, 0.0)


def test_sphere_with_friction_picks_up_spin():
    """A ball skidding onto the floor is held back at its lowest point r = -R N: it spins about +y."""
    radius = 0.1
    scene = _scene([_ball((0, 0, 0.5 + radius), velocity=(2.0, 0, 0))], [Shape("sphere", radius=radius)],
                   [[Material(0.5, 0.3, 0.3)]], dt=0.01, duration=0.5)
    trajectory, simulation = _run(scene, "backup")
    after = trajectory.times > simulation.events.of(0)[0, 0]
    spin = trajectory.angular_velocity_world[after, 0]
    assert np.all(spin[:, 1] > 0.0)  # r x F = (0, 0, -R) x (-F, 0, 0) = (0, R F, 0)
    np.testing.assert_array_equal(spin[:, [0, 2]], 0.0)


# --- act_after --------------------------------------------------------------------------------------------------


def test_act_after_is_first_order_and_pushes_out():
    """First-apex error proportional to dt (the bounce starts from where the step found the ball), never inside."""
    height, k = 1.0, 0.8
    t1 = math.sqrt(2.0 * height / G)
    slopes = []
    for steps_to_impact in (20, 40, 80):
        dt = t1 / (steps_to_impact + 0.5)  # the floor is crossed mid-step at every dt
        scene = _scene([_ball((0, 0, height))], [Shape("point")], [[Material(k)]], dt=dt,
                       duration=dt * (steps_to_impact + 5))
        trajectory, _ = _run(scene, "act_after")
        z, vz = trajectory.position_world[-1, 0, 2], trajectory.velocity_world[-1, 0, 2]
        assert vz > 0.0 and trajectory.position_world[:, 0, 2].min() >= 0.0
        slopes.append((z + vz**2 / (2.0 * G) - height * k**2) / dt)
    assert slopes[0] > 0.0
    np.testing.assert_allclose(slopes, slopes[-1], rtol=FIRST_ORDER_RTOL)


@pytest.mark.slow
def test_act_after_box_landing_flat_does_not_tip_and_rest_stays():
    """A flat box landing stays flat (its four corners respond together); a resting sphere does not move."""
    half = (0.2, 0.15, 0.1)
    bodies = [_ball((0, 0, 1.0), mass=2.0, inertia=_box_inertia(2.0, half)), _ball((2, 0, 0.1))]
    shapes = [Shape("box", half_extents_body=np.array(half)), Shape("sphere", radius=0.1)]
    scene = _scene(bodies, shapes, [[Material(0.5, 0.5, 0.3)]] * 2, dt=0.01, duration=2.0)
    trajectory, _ = _run(scene, "act_after")
    np.testing.assert_array_equal(trajectory.angular_velocity_world, 0.0)
    assert _corner_heights(trajectory, half)[0, :, 0].min() >= -INSIDE_TOL
    np.testing.assert_allclose(trajectory.position_world[:, 1, 2], 0.1, rtol=0, atol=REST_TOL)


# --- penalty --------------------------------------------------------------------------------------------------


def test_penalty_stability_limits_of_the_undamped_spring():
    """omega = sqrt(k_s / m): 0 for explicit Euler and the second-order pair, 2/omega, 2 sqrt 2 / omega."""
    mass = np.array([1.0, 4.0])
    omega = np.sqrt(1e4 / mass)
    expected = {"explicit_euler": 0.0, "midpoint": 0.0, "average_velocity": 0.0, "semi_implicit_euler": 2.0,
                "rk4": 2.0 * math.sqrt(2.0)}
    for scheme, c in expected.items():
        np.testing.assert_allclose(penalty_stability_limit(scheme, 1e4, mass), c / omega, rtol=ROUNDOFF)


def _penalty_drop(dt, duration, stiffness=1e4, damping=0.0, position=(0, 0, 0.2), velocity=(0, 0, 0), mu=0.0):
    return _scene([_ball(position, velocity=velocity)], [Shape("point")], [[Material(0.8, mu, mu)]], dt=dt,
                  duration=duration, stiffness=stiffness, damping=damping)


@pytest.mark.parametrize("fraction, stable", [pytest.param(0.1, True, marks=pytest.mark.slow), (1.5, False)])
def test_penalty_semi_implicit_euler_is_bounded_only_below_2_over_omega(fraction, stable):
    """Dropped on an undamped k_s = 1e4 N/m plane (omega = 100 rad/s): energy kept at dt = 0.1 (2/omega),
    gained many times over at 1.5 (2/omega)."""
    dt = fraction * 2.0 / 100.0
    scene = _penalty_drop(dt, 3.0)
    trajectory, _ = _run(scene, "penalty_semi_implicit_euler")
    z = trajectory.position_world[:, 0, 2]
    energy = 0.5 * trajectory.velocity_world[:, 0, 2] ** 2 + G * z
    out = z > 0.0  # out of contact: no spring energy
    assert out[-10:].any() or not stable
    if stable:
        np.testing.assert_allclose(energy[out], energy[0], rtol=BOUNDED_ENERGY_RTOL)
    else:
        assert not np.isfinite(energy).all() or energy[out].max() > 2.0 * energy[0]


@pytest.mark.slow
def test_penalty_rests_at_the_static_depth_and_slides_by_coulomb():
    """Damped (zeta = 0.5), a particle settles m g / k_s deep; sliding at 2 m/s with mu = 0.3 it stops
    after v^2 / (2 mu g), up to the friction's regularisation."""
    stiffness, damping = 1e4, 100.0
    settle = _penalty_drop(1e-3, 1.0, stiffness, damping, position=(0, 0, 0))
    trajectory, _ = _run(settle, "penalty_rk4")
    assert -trajectory.position_world[-1, 0, 2] == pytest.approx(G / stiffness, rel=EXACT_RTOL)
    slide = _penalty_drop(1e-3, 1.0, stiffness, damping, position=(0, 0, -G / stiffness), velocity=(2, 0, 0),
                          mu=0.3)
    trajectory, _ = _run(slide, "penalty_rk4")
    assert trajectory.position_world[-1, 0, 0] == pytest.approx(4.0 / (2.0 * 0.3 * G), rel=PENALTY_FRICTION_RTOL)


# --- many bodies ----------------------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("integrator", ["backup", "act_after", "penalty_rk4"])
def test_a_thousand_bodies_run_vectorised(integrator):
    """1000 seeded boxes, spheres and points thrown at a floor: finite, and (backup, act_after) none inside."""
    rng = np.random.default_rng(SEED)
    bodies, shapes = [], []
    for i in range(1000):
        half = rng.uniform(0.05, 0.2, 3)
        quat = rng.normal(size=4)
        bodies.append(_ball(rng.uniform([-5, -5, 0.3], [5, 5, 1.0]), 2.0 * rng.normal(size=3),
                            inertia=_box_inertia(1.0, half), quat=quat / np.linalg.norm(quat),
                            omega=rng.normal(size=3)))
        shapes.append([Shape("box", half_extents_body=half), Shape("sphere", radius=half[0]), Shape("point")][i % 3])
    scene = _scene(bodies, shapes, [[Material(0.5, 0.4, 0.3)]] * 1000, dt=0.01, duration=0.3)
    trajectory, _ = _run(scene, integrator)
    assert trajectory.is_finite()
    if integrator != "penalty_rk4":
        model = ContactModel.of(scene.contact, np.array([b.mass for b in scene.bodies]))
        rotation = quat_wxyz_to_matrix(trajectory.quat_wxyz[-1])
        assert model.points(trajectory.position_world[-1], rotation)[1].min() >= -INSIDE_TOL


@pytest.mark.parametrize("method", ["backup", "act_after"])
def test_a_box_landing_flat_while_sliding_does_not_spin(method):
    """A box landing flat at 1 m/s sideways with mu = 0.1: the face's normal impulses cancel the friction's moment,
    so it does not turn, and friction takes mu (1 + k) |v_n| of its sideways speed (by hand: v_n = sqrt(2 g h))."""
    half, height, k, mu = (0.15, 0.1, 0.05), 0.5, 0.5, 0.1
    box = _ball((0.0, 0.0, height + half[2]), velocity=(1.0, 0.0, 0.0), mass=3.0, inertia=_box_inertia(3.0, half))
    scene = _scene([box], [Shape("box", half_extents_body=np.array(half))], [[Material(k, mu, mu)]], dt=0.01,
                   duration=0.5, methods=(method,))
    trajectory, _ = _run(scene, method)
    assert np.abs(trajectory.angular_velocity_world).max() <= ROUNDOFF
    after = trajectory.times > math.sqrt(2 * height / G) + 0.01  # past the first impact
    expected = 1.0 - mu * (1 + k) * math.sqrt(2 * G * height)
    # backup meets the plane at the impact's instant; act_after finds it up to a step late, its normal speed up to
    # g dt larger, so friction takes up to mu (1 + k) g dt more (first order).
    late = 0.0 if method == "backup" else mu * (1 + k) * G * scene.dts[0]
    np.testing.assert_allclose(trajectory.velocity_world[after, 0, 0][:5], expected, rtol=0, atol=late + VELOCITY_ROUNDOFF)


def test_default_penalty_damping_gives_each_pair_its_restitution():
    """Without penalty_damping, each pair's damping is that of a linear spring-damper rebounding at its k:
    by hand for k_s = 1e4 N/m, m = 2 kg: k = 0.5 -> zeta = ln 2 / sqrt(pi^2 + ln^2 2) = 0.21545, c = 60.94 N s/m;
    k = 0 -> critical, 2 sqrt(k_s m) = 282.84 N s/m; k = 1 -> 0."""
    ball = _ball((0.0, 0.0, 1.0), mass=2.0)
    walls = (FLOOR, Plane((1.0, 0.0, 0.0), 5.0, "wall"), Plane((-1.0, 0.0, 0.0), 5.0, "other"))
    scene = _scene([ball], [Shape("point")], [[Material(0.5), Material(0.0), Material(1.0)]], planes=walls,
                   stiffness=1e4, damping=None)
    model = ContactModel.of(scene.contact, np.array([2.0]))
    np.testing.assert_allclose(model.damping, [[60.94, 282.84, 0.0]], rtol=0, atol=HAND_DIGITS)


def test_act_after_bounces_a_body_that_starts_on_the_plane_striking_it():
    """A point at z = 0 moving down at 8 m/s, k = 0.5: it strikes the plane at once, so act_after reflects it
    (first order: the velocity it has after flying one step, 8 + g dt, times k) instead of stopping it."""
    dt, k = 0.01, 0.5
    point = _ball((0.0, 0.0, 0.0), velocity=(0.0, 0.0, -8.0))
    scene = _scene([point], [Shape("point")], [[Material(k)]], dt=dt, duration=0.1, methods=("act_after",))
    trajectory, _ = _run(scene, "act_after")
    assert trajectory.velocity_world[1, 0, 2] == pytest.approx(k * (8.0 + G * dt), abs=VELOCITY_ROUNDOFF)


TIPPED_TOL = 1.0  # [deg] lying on a side: its face flat on the floor up to the settling's rounding


@pytest.mark.slow
@pytest.mark.parametrize("method", ["backup", "act_after"])
def test_a_tall_box_landing_while_sliding_fast_tips_over(method):
    """A 0.1 x 0.1 x 1 m box landing flat at 5 m/s sideways with mu = 0.5: friction moves the centre of pressure
    mu h = 0.5 x 0.5 = 0.25 m ahead, far past the 0.05 m half-width of its face (by hand), so it tips over and
    ends lying on a side (turned 90 degrees, its COM 0.05 m up) instead of sliding upright."""
    half = (0.05, 0.05, 0.5)
    box = _ball((0.0, 0.0, 0.55), velocity=(5.0, 0.0, 0.0), mass=1.0, inertia=_box_inertia(1.0, half))
    # it falls in ~sqrt(2 x 0.5 m / g) ~ 0.3 s and lies still from ~0.5 s (measured with both methods); 0.7 s leaves
    # it 0.2 s to be seen lying there
    scene = _scene([box], [Shape("box", half_extents_body=np.array(half))], [[Material(0.0, 0.5, 0.5)]], dt=0.001,
                   duration=0.7, methods=(method,))
    trajectory, _ = _run(scene, method)
    tilt = np.degrees(2 * np.arccos(np.clip(np.abs(trajectory.quat_wxyz[-1, 0, 0]), 0.0, 1.0)))
    assert abs(tilt - 90.0) <= TIPPED_TOL
    # backup puts a settling body at rest within its resting gap (core.contact.bodies.RESTING_GAP, 1e-6 m) of the plane;
    # act_after pushes out after each step and keeps a hop of order g dt^2
    settled = 2e-6 if method == "backup" else 2 * G * scene.dts[0] ** 2
    assert trajectory.position_world[-1, 0, 2] == pytest.approx(0.05, abs=settled)


@pytest.mark.slow
def test_hitting_the_event_cap_is_said_in_the_detail():
    """A ball with k = 0.9 and a rest speed of 1e-12 m/s bounces ever faster toward its accumulation time
    (by hand: sqrt(2h/g) (1 + 2k / (1 - k)) = 8.6 s from 1 m); the bounces left when a step holds more than the cap of
    events are cut short by putting the ball at rest, and the case's detail says so (never silently)."""
    ball = _ball((0.0, 0.0, 1.0))
    scene = _scene([ball], [Shape("point")], [[Material(0.9)]], dt=0.1, duration=10.0, rest_speed=1e-12,
                   methods=("backup",))
    _, simulation = _run(scene, "backup")
    assert "reached the cap of" in simulation.detail
