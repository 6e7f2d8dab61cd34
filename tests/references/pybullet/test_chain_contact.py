"""PyBullet's contact of a fixed-base chain's spheres with a plane (``references/pybullet/chain_contact.py``, issue
#46): every default it sets, pinned; the spheres placed where Pinocchio's independent model places them; the force of
one step from a pressed state the same as Pinocchio's time-stepping contact gives (both solve the same velocity-level
problem: two codes, one answer); a sphere above the plane pushed by nothing; copies that never touch each other; a
sliding foot's friction on the Coulomb cone of the scene's mu."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pybullet
import pytest

from simparity.comparisons.api import load_scene
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pybullet.adapter import FLOATING_MJCF_WHY, PybulletEngine
from simparity.references.pybullet.chain_contact import SOLVER, SPHERE_DYNAMICS
from simparity.references.pybullet.joint_dynamics import ChainBodies
from simparity.references.pybullet.joint_motion import PybulletJointMotion, _world

PLACED = 1e-12
"""[m] Two independent forward kinematics of the same file (PyBullet's double link states, Pinocchio's): rounding."""
SAME_STEP = 1e-8
"""Relative agreement of PyBullet's and Pinocchio's contact force from one state: the same semi-implicit Euler step
and frictionless velocity-level contact problem, solved by Bullet's PGS (every sweep) and by Pinocchio's ADMM,
polished: measured 2.4e-16."""
DT = 0.002


@pytest.fixture(scope="module")
def arm():
    return load_scene("arm-strike-press")


def test_the_spheres_weigh_nothing_and_take_every_contact_default(arm):
    bare, _ = _world(replace(arm, contact=None), DT, 1)
    world, contact = _world(arm, DT, 1)
    c = world.client
    for link in world.links:
        with_sphere = pybullet.getDynamicsInfo(world.body, link, physicsClientId=c)
        without = pybullet.getDynamicsInfo(bare.body, link, physicsClientId=bare.client)
        assert with_sphere[0] == without[0] and with_sphere[2] == without[2]  # mass, principal moments
    for link in set(contact.links):
        info = pybullet.getDynamicsInfo(world.body, link, physicsClientId=c)
        assert (info[1], info[5], info[6], info[7]) == (arm.contact.friction,
                                                        SPHERE_DYNAMICS["restitution"],
                                                        SPHERE_DYNAMICS["rollingFriction"],
                                                        SPHERE_DYNAMICS["spinningFriction"]) == (0.0, 0.0, 0.0, 0.0)
    parameters = pybullet.getPhysicsEngineParameters(physicsClientId=c)
    assert parameters["numSolverIterations"] == SOLVER["numSolverIterations"]
    assert parameters["fixedTimeStep"] == DT and parameters["numSubSteps"] == 0


@pytest.mark.parametrize("name", ["arm-strike-press", "pendulum-press"])
def test_the_spheres_are_where_an_independent_model_puts_them(name):
    scene = load_scene(name)
    rng = np.random.default_rng(46)
    q = scene.q0 + rng.uniform(-1.0, 1.0, size=(5, scene.chain.n_joints))
    ours = PybulletJointMotion(scene, DT).contact_centres(q)
    theirs = PinocchioEngine().build_joint_motion(scene, "semi_implicit_euler", DT).contact_centres(q)
    assert np.abs(ours - theirs).max() < PLACED


def test_a_pressed_arm_gets_the_force_pinocchio_s_contact_gives_and_a_lifted_one_none(arm):
    pressed = np.array([[0.95, -0.3], [0.9, -0.2]])  # both spheres into the plane, the arm driven down
    rates = np.array([[0.4, -0.1], [0.1, 0.3]])
    times = np.zeros(2)
    ours = PybulletJointMotion(arm, DT).contact_forces(pressed, rates, times)
    theirs = PinocchioEngine().build_joint_motion(arm, "semi_implicit_euler", DT).contact_forces(pressed, rates, times)
    assert np.abs(ours).max() > 1.0  # pushed: newtons, not rounding
    assert np.abs(ours - theirs).max() < SAME_STEP * np.abs(theirs).max()
    lifted = PybulletJointMotion(arm, DT).contact_forces(np.array([[0.0, 0.0]]), np.zeros((1, 2)), np.zeros(1))
    assert not lifted.any()


def test_copies_never_touch_each_other(arm):
    two = replace(arm, q0=np.repeat(arm.q0, 2, axis=0), qdot0=np.repeat(arm.qdot0, 2, axis=0))
    both = PybulletJointMotion(two, DT).run(120)  # through the strike
    alone = PybulletJointMotion(arm, DT).run(120)
    assert np.array_equal(both.q[:, 0], alone.q[:, 0]) and np.array_equal(both.q[:, 1], alone.q[:, 0])


def test_a_floating_base_on_the_ground_is_stepped_and_an_mjcf_one_is_n_a_with_why():
    scene = load_scene("solo12-drop-stand")
    assert PybulletEngine().supports_joint_motion(scene, "euler").ok
    assert PybulletEngine().chain_contact(scene).ok
    mjcf = replace(scene, chain=replace(scene.chain, urdf_path=None, mjcf_path="robot.xml"))
    support = PybulletEngine().supports_joint_motion(mjcf, "euler")
    assert not support.ok and support.reason == FLOATING_MJCF_WHY


def test_chain_bodies_without_contact_load_the_file_unchanged(arm):
    assert "<collision" not in ChainBodies(arm.chain, arm.gravity_world).urdf_text
    assert ChainBodies(arm.chain, arm.gravity_world, contact=arm.contact).urdf_text.count("<sphere") == 2


ON_THE_CONE = 1e-9
"""[1 of mu f_n] A sliding sphere's friction on Bullet's Coulomb cone: its rows scaled back onto it (measured 1 to
rounding); with ``enableConeFriction`` 0 each row is clamped alone, a box whose corner is sqrt(2) mu f_n."""


def test_a_sliding_foot_s_friction_is_on_the_cone_of_the_scene_s_mu():
    """``lateralFriction`` mu on every sphere link and ``enableConeFriction`` 1 (not readable back: pinned by what it
    does): Solo-12 pressed 0.1 mm into the slope and sliding downhill at 0.5 m/s, 30 degrees off Bullet's axes."""
    slope = load_scene("solo12-incline-slide")
    world, contact = _world(slope, DT, 1)
    assert {pybullet.getDynamicsInfo(world.body, link, physicsClientId=world.client)[1]
            for link in set(contact.links)} == {slope.contact.friction}
    normal = np.asarray(slope.contact.plane.normal_world)
    downhill = np.array([0.0, 0.0, -1.0]) + normal[2] * normal
    q, qdot = slope.q0.copy(), np.zeros((1, slope.chain.nv))
    q[0, :3] -= (0.002 + 1e-4) * normal  # the scene starts 2 mm above the plane
    qdot[0, :3] = 0.5 * downhill / np.linalg.norm(downhill)
    forces = PybulletJointMotion(slope, DT).contact_forces(q, qdot, np.zeros(1))[0]
    f_n = forces @ normal
    f_t = np.linalg.norm(forces - f_n[:, None] * normal, axis=1)
    assert np.all(f_n > 1.0)  # every foot pressed: newtons
    assert np.abs(f_t / (slope.contact.friction * f_n) - 1.0).max() < ON_THE_CONE
