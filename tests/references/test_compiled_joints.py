"""Each engine's compiled joints (type and limits, `JointDynamicsModel.compiled_joints`) read from real robot files,
and the two importer differences the scan of every example-robot-data and pybullet_data URDF found (issue #43), each
pinned with the file that shows it: MuJoCo reads lower == upper as no limit; PyBullet keeps a continuous joint's
written limits. Elsewhere every importer agrees with core's parser."""

from __future__ import annotations

import math
from importlib import metadata

import numpy as np
import pytest

from simparity.comparisons.measure.model_parity import joint_parity
from simparity.comparisons.scenes import library
from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_ROBOTS
from simparity.core.articulated.groups import chain_compiled_joints
from simparity.core.urdf import chain_from_urdf
from simparity.references.mujoco.joint_dynamics import MujocoJointDynamics
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics
from simparity.references.pybullet.joint_dynamics import PybulletJointDynamics

ENGINES = {"mujoco": MujocoJointDynamics, "pinocchio": PinocchioJointDynamics, "pybullet": PybulletJointDynamics}


def _robot(path: str, tip: str):
    robots = metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)
    return chain_from_urdf(str(robots / path), tip_link=tip, dynamics=True)


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_every_importer_reads_the_crafted_arm_s_types_and_limits_as_core(engine):
    """A revolute joint limited at +-2.5 rad, a prismatic one at [-0.2, 0.3] m and a continuous one: each engine's own
    way of saying 'unlimited' read by its adapter."""
    chain = library.load(["crafted-arm-dynamics"])[0].chain
    compiled = ENGINES[engine](chain, None).compiled_joints()
    assert compiled.prismatic.tolist() == [False, True, False]
    assert compiled.lower.tolist() == [-2.5, -0.2, -math.inf] and compiled.upper.tolist() == [2.5, 0.3, math.inf]
    values = joint_parity(compiled, chain_compiled_joints(chain), tuple(j.name for j in chain.joints))
    assert all(v.value == 0.0 for v in values.values())


def test_mujoco_reads_lower_equal_upper_as_no_limit():
    chain = _robot("double_pendulum_description/urdf/double_pendulum.urdf", "link2")  # <limit lower="0" upper="0">
    names = tuple(j.name for j in chain.joints)
    core = chain_compiled_joints(chain)
    assert core.lower.tolist() == [0.0, 0.0] and core.upper.tolist() == [0.0, 0.0]
    mujoco = ENGINES["mujoco"](chain, None).compiled_joints()
    assert np.all(np.isinf(mujoco.lower)) and np.all(np.isinf(mujoco.upper))
    counted = joint_parity(mujoco, core, names)["model_limit_mismatches"]
    assert counted.value == 2.0 and "'joint1'" in counted.note and "unlimited" in counted.note
    for engine in ("pinocchio", "pybullet"):
        assert joint_parity(ENGINES[engine](chain, None).compiled_joints(), core, names)[
            "model_limit_mismatches"].value == 0.0


def test_pybullet_keeps_a_continuous_joint_s_written_limits():
    chain = _robot("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector")
    names = tuple(j.name for j in chain.joints)
    core = chain_compiled_joints(chain)
    assert math.isinf(core.lower[0])  # j2s6s200_joint_1: continuous, <limit lower="-6.28318530718" ...>
    pybullet = ENGINES["pybullet"](chain, None).compiled_joints()
    assert pybullet.lower[0] == pytest.approx(-6.28318530718, rel=1e-15)
    counted = joint_parity(pybullet, core, names)["model_limit_mismatches"]
    assert counted.value >= 1.0 and "'j2s6s200_joint_1'" in counted.note
    for engine in ("mujoco", "pinocchio"):
        assert joint_parity(ENGINES[engine](chain, None).compiled_joints(), core, names)[
            "model_limit_mismatches"].value == 0.0
