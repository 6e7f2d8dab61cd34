"""Core's backup method (core/contact/backup.py) for rigid bodies against planes: bounces, friction, rest, corners and
tumbling bodies against closed forms (bouncing ball, sliding block, block on an incline) and hand impulses; nothing is
taken from the code under test. Scene builders and tolerances are test_bodies.py's; the file is apart so that its
long integrations and the other methods' run on two workers at once."""

import math

import numpy as np
import pytest

from simparity.core.rotations import quat_wxyz_from_rotvec, quat_wxyz_to_matrix
from simparity.core.model.scenes.contact import Material, Plane, Shape
from tests.core.contact.test_bodies import (
    DIP_TIME_TOL, ENERGY_RTOL, EXACT_RTOL, FLOOR, G, INSIDE_TOL, REST_TOL, ROUNDOFF, SEED, SLIDE_TOL, STOP_TOL,
    TUMBLING_ENERGY_RTOL, _ball, _box_inertia, _corner_heights, _impact_times, _run, _scene)


# --- backup: bounces ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dt", [pytest.param(0.001, marks=[pytest.mark.slow, pytest.mark.sweep]),
                                pytest.param(0.01, marks=pytest.mark.slow), 0.1])
def test_backup_bounces_follow_the_closed_form(dt):
    """Particles and spheres dropped from 1 m (k = 0.8 and 0.5): 10 impact times and apex heights h k^2n. Backing up
    time is exact at any step: 0.1 and 0.01 s (several impacts in a step, one) are the default run's, 0.001 s (3,700
    steps, ~9 s) the sweep's."""
    height, radius, duration = 1.0, 0.1, 3.7  # t_10 = 3.58 s at k = 0.8
    restitutions = (0.8, 0.5, 0.8, 0.5)
    bodies = [_ball((0, 0, height)), _ball((0, 0, height)), _ball((0.5, 0, height + radius)),
              _ball((0.5, 0, height + radius))]
    shapes = [Shape("point"), Shape("point"), Shape("sphere", radius=radius), Shape("sphere", radius=radius)]
    scene = _scene(bodies, shapes, [[Material(k)] for k in restitutions], dt=dt, duration=duration)
    trajectory, simulation = _run(scene, "backup")
    for b, k in enumerate(restitutions):
        impacts = simulation.events.of(b)[:10]
        expected = _impact_times(height, k, 10)
        np.testing.assert_allclose(impacts[:, 0], expected, rtol=EXACT_RTOL)
        apex = impacts[:, 2] ** 2 / (2.0 * G)  # rebound speed -> height reached
        np.testing.assert_allclose(apex, height * k ** (2 * np.arange(1, 11)), rtol=EXACT_RTOL)
        np.testing.assert_allclose(impacts[:, 2], -k * impacts[:, 1], rtol=EXACT_RTOL)
        # between impacts every sample lies on the right parabola: z + v^2 / 2g = h k^2n
        z = trajectory.position_world[:, b, 2] - (radius if b >= 2 else 0.0)
        assert z.min() >= 0.0
        flight = z + trajectory.velocity_world[:, b, 2] ** 2 / (2.0 * G)
        done = np.searchsorted(_impact_times(height, k, 60), trajectory.times, side="right")
        early = done <= 10
        np.testing.assert_allclose(flight[early], height * k ** (2 * done[early]), rtol=EXACT_RTOL)
    np.testing.assert_allclose(trajectory.angular_velocity_world, 0.0, atol=0.0)


@pytest.mark.slow
def test_backup_ends_the_bounces_at_rest_on_the_plane():
    """Past the pile-up of bounces the ball rests: one "rest" event, then exactly on the plane, no motion."""
    radius = 0.1
    scene = _scene([_ball((0, 0, 1.0 + radius), velocity=(0.3, 0, 0))], [Shape("sphere", radius=radius)],
                   [[Material(0.5, 0.4, 0.3)]], dt=0.01, duration=3.0)
    trajectory, simulation = _run(scene, "backup")
    assert simulation.events.kind.count("rest") == 1
    rest_time = simulation.events.of(0, "rest")[0, 0]
    after = trajectory.times > rest_time + 0.5  # long after: the friction has stopped it too
    np.testing.assert_allclose(trajectory.position_world[after, 0, 2], radius, rtol=0, atol=REST_TOL)
    np.testing.assert_array_equal(trajectory.velocity_world[after], 0.0)


def test_backup_never_leaves_a_fast_particle_inside_the_plane():
    """50 m/s into the floor at dt = 0.1: the impact is found inside the step and the particle bounces there."""
    start, velocity, k = 1.0, np.array([3.0, 0.0, -50.0]), 0.5
    scene = _scene([_ball((0, 0, start), velocity=velocity)], [Shape("point")], [[Material(k)]], dt=0.1,
                   duration=1.0)
    trajectory, simulation = _run(scene, "backup")
    assert trajectory.position_world[:, 0, 2].min() >= 0.0
    arrival = math.sqrt(50.0**2 + 2.0 * G * start)
    first = simulation.events.of(0)[0]
    np.testing.assert_allclose(first, [2.0 * start / (50.0 + arrival), -arrival, k * arrival], rtol=EXACT_RTOL)


def test_backup_catches_a_grazing_contact_within_one_step():
    """Thrown up to 1e-7 m beyond a ceiling: in and out within one 0.1 s step, the contact is still found."""
    ceiling = Plane((0.0, 0.0, -1.0), 2.0, "ceiling")  # z = 2, free side below
    gap, overshoot = 0.1, 1e-7
    up = math.sqrt(2.0 * G * (gap + overshoot))
    scene = _scene([_ball((0, 0, 2.0 - gap), velocity=(0, 0, up))], [Shape("point")], [[Material(1.0)]],
                   planes=(ceiling,), dt=0.1, duration=0.5)
    trajectory, simulation = _run(scene, "backup")
    speed = math.sqrt(2.0 * G * overshoot)
    hit = simulation.events.of(0)
    assert len(hit) == 1
    np.testing.assert_allclose(hit[0], [2.0 * gap / (up + speed), -speed, speed], rtol=EXACT_RTOL)
    assert trajectory.position_world[:, 0, 2].max() <= 2.0
    assert trajectory.velocity_world[-1, 0, 2] < -up  # turned back early: faster down than a free flight


def test_backup_catches_a_corner_dipping_in_and_out_within_one_step():
    """A spinning box (no gravity) whose corner sweeps 1.8 mm through the floor between two samples bounces."""
    half, omega, dt = (0.2, 0.15, 0.1), 6.0, 0.1
    reach = math.hypot(half[1], half[2])  # corner distance from the x axis
    lowest = math.atan2(half[1], half[2])  # rotation about x putting corner (., -b, -c) straight down
    height = 0.99 * reach
    quat = quat_wxyz_from_rotvec(np.array([lowest - 0.3, 0.0, 0.0]))  # 0.05 s before the lowest point
    box = _ball((0, 0, height), mass=2.0, inertia=_box_inertia(2.0, half), quat=quat, omega=(omega, 0, 0))
    scene = _scene([box], [Shape("box", half_extents_body=np.array(half))], [[Material(0.5)]], dt=dt,
                   duration=0.4, gravity=None)
    corners = _corner_heights(_run(scene, "act_after")[0], half)
    assert corners[0, 1, 0].min() > 0.0  # at the samples the corner is above the floor: nothing to see after
    trajectory, simulation = _run(scene, "backup")
    hit = simulation.events.of(0)
    assert len(hit) >= 1
    assert hit[0, 0] == pytest.approx((0.3 - math.acos(0.99)) / omega, abs=DIP_TIME_TOL)
    assert trajectory.velocity_world[-1, 0, 2] > 0.0  # pushed up by the floor
    assert _corner_heights(trajectory, half).min() >= -INSIDE_TOL


# --- backup: resting and sliding ------------------------------------------------------------------------------


@pytest.mark.parametrize("dt", [0.01, 0.05])
def test_backup_block_sliding_on_the_floor_stops_at_v2_over_2_mu_g(dt):
    """A point and a box lying flat, 2 m/s, mu_k = 0.3: they stop at v^2 / (2 mu_k g), flat on the floor."""
    speed, mu_k, half = 2.0, 0.3, (0.2, 0.15, 0.1)
    bodies = [_ball((0, 0, 0), velocity=(speed, 0, 0)),
              _ball((0, 1, half[2]), velocity=(speed, 0, 0), mass=2.0, inertia=_box_inertia(2.0, half))]
    shapes = [Shape("point"), Shape("box", half_extents_body=np.array(half))]
    scene = _scene(bodies, shapes, [[Material(0.5, 0.5, mu_k)]] * 2, dt=dt, duration=1.0)
    trajectory, _ = _run(scene, "backup")
    np.testing.assert_allclose(trajectory.position_world[-1, :, 0], speed**2 / (2.0 * mu_k * G), rtol=0,
                               atol=STOP_TOL)
    np.testing.assert_allclose(trajectory.position_world[:, :, 2], [[0.0, half[2]]] * len(trajectory.times),
                               rtol=0, atol=REST_TOL)
    np.testing.assert_array_equal(trajectory.velocity_world[-1], 0.0)
    np.testing.assert_array_equal(trajectory.angular_velocity_world, 0.0)


def _incline_scene(angle, mu_s, mu_k, dt, duration):
    normal = np.array([-math.sin(angle), 0.0, math.cos(angle)])  # z = x tan(angle)
    half = (0.2, 0.15, 0.1)
    start = np.array([0.3, 0.0, 0.3 * math.tan(angle)])
    tilt = quat_wxyz_from_rotvec(np.array([0.0, -angle, 0.0]))  # body z along the normal
    bodies = [_ball(start), _ball(start + half[2] * normal, mass=2.0, inertia=_box_inertia(2.0, half), quat=tilt)]
    shapes = [Shape("point"), Shape("box", half_extents_body=np.array(half))]
    scene = _scene(bodies, shapes, [[Material(0.5, mu_s, mu_k)]] * 2, planes=(Plane(normal, 0.0, "incline"),),
                   dt=dt, duration=duration)
    return scene, start + np.array([[0.0, 0.0, 0.0], half[2] * normal])


@pytest.mark.slow
def test_backup_block_below_the_friction_angle_stays_put():
    """tan 20 deg = 0.364 < mu_s = 0.5: a point and a box on the incline do not move."""
    scene, start = _incline_scene(math.radians(20.0), 0.5, 0.4, 0.01, 2.0)
    trajectory, _ = _run(scene, "backup")
    np.testing.assert_allclose(trajectory.position_world, np.broadcast_to(start, trajectory.position_world.shape),
                               rtol=0, atol=SLIDE_TOL)


@pytest.mark.parametrize("dt", [0.01, 0.05])
def test_backup_block_above_the_friction_angle_slides_by_the_closed_form(dt):
    """tan 20 deg > mu_s = 0.3: x(t) = x0 + g (sin a - mu_k cos a) t^2 / 2 down the slope, exactly."""
    angle, mu_k = math.radians(20.0), 0.2
    scene, start = _incline_scene(angle, 0.3, mu_k, dt, 1.0)
    trajectory, _ = _run(scene, "backup")
    down = np.array([-math.cos(angle), 0.0, -math.sin(angle)])
    along = 0.5 * G * (math.sin(angle) - mu_k * math.cos(angle)) * trajectory.times**2
    expected = start[None, :, :] + along[:, None, None] * down
    np.testing.assert_allclose(trajectory.position_world, expected, rtol=0, atol=SLIDE_TOL)


@pytest.mark.slow
def test_backup_resting_bodies_neither_sink_nor_jitter():
    """A sphere, a point and a box placed on the floor: 1000 steps later not a picometre has moved."""
    half = (0.2, 0.15, 0.1)
    bodies = [_ball((0, 0, 0.1)), _ball((1, 0, 0)), _ball((2, 0, half[2]), mass=2.0, inertia=_box_inertia(2.0, half))]
    shapes = [Shape("sphere", radius=0.1), Shape("point"), Shape("box", half_extents_body=np.array(half))]
    scene = _scene(bodies, shapes, [[Material(0.8, 0.5, 0.3)]] * 3, dt=0.01, duration=10.0)
    trajectory, _ = _run(scene, "backup")
    drift = trajectory.position_world - trajectory.position_world[0]
    assert np.abs(drift).max() < REST_TOL


# --- backup: bodies that turn ---------------------------------------------------------------------------------


@pytest.mark.slow
def test_backup_box_dropped_flat_bounces_like_a_particle():
    """A box landing on a face: the particle's impact times and apexes, offset by its half height; no spin."""
    half, k, height = (0.2, 0.15, 0.1), 0.8, 1.0
    box = _ball((0, 0, height + half[2]), mass=2.0, inertia=_box_inertia(2.0, half))
    scene = _scene([box], [Shape("box", half_extents_body=np.array(half))], [[Material(k)]], dt=0.01,
                   duration=3.7)
    trajectory, simulation = _run(scene, "backup")
    impacts = simulation.events.of(0)[:10]
    np.testing.assert_allclose(impacts[:, 0], _impact_times(height, k, 10), rtol=EXACT_RTOL)
    np.testing.assert_allclose(impacts[:, 2] ** 2 / (2 * G), height * k ** (2 * np.arange(1, 11)), rtol=EXACT_RTOL)
    np.testing.assert_array_equal(trajectory.angular_velocity_world, 0.0)


def test_backup_box_dropped_on_an_edge_starts_to_spin_by_the_hand_impulse():
    """Tilted 0.3 rad about x, the box lands on an edge; j = (1 + k) v / (1/m + r_y^2 / I_xx) at the edge."""
    half, mass, k, theta, z0 = (0.2, 0.15, 0.1), 2.0, 0.5, 0.3, 1.0
    a, b, c = half
    inertia_xx = mass * (b * b + c * c) / 3.0
    box = _ball((0, 0, z0), mass=mass, inertia=_box_inertia(mass, half), quat=(math.cos(theta / 2),
                                                                              math.sin(theta / 2), 0, 0))
    scene = _scene([box], [Shape("box", half_extents_body=np.array(half))], [[Material(k)]], dt=0.01, duration=0.6)
    trajectory, simulation = _run(scene, "backup")
    r_y, r_z = -b * math.cos(theta) + c * math.sin(theta), -(b * math.sin(theta) + c * math.cos(theta))
    drop = z0 + r_z
    t1, v = math.sqrt(2.0 * drop / G), math.sqrt(2.0 * G * drop)
    j = (1.0 + k) * v / (1.0 / mass + r_y**2 / inertia_xx)
    v_after, omega_after = -v + j / mass, r_y * j / inertia_xx
    energy_before = 0.5 * mass * v**2
    energy_after = 0.5 * mass * v_after**2 + 0.5 * inertia_xx * omega_after**2
    assert omega_after != 0.0 and energy_after < energy_before
    hits = simulation.events.of(0)
    np.testing.assert_allclose(hits[0], [t1, -v, k * v], rtol=EXACT_RTOL)
    sample = int(np.searchsorted(trajectory.times, t1))
    assert trajectory.times[sample] < hits[1, 0]  # a sample of the first rebound
    np.testing.assert_allclose(trajectory.angular_velocity_world[sample, 0], [omega_after, 0.0, 0.0],
                               rtol=0, atol=ROUNDOFF)
    np.testing.assert_allclose(trajectory.velocity_world[sample, 0, 2], v_after - G * (trajectory.times[sample] - t1),
                               rtol=0, atol=ROUNDOFF)


@pytest.mark.slow
def test_backup_point_masses_land_flat_like_a_particle_and_tilted_with_spin():
    """Four 0.25 kg points in a square: flat, they bounce like one particle; tilted, they pick up spin."""
    points = np.array([[0.1, 0.1, 0.0], [0.1, -0.1, 0.0], [-0.1, 0.1, 0.0], [-0.1, -0.1, 0.0]])
    inertia = np.diag([0.01, 0.01, 0.02])  # sum m (r^2 1 - r r^T) of the four points
    tilt = quat_wxyz_from_rotvec(np.array([0.2, 0.1, 0.0]))
    bodies = [_ball((0, 0, 1.0), inertia=inertia), _ball((1, 0, 1.0), inertia=inertia, quat=tilt)]
    shape = Shape("points", points_body=points)
    k = 0.8
    scene = _scene(bodies, [shape, shape], [[Material(k)]] * 2, dt=0.01, duration=1.6)
    trajectory, simulation = _run(scene, "backup")
    flat = simulation.events.of(0)[:2]
    np.testing.assert_allclose(flat[:, 0], _impact_times(1.0, k, 2), rtol=EXACT_RTOL)
    np.testing.assert_array_equal(trajectory.angular_velocity_world[:, 0], 0.0)
    first = simulation.events.of(1)[0, 0]
    after = trajectory.times > first
    assert np.abs(trajectory.angular_velocity_world[after, 1]).max() > 0.1
    energy = (0.5 * np.sum(trajectory.velocity_world[:, 1] ** 2, axis=1)
              + 0.5 * np.einsum("ti,tij,tj->t", trajectory.angular_velocity_world[:, 1],
                                _world_inertia(trajectory.quat_wxyz[:, 1], inertia),
                                trajectory.angular_velocity_world[:, 1])
              + G * trajectory.position_world[:, 1, 2])
    assert energy[after].max() < energy[0]


def _world_inertia(quat, inertia_body):
    rotation = quat_wxyz_to_matrix(quat)
    return rotation @ inertia_body @ np.swapaxes(rotation, -1, -2)


@pytest.mark.slow
def test_backup_tumbling_bodies_never_gain_energy_nor_go_inside():
    """Seeded random boxes thrown spinning at a floor and an incline: energy never above the start, no corner
    inside a plane at any sample, all at rest in the end."""
    rng = np.random.default_rng(SEED)
    planes = (FLOOR, Plane((-0.5, 0.0, 1.0), -0.5, "incline"))
    bodies, shapes, materials, halves = [], [], [], []
    for _ in range(8):
        half = rng.uniform(0.05, 0.3, 3)
        mass = rng.uniform(0.5, 3.0)
        quat = rng.normal(size=4)
        bodies.append(_ball((rng.uniform(-1, 0.5), rng.uniform(-1, 1), rng.uniform(1.3, 2.5)), rng.normal(size=3),
                            mass=mass, inertia=_box_inertia(mass, half), quat=quat / np.linalg.norm(quat),
                            omega=3.0 * rng.normal(size=3)))
        shapes.append(Shape("box", half_extents_body=half))
        materials.append([Material(rng.uniform(0.0, 0.9), 0.6, 0.4), Material(0.5, 0.3, 0.3)])
        halves.append(half)
    scene = _scene(bodies, shapes, materials, planes=planes, dt=0.01, duration=3.0)
    trajectory, _ = _run(scene, "backup")
    masses = np.array([b.mass for b in bodies])
    inertia = np.stack([b.inertia_body for b in bodies])
    rotation = quat_wxyz_to_matrix(trajectory.quat_wxyz)
    world = rotation @ inertia @ np.swapaxes(rotation, -1, -2)
    omega = trajectory.angular_velocity_world
    energy = (0.5 * masses * np.sum(trajectory.velocity_world**2, axis=-1)
              + 0.5 * np.einsum("tbi,tbij,tbj->tb", omega, world, omega)
              + masses * G * trajectory.position_world[..., 2])
    assert np.all(energy <= energy[0] * (1.0 + TUMBLING_ENERGY_RTOL))
    for b, half in enumerate(halves):
        corners = Shape("box", half_extents_body=half).vertices_body()
        points = np.einsum("tij,vj->tvi", rotation[:, b], corners) + trajectory.position_world[:, b, None, :]
        for plane in planes:
            assert (points @ plane.normal_world + plane.offset).min() >= -INSIDE_TOL
    np.testing.assert_array_equal(trajectory.velocity_world[-1], 0.0)


@pytest.mark.slow
def test_backup_ball_between_a_floor_and_an_incline():
    """Dropped onto a 45 deg incline: it bounces down onto the floor, never inside either, and rests there."""
    radius, mass = 0.1, 2.0
    incline = Plane((-1.0, 0.0, 1.0), 0.0, "incline")
    ball = _ball((0.3, 0, 1.0), mass=mass, inertia=np.eye(3) * 0.4 * mass * radius**2)
    scene = _scene([ball], [Shape("sphere", radius=radius)], [[Material(0.5, 0.3, 0.2)] * 2],
                   planes=(FLOOR, incline), dt=0.01, duration=4.0)
    trajectory, simulation = _run(scene, "backup")
    x = trajectory.position_world[:, 0]
    for plane in (FLOOR, incline):
        assert (x @ plane.normal_world + plane.offset - radius).min() >= -INSIDE_TOL
    assert {0, 1} <= set(simulation.events.plane)
    energy = (0.5 * mass * np.sum(trajectory.velocity_world[:, 0] ** 2, axis=1)
              + 0.2 * mass * radius**2 * np.sum(trajectory.angular_velocity_world[:, 0] ** 2, axis=1)
              + mass * G * x[:, 2])
    assert np.all(np.diff(energy) <= ENERGY_RTOL * energy[0])
    assert x[-1, 2] == pytest.approx(radius, abs=REST_TOL)
    np.testing.assert_array_equal(trajectory.velocity_world[-1], 0.0)


@pytest.mark.slow
def test_backup_ball_wedged_in_a_valley_is_put_at_rest():
    """Between two 45 deg slopes a ball resting on one slides into the other: the step's rest cap stops it."""
    planes = (Plane((-1.0, 0.0, 1.0), 0.0, "left"), Plane((1.0, 0.0, 1.0), 0.0, "right"))
    scene = _scene([_ball((0.05, 0, 1.0))], [Shape("point")], [[Material(0.5)] * 2], planes=planes, dt=0.01,
                   duration=3.0)
    trajectory, simulation = _run(scene, "backup")
    assert "cap" in simulation.events.kind
    np.testing.assert_allclose(trajectory.position_world[-1, 0], 0.0, atol=INSIDE_TOL)
