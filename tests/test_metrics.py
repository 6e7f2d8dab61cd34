"""Metrics that cannot lie: drift relative to E(0), orders only from errors that mean something,
saturated values n/a. Expected numbers are worked by hand from the definitions in docs/metrics.md."""

import math

import numpy as np
import pytest

from simparity.comparisons.metrics import (
    ENERGY_NEAR_ZERO,
    SATURATED_ORIENTATION,
    drifts,
    observed_order,
    rounding_floors,
    trajectory_errors,
)
from simparity.comparisons.runner import run_scene
from simparity.comparisons.engines import make_engine
from simparity.core.scene import DynamicsScene, Forces, RigidBody
from simparity.core.trajectory import Trajectory

ROUND_OFF = 1e-14
"""Relative slack for sums of a few float64 terms."""


def _body(mass=2.0, velocity=(0.0, 0.0, 0.0), position=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0)):
    return RigidBody("b", mass, np.diag([1.0, 2.0, 3.0]), np.array(position, float), np.array([1.0, 0, 0, 0]),
                     np.array(velocity, float), np.array(omega, float))


def _scene(body, gravity=(0.0, 0.0, -10.0), duration=1.0, dts=(0.5,)):
    return DynamicsScene("hand", "", "analytic", (body,), Forces(np.array(gravity, float)), duration, dts)


def _trajectory(positions, velocities, quats=None, omegas=None):
    """A one-body trajectory from per-sample lists."""
    t = len(positions)
    quats = np.tile([1.0, 0, 0, 0], (t, 1)) if quats is None else np.asarray(quats, float)
    omegas = np.zeros((t, 3)) if omegas is None else np.asarray(omegas, float)
    return Trajectory(np.linspace(0.0, 1.0, t), np.asarray(positions, float)[:, None],
                      quats[:, None], np.asarray(velocities, float)[:, None], omegas[:, None])


def test_energy_drift_is_relative_to_the_initial_energy():
    """m = 2 kg, g = 10: E(0) = 2*1/2 + 2*10*5 = 101 J, E(1) = 2*25/2 + 2*10*4 = 105 J: drift 4/101."""
    scene = _scene(_body(velocity=(1.0, 0, 0), position=(0, 0, 5.0)))
    traj = _trajectory([(0, 0, 5.0), (0, 0, 4.0)], [(1.0, 0, 0), (0, 0, -5.0)])
    drift = drifts(scene, traj)["energy_drift_max"]
    assert drift.value == pytest.approx(4 / 101, rel=ROUND_OFF) and not drift.note and not drift.unmeasurable


def test_energy_drift_falls_back_to_kinetic_energy_when_the_initial_energy_is_zero():
    """Dropped from rest at the origin: E(0) = 0; later KE = 2*26/2 = 26 J, PE = 2*10*(-1.25) = -25 J, so
    E = 1 J; |E(0)| < ENERGY_NEAR_ZERO x 51 J, so the drift is 1/26 and the row says what it is relative to."""
    scene = _scene(_body())
    traj = _trajectory([(0, 0, 0.0), (0, 0, -1.25)], [(0, 0, 0.0), (0, 0, -math.sqrt(26.0))])
    drift = drifts(scene, traj)["energy_drift_max"]
    assert drift.value == pytest.approx(1 / 26, rel=ROUND_OFF)
    assert "largest kinetic energy" in drift.note and f"{ENERGY_NEAR_ZERO:g}" in drift.note


def test_energy_drift_above_100_percent_is_saturated():
    """E(0) = 101 J, later E = 2*100/2 + 2*10*(-10) = -100 J: |dE| / E(0) = 201/101 > 100 %: n/a, not a number."""
    scene = _scene(_body(velocity=(1.0, 0, 0), position=(0, 0, 5.0)))
    traj = _trajectory([(0, 0, 5.0), (0, 0, -10.0)], [(1.0, 0, 0), (0, 0, -10.0)])
    drift = drifts(scene, traj)["energy_drift_max"]
    assert drift.value == pytest.approx(201 / 101) and drift.unmeasurable.startswith("saturated")


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
    order = observed_order([0.01, 0.02, 0.04], [3.1, 3.12, 3.14], saturation=SATURATED_ORIENTATION)
    assert math.isnan(order.value) and "3 saturated" in order.unmeasurable


def test_errors_at_the_rounding_floor_give_no_order():
    order = observed_order([0.01, 0.02, 0.04], [2e-12, 1e-12, 5e-13], floors=[4e-12, 2e-12, 1e-12])
    assert math.isnan(order.value) and "rounding floor" in order.unmeasurable


def test_rounding_floor_grows_with_steps_and_state_size():
    traj = _trajectory([(0, 0, 100.0), (0, 0, 0.0)], [(0, 0, -3.0), (0, 0, -4.0)])
    scene = _scene(_body())  # inertia diag(1, 2, 3): condition number 3
    one, many = rounding_floors(scene, traj, 1), rounding_floors(scene, traj, 1000)
    assert many["position_error_max"] == pytest.approx((1000 + 3) / (1 + 3) * one["position_error_max"])
    assert one["position_error_max"] == pytest.approx(one["velocity_error_max"] * (100 + 4) / 4)


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
