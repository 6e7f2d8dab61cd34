"""Metrics that cannot lie: drift relative to an energy scale that does not depend on the origin, orders
only from errors that mean something, saturated values n/a. Expected numbers are worked by hand from the definitions in docs/metrics.md."""

import dataclasses
import math

import numpy as np
import pytest

from simparity.comparisons.measure.metrics import (
    SATURATED_ORIENTATION,
    drifts,
    observed_order,
    rounding_floors,
    trajectory_errors,
)
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.engines.registry import make_engine
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from tests.helpers import builtin

ROUND_OFF = 1e-14
"""Relative slack for sums of a few float64 terms."""


def _body(mass=2.0, velocity=(0.0, 0.0, 0.0), position=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0),
          inertia=(1.0, 2.0, 3.0)):
    return RigidBody("b", mass, np.diag(inertia), np.array(position, float), np.array([1.0, 0, 0, 0]),
                     np.array(velocity, float), np.array(omega, float))


SMALL = (1e-4, 1e-4, 1e-4)
"""[kg m^2] A body of 2 kg this small has a size of sqrt(3e-4 / 4) = 8.7 mm: its energy floor m |g| size
(0.17 J at g = 10) stays below the energies of the hand-worked drifts."""


def _scene(body, gravity=(0.0, 0.0, -10.0), duration=1.0, dts=(0.5,)):
    return DynamicsScene("hand", "", "analytic", (body,), Forces(np.array(gravity, float)), duration, dts)


def _trajectory(positions, velocities, quats=None, omegas=None):
    """A one-body trajectory from per-sample lists."""
    t = len(positions)
    quats = np.tile([1.0, 0, 0, 0], (t, 1)) if quats is None else np.asarray(quats, float)
    omegas = np.zeros((t, 3)) if omegas is None else np.asarray(omegas, float)
    return Trajectory(np.linspace(0.0, 1.0, t), np.asarray(positions, float)[:, None],
                      quats[:, None], np.asarray(velocities, float)[:, None], omegas[:, None])


def test_energy_drift_is_relative_to_the_energy_a_body_trades_not_to_E0():
    """m = 2 kg, g = 10, from 5 m to 4 m: KE(0) = 1 J, the largest drop of potential 2*10*1 = 20 J, so the scale
    is 21 J (|E(0)| = 101 J would depend on the origin); E(1) - E(0) = 25 + 80 - 101 = 4 J: drift 4/21, the same
    with the whole scene 1 km higher."""
    for lift in (0.0, 1000.0):
        scene = _scene(_body(velocity=(1.0, 0, 0), position=(0, 0, 5.0 + lift), inertia=SMALL))
        traj = _trajectory([(0, 0, 5.0 + lift), (0, 0, 4.0 + lift)], [(1.0, 0, 0), (0, 0, -5.0)])
        drift = drifts(scene, traj)["energy_drift_max"]
        assert drift.value == pytest.approx(4 / 21, rel=1e-12) and not drift.unmeasurable


def test_energy_drift_of_a_body_dropped_from_rest_at_the_origin():
    """E(0) = 0 here, which no longer matters: later KE = 2*26/2 = 26 J, PE = 2*10*(-1.25) = -25 J, so E = 1 J;
    the scale is the drop, 25 J: drift 1/25."""
    scene = _scene(_body(inertia=SMALL))
    traj = _trajectory([(0, 0, 0.0), (0, 0, -1.25)], [(0, 0, 0.0), (0, 0, -math.sqrt(26.0))])
    assert drifts(scene, traj)["energy_drift_max"].value == pytest.approx(1 / 25, rel=1e-12)


def test_energy_drift_of_a_body_at_rest_is_relative_to_lifting_it_by_its_size():
    """A body that neither moves nor drops has nothing to trade: the scale is m |g| size, 2*10*sqrt(6/4) J
    (tr I = 6, so size sqrt(6 / 4) m), not 0."""
    scene = _scene(_body())
    traj = _trajectory([(0, 0, 0.0), (0, 0, 1e-3)], [(0, 0, 0.0), (0, 0, 0.0)])
    assert drifts(scene, traj)["energy_drift_max"].value == pytest.approx(2 * 10 * 1e-3 / (20 * math.sqrt(1.5)),
                                                                         rel=1e-12)


def test_energy_drift_above_100_percent_is_saturated():
    """E(0) = 101 J, later E = 2*400/2 + 2*10*4 = 480 J: the scale is KE(0) + the drop 1 + 20 = 21 J, and
    |dE| / 21 > 100 %: n/a, flagged saturated, not a number."""
    scene = _scene(_body(velocity=(1.0, 0, 0), position=(0, 0, 5.0), inertia=SMALL))
    traj = _trajectory([(0, 0, 5.0), (0, 0, 4.0)], [(1.0, 0, 0), (0, 0, -20.0)])
    drift = drifts(scene, traj)["energy_drift_max"]
    assert drift.value == pytest.approx(379 / 21) and drift.unmeasurable.startswith("saturated")
    assert drift.flag == "saturated"


def test_angular_momentum_drift_by_hand():
    """I = diag(1, 2, 3), omega from (0, 0, 1) to (0, 0.1, 1): L from (0, 0, 3) to (0, 0.2, 3), drift 0.2/3."""
    scene = DynamicsScene("hand", "", "analytic", (_body(omega=(0, 0, 1.0)),), Forces(), 1.0, (0.5,))
    traj = _trajectory([(0, 0, 0.0)] * 2, [(0, 0, 0.0)] * 2, omegas=[(0, 0, 1.0), (0, 0.1, 1.0)])
    assert drifts(scene, traj)["angular_momentum_drift_max"].value == pytest.approx(0.2 / 3, rel=ROUND_OFF)


def test_orientation_error_near_pi_is_saturated():
    """A body turned 3 rad away from the reference: the angle no longer measures how far: n/a."""
    ref = _trajectory([(0, 0, 0.0)] * 2, [(0, 0, 0.0)] * 2)
    half = 1.5  # a rotation of 3 rad about z: (cos 1.5, 0, 0, sin 1.5)
    traj = _trajectory([(0, 0, 0.0)] * 2, [(0, 0, 0.0)] * 2, quats=[(1.0, 0, 0, 0), (math.cos(half), 0, 0, math.sin(half))])
    orientation = trajectory_errors(traj, ref)["orientation_error_max"]
    assert orientation.value == pytest.approx(3.0) and "saturated" in orientation.unmeasurable
    small = _trajectory([(0, 0, 0.0)] * 2, [(0, 0, 0.0)] * 2, quats=[(1.0, 0, 0, 0), (math.cos(0.05), 0, 0, math.sin(0.05))])
    assert trajectory_errors(small, ref)["orientation_error_max"].value == pytest.approx(0.1, rel=1e-12)


def test_order_of_a_clean_power_law():
    """Errors 3 dt^2 exactly: order 2 over the whole ladder, with the fit's range and residual stated."""
    dts = np.array([0.01, 0.02, 0.04, 0.08])
    order = observed_order(dts, 3 * dts**2)
    assert order.value == pytest.approx(2.0, abs=1e-12)
    assert "0.01..0.08 (4 of 4" in order.note and "residual" in order.note


def test_order_fits_only_the_asymptotic_range():
    """The coarsest step is off the power law (local slope 0.5 against 2, 2): it is left out of the fit."""
    dts = np.array([0.01, 0.02, 0.04, 0.08])
    errors = 3 * dts**2
    errors[-1] = errors[-2] * 2**0.5
    order = observed_order(dts, errors)
    assert order.value == pytest.approx(2.0, abs=1e-12) and "(3 of 4" in order.note


def test_order_without_an_asymptotic_range_is_not_available():
    dts = np.array([0.01, 0.02, 0.04])
    order = observed_order(dts, np.array([1e-3, 1e-3 * 2**3, 1e-3 * 2**3 * 2**0.5]))  # slopes 3, 0.5
    assert math.isnan(order.value) and "asymptotic range" in order.unmeasurable


def test_saturated_orientation_errors_give_no_order():
    """Orientation errors pinned near pi (the old fit called this order 2e-6, ok)."""
    angles = np.array([3.1, 3.12, 3.14])
    order = observed_order([0.01, 0.02, 0.04], angles, saturation=angles / SATURATED_ORIENTATION)
    assert math.isnan(order.value) and "3 saturated" in order.unmeasurable and order.flag == "saturated"


def test_errors_at_the_rounding_floor_give_no_order():
    order = observed_order([0.01, 0.02, 0.04], [2e-12, 1e-12, 5e-13], floors=[4e-12, 2e-12, 1e-12])
    assert math.isnan(order.value) and "rounding floor" in order.unmeasurable


def test_rounding_floor_grows_with_steps_and_state_size():
    traj = _trajectory([(0, 0, 100.0), (0, 0, 0.0)], [(0, 0, -3.0), (0, 0, -4.0)])
    scene = _scene(_body())  # inertia diag(1, 2, 3): condition number 3
    one, many = rounding_floors(scene, traj, 1), rounding_floors(scene, traj, 1000)
    assert many["position_error_max"] == pytest.approx((1000 + 3) / (1 + 3) * one["position_error_max"])
    assert one["position_error_max"] == pytest.approx(one["velocity_error_max"] * (100 + 4) / 4)


@pytest.mark.slow
def test_exact_scheme_over_a_long_fall_has_no_order():
    """RK4 is exact under constant gravity: over 40,000 steps its errors are rounding, and its position and
    velocity orders are n/a (the old fixed 1e-11 m floor reported -2.0 and 0.06 as ok). Semi-implicit Euler,
    whose position error g t dt / 2 is truncation, keeps order 1 on the same ladder. (MuJoCo's, for speed.)"""
    body = _body(velocity=(3.0, 0.0, 20.0), position=(1.0, 2.0, 100.0))
    scene = DynamicsScene("long-fall", "", "analytic", (body,), Forces(np.array([0.0, 0.0, -9.81])), 40.0,
                          (0.001, 0.002, 0.004), integrators=("rk4", "euler"))
    rows = run_scene(scene, [make_engine("mujoco")], make_engine, repeats=1)
    orders = {(r.integrator, r.metric): r for r in rows if r.metric.startswith("order_")}
    for metric in ("order_position", "order_velocity"):
        assert orders[("rk4", metric)].status == "n/a" and "rounding floor" in orders[("rk4", metric)].detail
    assert orders[("euler", "order_position")].value == pytest.approx(1.0, abs=0.01)


def _scales_scene(body):
    return DynamicsScene("scales", "", "analytic", (body,), Forces(), 2.0, (0.5,))


def test_each_error_saturates_against_its_own_quantity_scale():
    """The reference moves 4 m at 2 m/s while spinning at 3 rad/s; an error of a quarter of a quantity's scale
    is saturated (n/a, flagged, the scale in the reason), just below it is a number."""
    from simparity.comparisons.measure.metrics import SATURATED_FRACTION, saturation_scales

    body = _body(velocity=(2.0, 0, 0), omega=(0, 0, 3.0), inertia=SMALL)
    times = np.linspace(0.0, 2.0, 3)
    ref = Trajectory(times, np.array([[[0.0, 0, 0]], [[2.0, 0, 0]], [[4.0, 0, 0]]]), np.tile([1.0, 0, 0, 0], (3, 1, 1)),
                     np.tile([2.0, 0, 0], (3, 1, 1)), np.tile([0, 0, 3.0], (3, 1, 1)))
    scales = saturation_scales(_scales_scene(body), ref)
    assert scales["position_error_max"].value[0] == pytest.approx(4.0)  # the range of motion
    for metric, field, scale in (("position_error_max", "position_world", 4.0), ("velocity_error_max", "velocity_world",
                                 None), ("angular_velocity_error_max", "angular_velocity_world", 3.0)):
        scale = scales[metric].value[0] if scale is None else scale
        for fraction, saturated in ((0.99, False), (1.01, True)):
            moved = np.array(getattr(ref, field))
            moved[1:, 0, 1] += fraction * SATURATED_FRACTION * scale
            kwargs = {f: getattr(ref, f) for f in ("times", "position_world", "quat_wxyz", "velocity_world",
                                                   "angular_velocity_world")} | {field: moved}
            measured = trajectory_errors(Trajectory(**kwargs), ref, scales)[metric]
            assert bool(measured.unmeasurable) is saturated, (metric, fraction)
            assert (measured.flag == "saturated") is saturated and (not saturated or "scale" in measured.unmeasurable)


def test_saturation_scales_have_physical_floors():
    """A box spinning in place has no range of motion: its position scale is its size; a body at rest has no
    speed: its velocity scale is its size over the run's duration, its angular one 1 / duration."""
    from simparity.comparisons.measure.metrics import saturation_scales

    times = np.linspace(0.0, 2.0, 3)
    still = Trajectory(times, np.zeros((3, 1, 3)), np.tile([1.0, 0, 0, 0], (3, 1, 1)), np.zeros((3, 1, 3)),
                       np.zeros((3, 1, 3)))
    size = math.sqrt(6.0 / 4.0)  # tr I = 6 kg m^2, m = 2 kg
    scales = saturation_scales(_scales_scene(_body()), still)
    assert scales["position_error_max"].value[0] == pytest.approx(size)
    assert scales["velocity_error_max"].value[0] == pytest.approx(size / 2.0)
    assert scales["angular_velocity_error_max"].value[0] == pytest.approx(1 / 2.0)


def test_order_fits_say_what_their_data_supports():
    """A clean fit above theory + 0.5 is n/a flagged superconvergent; below theory - 0.5 ok but flagged
    below-theory; a clean fit below order 0.5 is never ok: saturating when its errors near saturation, rounding near
    the floor, else not converging (an alarm)."""
    dts = np.array([0.01, 0.02, 0.04])
    above = observed_order(dts, dts**3, theory=2)
    assert above.flag == "superconvergent" and above.unmeasurable
    assert observed_order(dts, dts**3, theory=3).flag == ""
    assert observed_order(dts, dts**1, theory=2).flag == "below-theory"
    flat = 1e-3 * dts**0.1
    fits = {"saturated": observed_order(dts, flat, saturation=0.3, theory=1),
            "rounding-floor": observed_order(dts, flat, floors=flat / 10, theory=1),
            "not-converging": observed_order(dts, flat, floors=1e-12, saturation=1e-3, theory=1)}
    for flag, fit in fits.items():
        assert math.isnan(fit.value) is False or fit.unmeasurable  # the raw slope is kept for the harness only
        assert fit.unmeasurable and fit.flag == flag, flag


@pytest.mark.slow
def test_near_a_separatrix_euler_family_orders_are_never_ok():
    """A torque-free box spun 0.5 % off its intermediate axis: Euler-type schemes lose the orbit (angular
    velocity errors of about half of |omega|), so their errors are saturated and no order is ok; RK4 keeps the
    orbit and has its order; the midpoint rule's clean fit above theory is n/a, flagged."""
    body = RigidBody("box", 1.0, np.diag([0.2, 0.5, 0.6]), np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3),
                     np.array([0.02, 4.0, 0.02]))
    integrators = ("explicit_euler", "semi_implicit_euler", "midpoint", "rk4")
    scene = DynamicsScene("separatrix", "", "analytic", (body,), Forces(), 8.0, (0.0025, 0.005, 0.01),
                          integrators=integrators)
    rows = run_scene(scene, [make_engine("core")], make_engine, repeats=1)
    rotational = {(r.integrator, r.metric): r for r in rows if r.metric in ("order_orientation", "order_angular_velocity")}
    for euler in ("explicit_euler", "semi_implicit_euler"):
        assert all(rotational[(euler, m)].status == "n/a" for m in ("order_orientation", "order_angular_velocity"))
        errors = [r for r in rows if r.integrator == euler and r.metric == "angular_velocity_error_max"]
        assert {(r.status, r.flag) for r in errors} == {("n/a", "saturated")}
    assert rotational[("rk4", "order_angular_velocity")].status == "ok"
    assert rotational[("rk4", "order_angular_velocity")].flag == ""
    assert (rotational[("midpoint", "order_orientation")].status,
            rotational[("midpoint", "order_orientation")].flag) == ("n/a", "superconvergent")


def test_contact_events_raise_the_velocity_rounding_floor_with_the_distance_from_the_origin():
    """An impact is timed from a gap known to the position's rounding, which grows with the distance from the
    origin: the velocity's rounding floor grows with it (2 |g| gap / rest speed), is 0 without contact, and at a
    rest speed of 0 is bounded by a fall through the gap itself."""
    from simparity.comparisons.measure.metrics import event_velocity_floor

    scene = builtin("ball-bounce-k05")
    g = float(np.linalg.norm(scene.forces.gravity_world))
    near, far = event_velocity_floor(scene, 1e-13), event_velocity_floor(scene, 1e-10)
    assert far == pytest.approx(1000 * near) and near == pytest.approx(2 * g * 1e-13 / scene.contact.rest_speed)
    assert event_velocity_floor(dataclasses.replace(scene, contact=None), 1e-10) == 0.0
    resting = dataclasses.replace(scene, contact=dataclasses.replace(scene.contact, rest_speed=0.0))
    assert event_velocity_floor(resting, 1e-10) == pytest.approx(math.sqrt(2 * g * 1e-10))
