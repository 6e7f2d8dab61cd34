"""Contact metrics read from sampled trajectories built here by hand (a ball's exact bounce sequence)."""

import dataclasses
import math

import numpy as np
import pytest

from simparity.comparisons.measure.contact_metrics import contact_metrics, impacts
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.contact import Contact, Material, Plane, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory

G = 9.81
H = 1.0  # [m] drop height of the lowest point
EXACT = 1e-9  # [s, m, m/s] extrapolating a ballistic flight is exact up to rounding of values of order 1-10


def _bounce_heights(times: np.ndarray, k: float, impacts_wanted: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """Height and vertical velocity of a ball dropped from H with restitution k, written from the textbook
    sequence: t1 = sqrt(2H/g), v1 = g t1, each rebound k times the impact speed, flights 2 v / g."""
    starts, speeds = [0.0], [0.0]  # flight n starts at starts[n] with upward speed speeds[n] at height h0
    heights0 = [H]
    t1 = math.sqrt(2 * H / G)
    starts.append(t1)
    speeds.append(k * G * t1)
    heights0.append(0.0)
    for _ in range(impacts_wanted):
        starts.append(starts[-1] + 2 * speeds[-1] / G)
        speeds.append(k * speeds[-1])
        heights0.append(0.0)
    index = np.searchsorted(starts, times, side="right") - 1
    tau = times - np.array(starts)[index]
    v0, h0 = np.array(speeds)[index], np.array(heights0)[index]
    return h0 + v0 * tau - G * tau * tau / 2, v0 - G * tau


def _scene(k: float, shape: Shape = Shape("point")) -> DynamicsScene:
    body = RigidBody("ball", 1.0, np.eye(3), np.array([0, 0, H]), np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3))
    return DynamicsScene("bounce", "-", "analytic", (body,), Forces(gravity_world=np.array([0, 0, -G])), 1.2, (0.01,),
                         contact=Contact((Plane((0, 0, 1), 0.0, "floor"),), (shape,), ((Material(k),),),
                                         rest_speed=1e-3))


def _trajectory(times: np.ndarray, height: np.ndarray, velocity: np.ndarray) -> Trajectory:
    n = len(times)
    position = np.zeros((n, 1, 3))
    position[:, 0, 2] = height
    vel = np.zeros((n, 1, 3))
    vel[:, 0, 2] = velocity
    quat = np.tile([1.0, 0, 0, 0], (n, 1, 1))
    return Trajectory(times, position, quat, vel, np.zeros((n, 1, 3)))


@pytest.mark.parametrize("dt", [0.001, 0.01, 0.03])
def test_impacts_of_the_exact_bounce_sequence_are_exact_at_any_sampling(dt):
    """Impact times, velocities and apexes are recovered to rounding whatever the sample spacing."""
    k = 0.5
    times = np.arange(0, 1.2, dt)
    height, velocity = _bounce_heights(times, k)
    found = impacts(times, height, velocity, -G)
    t1 = math.sqrt(2 * H / G)
    v1 = G * t1
    expected_times = [t1, t1 + 2 * k * v1 / G]
    assert len(found.time) >= 2
    np.testing.assert_allclose(found.time[:2], expected_times, rtol=0, atol=EXACT)
    np.testing.assert_allclose(found.velocity_in[:2], [-v1, -k * v1], rtol=0, atol=EXACT)
    np.testing.assert_allclose(found.velocity_out[:2], [k * v1, k * k * v1], rtol=0, atol=EXACT)
    np.testing.assert_allclose(found.apex[:2], [H * k**2, H * k**4], rtol=0, atol=EXACT)


def test_a_soft_contact_spread_over_samples_is_one_impact():
    """A ball that sinks 5 mm and comes back over several samples: one impact, restitution from the free
    samples on either side."""
    dt, k = 0.001, 0.8
    times = np.arange(0, 0.6, dt)
    height, velocity = _bounce_heights(times, k)
    t1 = math.sqrt(2 * H / G)
    soft = (times > t1 - 0.004) & (times < t1 + 0.004)
    height = np.where(soft, -0.005 * np.cos((times - t1) / 0.008 * np.pi), height)
    velocity = np.where(soft, 0.0, velocity)  # inside the contact: not read (the samples touch the plane)
    found = impacts(times, height, velocity, -G)
    assert len(found.time) == 1
    assert found.velocity_out[0] / -found.velocity_in[0] == pytest.approx(k, abs=EXACT)


def test_contact_metrics_against_the_same_truth_are_zero_and_restitution_matches():
    """The truth measured against itself: zero errors, the requested restitution, no penetration or gain."""
    k = 0.5
    times = np.arange(0, 1.2, 0.005)
    truth = _trajectory(times, *_bounce_heights(times, k))
    values = contact_metrics(_scene(k), truth, truth)
    for metric in ("impact_time_error", "rebound_velocity_error", "apex_height_error", "impacts_missed"):
        assert values[metric].value == 0.0, metric
    assert values["restitution_measured"].value == pytest.approx(k, abs=EXACT)
    assert values["penetration_max"].value == 0.0
    assert values["tunnelled"].value == 0.0
    assert values["energy_gain_max"].value == 0.0


def test_a_bouncier_run_shows_its_restitution_energy_gain_and_late_impacts():
    """A run that rebounds at k = 0.6 where 0.5 was asked: restitution error 0.1, energy gained at no impact
    (0.6 < 1), the second impact late by 2 (0.6 - 0.5) v1 / g, the second rebound off by (0.36 - 0.25) v1, and
    the truth's third impact (t = 1.13 s) missing before the run ends; a run at k = 1.1 gains energy."""
    times = np.arange(0, 1.2, 0.005)
    truth = _trajectory(times, *_bounce_heights(times, 0.5))
    bouncier = _trajectory(times, *_bounce_heights(times, 0.6))
    values = contact_metrics(_scene(0.5), bouncier, truth)
    v1 = math.sqrt(2 * G * H)
    assert values["restitution_error"].value == pytest.approx(0.1, abs=EXACT)
    assert values["energy_loss_error"].value == pytest.approx(0.6**2 - 0.5**2, abs=EXACT)  # e^2 against k^2
    assert values["impact_time_error"].value == pytest.approx(2 * 0.1 * v1 / G, abs=EXACT)
    assert values["rebound_velocity_error"].value == pytest.approx(0.11 * v1, abs=EXACT)
    assert values["impacts_missed"].value == 1.0
    assert values["energy_gain_max"].value == 0.0
    one_rebound = times[times < math.sqrt(2 * H / G) * (1 + 2 * 1.1) - 0.01]  # up to just before the 2nd impact
    gaining = _trajectory(one_rebound, *_bounce_heights(one_rebound, 1.1))
    gain = contact_metrics(_scene(0.5), gaining, None)["energy_gain_max"].value
    # The impact adds (k^2 - 1) K1 (free flight conserves energy between the samples around it), relative
    # to the impact's budget: the body's energy above the plane before it, K1 = m g H.
    assert gain == pytest.approx(1.1**2 - 1, rel=1e-9)


def test_penetration_and_tunnelling():
    """A ball that goes straight through the floor at 5 m/s has tunnelled; one resting 1 mm inside it (a soft
    contact) has penetrated but not tunnelled."""
    times = np.arange(0, 0.5, 0.01)
    height = 1.0 - 5.0 * times  # the lowest point: straight through the floor at 5 m/s
    velocity = np.full_like(times, -5.0)
    scene = _scene(0.5, Shape("sphere", radius=0.1))
    values = contact_metrics(scene, _trajectory(times, height + 0.1, velocity), None)
    assert values["penetration_max"].value == pytest.approx(5.0 * times[-1] - 1.0, abs=1e-12)
    assert values["tunnelled"].value == 1.0
    resting = contact_metrics(scene, _trajectory(times, np.full_like(times, 0.1 - 1e-3), np.zeros_like(times)), None)
    assert resting["penetration_max"].value == pytest.approx(1e-3, abs=1e-15)
    assert resting["tunnelled"].value == 0.0
    # A soft contact's jitter: the point dips 2 mm after its impact, then wobbles within 1 mm, moving in at 5 cm/s
    # at the end: inside and moving in, but not deeper than before, so not gone through.
    depth = np.where(times < 0.1, -2e-3, -1e-3 + 5e-4 * np.sin(times * 40))
    wobble = np.full_like(times, -0.05)
    jitter = contact_metrics(_scene(0.5), _trajectory(times, depth, wobble), None)
    assert jitter["tunnelled"].value == 0.0


def test_a_turning_body_gives_no_restitution():
    """A ball spinning at 5 rad/s (its surface at 0.5 m/s, above the settling speed) bounces: the COM's rebound
    is not the contact point's, so restitution is n/a with that reason, while impacts are still compared."""
    k = 0.5
    times = np.arange(0, 1.2, 0.005)
    spinning = _trajectory(times, *_bounce_heights(times, k))
    omega = np.zeros_like(spinning.angular_velocity_world)
    omega[..., 0] = 5.0
    spinning = Trajectory(times, spinning.position_world, spinning.quat_wxyz, spinning.velocity_world, omega)
    values = contact_metrics(_scene(k, Shape("sphere", radius=0.1)), spinning, spinning)
    assert "turns" in values["restitution_measured"].unmeasurable
    assert values["impact_time_error"].value == 0.0


def _gaining_bounces(times: np.ndarray, ratios: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """Height and velocity of the ball dropped from H whose n-th impact rebounds at ratios[n] x its impact speed
    (then k = 0.5), written from the same textbook sequence as :func:`_bounce_heights`."""
    t, speed, starts, speeds = math.sqrt(2 * H / G), math.sqrt(2 * G * H), [0.0], [0.0]
    heights0 = [H]
    for ratio in ratios + [0.5] * 20:
        speed *= ratio
        starts.append(t)
        speeds.append(speed)
        heights0.append(0.0)
        t += 2 * speed / G
    index = np.searchsorted(starts, times, side="right") - 1
    tau = times - np.array(starts)[index]
    v0, h0 = np.array(speeds)[index], np.array(heights0)[index]
    return h0 + v0 * tau - G * tau * tau / 2, v0 - G * tau


def test_a_sustained_gain_is_a_blow_up_and_a_single_one_a_number():
    """After a nearly plastic first impact, three successive rebounds 20 % faster than their impacts (apexes
    1.44 x higher each): each gain is small beside the first drop's energy, but together they are a contact that
    pumps energy in: diverged, with the count; one such rebound stays a number (energy_kept_max 1.44)."""
    from simparity.comparisons.measure.contact_metrics import contact_blow_up, read_contact

    times = np.arange(0, 6.0, 0.001)
    pumping = _trajectory(times, *_gaining_bounces(times, [0.3, 1.2, 1.2, 1.2]))
    scene = _scene(0.5)
    assert "gained energy at 3 of its 7 impacts on floor (3 in succession" in contact_blow_up(
        scene, read_contact(scene, pumping))
    once = _trajectory(times, *_gaining_bounces(times, [1.2]))
    assert contact_blow_up(scene, read_contact(scene, once)) == ""
    values = contact_metrics(scene, once, None)
    assert values["energy_kept_max"].value == pytest.approx(1.44, rel=1e-6)
    assert values["restitution_max"].value == pytest.approx(1.2, rel=1e-6)
    assert values["restitution_min"].value == pytest.approx(0.5, rel=1e-6)


def test_a_run_that_ends_inside_a_bounce_has_no_rebound():
    """A ball 2 mm inside the floor and still sinking at 1 m/s at the last sample: its rebound is unknown, not 0
    (it never ended); a ball resting on the floor at the end did stay (a rebound of 0)."""
    dt = 0.001
    times = np.arange(0, math.sqrt(2 * H / G) + 0.005, dt)
    height, velocity = _bounce_heights(times, 0.5)
    inside = times > math.sqrt(2 * H / G)
    height = np.where(inside, -0.002, height)
    velocity = np.where(inside, -1.0, velocity)
    found = impacts(times, height, velocity, -G, min_speed=0.1)
    assert len(found.time) == 1 and math.isnan(found.velocity_out[0])
    values = contact_metrics(_scene(0.5), _trajectory(times, height, velocity),
                             _trajectory(times, height, velocity))
    assert values["rebound_velocity_error"].unmeasurable and math.isnan(values["rebound_velocity_error"].value)
    resting = impacts(times, np.where(inside, 0.0, height), np.where(inside, 0.0, velocity), -G, min_speed=0.1)
    assert resting.velocity_out[0] == 0.0


def test_an_impact_in_the_first_step_has_no_time_error():
    """A ball released 1 mm above the floor at 1 m/s down hits it within the first step: both runs back the
    impact up from the same initial state, so the time error would be 0 by construction: n/a."""
    dt, h0, v0 = 0.01, 1e-3, 1.0
    times = np.arange(0, 0.08, dt)  # ends before the second impact
    t1 = (-v0 + math.sqrt(v0 * v0 + 2 * G * h0)) / G
    v1 = v0 + G * t1
    tau = times - t1
    height = np.where(times < t1, h0 - v0 * times - G * times**2 / 2, 0.5 * v1 * tau - G * tau**2 / 2)
    velocity = np.where(times < t1, -v0 - G * times, 0.5 * v1 - G * tau)
    run = _trajectory(times, height, velocity)
    value = contact_metrics(_scene(0.5), run, run)["impact_time_error"]
    assert value.unmeasurable and "first step" in value.unmeasurable and value.flag == "nothing-to-measure"


def test_a_resting_body_jitters_without_diverging():
    """A box resting on the floor that jitters 0.1 mm up and down at 5 cm/s: its energy rises across each
    touch by a few 1e-4 of m |g| size, not of its own (tiny) kinetic energy: not a blow-up; the jitter is its
    own metric (0.2 mm peak to peak)."""
    from simparity.comparisons.measure.contact_metrics import contact_blow_up, read_contact

    times = np.arange(0, 2.0, 0.001)
    half = np.array([0.1, 0.1, 0.05])
    scene = _scene(0.5, Shape("box", half_extents_body=half))
    lift = 1e-4 * np.abs(np.sin(times * 50))
    box = _trajectory(times, 0.05 + lift, 5e-3 * np.cos(times * 50) * np.sign(np.sin(times * 50)))
    reading = read_contact(scene, box)
    assert contact_blow_up(scene, reading) == ""
    values = contact_metrics(scene, box, None)
    assert values["rest_jitter"].value == pytest.approx(1e-4, rel=1e-3)
    assert values["energy_gain_max"].value < 1e-3


def test_contact_verdicts_do_not_depend_on_where_the_origin_is():
    """The same bounce with the floor and the ball 1 km higher: the same statuses and values (up to rounding of
    positions of 1 km) and the same verdict on divergence."""
    from simparity.comparisons.measure.divergence import blow_up

    times = np.arange(0, 1.2, 0.005)
    height, velocity = _bounce_heights(times, 0.6)
    truth = _trajectory(times, *_bounce_heights(times, 0.5))
    here = contact_metrics(_scene(0.5), _trajectory(times, height, velocity), truth)
    lifted_scene = dataclasses.replace(_scene(0.5), contact=dataclasses.replace(
        _scene(0.5).contact, planes=(Plane((0, 0, 1), -1000.0, "floor"),)))
    lifted_truth = _trajectory(times, truth.position_world[:, 0, 2] + 1000.0, truth.velocity_world[:, 0, 2])
    there = contact_metrics(lifted_scene, _trajectory(times, height + 1000.0, velocity), lifted_truth)
    for metric, value in here.items():
        assert bool(value.unmeasurable) == bool(there[metric].unmeasurable), metric
        if not value.unmeasurable:
            assert there[metric].value == pytest.approx(value.value, rel=1e-9, abs=1e-9), metric
    assert blow_up(_scene(0.5), truth)[0] == blow_up(lifted_scene, lifted_truth)[0] == ""
