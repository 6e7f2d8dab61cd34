"""Pinocchio adapter: conventions pinned; kinematics and harness-stepped dynamics checked."""

import numpy as np
import pinocchio as pin
import pytest

from core.kinematics import forward_kinematics, jacobian_world
from core.scene import Chain
from references.pinocchio_adapter import PinocchioEngine, free_bodies_model
from tests.helpers import builtin, exact_projectile, random_chain, tumbling_box

KINEMATICS_TOL = 1e-12  # see tests/test_mujoco_adapter.py
ACCUMULATED_ROUNDING_TOL = 1e-9
# Pinocchio keeps the inertia as a packed symmetric matrix; reading it back rounds by 1 ulp.
STORED_INERTIA_RTOL = 1e-15


@pytest.mark.parametrize("which", ["planar-arm", "random-7", "unlimited"])
def test_fk_and_jacobian_agree_with_core(which):
    """Frames and Jacobian equal core's to 1e-12, continuous (nq = 2) joints included."""
    rng = np.random.default_rng(41)
    if which == "planar-arm":
        scene = builtin("lecture-planar-arm")
        chain, q = scene.chain, scene.configurations()
    else:
        chain = random_chain(rng, 7)
        if which == "unlimited":
            joints = tuple(j.__class__(j.name, j.type, j.axis, j.origin_xyz, j.origin_rotation)
                           if j.type == "revolute" else j for j in chain.joints)
            chain = Chain(chain.name, joints, chain.end_effector_name, chain.end_effector_xyz,
                          chain.end_effector_rotation)
        q = rng.uniform(-np.pi, np.pi, size=(100, chain.n_joints))
    model = PinocchioEngine().build_kinematics(chain)
    poses, ref = model.forward_kinematics(q), forward_kinematics(chain, q)
    np.testing.assert_allclose(poses.position_world, ref.position_world, atol=KINEMATICS_TOL)
    np.testing.assert_allclose(poses.rotation_world, ref.rotation_world, atol=KINEMATICS_TOL)
    np.testing.assert_allclose(model.jacobian_world(q), jacobian_world(chain, q), atol=KINEMATICS_TOL)


def test_projectile_error_is_semi_implicit_eulers():
    """The harness's Euler on aba: position off by exactly g t dt / 2, velocity exact."""
    scene = builtin("lecture-projectile")
    dt = scene.dts[-1]
    traj = PinocchioEngine().build_dynamics(scene, "euler", dt).run(scene.n_steps(dt))
    position, velocity = exact_projectile(scene, traj.times)
    offset = scene.forces.gravity_world * traj.times[:, None, None] * dt / 2
    np.testing.assert_allclose(traj.position_world - position, offset, atol=ACCUMULATED_ROUNDING_TOL)
    np.testing.assert_allclose(traj.velocity_world, velocity, atol=ACCUMULATED_ROUNDING_TOL)


def test_free_flyer_conventions():
    """q[3:7] is x,y,z,w and v is LOCAL: a body turned 90 deg about z moving +x in the world has v_local = -y."""
    scene = tumbling_box(quat_wxyz=(np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)), gravity=None)
    model = free_bodies_model(scene)
    data = model.createData()
    q = pin.neutral(model)
    q[3:7] = [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]  # x, y, z, w
    pin.forwardKinematics(model, data, q)
    np.testing.assert_allclose(data.oMi[1].rotation @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    v = np.zeros(6)
    v[:3] = data.oMi[1].rotation.T @ [1.0, 0, 0]
    np.testing.assert_allclose(v[:3], [0, -1, 0], atol=1e-15)
    pin.forwardKinematics(model, data, q, v)
    np.testing.assert_allclose(data.oMi[1].rotation @ data.v[1].linear, [1, 0, 0], atol=1e-15)


def test_model_inertia_and_gravity_are_the_scenes():
    """Mass, inertia about the COM and gravity in the model are exactly the scene's; no gravity when absent."""
    scene = tumbling_box()
    model = free_bodies_model(scene)
    np.testing.assert_allclose(model.inertias[1].inertia, scene.bodies[0].inertia_body, rtol=STORED_INERTIA_RTOL)
    assert model.inertias[1].mass == 2.0 and not np.any(model.inertias[1].lever)
    np.testing.assert_array_equal(model.gravity.linear, [0, 0, -9.81])
    assert not np.any(free_bodies_model(tumbling_box(gravity=None)).gravity.linear)
