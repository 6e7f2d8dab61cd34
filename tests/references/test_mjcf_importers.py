"""Every engine's own MJCF importer on the same file (issue #45): what each is given
(:mod:`references.common.dynamics_mjcf`), and each importer difference the robot corpus found, pinned on the smallest
file that shows it (docs/robots.md)."""

from __future__ import annotations

import os
import tempfile
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pybullet_data
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.mjcf import chain_from_mjcf
from simparity.references.common.dynamics_mjcf import dynamics_mjcf, mjcf_changes, mjcf_joint_names
from simparity.references.common.quiet import captured_output
from simparity.references.mujoco.joint_dynamics import MujocoJointDynamics
from simparity.references.pinocchio.joint_dynamics import pinocchio_dynamics_problem
from simparity.references.pybullet.adapter import FIXED_BASE_JOINT, _Client, _load_mjcf, pybullet_mjcf
from simparity.references.pybullet.quiet import pybullet

MJCF = os.path.join(pybullet_data.getDataPath(), "mjcf")
GRAVITY = np.array([0.0, 0.0, -9.81])
ROUNDING = 1e-12
"""Relative: the same numbers compiled by two codes (masses, inertias summed from geoms)."""


def _write(folder, text: str, name: str = "model.xml") -> str:
    path = os.path.join(folder, name)
    with open(path, "w", encoding="utf-8") as handle:
        handle.write(text)
    return path


def _pinocchio(text: str) -> pin.Model:
    with tempfile.TemporaryDirectory() as folder, captured_output():
        return pin.buildModelFromMJCF(_write(folder, text))


def _one_body(geom: str, joint: str = 'type="hinge" axis="1 0 0"', compiler: str = 'angle="radian"') -> str:
    return (f'<mujoco><compiler {compiler}/><worldbody><body name="a"><joint name="j" {joint}/>'
            f'<geom {geom}/></body></worldbody></mujoco>')


def test_the_file_given_keeps_the_chain_and_welds_the_rest(tmp_path):
    """The ant from its torso to one foot: the other legs' joints removed (welded at the file's pose), the actuators
    that name them left out, the torso at the origin without its free joint; MuJoCo's model of that file has the
    chain's joints only, and its masses are those of MuJoCo's own compile of the original file."""
    chain = chain_from_mjcf(os.path.join(MJCF, "ant.xml"), "torso", "front_left_foot", dynamics=True)
    assert mjcf_joint_names(chain) == ("hip_1", "ankle_1")
    changes = mjcf_changes(chain)
    assert changes.held == ("hip_2", "ankle_2", "hip_3", "ankle_3", "hip_4", "ankle_4")
    assert changes.sections == ("<actuator>",)
    given = mujoco.MjModel.from_xml_string(dynamics_mjcf(chain))
    original = mujoco.MjModel.from_xml_path(os.path.join(MJCF, "ant.xml"))
    assert given.njnt == 2 and given.nu == 0
    for body in range(1, given.nbody):
        name = given.body(body).name
        assert given.body_mass[body] == pytest.approx(original.body(name).mass[0], rel=ROUNDING), name
    assert np.array_equal(given.body_pos[1], np.zeros(3))  # the torso at the world's origin


def test_mujoco_s_own_options_of_the_file_are_overridden():
    """pybullet_data's reacher.xml asks for RK4 (mjd_inverseFD refuses it) and the pusher for gravity 0: the
    dynamics model is Euler, the scene's gravity, constraints off, no fluid forces."""
    chain = chain_from_mjcf(os.path.join(MJCF, "pusher.xml"), "world", "fingertip", dynamics=True)
    model = MujocoJointDynamics(chain, GRAVITY).model
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_EULER
    assert np.array_equal(model.opt.gravity, GRAVITY)
    assert model.opt.disableflags == mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    assert model.opt.density == model.opt.viscosity == 0.0 and not np.any(model.body_gravcomp)


def test_pinocchio_leaves_visual_geoms_out_of_a_body_s_mass():
    """A geom with contype = conaffinity = 0 counts for MuJoCo's inferred mass, not for Pinocchio's (pusher.xml and
    striker.xml default every geom so: Pinocchio's arm weighs 0.18 kg, MuJoCo's 13.7)."""
    plain, visual = _one_body('type="sphere" size="0.1"'), _one_body('type="sphere" size="0.1" contype="0" '
                                                                      'conaffinity="0"')
    for text in (plain, visual):
        assert mujoco.MjModel.from_xml_string(text).body_mass[1] == pytest.approx(4.18879020478639, rel=ROUNDING)
    assert _pinocchio(plain).inertias[1].mass == pytest.approx(4.18879020478639, rel=ROUNDING)
    assert _pinocchio(visual).inertias[1].mass == 0.0


def test_pinocchio_converts_a_slide_joint_s_range_from_degrees():
    """compiler angle="degree" (MJCF's default) turns a hinge's range into radians, not a slide's (MuJoCo); Pinocchio
    converts both (inverted_double_pendulum.xml's cart: [-1, 1] m becomes [-0.01745, 0.01745])."""
    text = _one_body('type="sphere" size="0.1"', 'type="slide" axis="1 0 0" range="-1 1" limited="true"',
                     'angle="degree"')
    assert np.array_equal(mujoco.MjModel.from_xml_string(text).jnt_range[0], [-1.0, 1.0])
    model = _pinocchio(text)
    assert model.upperPositionLimit[0] == pytest.approx(np.pi / 180, rel=ROUNDING)


def test_pinocchio_merges_a_body_s_joints_and_its_rows_say_so():
    """The MuJoCo humanoid's hips hold three hinges in one body: Pinocchio makes one composite joint of them, and its
    dynamics of such a chain are n/a naming the composite joints."""
    chain = chain_from_mjcf(os.path.join(MJCF, "humanoid.xml"), "torso", "right_foot", dynamics=True)
    problem = pinocchio_dynamics_problem(chain)
    assert "composite joint" in problem and "Composite_right_hip_x" in problem
    assert not make_engine("pinocchio").supports_joint_dynamics(chain, "recursive").ok
    assert make_engine("mujoco").supports_joint_dynamics(chain, "recursive").ok


def _pybullet_link(text: str, name: str) -> tuple[float, tuple[float, ...]]:
    """(mass, principal moments) of link ``name`` in PyBullet's MJCF import of ``text``."""
    client = _Client()
    body = _load_mjcf(client.id, text)
    for j in range(pybullet.getNumJoints(body, physicsClientId=client.id)):
        if pybullet.getJointInfo(body, j, physicsClientId=client.id)[12].decode() == name:
            info = pybullet.getDynamicsInfo(body, j, physicsClientId=client.id)
            return info[0], info[2]
    raise AssertionError(f"no link {name}")


def _anchored(geom: str) -> str:
    """One hinged body under a massless anchor held by PyBullet's fixed joint (its MJCF importer's one body)."""
    fixed = " ".join(f'{k}="{v}"' for k, v in FIXED_BASE_JOINT.items())
    return (f'<mujoco><compiler angle="radian"/><worldbody><body name="anchor"><joint {fixed}/><body name="a">'
            f'<joint name="j" type="hinge" axis="1 0 0" limited="false" armature="0" damping="0" stiffness="0"/>'
            f'<geom {geom}/></body></body></worldbody></mujoco>')


def test_pybullet_s_mjcf_importer_gives_capsules_and_cylinders_other_inertias():
    """A sphere's mass and inertia agree with MuJoCo's; a capsule's and a cylinder's inertia do not (the inverted
    double pendulum's poles: 29 % off), and a box's size is read in float32 (48.0000033 kg for 48)."""
    for geom, agrees in (('type="sphere" size="0.1"', True),
                         ('type="capsule" fromto="0 0 0 0 0 0.6" size="0.05"', False),
                         ('type="cylinder" fromto="0 0 0 0 0 0.6" size="0.05"', False)):
        mine = mujoco.MjModel.from_xml_string(_one_body(geom))
        mass, moments = _pybullet_link(_anchored(geom), "a")
        assert mass == pytest.approx(mine.body_mass[1], rel=1e-6)
        assert np.allclose(sorted(moments), sorted(mine.body_inertia[1]), rtol=1e-6) == agrees, (geom, moments)
    mass, _ = _pybullet_link(_anchored('type="box" size="0.1 0.2 0.3"'), "a")
    assert mass != 48.0 and mass == pytest.approx(48.0, rel=1e-6)


def test_pybullet_needs_its_own_fixed_joint_to_fix_an_mjcf_base():
    """PyBullet's MJCF importer makes a root body without a joint free (the ant's M 8 x 8 for two hinges); its own
    fixed joint (FIXED_BASE_JOINT, as pybullet_data's humanoid_fixed.xml) fixes it: M 2 x 2."""
    chain = chain_from_mjcf(os.path.join(MJCF, "ant.xml"), "torso", "front_left_foot", dynamics=True)
    for text, size in ((dynamics_mjcf(chain), 8), (pybullet_mjcf(chain), 2)):
        client = _Client()
        body = _load_mjcf(client.id, text)
        movable = [j for j in range(pybullet.getNumJoints(body, physicsClientId=client.id))
                   if pybullet.getJointInfo(body, j, physicsClientId=client.id)[2] != pybullet.JOINT_FIXED]
        with captured_output():
            mass_matrix = pybullet.calculateMassMatrix(body, [0.0] * len(movable), physicsClientId=client.id)
        assert np.shape(mass_matrix) == (size, size)
    assert ET.fromstring(pybullet_mjcf(chain)).find("worldbody/body/joint").get("type") == "fixed"


def test_pinocchio_ignores_a_default_class_geom_mass():
    """A ``<default><geom mass>`` sets the geom's mass in MuJoCo; Pinocchio infers it from the density instead
    (dm_control's acrobot: 8.38 kg against 1.0; a held-out review's finding)."""
    text = ('<mujoco><compiler angle="radian"/><default><geom mass="1"/></default><worldbody><body name="a">'
            '<joint name="j" axis="1 0 0"/><geom type="sphere" size="0.1"/></body></worldbody></mujoco>')
    assert mujoco.MjModel.from_xml_string(text).body_mass[1] == 1.0
    assert _pinocchio(text).inertias[1].mass == pytest.approx(4.18879020478639, rel=ROUNDING)


def test_pinocchio_shifts_a_hinge_s_range_by_its_ref():
    """A hinge with ref 60 degrees and range [-90, 120]: MuJoCo's range is qpos's, [-90, 120]; Pinocchio's q is qpos
    too (its dynamics agree) but its limits are the range less ref, [-150, 60]."""
    text = ('<mujoco><worldbody><body name="a"><joint name="j" axis="0 1 0" ref="60" range="-90 120" limited="true"/>'
            '<geom type="sphere" size="0.1" pos="0.2 0 0"/></body></worldbody></mujoco>')
    assert np.allclose(np.degrees(mujoco.MjModel.from_xml_string(text).jnt_range[0]), [-90.0, 120.0])
    model = _pinocchio(text)
    assert np.allclose(np.degrees([model.lowerPositionLimit[0], model.upperPositionLimit[0]]), [-150.0, 60.0])


def test_pybullet_gives_an_ellipsoid_no_mass():
    """PyBullet's MJCF importer makes a body whose only geom is an ellipsoid massless (MuJoCo: its volume times 1000)."""
    geom = 'type="ellipsoid" size="0.1 0.05 0.03"'
    assert mujoco.MjModel.from_xml_string(_one_body(geom)).body_mass[1] > 0
    assert _pybullet_link(_anchored(geom), "a")[0] == 0.0


def test_pybullet_is_n_a_naming_the_joints_its_mjcf_importer_drops(tmp_path):
    """A hinge written without ``type`` (MJCF's default) is a joint for MuJoCo and core, none for PyBullet's MJCF
    importer: its rows are n/a naming the joint, never a failed case (a held-out review's finding)."""
    path = _write(tmp_path, '<mujoco><worldbody><body name="base"><body name="a"><joint name="j1" axis="0 1 0"/>'
                            '<geom type="sphere" size="0.1" pos="0.2 0 0"/></body></body></worldbody></mujoco>')
    chain = chain_from_mjcf(path, "base", "a", dynamics=True)
    support = make_engine("pybullet").supports_joint_dynamics(chain, "recursive")
    assert not support.ok and "lacks the chain's joints ['j1']" in support.reason
    assert make_engine("mujoco").supports_joint_dynamics(chain, "recursive").ok

