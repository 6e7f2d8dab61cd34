"""Every engine's FK and Jacobian against core's, on the lecture's arm, random spatial chains and library robots.

The UR5 comes from its DH parameters; the iiwa is loaded from its URDF file by each engine's
own importer (core reads it with its own URDF reader).
"""

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.kinematics import forward_kinematics, jacobian_world
from simparity.core.rotations import geodesic_angle_matrix
from tests.helpers import builtin, random_chain, unlimited

# Double-precision kinematics of ~1 m chains agree to ~1e-15; 1e-12 is the project's bound.
DOUBLE_TOL = 1e-12
# PyBullet's getLinkState is FLOAT32: ~6e-8 relative on coordinates up to ~3 m and ~3e-7
# rad; these leave a factor ~3-8 of margin. Its calculateJacobian is double.
FLOAT32_POSITION_TOL = 1e-6  # [m]
FLOAT32_ORIENTATION_TOL = 2e-6  # [rad]
FRAME_TOLERANCES = {  # engine -> (position [m], orientation [rad])
    "mujoco": (DOUBLE_TOL, DOUBLE_TOL),
    "pinocchio": (DOUBLE_TOL, DOUBLE_TOL),
    "pybullet": (FLOAT32_POSITION_TOL, FLOAT32_ORIENTATION_TOL),
}


def _case(name):
    """(chain, configurations) of a named case."""
    if name in ("lecture-planar-arm", "ur5-kinematics", "iiwa-kinematics"):
        scene = builtin(name)
        return scene.chain, scene.configurations()
    rng = np.random.default_rng(21)
    if name.startswith("unlimited"):  # revolute only: URDF has no unlimited prismatic joint
        chain = unlimited(random_chain(rng, int(name.split("-")[-1]), prismatic_every=0))
    else:
        chain = random_chain(rng, int(name.split("-")[-1]))
    lower = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    upper = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    return chain, rng.uniform(lower, upper, size=(100, chain.n_joints))


@pytest.mark.parametrize("case", ["lecture-planar-arm", "random-7", "random-12", "unlimited-7", "ur5-kinematics",
                                  "iiwa-kinematics"])
@pytest.mark.parametrize("engine", sorted(FRAME_TOLERANCES))
def test_frames_and_jacobian_agree_with_core(engine, case):
    """Every link frame within the engine's precision; the end-effector Jacobian to 1e-12."""
    chain, q = _case(case)
    model = make_engine(engine).build_kinematics(chain)
    poses, ref = model.forward_kinematics(q), forward_kinematics(chain, q)
    position_tol, orientation_tol = FRAME_TOLERANCES[engine]
    np.testing.assert_allclose(poses.position_world, ref.position_world, atol=position_tol)
    assert geodesic_angle_matrix(poses.rotation_world, ref.rotation_world).max() <= orientation_tol
    np.testing.assert_allclose(model.jacobian_world(q), jacobian_world(chain, q), atol=DOUBLE_TOL)


def test_library_scenes_are_what_the_issue_asks():
    """1000 configurations each; the iiwa is handed to the engines as its original URDF file."""
    for name in ("ur5-kinematics", "iiwa-kinematics"):
        assert builtin(name).n_configurations == 1000
    assert builtin("iiwa-kinematics").chain.urdf_path.endswith("kuka_iiwa/model.urdf")
    assert builtin("ur5-kinematics").chain.urdf_path is None


@pytest.mark.parametrize("engine", ["pybullet", "pinocchio"])
def test_unlimited_prismatic_joint_is_not_available_in_urdf_engines(engine):
    """A chain URDF cannot express gets n/a with the joint named, not a crash."""
    chain = unlimited(random_chain(np.random.default_rng(3), 3))
    support = make_engine(engine).supports_kinematics(chain)
    assert not support.ok and "prismatic joint 'j2'" in support.reason


@pytest.mark.parametrize("engine", sorted(FRAME_TOLERANCES))
def test_sub_chain_of_a_urdf_file_with_joints_beyond_the_tip(engine):
    """The iiwa file cut at link 5 (two movable joints past the tip): engines map the chain's joints by name."""
    from simparity.core.urdf import chain_from_urdf

    chain = chain_from_urdf(builtin("iiwa-kinematics").chain.urdf_path, tip_link="lbr_iiwa_link_5")
    q = np.random.default_rng(8).uniform(chain.lower, chain.upper, size=(50, chain.n_joints))
    model = make_engine(engine).build_kinematics(chain)
    position_tol, _ = FRAME_TOLERANCES[engine]
    np.testing.assert_allclose(model.forward_kinematics(q).position_world, forward_kinematics(chain, q).position_world,
                               atol=position_tol)
    np.testing.assert_allclose(model.jacobian_world(q), jacobian_world(chain, q), atol=DOUBLE_TOL)
