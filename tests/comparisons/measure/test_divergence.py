"""Blow-up detection from the scene's energy budget, with bounds worked by hand."""

import math

import numpy as np

from simparity.comparisons.measure.divergence import AT_REST, DIVERGENCE_MARGIN, divergence
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.core.model.results import DIVERGED, OK
from simparity.core.model.scenes.bodies import AppliedForce, Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory


def _body(velocity=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0), inertia=(1.0, 2.0, 3.0), mass=2.0, position=(0, 0, 0)):
    return RigidBody("b", mass, np.diag(inertia), np.array(position, float), np.array([1.0, 0, 0, 0]),
                     np.array(velocity, float), np.array(omega, float))


def _trajectory(velocities, omegas=None, positions=None):
    t = len(velocities)
    omegas = np.zeros((t, 3)) if omegas is None else np.asarray(omegas, float)
    positions = np.zeros((t, 3)) if positions is None else np.asarray(positions, float)
    return Trajectory(np.linspace(0.0, 2.0, t), positions[:, None], np.tile([1.0, 0, 0, 0], (t, 1, 1)),
                      np.asarray(velocities, float)[:, None], omegas[:, None])


def test_speed_bound_from_gravity_and_applied_force():
    """|v0| = 5, |g| = 10, a 6 N force on 2 kg, T = 2 s: |v| <= 5 + (10 + 3) 2 = 31 m/s, diverged past 2 x 31."""
    forces = Forces(np.array([0.0, 0.0, -10.0]), applied=(AppliedForce(0, np.array([6.0, 0, 0]), np.zeros(3)),))
    scene = DynamicsScene("s", "", "tight", (_body(velocity=(3.0, 0, 4.0)),), forces, 2.0, (0.1,))
    limit = DIVERGENCE_MARGIN * 31.0 + AT_REST
    assert divergence(scene, _trajectory([(3.0, 0, 4.0), (0, 0, limit * 0.999)])) == ""
    reason = divergence(scene, _trajectory([(3.0, 0, 4.0), (0, 0, limit * 1.001)]))
    assert reason.startswith("speed of b reached") and "the 31 its forces allow" in reason


def test_speed_bound_with_wind_counts_the_air_speed():
    """Drag toward w = (10, 0, 0) from v0 = 0, no other force: |v| <= |w| + |v0 - w| = 20 m/s."""
    forces = Forces(air_velocity_world=np.array([10.0, 0, 0]), linear_drag=np.array([1.0]))
    scene = DynamicsScene("s", "", "analytic", (_body(),), forces, 2.0, (0.1,))
    assert "the 20 its" in divergence(scene, _trajectory([(0, 0, 0.0), (41.0, 0, 0)]))


def test_angular_speed_bound_from_rotational_energy():
    """omega0 = (1, 0, 0) about I_min = 1 under angular drag (which only takes energy away): KE_rot = 1/2,
    |omega| <= sqrt(2 KE / I_min) = 1 rad/s."""
    scene = DynamicsScene("s", "", "analytic", (_body(omega=(1.0, 0, 0)),), Forces(angular_linear_drag=np.array([0.1])),
                          2.0, (0.1,))
    assert divergence(scene, _trajectory([(0, 0, 0.0)] * 2, omegas=[(1.0, 0, 0), (0, 1.9, 0)])) == ""
    assert "angular speed of b reached 2.1" in divergence(
        scene, _trajectory([(0, 0, 0.0)] * 2, omegas=[(1.0, 0, 0), (0, 2.1, 0)]))


def test_energy_that_more_than_doubles_is_divergence():
    """m = 2, g = 10, at height 5 at rest: it has no kinetic energy and drops nowhere, so its energy scale is
    m |g| size = 2 * 10 * sqrt(6 / 4) = 24.5 J (not E(0) = 100 J, which depends on the origin); a run that ends at
    height 5 moving at 12 m/s has gained 144 J = 5.88 x that: diverged, though 12 m/s is within the speed bound
    (|g| T = 20)."""
    for lift in (0.0, 1000.0):
        scene = DynamicsScene("s", "", "analytic", (_body(position=(0, 0, 5.0 + lift)),), Forces(np.array([0, 0, -10.0])),
                              2.0, (0.1,))
        traj = _trajectory([(0, 0, 0.0), (12.0, 0, 0)], positions=[(0, 0, 5.0 + lift), (0, 0, 5.0 + lift)])
        assert divergence(scene, traj).startswith("energy of b rose by 5.88 x its energy scale 24.5 J")


def test_a_blown_up_stiff_rod_is_diverged():
    """A rod (inertia 1:1000) spinning at 50 rad/s about its long axis, wobbling: explicit Euler at 10 ms blows up
    (to ~750 rad/s, energy x 100s) while staying finite; RK4 stays ok. (The old 1e6 x bound passed it.)"""
    rod = RigidBody("rod", 1.0, np.diag([1e-3, 1.0, 1.0]), np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3),
                    np.array([50.0, 1.0, 0.5]))
    scene = DynamicsScene("rod", "", "analytic", (rod,), Forces(), 2.0, (0.01,),
                          integrators=("explicit_euler", "rk4"))
    rows = run_scene(scene, [make_engine("core")], make_engine, repeats=1)
    status = {r.integrator: r for r in rows if r.metric == "angular_velocity_error_max"}
    assert status["explicit_euler"].status == DIVERGED and "angular speed of rod" in status["explicit_euler"].detail
    assert status["rk4"].status == OK and not math.isnan(status["rk4"].value)
