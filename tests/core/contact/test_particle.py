"""The lecture's particle-plane collision handling ("Bodies in Contact")."""

import re

import numpy as np
import pytest

from simparity.core.contact.particle import (
    BAD_RESTITUTION,
    UNKNOWN_METHOD,
    Plane,
    penalty_force,
    reflect_velocity,
    simulate_bouncing,
    step_particles,
    time_of_impact,
)
from simparity.core.model.scenes.contact import ZERO_NORMAL

G = 9.81  # [m/s^2]
SEED = 20240617

# Hand values and single formulas: a few roundings of O(1) numbers.
ROUNDOFF_TOL = 1e-12
# "backup" is exact under constant gravity; what is left is roundoff accumulated over a
# few thousand steps (~1e-13), so 1e-10 relative leaves a wide margin.
EXACT_BOUNCE_RTOL = 1e-10
# err / dt of a first-order method is constant up to O(dt) terms; at dt <= t1 / 20 those
# are a few per cent of the leading term.
FIRST_ORDER_SLOPE_RTOL = 0.05
# The semi-implicit Euler fixed point is exactly the static equilibrium; after 2 s the
# transient has decayed by e^-50, so only roundoff of ~1e-3 m positions remains.
EQUILIBRIUM_RTOL = 1e-9
# Undamped penalty contact with semi-implicit Euler: bounded O(omega dt) energy error,
# omega dt = 0.01 here.
UNDAMPED_ENERGY_RTOL = 1e-2


def _random_plane(rng: np.random.Generator) -> Plane:
    return Plane(rng.normal(size=3), rng.uniform(-1.0, 1.0))


def _tangential(v: np.ndarray, normal: np.ndarray) -> np.ndarray:
    return v - (v @ normal)[..., None] * normal


def test_plane_is_normalised_and_gives_signed_distance():
    """(a, b, c, d) is scaled to a unit normal and E(p) is the signed distance of hand examples."""
    plane = Plane((3.0, 4.0, 0.0), 10.0)
    np.testing.assert_allclose(plane.normal_world, [0.6, 0.8, 0.0], rtol=0, atol=ROUNDOFF_TOL)
    assert plane.offset == pytest.approx(2.0, abs=ROUNDOFF_TOL)
    assert plane.signed_distance(np.array([1.0, 1.0, 7.0])) == pytest.approx(3.4, abs=ROUNDOFF_TOL)
    floor = Plane((0.0, 0.0, 2.0), -4.0)  # 2 z - 4 = 0: the plane z = 2
    points = np.array([[[0.0, 0.0, 3.0], [5.0, -1.0, 2.0]], [[0.0, 0.0, 0.0], [1.0, 1.0, 2.5]]])
    np.testing.assert_allclose(floor.signed_distance(points), [[1.0, 0.0], [-2.0, 0.5]], rtol=0, atol=ROUNDOFF_TOL)
    assert not floor.normal_world.flags.writeable


@pytest.mark.parametrize("normal", [(0.0, 0.0, 0.0), (np.nan, 0.0, 1.0)])
def test_plane_rejects_a_degenerate_normal(normal):
    """A zero or non-finite normal has no plane."""
    with pytest.raises(ValueError, match=re.escape(ZERO_NORMAL)):
        Plane(normal, 1.0)


@pytest.mark.parametrize("restitution", [0.0, 0.3, 1.0])
def test_reflection_scales_the_normal_component_and_keeps_the_tangential(restitution):
    """v.N becomes -k v.N for incoming particles; the tangential part is untouched."""
    rng = np.random.default_rng(SEED)
    normal = _random_plane(rng).normal_world
    v = rng.normal(size=(50, 3))
    v -= 2.0 * np.maximum(v @ normal, 0.0)[:, None] * normal  # all moving into the plane
    out = reflect_velocity(v, normal, restitution)
    np.testing.assert_allclose(out @ normal, -restitution * (v @ normal), rtol=0, atol=ROUNDOFF_TOL)
    np.testing.assert_allclose(_tangential(out, normal), _tangential(v, normal), rtol=0, atol=ROUNDOFF_TOL)


def test_elastic_reflection_keeps_speed_and_plastic_leaves_no_normal_velocity():
    """k = 1 keeps |v| (elastic), k = 0 leaves the particle sliding along the plane."""
    rng = np.random.default_rng(SEED)
    normal = _random_plane(rng).normal_world
    v = rng.normal(size=(50, 3))
    v -= 2.0 * np.maximum(v @ normal, 0.0)[:, None] * normal
    np.testing.assert_allclose(
        np.linalg.norm(reflect_velocity(v, normal, 1.0), axis=1), np.linalg.norm(v, axis=1), rtol=ROUNDOFF_TOL
    )
    np.testing.assert_allclose(reflect_velocity(v, normal, 0.0) @ normal, 0.0, rtol=0, atol=ROUNDOFF_TOL)


def test_particle_moving_away_is_not_reflected():
    """Only v.N < 0 is reflected: a particle leaving the plane (or sliding on it) keeps its velocity."""
    normal = np.array([0.0, 0.0, 1.0])
    v = np.array([[1.0, 2.0, 3.0], [-1.0, 0.5, 0.0], [0.0, 0.0, -2.0]])
    out = reflect_velocity(v, normal, 0.5)
    np.testing.assert_array_equal(out[:2], v[:2])
    np.testing.assert_allclose(out[2], [0.0, 0.0, 1.0], rtol=0, atol=ROUNDOFF_TOL)
    with pytest.raises(ValueError, match=re.escape(BAD_RESTITUTION)):
        reflect_velocity(v, normal, 1.5)


def test_time_of_impact_is_exact_on_a_constant_velocity_segment():
    """The backed-up point lies on the plane; non-crossing steps give 1, a start on the plane 0."""
    rng = np.random.default_rng(SEED)
    plane = _random_plane(rng)
    n = plane.normal_world
    on_plane = rng.normal(size=(40, 3))
    on_plane = _tangential(on_plane, n) - plane.offset * n
    before, after = rng.uniform(0.1, 2.0, size=40), rng.uniform(0.1, 2.0, size=40)
    drift = _tangential(rng.normal(size=(40, 3)), n)
    p0 = on_plane + before[:, None] * n - drift
    p1 = on_plane - after[:, None] * n + drift
    s = time_of_impact(p0, p1, plane)
    np.testing.assert_allclose(s, before / (before + after), rtol=ROUNDOFF_TOL)
    np.testing.assert_allclose(plane.signed_distance(p0 + s[:, None] * (p1 - p0)), 0.0, rtol=0, atol=ROUNDOFF_TOL)
    np.testing.assert_array_equal(time_of_impact(p1, p0, plane), 1.0)  # leaving: no impact
    np.testing.assert_array_equal(time_of_impact(p0, p0 + drift, plane), 1.0)  # staying outside
    np.testing.assert_array_equal(time_of_impact(p1, p1 - drift, plane), 1.0)  # staying inside
    start_on_plane = time_of_impact(np.array([[1.0, 2.0, 0.0]]), np.array([[1.0, 2.0, -1.0]]), Plane((0, 0, 1), 0))
    np.testing.assert_array_equal(start_on_plane, 0.0)


def _impact_times(height: float, restitution: float, count: int) -> np.ndarray:
    """t_1 = sqrt(2h/g), t_{n+1} = t_n + 2 e^n sqrt(2h/g): the closed form of a bouncing ball."""
    t1 = np.sqrt(2.0 * height / G)
    return t1 + np.concatenate([[0.0], np.cumsum(2.0 * restitution ** np.arange(1, count) * t1)])


@pytest.mark.parametrize("dt", [1e-3, 0.0371, 0.13])
def test_backup_bounces_follow_the_closed_form_at_any_dt(dt):
    """With backing up, apexes are h e^(2n) and impact times the closed form, to roundoff, at any dt."""
    rng = np.random.default_rng(SEED)
    restitution, heights, n_bounces = 0.8, np.array([0.5, 0.8, 1.2]), 6
    plane = _random_plane(rng)
    n = plane.normal_world
    p0 = _tangential(rng.normal(size=(3, 3)), n) + (heights - plane.offset)[:, None] * n
    v0 = _tangential(rng.normal(size=(3, 3)), n)
    duration = min(_impact_times(h, restitution, n_bounces + 1)[-1] for h in heights)
    assert 2.0 * restitution**n_bounces * np.sqrt(2.0 * heights.min() / G) > dt  # one bounce per step
    n_steps = int(duration / dt)
    positions, velocities = simulate_bouncing(p0, v0, -G * n, dt, n_steps, plane, restitution, "backup")
    times = dt * np.arange(n_steps + 1)
    for b, h in enumerate(heights):
        distance, normal_speed = plane.signed_distance(positions[:, b]), velocities[:, b] @ n
        apex = distance + normal_speed**2 / (2.0 * G)  # height the current flight reaches
        impacts = _impact_times(h, restitution, n_bounces + 1)
        bounces_so_far = np.searchsorted(impacts, times, side="right")
        np.testing.assert_allclose(apex, h * restitution ** (2 * bounces_so_far), rtol=0, atol=EXACT_BOUNCE_RTOL * h)
        first_after = np.searchsorted(bounces_so_far, np.arange(1, bounces_so_far[-1] + 1))
        assert len(first_after) >= 3
        # back from the first sample after each bounce along its parabola to the plane
        take_off = np.sqrt(2.0 * G * apex[first_after])
        recovered = times[first_after] - (take_off - normal_speed[first_after]) / G
        np.testing.assert_allclose(recovered, impacts[: len(first_after)], rtol=EXACT_BOUNCE_RTOL)
        assert distance.min() >= -EXACT_BOUNCE_RTOL * h
        np.testing.assert_allclose(
            _tangential(velocities[:, b], n), np.broadcast_to(v0[b], (n_steps + 1, 3)), rtol=0, atol=ROUNDOFF_TOL
        )


def test_backup_catches_a_particle_that_rises_and_returns_within_one_step():
    """Thrown up from 0.05 m at 1 m/s under g = 10, it lands at s = (1 + sqrt 2) / 10 inside a 0.3 s step."""
    gravity, dt, restitution = 10.0, 0.3, 0.5
    p, v = step_particles(np.array([[0.0, 0.0, 0.05]]), np.array([[2.0, 0.0, 1.0]]), np.array([0.0, 0.0, -gravity]),
                          dt, Plane((0.0, 0.0, 1.0), 0.0), restitution)
    rest = dt - (1.0 + np.sqrt(2.0)) / 10.0
    take_off = restitution * np.sqrt(2.0)  # lands at sqrt(1 + 2 g 0.05) = sqrt 2 m/s
    np.testing.assert_allclose(p[0], [0.6, 0.0, take_off * rest - gravity * rest**2 / 2.0], rtol=0, atol=ROUNDOFF_TOL)
    np.testing.assert_allclose(v[0], [2.0, 0.0, take_off - gravity * rest], rtol=0, atol=ROUNDOFF_TOL)


def test_backup_under_a_ceiling_hits_only_what_reaches_it():
    """Gravity along N (a ceiling): one turning back short of it flies freely, one reaching it bounces."""
    gravity, dt, restitution = 10.0, 0.3, 0.5
    ceiling = Plane((0.0, 0.0, -1.0), 2.0)  # z = 2, free side below
    start = np.array([[0.0, 0.0, 1.9], [0.0, 0.0, 1.9]])
    up = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 2.0]])  # peaks at 1.95 m; reaches 2 m at s = (2 - sqrt 2) / 10
    p, v = step_particles(start, up, np.array([0.0, 0.0, -gravity]), dt, ceiling, restitution)
    np.testing.assert_allclose([p[0, 2], v[0, 2]], [1.9 + dt - gravity * dt**2 / 2.0, 1.0 - gravity * dt],
                               rtol=0, atol=ROUNDOFF_TOL)
    rest = dt - (2.0 - np.sqrt(2.0)) / 10.0
    take_off = -restitution * np.sqrt(2.0)  # arrives at sqrt(4 - 2 g 0.1) = sqrt 2 m/s
    np.testing.assert_allclose([p[1, 2], v[1, 2]], [2.0 + take_off * rest - gravity * rest**2 / 2.0,
                                                    take_off - gravity * rest], rtol=0, atol=ROUNDOFF_TOL)


def test_backup_comes_to_rest_on_the_plane_after_the_bounces_pile_up():
    """Past the time of infinitely many bounces, "backup" rests on the plane; the bare response sinks."""
    restitution, dt = 0.8, 0.01
    plane = Plane((0.0, 0.0, 1.0), 0.0)
    pile_up = np.sqrt(2.0 / G) * (1.0 + restitution) / (1.0 - restitution)  # sum of all bounce intervals, h = 1 m
    n_steps = int(2.0 * pile_up / dt)
    heights = {}
    for method in ("backup", "detect_and_reflect"):
        positions, _ = simulate_bouncing([[0.0, 0.0, 1.0]], [[0.5, 0.0, 0.0]], [0.0, 0.0, -G], dt, n_steps, plane,
                                         restitution, method)
        heights[method] = positions[:, 0, 2]
    assert heights["backup"].min() >= 0.0
    assert np.abs(heights["backup"][-100:]).max() <= G * dt**2
    assert heights["detect_and_reflect"][-1] < -10.0 * G * dt**2


def test_detect_and_reflect_is_first_order_and_penetrates():
    """Without backing up, the first apex error is proportional to dt and the ball goes below the plane."""
    height, restitution = 1.0, 0.8
    plane = Plane((0.0, 0.0, 1.0), 0.0)
    t1, impact_speed = np.sqrt(2.0 * height / G), np.sqrt(2.0 * G * height)
    slopes = []
    for steps_to_impact in (20, 40, 80):
        dt = t1 / (steps_to_impact + 0.5)  # the plane is crossed mid-step at every dt
        positions, velocities = simulate_bouncing(
            [[0.0, 0.0, height]], [[0.0, 0.0, 0.0]], [0.0, 0.0, -G], dt, steps_to_impact + 3, plane,
            restitution, "detect_and_reflect",
        )
        z, vz = positions[-1, 0, 2], velocities[-1, 0, 2]
        assert vz > 0.0
        slopes.append((z + vz**2 / (2.0 * G) - height * restitution**2) / dt)
        assert positions[:, 0, 2].min() < -0.4 * impact_speed * dt
    # the bounce starts about |v| dt / 2 below the plane: apex error -(1 - e^2) |v| dt / 2
    np.testing.assert_allclose(slopes, -(1.0 - restitution**2) * impact_speed / 2.0, rtol=FIRST_ORDER_SLOPE_RTOL)


def test_step_rejects_an_unknown_method():
    """Only the listed collision methods are accepted."""
    with pytest.raises(ValueError, match=re.escape(UNKNOWN_METHOD)):
        step_particles(np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(3), 0.1, Plane((0, 0, 1), 0), 0.5, "penalty")


def test_penalty_force_hand_values_and_never_pulls():
    """F = (-k_s E - k_d v.N) N inside the plane, zero outside, and never attractive."""
    plane = Plane((0.0, 0.0, 1.0), 0.0)
    p = np.array([[0.0, 0.0, -0.01], [0.0, 0.0, 0.01], [0.0, 0.0, -0.01]])
    v = np.array([[1.0, 0.0, -0.5], [0.0, 0.0, -3.0], [0.0, 0.0, 5.0]])
    force = penalty_force(p, v, plane, stiffness=100.0, damping=2.0)
    np.testing.assert_allclose(force, [[0.0, 0.0, 2.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], rtol=0, atol=ROUNDOFF_TOL)


def _semi_implicit_penalty(p, v, mass, gravity, plane, stiffness, damping, dt, n_steps):
    """Semi-implicit Euler (v first, then x with the new v) under gravity and the penalty force."""
    for _ in range(n_steps):
        v = v + (gravity + penalty_force(p, v, plane, stiffness, damping) / mass[:, None]) * dt
        p = p + v * dt
    return p, v


def test_penalty_contact_settles_at_static_equilibrium():
    """A particle resting on the plane sinks to the depth m g / k_s where the spring carries its weight."""
    rng = np.random.default_rng(SEED)
    plane = _random_plane(rng)
    n = plane.normal_world
    mass, stiffness = np.array([0.5, 1.0, 2.0]), np.array([2e4, 1e4, 5e3])
    damping = 2.0 * 0.5 * np.sqrt(stiffness * mass)  # damping ratio 0.5
    p0 = _tangential(rng.normal(size=(3, 3)), n) - plane.offset * n
    p, v = _semi_implicit_penalty(p0, np.zeros((3, 3)), mass, -G * n, plane, stiffness, damping, 1e-3, 2000)
    np.testing.assert_allclose(-plane.signed_distance(p), mass * G / stiffness, rtol=EQUILIBRIUM_RTOL)
    np.testing.assert_allclose(_tangential(p, n), _tangential(p0, n), rtol=0, atol=ROUNDOFF_TOL)


def test_penalty_damping_loses_energy_in_a_bounce():
    """Dropped on a penalty plane, the particle leaves with its energy if k_d = 0 and with less if k_d > 0."""
    plane = Plane((0.0, 0.0, 1.0), 0.0)
    mass, stiffness, height = np.array([1.0, 1.0]), 1e4, 0.2
    damping = np.array([0.0, 20.0])  # damping ratio 0 and 0.1
    p0 = np.array([[0.0, 0.0, height]] * 2)
    # fall 0.2 s, contact ~0.03 s, then about half of the rise
    p, v = _semi_implicit_penalty(p0, np.zeros((2, 3)), mass, np.array([0.0, 0.0, -G]), plane, stiffness,
                                  damping, 1e-4, 3300)
    assert np.all(p[:, 2] > 0.0) and np.all(v[:, 2] > 0.0)  # out of contact, rising
    energy_ratio = (p[:, 2] + v[:, 2] ** 2 / (2.0 * G)) / height
    assert energy_ratio[0] == pytest.approx(1.0, rel=UNDAMPED_ENERGY_RTOL)
    assert energy_ratio[1] < 0.9
