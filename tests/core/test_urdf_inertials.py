"""URDF mass properties: each chain link's LinkInertia (everything rigidly attached to it, held branches
included) matches Pinocchio's, damping is read, held joints are listed, and bad inertials are refused."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from importlib.metadata import distribution

import numpy as np
import pinocchio as pin
import pybullet_data
import pytest
from simparity.core.model.errors import SceneError
from simparity.core.urdf import chain_from_urdf

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ROBOTS_DIR = str(distribution("example-robot-data").locate_file("cmeel.prefix/share/example-robot-data/robots"))
CRAFTED = os.path.join(REPO, "comparisons/scenes/urdf/crafted-arm.urdf")

REL_TOL = 1e-12
"""Relative agreement with Pinocchio of a link's mass, COM and inertia: both sum the same float64 inertials
after the same rotations, in a different order (measured: at most 1e-15 relative)."""

HAND_TOL = 1e-15
"""[kg, m, kg m^2] Agreement with the hand computation of quantities of order 0.01 to 3: float64 rounding."""

ROBOTS = {  # name -> (file, base_link, tip_link)
    "crafted": (CRAFTED, None, "flange"),
    "iiwa": (os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf"), None, None),
    "panda": (os.path.join(ROBOTS_DIR, "panda_description/urdf/panda.urdf"), None, "panda_hand_tcp"),
    "ur5": (os.path.join(ROBOTS_DIR, "ur_description/urdf/ur5_robot.urdf"), None, "tool0"),
    # fixed branches (fingers' bases) off the last link, hanging beyond the tip
    "kinova": (os.path.join(ROBOTS_DIR, "kinova_description/robots/kinova.urdf"), None, "j2s6s200_end_effector"),
    # base below the root (wheels, head and antennas not all modelled); a hand of 36 held joints (mimic ones
    # included) beyond the tip
    "tiago": (os.path.join(ROBOTS_DIR, "tiago_description/robots/tiago.urdf"), "torso_lift_link", "arm_7_link"),
}


def _close(value, expected) -> bool:
    """Relative agreement to REL_TOL (exact agreement for a zero)."""
    value, expected = np.asarray(value, dtype=float), np.asarray(expected, dtype=float)
    return bool(np.linalg.norm(value - expected) <= REL_TOL * np.linalg.norm(expected))


def _pinocchio(path: str, chain_names: set[str]) -> tuple[pin.Model, pin.Model]:
    """Pinocchio's full model, and its reduced model with every joint off the chain locked at neutral."""
    model = pin.buildModelFromUrdf(path)
    locked = [i for i in range(1, model.njoints) if model.names[i] not in chain_names]
    return model, pin.buildReducedModel(model, locked, pin.neutral(model))


def _file_order(path: str) -> list[str]:
    return [joint.get("name", "") for joint in ET.parse(path).getroot().findall("joint")]


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_link_inertias_match_pinocchio(robot):
    """Mass, COM (Pinocchio's lever, in the joint frame = the child link frame) and inertia about the COM of
    every chain link, with fixed children and held branches merged, agree with Pinocchio's reduced model."""
    path, base, tip = ROBOTS[robot]
    chain = chain_from_urdf(path, base_link=base, tip_link=tip)
    _, reduced = _pinocchio(path, {joint.name for joint in chain.joints})
    assert reduced.njoints - 1 == chain.n_joints
    for joint in chain.joints:
        expected = reduced.inertias[reduced.getJointId(joint.name)]
        assert joint.link is not None and joint.link.mass > 0, joint.name
        assert _close(joint.link.mass, expected.mass), (joint.name, joint.link.mass, expected.mass)
        assert _close(joint.link.com_xyz, expected.lever), (joint.name, joint.link.com_xyz, expected.lever)
        assert _close(joint.link.inertia_com, expected.inertia), (joint.name, joint.link.inertia_com)
    assert chain.dynamics_problem() == ""


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_damping_matches_pinocchio(robot):
    """Joint.damping is Pinocchio's model.damping (both read <dynamics damping>; 0 where absent)."""
    path, base, tip = ROBOTS[robot]
    chain = chain_from_urdf(path, base_link=base, tip_link=tip)
    model, _ = _pinocchio(path, {joint.name for joint in chain.joints})
    for joint in chain.joints:
        assert joint.damping == model.damping[model.joints[model.getJointId(joint.name)].idx_v], joint.name


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_held_joints_are_the_movable_joints_below_the_base_off_the_chain(robot):
    """Held joints: Pinocchio's joints (its movable ones) below the base link that are not on the chain, in
    the file's order."""
    path, base, tip = ROBOTS[robot]
    chain = chain_from_urdf(path, base_link=base, tip_link=tip)
    model = pin.buildModelFromUrdf(path)
    base_joint = model.frames[model.getFrameId(base)].parentJoint if base else 0  # the universe for the root
    on_chain = {joint.name for joint in chain.joints}
    below = {model.names[i] for i in range(1, model.njoints)
             if i != base_joint and base_joint in model.supports[i]} - on_chain
    order = _file_order(path)
    assert set(chain.held_joints) == below
    assert list(chain.held_joints) == sorted(below, key=order.index)


def test_crafted_arm_by_name():
    """The crafted arm's traps, spelled out: damping 0.3 / 1.5 / 0 (friction 0.7 not read), the finger
    held, the payload and the finger riding on link3 (0.8 + 0.6 + 0.15 kg)."""
    chain = chain_from_urdf(CRAFTED, tip_link="flange")
    assert [joint.damping for joint in chain.joints] == [0.3, 1.5, 0.0]
    assert chain.held_joints == ("finger",)
    assert [joint.link.mass for joint in chain.joints] == pytest.approx([1.7, 1.1, 1.55], abs=HAND_TOL)


def _two_masses(link1_inertial: str = "", extra: str = "") -> str:
    """l1 (revolute j1) carries l1b by a fixed joint (0, 0.3, 0), yaw 90 deg; j2 follows on l1b; l2 and the
    tool have no <inertial>."""
    link1_inertial = link1_inertial or ('<inertial><origin xyz="0.1 0 0"/><mass value="2"/>'
                                        '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>')
    return f"""<robot name="two">
  <link name="base"/>
  <link name="l1">{link1_inertial}</link>
  <link name="l1b"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="2e-3" iyz="0" izz="3e-3"/></inertial></link>
  <link name="l2"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1"/><dynamics damping="0.25" friction="3"/></joint>
  <joint name="weld" type="fixed"><parent link="l1"/><child link="l1b"/>
    <origin xyz="0 0.3 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="j2" type="revolute"><parent link="l1b"/><child link="l2"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-1" upper="1"/></joint>
  <joint name="end" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>
  {extra}
</robot>"""


def test_two_masses_on_a_fixed_joint_by_hand():
    """m1 = 2 kg at p1 = (0.1, 0, 0), m2 = 1 kg at p2 = (0, 0.3, 0) + Rz(90 deg) (0.2, 0, 0) = (0, 0.5, 0):
    mass 3, COM (0.2/3, 0.5/3, 0); about it I = I1 + Rz I2 Rz^T + mu (|r|^2 E - r r^T) with the reduced mass
    mu = 2/3 kg and r = p2 - p1 = (-0.1, 0.5, 0), Rz diag(1e-3, 2e-3, 3e-3) Rz^T = diag(2e-3, 1e-3, 3e-3).
    The next joint's massless link l2 (and its tool) is a massless LinkInertia; damping 0.25 is read."""
    chain = chain_from_urdf(_two_masses())
    link1, link2 = (joint.link for joint in chain.joints)
    mu = 2.0 / 3.0
    expected = (np.diag([1e-4 + 2e-3 + mu * 0.25, 1e-4 + 1e-3 + mu * 0.01, 1e-4 + 3e-3 + mu * 0.26])
                + mu * np.array([[0.0, 0.05, 0.0], [0.05, 0.0, 0.0], [0.0, 0.0, 0.0]]))  # -mu r_x r_y = +0.05 mu
    assert link1.mass == pytest.approx(3.0, abs=HAND_TOL)
    np.testing.assert_allclose(link1.com_xyz, [0.2 / 3, 0.5 / 3, 0.0], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(link1.inertia_com, expected, rtol=0, atol=HAND_TOL)
    assert link2.mass == 0.0 and not np.any(link2.com_xyz) and not np.any(link2.inertia_com)
    assert [joint.damping for joint in chain.joints] == [0.25, 0.0]
    assert chain.held_joints == ()
    assert "j2" in chain.dynamics_problem()  # j2 moves no mass: refused for dynamics, not at parse time


def test_a_chain_without_any_inertial_loads_for_kinematics():
    """Every link massless: the chain loads (kinematics needs no mass) and dynamics_problem refuses it."""
    text = _two_masses().replace('<link name="l1b"><inertial>', '<link name="l1b"><unused>').replace(
        '</inertial></link>\n  <link name="l2"/>', '</unused></link>\n  <link name="l2"/>')
    chain = chain_from_urdf(text.replace('<link name="l1"><inertial>', '<link name="l1"><unused>').replace(
        '</inertial></link>\n  <link name="l1b">', '</unused></link>\n  <link name="l1b">'))
    assert all(joint.link is not None and joint.link.mass == 0 for joint in chain.joints)
    assert chain.dynamics_problem() != ""


def test_a_held_branch_rides_at_its_origin():
    """A prismatic joint off the chain on l2 (held at 0) carries 0.5 kg at its origin (0.1, 0, 0) + COM (0, 0.2,
    0) of its link: l2's link is that mass at (0.1, 0.2, 0) with its own inertia, and the joint is held."""
    branch = ('<link name="finger"><inertial><origin xyz="0 0.2 0"/><mass value="0.5"/>'
              '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="2e-4" iyz="0" izz="3e-4"/></inertial></link>'
              '<joint name="slide" type="prismatic"><parent link="l2"/><child link="finger"/>'
              '<origin xyz="0.1 0 0"/><axis xyz="0 1 0"/><limit lower="0" upper="0.05"/></joint>')
    chain = chain_from_urdf(_two_masses(extra=branch), tip_link="tool")
    link2 = chain.joints[1].link
    assert chain.held_joints == ("slide",)
    assert link2.mass == 0.5
    np.testing.assert_allclose(link2.com_xyz, [0.1, 0.2, 0.0], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(link2.inertia_com, np.diag([1e-4, 2e-4, 3e-4]), rtol=0, atol=HAND_TOL)


L1 = "robot/link[@name='l1']/inertial"
_DEFAULT_INERTIA = 'ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"'


def _l1(mass: str = '<mass value="2"/>', inertia: str = _DEFAULT_INERTIA, origin: str = '<origin xyz="0.1 0 0"/>'):
    return f"<inertial>{origin}{mass}<inertia {inertia}/></inertial>"


BAD = {  # name -> (l1's <inertial>, key of the error)
    "malformed mass": (_l1(mass='<mass value="two"/>'), f"{L1}/mass/@value"),
    "nan mass": (_l1(mass='<mass value="nan"/>'), f"{L1}/mass/@value"),
    "negative mass": (_l1(mass='<mass value="-1"/>'), f"{L1}/mass/@value"),
    "mass above the range": (_l1(mass='<mass value="1e12"/>'), f"{L1}/mass/@value"),
    "mass below the range": (_l1(mass='<mass value="1e-20"/>'), f"{L1}/mass/@value"),
    "no mass": (_l1(mass=""), f"{L1}/mass"),
    "no mass value": (_l1(mass="<mass/>"), f"{L1}/mass/@value"),
    "infinite ixy": (_l1(inertia=_DEFAULT_INERTIA.replace('ixy="0"', 'ixy="inf"')), f"{L1}/inertia/@ixy"),
    "no izz": (_l1(inertia=_DEFAULT_INERTIA.replace(' izz="1e-4"', "")), f"{L1}/inertia/@izz"),
    "no inertia": ('<inertial><mass value="1"/></inertial>', f"{L1}/inertia"),
    "ixx above the range": (_l1(inertia=_DEFAULT_INERTIA.replace('ixx="1e-4"', 'ixx="1e13"')), f"{L1}/inertia/@ixx"),
    "triangle inequality": (_l1(inertia='ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="2.1"'), f"{L1}/inertia"),
    "not positive semidefinite": (_l1(inertia='ixx="-1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"'),
                                  f"{L1}/inertia"),
    "malformed inertial origin": (_l1(origin='<origin xyz="0 0 x"/>'), f"{L1}/origin/@xyz"),
    "inertial origin above the range": (_l1(origin='<origin xyz="0 0 1e7"/>'), f"{L1}/origin/@xyz"),
    "inertial rpy above the range": (_l1(origin='<origin rpy="0 5e3 0"/>'), f"{L1}/origin/@rpy"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_inertials_are_refused_naming_the_element(case):
    inertial, key = BAD[case]
    with pytest.raises(SceneError) as caught:
        chain_from_urdf(_two_masses(link1_inertial=inertial), dynamics=True)
    assert caught.value.key == key, str(caught.value)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("case", ["triangle inequality", "not positive semidefinite"])
def test_a_non_physical_tensor_is_refused_for_dynamics_only(case):
    """Real URDFs carry such placeholders (pybullet_data's xarm6): kinematics never sees them and loads the file."""
    inertial, _ = BAD[case]
    assert chain_from_urdf(_two_masses(link1_inertial=inertial)).n_joints >= 1


@pytest.mark.parametrize("damping", ["-0.5", "nan", "x"])
def test_bad_damping_is_refused(damping):
    with pytest.raises(SceneError) as caught:
        chain_from_urdf(_two_masses().replace('damping="0.25"', f'damping="{damping}"'))
    assert caught.value.key == "robot/joint[@name='j1']/dynamics/@damping", str(caught.value)


@pytest.mark.parametrize("inertia", [
    'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"',  # a point mass
    'ixx="0" ixy="0" ixz="0" iyy="0.5" iyz="0" izz="0.5"',  # a thin rod along x
    'ixx="1" ixy="1e-35" ixz="-2e-21" iyy="1" iyz="0" izz="2.000001"',  # a thin plate quoted to 7 digits
])
def test_singular_and_rounded_physical_tensors_load(inertia):
    """Physical tensors that are not positive definite, or break a + b = c by rounding, load."""
    chain = chain_from_urdf(_two_masses(link1_inertial=_l1(inertia=inertia)))
    assert chain.joints[0].link.mass == 3.0


def test_links_outside_the_chain_links_are_not_held_to_a_physical_tensor():
    """A non-physical tensor on a link fixed to the base (it never moves) loads; a malformed <inertial> above
    the base link is not read at all."""
    bad = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="5"/></inertial>'
    mount = (f'<link name="mount">{bad}</link><joint name="m" type="fixed"><parent link="base"/>'
             '<child link="mount"/></joint>')
    chain = chain_from_urdf(_two_masses(extra=mount), tip_link="tool")
    assert chain.joints[0].link.mass == 3.0
    above = ('<link name="world"><inertial><mass value="-5"/></inertial></link>'
             '<joint name="w" type="fixed"><parent link="world"/><child link="base"/></joint>')
    chain = chain_from_urdf(_two_masses(extra=above), base_link="base", tip_link="tool")
    assert chain.joints[0].link.mass == 3.0 and chain.base_link == "base"
