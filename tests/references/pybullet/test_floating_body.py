"""PyBullet's free multibody in the project's floating-base convention (:mod:`references.pybullet.floating_body`):
Go1's trunk has its centre of mass off the link origin and a non-diagonal inertia (so a turned principal frame), the
case where PyBullet's base frame is not the base link's. The base's centre of mass is checked against the file's
``<inertial>`` read here, and the energy and momentum summed from PyBullet's links against Pinocchio's model."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from simparity.comparisons.api import load_scene
from simparity.references.common.conventions import quat_wxyz_to_matrix
from simparity.references.common.dynamics_urdf import dynamics_urdf
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pybullet.floating_body import MassStates
from simparity.references.pybullet.joint_dynamics import ChainBodies
from simparity.references.pybullet.quiet import pybullet
from tests.helpers import floating_states

ROUND_TRIP = 1e-14
"""[m, 1, m/s, rad/s] A state put on the body and read back: a quaternion product and its conjugate's, and one
cross product, on values of order 1."""
FILE_POSE = 1e-15
"""[m, m/s] The base's centre of mass against the file's <inertial> origin: one rotation of a ~2 cm offset."""
MODEL_RTOL = 1e-7
"""[1] PyBullet's links against Pinocchio's model: Bullet diagonalises each inertia by its Jacobi iteration and drops
what is left off the diagonal (8e-9 relative on the Panda, docs of references/pybullet/joint_dynamics.py); the
masses and centres of mass are the file's."""


@pytest.fixture(scope="module")
def go1():
    chain = load_scene("go1-floating-dynamics").chain
    return chain, ChainBodies(chain, np.array([0.0, 0.0, -9.81]))


def test_a_state_put_on_the_body_is_read_back(go1):
    chain, bodies = go1
    q, v, _, _ = floating_states(chain, 5, seed=11)
    for row, rates in zip(q, v):
        bodies.reset(row, rates)
        back_q, back_v = bodies.state()
        sign = np.sign(back_q[3:7] @ row[3:7])  # q and -q are one rotation
        np.testing.assert_allclose(back_q * np.r_[1, 1, 1, [sign] * 4, np.ones(len(row) - 7)], row, atol=ROUND_TRIP)
        np.testing.assert_allclose(back_v, rates, atol=ROUND_TRIP)


def test_the_base_s_centre_of_mass_is_where_the_file_puts_it(go1):
    chain, bodies = go1
    trunk = next(link for link in ET.fromstring(dynamics_urdf(chain)).iter("link") if link.get("name") == "trunk")
    offset = np.array([float(x) for x in trunk.find("inertial/origin").get("xyz").split()])
    assert np.linalg.norm(offset) > 0.02  # the case this test is for
    q, v, _, _ = floating_states(chain, 3, seed=12)
    for row, rates in zip(q, v):
        bodies.reset(row, rates)
        position, _ = pybullet.getBasePositionAndOrientation(bodies.body, physicsClientId=bodies.client)
        linear, angular = pybullet.getBaseVelocity(bodies.body, physicsClientId=bodies.client)
        arm = quat_wxyz_to_matrix(row[3:7]) @ offset
        np.testing.assert_allclose(position, row[:3] + arm, atol=FILE_POSE)
        np.testing.assert_allclose(linear, rates[:3] + np.cross(rates[3:6], arm), atol=FILE_POSE)
        np.testing.assert_allclose(angular, rates[3:6], atol=FILE_POSE)


def test_energy_and_momentum_from_its_links_are_pinocchio_s(go1):
    chain, bodies = go1
    truth = PinocchioFloatingDynamics(chain, np.array([0.0, 0.0, -9.81]))
    q, v, _, _ = floating_states(chain, 4, seed=13)
    kinetic = truth.link_kinetic_energy(q, v)
    linear, angular, _ = truth.centroidal_momentum(q, v)
    for k, (row, rates) in enumerate(zip(q, v)):
        bodies.reset(row, rates)
        states = MassStates.of(bodies.client, bodies.body, bodies.links)
        assert states.kinetic() == pytest.approx(kinetic[k], rel=MODEL_RTOL)
        momentum = states.momentum()
        scale = np.linalg.norm(np.r_[linear[k], angular[k]])
        np.testing.assert_allclose(momentum, np.r_[linear[k], angular[k]], atol=MODEL_RTOL * scale)


def test_a_free_base_without_mass_is_n_a_with_why():
    """Bullet holds a free multibody whose base has no mass kinematic: a1's root ``base`` (its ``trunk`` welded to it)
    flew 1.35 rad off at every step while every check passed (a held-out trial); the base with a mass is stepped."""
    from simparity.comparisons.scenes.loading.scene_file import parse_scene
    from simparity.references.pybullet.adapter import PybulletEngine

    data = {"scene": {"name": "a1-root", "kind": "joint_motion", "reference": "pinocchio"},
            "chain": {"urdf": "example-robot-data:a1_description/urdf/a1.urdf", "base_link": "base",
                      "tip_link": "FR_foot", "floating_base": True},
            "initial": {"q": [0.2, 0.7, -1.5]}, "simulation": {"duration": 0.1, "dt": [0.01]}}
    support = PybulletEngine().supports_joint_motion(parse_scene(data, "a1-root.toml"), "euler")
    assert not support.ok and "'base' has mass 0" in support.reason
    data["chain"]["base_link"] = "trunk"
    assert PybulletEngine().supports_joint_motion(parse_scene(data, "a1-trunk.toml"), "euler").ok


DAMPING_FREE = 1e-12
"""[1] A free base sliding with nothing acting keeps its momentum to rounding; Bullet's default link damping (0.04,
body-wide) left on the base took 2.7e-2 of it over the 0.5 s here (measured)."""


def test_a_free_base_has_no_default_damping():
    """Go1 thrown without a turn, its joints still, no gravity and no torque: nothing acts, so PyBullet's step (its
    base's linear damping set to 0 by the adapter) keeps the robot's momentum."""
    from dataclasses import replace

    from simparity.references.pybullet.joint_motion import PybulletJointMotion

    scene = load_scene("go1-free-flight")
    qdot0 = np.zeros_like(scene.qdot0)
    qdot0[:, :3] = [0.2, -0.1, 0.3]
    sliding = replace(scene, qdot0=qdot0, torque=np.zeros_like(scene.torque), gravity_world=None)
    sim = PybulletJointMotion(sliding, 0.005)
    traj = sim.run(sliding.n_steps(0.005))
    momentum = sim.momentum(traj.q[[0, -1], 0], traj.qdot[[0, -1], 0])
    np.testing.assert_allclose(momentum[1], momentum[0], atol=DAMPING_FREE * np.linalg.norm(momentum[0]))
