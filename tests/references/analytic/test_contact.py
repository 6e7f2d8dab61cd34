"""The analytic contact reference: bounces, rest, slides and impacts against hand-computed values.

Every expected value below is computed in the test from the textbook formulas (free fall
t = sqrt(2h/g), rebound k^n v1, stopping distance v^2 / (2 mu_k g), slide acceleration
g (sin a - mu_k cos a), impulses j_n = (1 + k) m |v_n|), never from the module under test.
"""

import math
import time

import numpy as np
import pytest

from simparity.core.model.scenes.bodies import AppliedForce, Forces, RigidBody
from simparity.core.model.scenes.contact import Contact, Material, Plane, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.references.analytic.engine import AnalyticEngine
from simparity.references.analytic.contact import contact_events

G = 9.81
GRAVITY = np.array([0.0, 0.0, -G])

EXACT_TOL = 1e-12
"""[m, m/s, s] Two float64 evaluations of the same closed form over a few seconds and metres
(event times accumulate rounding over tens of impacts: ~1e-15 each)."""

SEQUENCE_RTOL = 1e-13
"""Relative: the closed form's bounce speeds against k^n v1 written by hand, a product of up to ~10 factors,
each rounded at ~1e-16."""

PENETRATION_TOL = 1e-12
"""[m] The support distance may be negative by rounding only (the brief's bound)."""

ENERGY_RTOL = 1e-12
"""Energy may 'increase' between samples by float64 rounding of 1/2 m v^2 - m g.x only."""

BIG_RUN_SECONDS = 10.0
"""A generous bound for 10^6 samples (measured ~0.6 s): catches a Python loop per sample (~minutes)."""

ANGLE = math.radians(20.0)
INCLINE_NORMAL = np.array([math.sin(ANGLE), 0.0, math.cos(ANGLE)])  # (0, 0, 1) turned 20 deg about +y
DOWNHILL = np.array([math.cos(ANGLE), 0.0, -math.sin(ANGLE)])  # unit, along the plane, gravity's side
ACROSS = np.array([0.0, 1.0, 0.0])
INCLINE_D = -0.5  # the plane passes through 0.5 N, not through the origin


def rot_x(angle):
    """(quat_wxyz, matrix) of a rotation by ``angle`` about +x, written out by hand."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([math.cos(angle / 2), math.sin(angle / 2), 0, 0]), np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([math.cos(angle / 2), 0, math.sin(angle / 2), 0]), np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def body(position, velocity=(0, 0, 0), quat=(1, 0, 0, 0), omega=(0, 0, 0), name="b", mass=1.0):
    return RigidBody(name, mass, np.eye(3) * 0.01, np.array(position, float), np.array(quat, float),
                     np.array(velocity, float), np.array(omega, float))


def scene_of(bodies, shapes, materials, planes=(Plane((0, 0, 1), 0.0, "floor"),), duration=3.0, dt=1e-3,
             rest_speed=1e-3, forces=None):
    forces = forces or Forces(gravity_world=GRAVITY)
    contact = Contact(tuple(planes), tuple(shapes), tuple(tuple(row) for row in materials), rest_speed=rest_speed)
    return DynamicsScene("contact", "-", "analytic", tuple(bodies), forces, duration, (dt,), contact=contact)


def run(scene, dt=None):
    dt = dt or scene.dts[0]
    engine = AnalyticEngine()
    support = engine.supports_dynamics(scene, "exact")
    assert support.ok, support.reason
    return engine.build_dynamics(scene, "exact", dt).run(scene.n_steps(dt))


def reason(scene):
    support = AnalyticEngine().supports_dynamics(scene, "exact")
    assert not support.ok
    return support.reason


def box_vertices(half, matrix):
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return (signs * half) @ matrix.T


def bounce_by_hand(h, k, g_n, rest_speed):
    """Impact times, speeds before each impact, and the rest time of a drop from height h (normal axis)."""
    v1 = math.sqrt(2 * g_n * h)
    times, speeds = [math.sqrt(2 * h / g_n)], [v1]
    while k * speeds[-1] >= rest_speed:  # the rebound k v is still a bounce
        times.append(times[-1] + 2 * k * speeds[-1] / g_n)
        speeds.append(k * speeds[-1])
    return np.array(times), np.array(speeds)


def height_by_hand(t, h, k, g_n, times, speeds):
    """Normal distance (T,) and normal velocity (T,) of the bounce at times t."""
    z, v = np.empty_like(t), np.empty_like(t)
    first = t < times[0]
    z[first], v[first] = h - 0.5 * g_n * t[first] ** 2, -g_n * t[first]
    for n in range(len(times)):
        end = times[n + 1] if n + 1 < len(times) else np.inf
        inside = (t >= times[n]) & (t < end)
        up = k * speeds[n] if n + 1 < len(times) else 0.0
        tau = t[inside] - times[n]
        z[inside] = up * tau - 0.5 * g_n * tau ** 2 if up else 0.0
        v[inside] = up - g_n * tau if up else 0.0
    return z, v


# ------------------------------------------------------------------------------------------- bounces


def test_ball_dropped_bounces_with_the_hand_sequence_and_rests_by_the_rule():
    """A sphere (r = 0.1) dropped from h = 1 m above the floor, k = 0.8, rest below 0.5 m/s."""
    h, k, r, rest = 1.0, 0.8, 0.1, 0.5
    scene = scene_of([body([0.3, -0.2, h + r])], [Shape("sphere", radius=r)], [[Material(k)]], duration=4.0,
                     dt=1e-3, rest_speed=rest)
    v1 = math.sqrt(2 * G * h)
    # By hand: rebounds k^n v1; the first below 0.5 m/s is k^10 v1 = 0.4756 (k^9 v1 = 0.5945).
    n_rest = math.ceil(math.log(rest / v1) / math.log(k))
    assert n_rest == 10
    impact_times = [math.sqrt(2 * h / G) + sum(2 * k ** i * v1 / G for i in range(1, n)) for n in range(1, n_rest + 1)]
    t_rest = impact_times[-1]
    t_inf = math.sqrt(2 * h / G) + 2 * k * v1 / (G * (1 - k))
    assert t_rest < t_inf

    events = contact_events(scene, 0, scene.duration)
    assert events.kinds == ("impact",) * n_rest + ("rest",)
    np.testing.assert_allclose(events.times[:n_rest], impact_times, rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(events.normal_velocity_before[:n_rest], [-k ** n * v1 for n in range(n_rest)],
                               rtol=SEQUENCE_RTOL)
    # Apex heights h k^(2n) follow from the rebound speeds: v^2 / (2 g).
    after = events.normal_velocity_after[:n_rest]
    np.testing.assert_allclose(after[:-1] ** 2 / (2 * G), [h * k ** (2 * n) for n in range(1, n_rest)], rtol=EXACT_TOL)
    assert after[-1] == 0.0
    np.testing.assert_allclose(events.position_world[:, 2], r, atol=EXACT_TOL)

    traj = run(scene)
    detail = AnalyticEngine().build_dynamics(scene, "exact", 1e-3).detail
    assert "k=0.8" in detail and "frictionless" in detail and "rest below 0.5 m/s" in detail
    times, speeds = bounce_by_hand(h, k, G, rest)
    z, vz = height_by_hand(traj.times, h, k, G, times, speeds)
    np.testing.assert_allclose(traj.position_world[:, 0, 2], r + z, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world[:, 0, 2], vz, atol=EXACT_TOL)
    np.testing.assert_array_equal(traj.position_world[:, 0, :2], np.broadcast_to([0.3, -0.2], (len(traj.times), 2)))
    resting = traj.times > t_rest
    assert resting.sum() > 100 and np.all(traj.velocity_world[resting] == 0)
    np.testing.assert_allclose(traj.position_world[resting, 0, 2], r, atol=EXACT_TOL)
    np.testing.assert_array_equal(traj.quat_wxyz[:, 0], np.broadcast_to([1, 0, 0, 0], (len(traj.times), 4)))
    assert np.all(traj.angular_velocity_world == 0)


def test_box_dropped_flat_lands_on_its_face():
    """A box turned 90 deg about x (body y vertical: half height 0.3) dropped 1 m: offset 0.3, k = 0.5."""
    half = np.array([0.2, 0.3, 0.1])
    quat, matrix = rot_x(math.pi / 2)
    h, k = 1.0, 0.5
    scene = scene_of([body([0, 0, h + 0.3], quat=quat)], [Shape("box", half_extents_body=half)], [[Material(k)]],
                     duration=2.0, rest_speed=0.2)
    events = contact_events(scene, 0, scene.duration)
    v1 = math.sqrt(2 * G * h)
    assert events.kinds[:2] == ("impact", "impact")
    np.testing.assert_allclose(events.times[:2], [math.sqrt(2 * h / G), math.sqrt(2 * h / G) + 2 * k * v1 / G],
                               atol=EXACT_TOL)
    np.testing.assert_allclose(events.position_world[:, 2], 0.3, atol=EXACT_TOL)
    traj = run(scene)
    lowest = traj.position_world[:, 0, 2] + box_vertices(half, matrix)[:, 2].min()
    assert lowest.min() >= -PENETRATION_TOL and lowest.min() < 1e-9  # it does land
    np.testing.assert_array_equal(traj.quat_wxyz[:, 0], np.broadcast_to(quat, (len(traj.times), 4)))


def test_edge_landing_is_refused_but_a_flight_that_never_lands_is_not():
    quat, _ = rot_x(math.pi / 4)
    shape, material = Shape("box", half_extents_body=np.array([0.2, 0.3, 0.1])), [[Material(0.5)]]
    lands = scene_of([body([0, 0, 1.0], quat=quat)], [shape], material, duration=1.0)
    assert "edge" in reason(lands) and "turn" in reason(lands)
    flies = scene_of([body([0, 0, 10.0], quat=quat)], [shape], material, duration=1.0)  # falls 4.9 m of 9.7
    traj = run(flies)
    t = traj.times
    np.testing.assert_allclose(traj.position_world[:, 0, 2], 10.0 - 0.5 * G * t ** 2, atol=EXACT_TOL)


# ------------------------------------------------------------------------------------------- sliding


def test_block_sliding_on_the_floor_stops_after_v2_over_2_mu_g():
    """v = 2 m/s along +x, mu_k = 0.4: stops at t = v/(mu_k g) after v^2/(2 mu_k g)."""
    v, mu_s, mu_k, half = 2.0, 0.5, 0.4, np.array([0.2, 0.15, 0.1])
    scene = scene_of([body([1.0, 2.0, 0.1], velocity=[v, 0, 0])], [Shape("box", half_extents_body=half)],
                     [[Material(0.0, mu_s, mu_k)]], duration=1.0)
    t_stop, distance = v / (mu_k * G), v * v / (2 * mu_k * G)
    events = contact_events(scene, 0, scene.duration)
    assert events.kinds == ("rest", "stop")
    assert events.times[1] == pytest.approx(t_stop, abs=EXACT_TOL)
    np.testing.assert_allclose(events.position_world[1], [1.0 + distance, 2.0, 0.1], atol=EXACT_TOL)
    traj = run(scene)
    t = traj.times
    sliding = t < t_stop
    ts = t[sliding]
    np.testing.assert_allclose(traj.position_world[sliding, 0, 0], 1.0 + v * ts - 0.5 * mu_k * G * ts ** 2,
                               atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world[sliding, 0, 0], v - mu_k * G * ts, atol=EXACT_TOL)
    stopped = traj.position_world[~sliding, 0]
    np.testing.assert_allclose(stopped, np.broadcast_to([1.0 + distance, 2.0, 0.1], stopped.shape), atol=EXACT_TOL)
    assert np.all(traj.velocity_world[~sliding] == 0)


def incline_block(mu_s, mu_k, along=0.3, velocity=(0, 0, 0), half=(0.2, 0.1, 0.05), duration=1.5):
    """A box whose bottom face lies on the 20 deg incline (turned 20 deg about y as the plane), at rest."""
    quat, _ = rot_y(ANGLE)
    x0 = (-INCLINE_D + half[2]) * INCLINE_NORMAL + along * DOWNHILL + 0.7 * ACROSS
    plane = Plane(INCLINE_NORMAL * 2.0, INCLINE_D * 2.0, "incline")  # lecture coefficients, normalised by Plane
    return scene_of([body(x0, velocity=velocity, quat=quat)], [Shape("box", half_extents_body=np.array(half))],
                    [[Material(0.0, mu_s, mu_k)]], planes=[plane], duration=duration), x0


def test_block_on_incline_below_the_friction_angle_stays():
    scene, x0 = incline_block(mu_s=0.5, mu_k=0.3)  # tan 20 deg = 0.364 < 0.5
    traj = run(scene)
    np.testing.assert_allclose(traj.position_world[:, 0], np.broadcast_to(x0, (len(traj.times), 3)), atol=EXACT_TOL)
    assert np.all(traj.velocity_world == 0)
    assert contact_events(scene, 0, scene.duration).kinds == ("rest",)


def test_block_on_incline_above_the_friction_angle_slides_with_g_sin_minus_mu_cos():
    mu_s, mu_k = 0.3, 0.2  # tan 20 deg = 0.364 > 0.3
    scene, x0 = incline_block(mu_s, mu_k)
    traj = run(scene)
    t = traj.times[:, None]
    a = G * (math.sin(ANGLE) - mu_k * math.cos(ANGLE))
    np.testing.assert_allclose(traj.position_world[:, 0], x0 + 0.5 * a * t ** 2 * DOWNHILL, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world[:, 0], a * t * DOWNHILL, atol=EXACT_TOL)
    assert contact_events(scene, 0, scene.duration).kinds == ("rest", "slide")


def test_block_pushed_up_the_incline_stops_then_slides_back():
    """Up the slope at 1 m/s: decelerates with g (sin a + mu_k cos a), stops, then comes down with
    g (sin a - mu_k cos a) (the incline is steeper than the friction angle)."""
    mu_s, mu_k, v = 0.3, 0.2, 1.0
    scene, x0 = incline_block(mu_s, mu_k, velocity=-v * DOWNHILL)
    up, down = G * (math.sin(ANGLE) + mu_k * math.cos(ANGLE)), G * (math.sin(ANGLE) - mu_k * math.cos(ANGLE))
    t_stop = v / up
    top = x0 - v * v / (2 * up) * DOWNHILL
    events = contact_events(scene, 0, scene.duration)
    assert events.kinds == ("rest", "stop", "slide")
    assert events.times[1] == pytest.approx(t_stop, abs=EXACT_TOL)
    traj = run(scene)
    t = traj.times[:, None]
    expected = np.where(t < t_stop, x0 - (v * t - 0.5 * up * t ** 2) * DOWNHILL,
                        top + 0.5 * down * (t - t_stop) ** 2 * DOWNHILL)
    np.testing.assert_allclose(traj.position_world[:, 0], expected, atol=EXACT_TOL)


def test_tall_block_held_by_friction_on_the_incline_would_tip():
    """h = 1 m above a face 0.2 m long: friction's torque moves the pressure 1 x tan 20 = 0.36 m > 0.2 m."""
    scene, _ = incline_block(mu_s=0.5, mu_k=0.3, half=(0.2, 0.1, 1.0))
    assert "tip over" in reason(scene)


def test_ball_bouncing_on_the_incline_keeps_its_tangential_parabola():
    """Frictionless: the normal motion is a bounce under g cos a, the along-slope motion x0 + g sin a t^2 / 2
    throughout (impacts only reverse the normal velocity), also after it comes to rest and slides."""
    r, h, k, rest = 0.1, 0.8, 0.7, 0.3
    x0 = (-INCLINE_D + r + h) * INCLINE_NORMAL - 0.4 * DOWNHILL
    scene = scene_of([body(x0)], [Shape("sphere", radius=r)], [[Material(k)]],
                     planes=[Plane(INCLINE_NORMAL, INCLINE_D, "incline")], duration=3.0, rest_speed=rest)
    traj = run(scene)
    g_n, g_t = G * math.cos(ANGLE), G * math.sin(ANGLE)
    times, speeds = bounce_by_hand(h, k, g_n, rest)
    assert len(times) > 3
    events = contact_events(scene, 0, scene.duration)
    assert events.kinds == ("impact",) * len(times) + ("rest",)
    np.testing.assert_allclose(events.times[:-1], times, atol=EXACT_TOL)
    z, vz = height_by_hand(traj.times, h, k, g_n, times, speeds)
    t = traj.times
    position = traj.position_world[:, 0]
    np.testing.assert_allclose(position @ INCLINE_NORMAL + INCLINE_D - r, z, atol=EXACT_TOL)
    np.testing.assert_allclose(position @ DOWNHILL, x0 @ DOWNHILL + 0.5 * g_t * t ** 2, atol=EXACT_TOL)
    np.testing.assert_allclose(position @ ACROSS, 0.0, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world[:, 0] @ INCLINE_NORMAL, vz, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world[:, 0] @ DOWNHILL, g_t * t, atol=EXACT_TOL)


# ------------------------------------------------------------------------------------------- friction at impact


@pytest.mark.parametrize("mu_s, mu_k, sticks", [(0.5, 0.4, True), (0.3, 0.2, False)])
def test_oblique_impact_of_a_point_with_friction(mu_s, mu_k, sticks):
    """Point from 1 m with vx = 3 m/s, k = 0.5: j_n/m = 1.5 sqrt(2 g) = 6.644 m/s. Sticks when 3 <= mu_s j_n
    (0.5: 3.32), else vx -> 3 - mu_k j_n (0.2: 1.671)."""
    h, k, vx = 1.0, 0.5, 3.0
    scene = scene_of([body([0, 0, h], velocity=[vx, 0, 0])], [Shape("point")], [[Material(k, mu_s, mu_k)]],
                     duration=1.2, rest_speed=0.1)
    v1 = math.sqrt(2 * G * h)
    jn = (1 + k) * v1
    assert (vx <= mu_s * jn) == sticks
    vx_after = 0.0 if sticks else vx - mu_k * jn
    t1 = math.sqrt(2 * h / G)
    t2 = t1 + 2 * k * v1 / G
    traj = run(scene)
    t = traj.times
    between = (t > t1) & (t < t2)
    assert between.sum() > 100
    np.testing.assert_allclose(traj.velocity_world[between, 0, 0], vx_after, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.position_world[between, 0, 0], vx * t1 + vx_after * (t[between] - t1),
                               atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world[between, 0, 2], k * v1 - G * (t[between] - t1), atol=EXACT_TOL)
    np.testing.assert_allclose(traj.position_world[t < t1, 0, 0], vx * t[t < t1], atol=EXACT_TOL)
    events = contact_events(scene, 0, t2 + 1e-9)
    np.testing.assert_allclose(events.position_world[0], [vx * t1, 0, 0], atol=EXACT_TOL)


def test_no_gravity_ball_reflects_and_flies_on():
    """No gravity: a sphere at 1 m/s toward the floor hits after (1 - r) s and leaves at k m/s."""
    r, k = 0.1, 0.6
    scene = scene_of([body([0, 0, 1.0], velocity=[0.5, 0, -1.0])], [Shape("sphere", radius=r)], [[Material(k)]],
                     duration=2.0, forces=Forces())
    traj = run(scene)
    t, t1 = traj.times, 1.0 - r
    expected_z = np.where(t < t1, 1.0 - t, r + k * (t - t1))
    np.testing.assert_allclose(traj.position_world[:, 0, 2], expected_z, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.position_world[:, 0, 0], 0.5 * t, atol=EXACT_TOL)
    assert contact_events(scene, 0, 2.0).kinds == ("impact",)


# ------------------------------------------------------------------------------------------- planes


def test_a_far_wall_is_allowed_and_a_corner_is_not():
    floor, wall = Plane((0, 0, 1), 0.0, "floor"), Plane((-1, 0, 0), 5.0, "wall")  # wall at x = 5
    shapes, materials = [Shape("sphere", radius=0.1)], [[Material(0.5), Material(0.5)]]
    slow = scene_of([body([0, 0, 1.0], velocity=[1.0, 0, 0])], shapes, materials, planes=[floor, wall], duration=2.0)
    traj = run(slow)
    assert traj.position_world[:, 0, 0].max() == pytest.approx(2.0, abs=EXACT_TOL)  # never reaches x = 4.9
    fast = scene_of([body([0, 0, 1.0], velocity=[10.0, 0, 0])], shapes, materials, planes=[floor, wall],
                    duration=2.0)
    assert "more than one plane" in reason(fast)


# ------------------------------------------------------------------------------------------- n/a


@pytest.mark.slow
def test_unsupported_cases_name_their_reason():
    floor = [[Material(0.5)]]
    sphere = [Shape("sphere", radius=0.1)]
    spinning = scene_of([body([0, 0, 1.0], omega=[0, 0, 1.0])], sphere, floor)
    assert "angular velocity" in reason(spinning)
    dragged = scene_of([body([0, 0, 1.0])], sphere, floor,
                       forces=Forces(gravity_world=GRAVITY, linear_drag=np.array([0.1])))
    assert "drag with contact" in reason(dragged)
    pushed = scene_of([body([0, 0, 1.0])], sphere, floor, forces=Forces(
        gravity_world=GRAVITY, applied=(AppliedForce(0, np.array([1.0, 0, 0]), np.zeros(3)),)))
    assert "applied force" in reason(pushed)
    rolling = scene_of([body([0, 0, 1.0], velocity=[1.0, 0, 0])], sphere, [[Material(0.5, 0.3, 0.2)]])
    assert "sphere with friction" in reason(rolling) and "roll" in reason(rolling)
    inside = scene_of([body([0, 0, 0.05])], sphere, floor)
    assert "inside" in reason(inside)
    scene, _ = incline_block(0.3, 0.2, velocity=0.5 * ACROSS)  # slipping across the slope with friction
    assert "curved slide" in reason(scene)
    # rest_speed 0 and k close to 1: an accumulating sequence of ~10^6 impacts before t_inf ~ 900 s.
    zeno = scene_of([body([0, 0, 1.1])], sphere, [[Material(0.999)]], duration=1000.0, dt=1.0, rest_speed=0.0)
    assert "impacts" in reason(zeno)
    offset = scene_of([body([0, 0, 0.1])], [Shape("box", half_extents_body=np.array([0.1, 0.1, 0.1]),
                                                  center_body=np.array([0.3, 0, 0]))], floor)
    assert "tip over" in reason(offset)


def test_a_sphere_dropped_straight_with_friction_is_supported():
    """Friction is harmless when the contact point never slips: a vertical drop on a flat floor."""
    scene = scene_of([body([0, 0, 1.1])], [Shape("sphere", radius=0.1)], [[Material(0.5, 0.5, 0.4)]])
    traj = run(scene)
    assert np.all(traj.position_world[:, 0, :2] == 0)


# ------------------------------------------------------------------------------------------- invariants


def _invariant_scenes():
    quat, _ = rot_x(math.pi / 2)
    flat_box = Shape("box", half_extents_body=np.array([0.2, 0.3, 0.1]))
    yield "ball", scene_of([body([0, 0, 1.1], velocity=[0.7, 0.2, 0])], [Shape("sphere", radius=0.1)],
                           [[Material(0.8)]], duration=4.0, rest_speed=0.2)
    yield "box", scene_of([body([0, 0, 1.3], velocity=[2.0, -1.0, 0.5], quat=quat)], [flat_box],
                          [[Material(0.6, 0.4, 0.3)]], duration=3.0, rest_speed=0.3)
    yield "point", scene_of([body([0, 0, 1.0], velocity=[3.0, 0, 0])], [Shape("point")],
                            [[Material(0.5, 0.3, 0.2)]], duration=3.0, rest_speed=0.1)
    yield "slide-up", incline_block(0.3, 0.2, velocity=-1.0 * DOWNHILL)[0]
    yield "incline-ball", scene_of([body((0.5 + 0.1 + 0.8) * INCLINE_NORMAL)], [Shape("sphere", radius=0.1)],
                                   [[Material(0.7)]], planes=[Plane(INCLINE_NORMAL, INCLINE_D, "incline")],
                                   duration=3.0, rest_speed=0.3)


@pytest.mark.parametrize("name, scene", list(_invariant_scenes()), ids=[n for n, _ in _invariant_scenes()])
def test_samples_never_penetrate_and_energy_never_increases(name, scene):
    traj = run(scene)
    shape, plane = scene.contact.shapes[0], scene.contact.planes[0]
    b = scene.bodies[0]
    w, x, y, z = b.quat_wxyz
    matrix = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                       [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                       [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    if shape.kind == "box":
        low = (box_vertices(np.asarray(shape.half_extents_body), matrix) @ plane.normal_world).min()
    else:
        low = -shape.radius
    position, velocity = traj.position_world[:, 0], traj.velocity_world[:, 0]
    distance = position @ plane.normal_world + plane.offset + low
    assert distance.min() >= -PENETRATION_TOL
    assert distance.min() < 1e-9  # it does touch
    energy = b.mass * (0.5 * np.sum(velocity ** 2, axis=1) - position @ GRAVITY)
    scale = np.max(np.abs(energy)) + b.mass * G
    assert np.max(np.diff(energy)) <= ENERGY_RTOL * scale
    assert energy[-1] < energy[0] - 0.1  # and it does lose energy


@pytest.mark.slow
def test_a_million_samples_are_evaluated_at_once():
    h, k, r, rest = 1.0, 0.8, 0.1, 0.5
    scene = scene_of([body([0, 0, h + r])], [Shape("sphere", radius=r)], [[Material(k)]], duration=4.0,
                     dt=4e-6, rest_speed=rest)
    start = time.perf_counter()
    traj = run(scene)
    elapsed = time.perf_counter() - start
    assert len(traj.times) == 1_000_001 and elapsed < BIG_RUN_SECONDS
    times, speeds = bounce_by_hand(h, k, G, rest)
    pick = np.arange(0, len(traj.times), 997)
    z, _ = height_by_hand(traj.times[pick], h, k, G, times, speeds)
    np.testing.assert_allclose(traj.position_world[pick, 0, 2], r + z, atol=EXACT_TOL)


def test_ball_thrown_up_at_a_ceiling_bounces_once_and_falls_away():
    """Ceiling z = 2 (N = -z, gravity pulls away from it): thrown up at 7 m/s from z = 0.5 + r, the top of the
    sphere reaches it after t1 = (v - sqrt(v^2 - 2 g D)) / g, D = 1.5 - 2 r ... and leaves at k times its speed."""
    r, v, k = 0.1, 7.0, 0.5
    ceiling = Plane((0, 0, -1), 2.0, "ceiling")
    gap = 2.0 - (0.5 + r) - r  # from the sphere's top to the ceiling
    scene = scene_of([body([0, 0, 0.5 + r], velocity=[0, 0, v])], [Shape("sphere", radius=r)], [[Material(k)]],
                     planes=[ceiling], duration=1.0)
    speed = math.sqrt(v * v - 2 * G * gap)
    t1 = (v - speed) / G
    events = contact_events(scene, 0, 1.0)
    assert events.kinds == ("impact",)
    assert events.times[0] == pytest.approx(t1, abs=EXACT_TOL)
    traj = run(scene)
    t = traj.times
    after = t > t1
    np.testing.assert_allclose(traj.velocity_world[after, 0, 2], -k * speed - G * (t[after] - t1), atol=EXACT_TOL)
    np.testing.assert_allclose(traj.position_world[after, 0, 2], 2.0 - r - k * speed * (t[after] - t1)
                               - 0.5 * G * (t[after] - t1) ** 2, atol=EXACT_TOL)


def test_a_body_starting_on_the_floor_moving_in_is_an_impact_at_t0():
    """On the floor with v_n = -2 m/s, k = 0.5: an impact at t = 0 (sample 0 keeps the initial state), then
    a flight of 2 (k 2) / g; at rest with v_n = 0 it is resting contact from t = 0 instead."""
    k, v = 0.5, 2.0
    scene = scene_of([body([0, 0, 0.0], velocity=[0, 0, -v])], [Shape("point")], [[Material(k)]], duration=1.0)
    events = contact_events(scene, 0, 1.0)
    assert events.kinds[:2] == ("impact", "impact") and events.times[0] == 0.0
    assert events.times[1] == pytest.approx(2 * k * v / G, abs=EXACT_TOL)
    traj = run(scene)
    assert traj.velocity_world[0, 0, 2] == -v
    t = traj.times[1:20]
    np.testing.assert_allclose(traj.position_world[1:20, 0, 2], k * v * t - 0.5 * G * t ** 2, atol=EXACT_TOL)
    resting = scene_of([body([0, 0, 0.0])], [Shape("point")], [[Material(k)]], duration=1.0)
    assert contact_events(resting, 0, 1.0).kinds == ("rest",)
    assert np.all(run(resting).position_world == 0)


def test_points_body_lands_on_its_lowest_face_and_refuses_an_edge():
    """A 'points' body: four feet at z = -0.2 around the COM and a mast at +0.5 lands on its feet (offset 0.2);
    with two feet it would land on an edge."""
    feet = np.array([[0.1, 0.1, -0.2], [-0.1, 0.1, -0.2], [-0.1, -0.1, -0.2], [0.1, -0.1, -0.2], [0, 0, 0.5]])
    scene = scene_of([body([0, 0, 1.2])], [Shape("points", points_body=feet)], [[Material(0.0)]], duration=1.0)
    events = contact_events(scene, 0, 1.0)
    assert events.kinds == ("impact", "rest")
    assert events.times[0] == pytest.approx(math.sqrt(2 * 1.0 / G), abs=EXACT_TOL)
    np.testing.assert_allclose(run(scene).position_world[-1, 0], [0, 0, 0.2], atol=EXACT_TOL)
    edge = scene_of([body([0, 0, 1.2])], [Shape("points", points_body=feet[[0, 1, 4]])], [[Material(0.0)]],
                    duration=1.0)
    assert "edge" in reason(edge)


def test_an_impact_that_ends_in_rest_limits_friction_by_its_own_impulse():
    """k = 0.5 but rest below 10 m/s: the first impact ends in rest, so the normal impulse is m |v_n|
    (normal velocity -v1 -> 0), not (1 + k) m |v_n|. vx = 3 > mu_s v1 = 2.21: slip to 3 - mu_k v1 = 1.228,
    then a slide that stops after 1.228 / (mu_k g)."""
    h, k, vx, mu_s, mu_k = 1.0, 0.5, 3.0, 0.5, 0.4
    scene = scene_of([body([0, 0, h], velocity=[vx, 0, 0])], [Shape("point")], [[Material(k, mu_s, mu_k)]],
                     duration=1.5, rest_speed=10.0)
    v1, t1 = math.sqrt(2 * G * h), math.sqrt(2 * h / G)
    assert vx > mu_s * v1 and vx <= mu_s * (1 + k) * v1  # the two impulses would decide differently
    slide = vx - mu_k * v1
    t_stop = t1 + slide / (mu_k * G)
    events = contact_events(scene, 0, scene.duration)
    assert events.kinds == ("impact", "rest", "stop")
    assert events.times[2] == pytest.approx(t_stop, abs=EXACT_TOL)
    np.testing.assert_allclose(events.position_world[2], [vx * t1 + slide ** 2 / (2 * mu_k * G), 0, 0],
                               atol=EXACT_TOL)
