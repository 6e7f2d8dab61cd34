"""What MuJoCo is given for a chain's contact (``references/mujoco/contact.py``), each default pinned: a plane and one
sphere geom per contact sphere on its frame's body, frictionless, no margin, its default soft-contact constants, only
contact among the constraints, no mass added; its sphere centres those of core's FK, and its forces push along the
normal only."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from simparity.comparisons.api import load_scene
from simparity.core.articulated.motion import CoreJointMotion
from simparity.references.mujoco.contact import SOLIMP, SOLREF, SPHERE_PREFIX
from simparity.references.mujoco.joint_dynamics import ChainModel
from simparity.references.mujoco.joint_motion import MujocoJointMotion

FK_AGREEMENT = 1e-12
"""[m] Two forward kinematics of one URDF: rounding of a few products of order-1 numbers."""


@pytest.fixture(scope="module")
def scene():
    return load_scene("solo12-drop-stand")


def test_the_geoms_and_options_are_the_scene_s_and_nothing_else(scene):
    model = MujocoJointMotion(scene, "euler", 0.002).model
    bare = ChainModel(scene.chain, scene.gravity_world).model
    spheres = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{SPHERE_PREFIX}{k}")
               for k in range(len(scene.contact.spheres))]
    planes = np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
    assert model.ngeom == len(spheres) + 1 and len(planes) == 1 and min(spheres) >= 0
    np.testing.assert_array_equal(model.geom_size[spheres, 0], scene.contact.radii)
    assert np.all(model.geom_condim == 1) and np.all(model.geom_margin == 0) and np.all(model.geom_gap == 0)
    np.testing.assert_array_equal(model.geom_solref, np.tile(SOLREF, (model.ngeom, 1)))
    np.testing.assert_array_equal(model.geom_solimp, np.tile(SOLIMP, (model.ngeom, 1)))
    assert np.all(model.geom_contype[spheres] == 0) and np.all(model.geom_conaffinity[spheres] == 1)
    assert model.geom_contype[planes[0]] == 1 and model.geom_conaffinity[planes[0]] == 0  # spheres touch the plane only
    disabled = model.opt.disableflags
    for flag in (mujoco.mjtDisableBit.mjDSBL_LIMIT, mujoco.mjtDisableBit.mjDSBL_EQUALITY,
                 mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS):
        assert disabled & flag
    assert not disabled & (mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    np.testing.assert_array_equal(model.body_mass, bare.body_mass)  # the geoms weigh nothing
    np.testing.assert_array_equal(model.body_inertia, bare.body_inertia)


def test_sphere_centres_agree_with_core_s_fk_and_forces_push_along_the_normal(scene):
    rng = np.random.default_rng(46)
    q = np.tile(scene.q0, (5, 1))
    q[:, 7:] = rng.uniform(-1, 1, (5, 3))
    q[:, 2] = 0.33  # every foot below the plane's level: pressing
    qdot = rng.uniform(-0.1, 0.1, (5, scene.chain.nv))
    mj, core = MujocoJointMotion(scene, "euler", 0.002), CoreJointMotion(scene, "rk4", 0.002)
    np.testing.assert_allclose(mj.contact_centres(q), core.contact_centres(q), rtol=0, atol=FK_AGREEMENT)
    times = np.zeros(len(q))
    for forces in (mj.contact_forces(q, qdot, times), core.contact_forces(q, qdot, times)):
        assert np.all(forces[..., :2] == 0.0) and np.all(forces[..., 2] >= 0.0) and np.any(forces[..., 2] > 0.0)
