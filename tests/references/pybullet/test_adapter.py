"""PyBullet adapter: overridden defaults and conventions pinned; kinematics and dynamics checked."""

import dataclasses
import tempfile

import numpy as np
import pybullet

from simparity.references.common.conventions import wxyz_from_xyzw, xyzw_from_wxyz
from simparity.references.pybullet.adapter import PybulletEngine
from simparity.references.common.urdf_export import body_urdf
from tests.helpers import builtin, exact_projectile, tumbling_box

ACCUMULATED_ROUNDING_TOL = 1e-9




def test_projectile_error_is_semi_implicit_eulers():
    """PyBullet's step is semi-implicit Euler: position off by exactly g t dt / 2, velocity exact."""
    scene = builtin("lecture-projectile")
    dt = scene.dts[-1]
    traj = PybulletEngine().build_dynamics(scene, "euler", dt).run(scene.n_steps(dt))
    position, velocity = exact_projectile(scene, traj.times)
    offset = scene.forces.gravity_world * traj.times[:, None, None] * dt / 2
    np.testing.assert_allclose(traj.position_world - position, offset, atol=ACCUMULATED_ROUNDING_TOL)
    np.testing.assert_allclose(traj.velocity_world, velocity, atol=ACCUMULATED_ROUNDING_TOL)


def test_default_damping_is_overridden():
    """Without gravity a moving body keeps its velocity exactly (PyBullet's default 0.04 damping is off)."""
    scene = tumbling_box(inertia_body=0.2 * np.eye(3), gravity=None, duration=1.0)
    traj = PybulletEngine().build_dynamics(scene, "euler", scene.dts[0]).run(240)
    np.testing.assert_allclose(traj.velocity_world[-1, 0], scene.bodies[0].velocity_world, rtol=1e-14)
    np.testing.assert_allclose(traj.angular_velocity_world[-1, 0], scene.bodies[0].angular_velocity_world, rtol=1e-13)


def _plain_pybullet_velocity(velocity, omega, steps, damping=None):
    """(linear, angular) velocity of the test box after ``steps`` steps in PyBullet loaded the plain
    way (no gravity, every default kept except, if given, the damping)."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as f:
            f.write(body_urdf(tumbling_box(inertia_body=0.2 * np.eye(3)).bodies[0]))
        uid = pybullet.loadURDF(f.name, flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        if damping is not None:
            pybullet.changeDynamics(uid, -1, linearDamping=damping, angularDamping=damping, physicsClientId=client)
        pybullet.resetBaseVelocity(uid, velocity, omega, physicsClientId=client)
        for _ in range(steps):
            pybullet.stepSimulation(physicsClientId=client)
        linear, angular = pybullet.getBaseVelocity(uid, physicsClientId=client)
    finally:
        pybullet.disconnect(client)
    return np.array(linear), np.array(angular)


def test_default_damping_exists_so_the_override_matters():
    """Control: a body loaded the plain way (defaults) loses speed, so the adapter's override is needed."""
    linear, _ = _plain_pybullet_velocity([10.0, 0, 0], [0, 0, 0], 240)
    assert np.linalg.norm(linear) < 9.0  # 10 m/s decays to ~6.9 m/s in 1 s with the default damping


def test_default_velocity_cap_is_raised():
    """PyBullet clips a 300 rad/s spin to 100 rad/s by default; the adapter keeps it (isotropic, torque-free)."""
    _, angular = _plain_pybullet_velocity([0, 0, 0], [0, 0, 300.0], 10, damping=0.0)
    np.testing.assert_allclose(angular, [0, 0, 100.0])  # the default cap, measured
    scene = tumbling_box(inertia_body=0.2 * np.eye(3), gravity=None, duration=10 / 240)
    body = dataclasses.replace(scene.bodies[0], angular_velocity_world=np.array([0.0, 0.0, 300.0]))
    traj = PybulletEngine().build_dynamics(dataclasses.replace(scene, bodies=(body,)), "euler", 1 / 240).run(10)
    np.testing.assert_allclose(traj.angular_velocity_world[-1, 0], [0, 0, 300.0], atol=1e-12)


def test_slow_body_keeps_moving():
    """A body drifting at 1 mm/s for 5 s keeps its velocity (sleeping is off; 3.2.7's defaults did not sleep either)."""
    scene = tumbling_box(inertia_body=0.2 * np.eye(3), gravity=None, duration=5.0)
    body = dataclasses.replace(scene.bodies[0], velocity_world=np.array([1e-3, 0.0, 0.0]),
                               angular_velocity_world=np.zeros(3))
    traj = PybulletEngine().build_dynamics(dataclasses.replace(scene, bodies=(body,)), "euler", 1 / 240).run(1200)
    np.testing.assert_allclose(traj.velocity_world[-1, 0], [1e-3, 0, 0], rtol=1e-12)
    np.testing.assert_allclose(traj.position_world[-1, 0] - traj.position_world[0, 0], [5e-3, 0, 0], rtol=1e-9)


def test_quaternion_order_conversion():
    """x,y,z,w <-> w,x,y,z round-trips and puts w where each side expects it."""
    q = np.array([0.9, 0.1, -0.3, 0.2])
    np.testing.assert_array_equal(xyzw_from_wxyz(q), [0.1, -0.3, 0.2, 0.9])
    np.testing.assert_array_equal(wxyz_from_xyzw(xyzw_from_wxyz(q)), q)
