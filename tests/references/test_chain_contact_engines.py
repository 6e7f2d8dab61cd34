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


CONE_ROUNDING = 1e-12
"""[1] A force on its Coulomb cone's edge, |f_t| - mu f_n relative to f_n: rounding of a norm and a product."""
SLIDING = 0.5
"""[m/s] The test's slip along the slope: 50 x core's friction regularisation speed (1e-2 m/s), so that its friction
is the full Coulomb force there."""


@pytest.fixture(scope="module")
def slope():
    return load_scene("solo12-incline-slide")


def test_mujoco_gets_the_scene_s_friction_on_an_elliptic_cone(slope):
    model = MujocoJointMotion(slope, "euler", 0.001).model
    assert np.all(model.geom_condim == 3) and model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    np.testing.assert_array_equal(model.geom_friction, np.tile([slope.contact.friction, 0.0, 0.0], (model.ngeom, 1)))


def _pressed_sliding(scene, copies: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, qdot, the unit slip direction (3,)): the base pressed 1 mm into the slope and translating downhill at
    :data:`SLIDING`, no rotation, the free leg still."""
    normal = np.asarray(scene.contact.plane.normal_world)
    downhill = np.array([0.0, 0.0, -1.0]) - normal * -normal[2]
    downhill /= np.linalg.norm(downhill)
    q = np.tile(scene.q0, (copies, 1))
    q[:, :3] -= (0.002 + rng.uniform(0.0, 1e-3, (copies, 1))) * normal  # 2 mm of drop, then pressing
    qdot = np.zeros((copies, scene.chain.nv))
    qdot[:, :3] = SLIDING * downhill
    return q, qdot, downhill


def test_core_s_friction_is_coulomb_s_against_the_slip_and_mujoco_s_stays_in_its_cone(slope):
    """Translating without rotation, every contact point slips with the base: core's friction is -mu f_n along that
    slip (the law itself, not core's numbers); MuJoCo's soft friction is its own, but never outside the cone."""
    q, qdot, downhill = _pressed_sliding(slope, 4, np.random.default_rng(46))
    normal, mu, times = np.asarray(slope.contact.plane.normal_world), slope.contact.friction, np.zeros(4)
    core = CoreJointMotion(slope, "rk4", 0.001).contact_forces(q, qdot, times)
    f_n = core @ normal
    assert np.all(f_n > 0)
    tangential = core - f_n[..., None] * normal
    np.testing.assert_allclose(tangential, -mu * f_n[..., None] * downhill, rtol=0, atol=CONE_ROUNDING * f_n.max())
    mj = MujocoJointMotion(slope, "euler", 0.001).contact_forces(q, qdot, times)
    mj_n = mj @ normal
    assert np.all(mj_n > 0)
    mj_t = np.linalg.norm(mj - mj_n[..., None] * normal, axis=-1)
    assert np.all(mj_t <= mu * mj_n * (1 + CONE_ROUNDING)) and np.all(mj_t > 0)
