"""Core's floating base stepped through time (core/articulated/stepping.py, core/articulated/motion.py, issue #46)
against laws that need no engine: joint forces are internal, so a robot in free flight keeps its linear momentum and
its angular momentum about its centre of mass; under gravity it moves as in free flight (the equivalence principle), its
momentum growing by m g t; a robot translating with its joints at rest moves on a straight line at constant speed. Against the other engines: tests/references/
test_floating_motion_engines.py."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.core.articulated import stepping
from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from tests.helpers import solo12_leg

DURATION = 0.5
"""[s] Long enough for the leg to wind up (0.6 rad) and the base to turn half a radian."""
Q0 = np.array([0.1, -0.2, 0.4, 0.8775825618903728, 0.0, 0.479425538604203, 0.0, 0.3, 0.8, -1.6])
QDOT0 = np.array([0.2, -0.1, 0.3, 0.5, 1.0, -0.7, 1.0, -2.0, 3.0])
TORQUE = np.array([0.02, -0.03, 0.01])
ORDER_BAND = 0.3
"""How far an observed order of the momentum drift may be from the scheme's over one halving of dt (the drift's
leading term dominates at these steps: measured within 0.05)."""
ROUNDING = 1e-12
"""Relative momentum and position error of rounding over a hundred steps of sums of order-1 terms."""


@pytest.fixture(scope="module")
def leg():
    return solo12_leg()


def _scene(chain, gravity=None, q0=Q0, qdot0=QDOT0, torque=TORQUE) -> JointMotionScene:
    return JointMotionScene(name="free-flight", description="", reference="core", chain=chain, gravity_world=gravity,
                            q0=q0, qdot0=qdot0, torque=torque, duration=DURATION, dts=(0.01,))


def _momentum_drift(scene: JointMotionScene, scheme: str, dt: float) -> float:
    """max_t |(P, L)(t) - (P, L)(0)| [SI] of core's run (angular momentum about the world's origin)."""
    sim = CoreJointMotion(scene, scheme, dt)
    traj = sim.run(scene.n_steps(dt))
    momentum = sim.momentum(traj.q[:, 0], traj.qdot[:, 0])
    return float(np.abs(momentum - momentum[0]).max())


@pytest.mark.parametrize("scheme, dt", [("explicit_euler", 0.0025), ("midpoint", 0.01), ("rk4", 0.01)])
def test_free_flight_keeps_its_momentum_up_to_the_scheme_s_error(leg, scheme, dt):
    """Joint torques act between links: the drift is the scheme's truncation alone, falling at its order as dt halves
    (from ``dt``, where the leading term dominates: explicit Euler's order at 10 ms is still 1.35)."""
    scene = _scene(leg)
    coarse, fine = _momentum_drift(scene, scheme, dt), _momentum_drift(scene, scheme, dt / 2)
    order = stepping.ORDER[scheme]
    assert abs(np.log2(coarse / fine) - order) < ORDER_BAND, (coarse, fine)


@pytest.mark.parametrize("scheme", stepping.SCHEMES)
def test_under_gravity_the_robot_moves_as_in_free_flight_and_its_momentum_grows_by_m_g_t(leg, scheme):
    """The equivalence principle: uniform gravity is an acceleration of the whole robot, so its orientation and joints
    move exactly as without gravity and its momentum differs by m g t, step by step, to rounding, in every scheme (a
    stage's gravity is constant, and each scheme adds it as it adds any acceleration)."""
    gravity = np.array([0.3, -0.2, -9.81])
    mass = leg.base_inertia.mass + sum(j.link.mass for j in leg.joints)
    free, falling = (CoreJointMotion(_scene(leg, g), scheme, 0.01) for g in (None, gravity))
    a, b = free.run(50), falling.run(50)
    assert np.abs(b.q[:, 0, 3:] - a.q[:, 0, 3:]).max() < ROUNDING
    grown = falling.momentum(b.q[:, 0], b.qdot[:, 0])[:, :3] - free.momentum(a.q[:, 0], a.qdot[:, 0])[:, :3]
    assert np.abs(grown - mass * np.outer(a.times, gravity)).max() < ROUNDING * mass * 9.81


def test_a_robot_translating_with_its_joints_at_rest_moves_on_a_straight_line(leg):
    """No rotation, no joint motion, no force: every scheme moves the base by v t exactly (to rounding), the
    quaternion and the joints untouched."""
    still = QDOT0.copy()
    still[3:] = 0.0
    scene = _scene(leg, qdot0=still, torque=np.zeros(3))
    for scheme in stepping.SCHEMES:
        traj = CoreJointMotion(scene, scheme, 0.01).run(scene.n_steps(0.01))
        expected = Q0[:3] + np.outer(traj.times, still[:3])
        assert np.abs(traj.q[:, 0, :3] - expected).max() < ROUNDING, scheme
        assert np.abs(traj.q[:, 0, 3:] - Q0[3:]).max() < ROUNDING, scheme
        assert np.abs(traj.qdot[:, 0] - still).max() < ROUNDING, scheme


def test_the_quaternion_stays_unit(leg):
    traj = CoreJointMotion(_scene(leg), "explicit_euler", 0.01).run(50)
    assert np.abs(np.linalg.norm(traj.q[:, 0, 3:7], axis=1) - 1.0).max() < 1e-15


def test_a_floating_scene_refuses_what_it_cannot_mean(leg):
    """A quaternion that is not unit, a perturbation or segments (they move every configuration component alike): one
    SceneError naming the key each."""
    bad = Q0.copy()
    bad[3] = 0.9
    with pytest.raises(SceneError, match="base_quat_wxyz.*length"):
        _scene(leg, q0=bad)
    with pytest.raises(SceneError, match="perturbation.*floating base"):
        JointMotionScene(name="x", description="", reference="core", chain=leg, gravity_world=None, q0=Q0,
                         qdot0=QDOT0, torque=TORQUE, duration=1.0, dts=(0.01,), perturbation=1e-4)
    with pytest.raises(SceneError, match="qdot0"):
        _scene(leg, qdot0=QDOT0[:-1])
