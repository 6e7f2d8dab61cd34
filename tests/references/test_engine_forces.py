"""Each engine is given the scene's forces its own way; one step of each is checked by hand.

MuJoCo (mj_applyFT at the world point, dof_damping, xfrc_applied), PyBullet
(applyExternalForce at the world position, applyExternalTorque) and Pinocchio (aba's
fext via SE3.act) all take one semi-implicit Euler step: v1 = v0 + dt F / m and, with the
spin along a principal axis (no gyroscopic term), omega1 = omega0 + dt tau / I_zz.
"""

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.model.scenes.bodies import AppliedForce, Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from tests.helpers import HAND_WRENCH, hand_wrench_forces

ENGINES = [("mujoco", "euler"), ("pybullet", "euler"), ("pinocchio", "euler"), ("core", "engine_euler")]
DT = 0.01  # [s]
INERTIA = np.diag([0.1, 0.2, 0.3])  # [kg m^2]
ONE_STEP_TOL = 1e-13  # [m/s, rad/s]: one step of a few float64 operations on values of a few units


def _scene(body: RigidBody, forces: Forces) -> DynamicsScene:
    return DynamicsScene("hand", "-", "analytic", (body,), forces, DT, (DT,))


@pytest.mark.parametrize("engine, integrator", ENGINES)
def test_force_at_a_body_point_turns_the_body(engine, integrator):
    """f = (1, 0, 0) N at p = (0, 0.5, 0) m on a body at rest: tau = p x f = (0, 0, -0.5) N m."""
    body = RigidBody("b", 2.0, INERTIA, np.zeros(3), (1.0, 0.0, 0.0, 0.0), np.zeros(3), np.zeros(3))
    forces = Forces(applied=(AppliedForce(0, [1.0, 0.0, 0.0], [0.0, 0.5, 0.0]),))
    traj = make_engine(engine).build_dynamics(_scene(body, forces), integrator, DT).run(1)
    np.testing.assert_allclose(traj.velocity_world[1, 0], [DT * 1.0 / 2.0, 0.0, 0.0], rtol=0, atol=ONE_STEP_TOL)
    np.testing.assert_allclose(traj.angular_velocity_world[1, 0], [0.0, 0.0, -DT * 0.5 / 0.3], rtol=0,
                               atol=ONE_STEP_TOL)


@pytest.mark.parametrize("engine, integrator", ENGINES)
def test_every_force_of_the_hand_computed_wrench(engine, integrator):
    """Weight, drag in wind, quadratic drag, angular drags and a force at a turned body point, by hand."""
    h = HAND_WRENCH
    body = RigidBody("b", h["mass"], INERTIA, np.zeros(3), h["quat_wxyz"], h["velocity"], h["omega"])
    traj = make_engine(engine).build_dynamics(_scene(body, hand_wrench_forces()), integrator, DT).run(1)
    expected_v = np.array(h["velocity"]) + DT * np.array(h["expected_force"]) / h["mass"]
    expected_omega = np.array(h["omega"]) + DT * np.array(h["expected_torque"]) / INERTIA[2, 2]
    np.testing.assert_allclose(traj.velocity_world[1, 0], expected_v, rtol=0, atol=ONE_STEP_TOL)
    np.testing.assert_allclose(traj.angular_velocity_world[1, 0], expected_omega, rtol=0, atol=ONE_STEP_TOL)
