"""Real robot files accepted as they are (issue #38, section 4), on constructed inputs: an inertia's rounding is
judged against the link's own scale, a joint with lower == upper loads, a link of mass 0 with an inertia is treated
alike whether it comes from a URDF or a scene file, and every refusal names the link or joint and its branch."""

from __future__ import annotations

import numpy as np
import pytest
from simparity.comparisons.scenes.loading.scene_file import parse_scene
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.chain import sample_configurations
from simparity.core.urdf import chain_from_urdf

HEAD_COM = (0.0185, -0.1108, 0.0)
"""[m] iCub's head: the centre of mass of a 1.34 kg link written with ixz = 2.4e-35 kg m^2 and nothing else."""


def _tensor_attributes(inertia) -> str:
    i = np.asarray(inertia, dtype=float).tolist()
    return (f'ixx="{i[0][0]!r}" ixy="{i[0][1]!r}" ixz="{i[0][2]!r}" iyy="{i[1][1]!r}" iyz="{i[1][2]!r}" '
            f'izz="{i[2][2]!r}"')


def _urdf(head_mass: float, head_com, head_inertia, knee=(-1.0, 1.0)) -> str:
    """A torso on a fixed root, a neck (revolute) carrying a head, and a leg (hip, knee) beside it."""
    def link(name, mass, com, inertia):
        return (f'<link name="{name}"><inertial><origin xyz="{" ".join(repr(float(v)) for v in com)}"/>'
                f'<mass value="{float(mass)!r}"/><inertia {_tensor_attributes(inertia)}/></inertial></link>')

    def joint(name, parent, child, limits=(-1.0, 1.0)):
        return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/><limit lower="{limits[0]!r}" upper="{limits[1]!r}"/>'
                '</joint>')

    solid = np.diag([1e-3, 1e-3, 1e-3])
    return ('<robot name="walker"><link name="root"/>'
            + link("torso", 5.0, (0, 0, 0.2), solid) + link("head", head_mass, head_com, head_inertia)
            + link("thigh", 2.0, (0, 0, -0.2), solid) + link("shin", 1.0, (0, 0, -0.2), solid)
            + '<joint name="waist" type="fixed"><parent link="root"/><child link="torso"/></joint>'
            + joint("neck", "torso", "head") + joint("hip", "torso", "thigh") + joint("knee", "thigh", "shin", knee)
            + "</robot>")


def _scene(mass: float, com, inertia, knee=(-1.0, 1.0)) -> dict:
    """The leg of :func:`_urdf` in a scene file, its shin given ``mass``, ``com`` and ``inertia``."""
    def joint(name, limits, link_mass, link_com, link_inertia):
        return {"name": name, "type": "revolute", "axis": [0.0, 1.0, 0.0], "origin_xyz": [0.0, 0.0, 0.1],
                "lower": limits[0], "upper": limits[1], "mass": link_mass, "com_xyz": list(link_com),
                "inertia": np.asarray(link_inertia, dtype=float).tolist()}

    return {"scene": {"name": "leg", "kind": "joint_dynamics", "reference": "pinocchio"},
            "chain": {"joint": [joint("hip", (-1.0, 1.0), 2.0, (0.0, 0.0, -0.2), np.diag([1e-3] * 3)),
                                joint("knee", knee, mass, com, inertia)]}}


ROUNDED = np.array([[0.0, 0.0, 2.40741e-35], [0.0, 0.0, 0.0], [2.40741e-35, 0.0, 0.0]])
"""Principal moments (-2.4e-35, 0, 2.4e-35): a point mass written with a floating-point residue."""

NEGATIVE = np.diag([-2.7e-3, 3.95e-2, 5.4e-2])
"""A real negative principal moment (romeo_laas_small's hip: -0.0027 on 0.054 kg m^2)."""


def test_a_rounding_level_negative_eigenvalue_loads_on_both_routes():
    """iCub's head: refused before as 'not positive semidefinite (-2.4e-35, 0, 2.4e-35)'."""
    chain = chain_from_urdf(_urdf(1.33687, HEAD_COM, ROUNDED), tip_link="head", dynamics=True)
    assert chain.joints[0].link.mass == 1.33687
    scene = parse_scene(_scene(1.33687, HEAD_COM, ROUNDED))
    assert scene.chain.joints[1].link.mass == 1.33687


def test_a_residue_on_a_point_mass_at_its_link_origin_loads():
    """No parallel-axis term to judge the residue against: the physical floor (a microgram bead) is the scale."""
    chain = chain_from_urdf(_urdf(0.5, (0.0, 0.0, 0.0), ROUNDED), tip_link="head", dynamics=True)
    assert chain.joints[0].link.mass == 0.5


@pytest.mark.parametrize("inertia, words", [
    (NEGATIVE, "not positive semidefinite"),
    (np.diag([1e-3, 1e-3, 2.1e-3]), "triangle inequality"),
    # a residue relative to its scale, but far above rounding: 1e-10 of a 1e-2 kg m^2 link
    (np.array([[0.0, 0.0, 1e-12], [0.0, 0.0, 0.0], [1e-12, 0.0, 0.0]]), "not positive semidefinite"),
])
def test_a_physical_violation_is_refused_on_both_routes_naming_the_link_and_its_branch(inertia, words):
    with pytest.raises(SceneError) as urdf:
        chain_from_urdf(_urdf(1.0, (0.0, 0.1, 0.0), inertia), tip_link="head", dynamics=True)
    assert urdf.value.key == "robot/link[@name='head']/inertial/inertia"
    assert words in urdf.value.problem and "link 'head' on the branch root > torso > head" in urdf.value.problem
    with pytest.raises(SceneError) as scene:
        parse_scene(_scene(1.0, (0.0, 0.1, 0.0), inertia), "leg.toml")
    assert scene.value.key == "chain.joint[1].inertia"
    assert words in scene.value.problem and "joint 'knee' on the branch base > hip > knee" in scene.value.problem


def test_a_knee_with_lower_equal_to_upper_loads_and_is_sampled_at_that_value():
    """No limit acts in joint dynamics; where limits are used (sampled poses), the joint is held at its value."""
    chain = chain_from_urdf(_urdf(1.0, HEAD_COM, np.diag([1e-3] * 3), knee=(0.3, 0.3)), tip_link="shin",
                            dynamics=True)
    assert [j.name for j in chain.joints] == ["hip", "knee"]
    q = sample_configurations(chain, 50, np.random.default_rng(0))
    assert np.all(q[:, 1] == 0.3) and np.ptp(q[:, 0]) > 0
    scene = parse_scene(_scene(1.0, (0.0, 0.0, -0.2), np.diag([1e-3] * 3), knee=(0.3, 0.3)))
    assert (scene.chain.joints[1].lower, scene.chain.joints[1].upper) == (0.3, 0.3)


def test_lower_above_upper_is_still_refused_on_both_routes_naming_the_joint_and_its_branch():
    with pytest.raises(SceneError) as urdf:
        chain_from_urdf(_urdf(1.0, HEAD_COM, np.diag([1e-3] * 3), knee=(0.3, 0.2)), tip_link="shin")
    assert urdf.value.key == "robot/joint[@name='knee']/limit"
    assert "joint 'knee' on the branch root > torso > thigh > shin" in urdf.value.problem
    with pytest.raises(SceneError) as scene:
        parse_scene(_scene(1.0, (0.0, 0.0, -0.2), np.diag([1e-3] * 3), knee=(0.3, 0.2)), "leg.toml")
    assert "joint 'knee' on the branch base > hip > knee" in scene.value.problem


def test_a_massless_link_with_an_inertia_is_treated_alike_on_both_routes():
    """pybullet_data's Panda flange (mass 0, inertia 0.1 E) and Bolt's feet: a rotor inertia whose mass is counted
    elsewhere. Both routes load it, with the same mass properties."""
    inertia = np.diag([0.1, 0.1, 0.1])
    chain = chain_from_urdf(_urdf(0.0, (0.0, 0.0, 0.0), inertia), tip_link="head", dynamics=True)
    scene = parse_scene(_scene(0.0, (0.0, 0.0, 0.0), inertia))
    from_urdf, from_scene = chain.joints[0].link, scene.chain.joints[1].link
    assert from_urdf.mass == from_scene.mass == 0.0
    assert np.array_equal(from_urdf.inertia_com, from_scene.inertia_com)
    from simparity.references.common.dynamics_urdf import dynamics_source

    assert dynamics_source(scene.chain).endswith("links of mass 0 with a rotational inertia, kept as written in every "
                                                 "engine (a rotor's inertia whose mass is counted elsewhere): knee")


def test_a_long_branch_is_named_in_one_readable_line():
    """A finger far from the root: the branch's middle is elided, its root and the link itself are named."""
    links = [f"l{i}" for i in range(12)]
    body = "".join(f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" '
                   f'iyz="0" izz="{3 if name == "l11" else 1}"/></inertial></link>' for name in links)
    body += "".join(f'<joint name="j{i}" type="continuous"><parent link="l{i - 1}"/><child link="l{i}"/>'
                    '<axis xyz="0 0 1"/></joint>' for i in range(1, 12))
    with pytest.raises(SceneError) as caught:
        chain_from_urdf(f'<robot name="hand">{body}</robot>', dynamics=True)
    assert "link 'l11' on the branch l0 > l1 > l2 > ... 5 more ... > l8 > l9 > l10 > l11" in caught.value.problem
    assert "\n" not in str(caught.value)


def test_an_axis_a_rounding_away_from_minus_z_is_aligned_without_cancelling():
    """iCub's knee axis (0, 1.2e-16, -1): Rodrigues' 1 / (1 + a_z) divided by zero and core's dynamics came out
    non-finite. The alignment maps e_z onto the axis, is a rotation, and the chain's M matches the exact -e_z one."""
    from simparity.core.articulated.chain_arrays import z_alignment

    axis = np.array([0.0, 1.22465e-16, -1.0])
    alignment = z_alignment(axis)
    np.testing.assert_allclose(alignment @ [0.0, 0.0, 1.0], axis, rtol=0, atol=4 * np.finfo(float).eps)
    np.testing.assert_allclose(alignment.T @ alignment, np.eye(3), rtol=0, atol=4 * np.finfo(float).eps)
    assert np.linalg.det(alignment) > 0


DYNAMICS_FILE = """<robot name="arm">
  <link name="base"><inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="plate"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <link name="sensor_frame"/>
  <link name="rotor"><inertial><mass value="0"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <link name="finger"><inertial><mass value="0.1"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="mount" type="fixed"><parent link="base"/><child link="plate"/></joint>
  <joint name="shoulder" type="revolute"><parent link="plate"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics damping="0.1" friction="0.4"/></joint>
  <joint name="sensor" type="fixed"><parent link="upper"/><child link="sensor_frame"/></joint>
  <joint name="spin" type="fixed"><parent link="upper"/><child link="rotor"/></joint>
  <joint name="grip" type="prismatic"><parent link="upper"/><child link="finger"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="tool"/><origin xyz="0.2 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_what_every_engine_is_given_is_named_link_by_link_in_show_and_the_rows_detail(tmp_path):
    """Before: 'links without <inertial> massless' and 'held at 0', whatever the file. Now each change names its
    links or joints, in ``simparity show`` and in the detail every adapter's rows carry (dynamics_source)."""
    from simparity.comparisons.scenes.describe import describe
    from simparity.comparisons.scenes.loading.scene_file import load_scene
    from simparity.references.common.dynamics_urdf import dynamics_source

    (tmp_path / "arm.urdf").write_text(DYNAMICS_FILE, encoding="utf-8")
    (tmp_path / "arm.toml").write_text('[scene]\nname = "arm"\nkind = "joint_dynamics"\nreference = "pinocchio"\n'
                                       '[chain]\nurdf = "arm.urdf"\ntip_link = "tool"\n', encoding="utf-8")
    scene = load_scene(tmp_path / "arm.toml")
    expected = {"given an explicit massless one": "sensor_frame", "welded to the fixed base": "base, plate",
                "held at 0 as fixed joints": "grip", "friction": "shoulder",
                "mass 0 with a rotational inertia": "rotor"}
    for text in (describe(scene), dynamics_source(scene.chain)):
        for what, names in expected.items():
            assert any(what in part and part.endswith(f": {names}") for part in text.replace("\n", "; ").split("; ")), \
                (what, text)


def test_pybullets_nullspace_ik_is_not_offered_on_a_joint_with_lower_equal_to_upper(tmp_path):
    """calculateInverseKinematics' null-space solve never returned on such a chain (example-robot-data's quadruped,
    whose knees have lower == upper == 0, hit the 900 s case limit): the solver is n/a naming the joint, the others
    are offered."""
    from simparity.comparisons.engines.registry import make_engine

    (tmp_path / "walker.urdf").write_text(_urdf(1.0, HEAD_COM, np.diag([1e-3] * 3), knee=(0.3, 0.3)), encoding="utf-8")
    chain = chain_from_urdf(str(tmp_path / "walker.urdf"), tip_link="shin")
    pybullet = make_engine("pybullet")
    support = pybullet.supports_ik(chain, "calculateInverseKinematics-tuned-nullspace", True)
    assert not support.ok and "knee" in support.reason
    assert pybullet.supports_ik(chain, "calculateInverseKinematics-tuned", True).ok


def test_pybullet_names_the_joints_whose_axis_it_normalises():
    """The crafted arm's three movable joints have non-unit axes (0 0 -2, 0.3 -0.5 0.8, 1 1 0): each is named; its
    fixed joints (whose axis means nothing) are not."""
    from simparity.comparisons.scenes import library
    from simparity.references.pybullet.joint_dynamics import axes_changed

    chain = library.load(["crafted-arm-dynamics"])[0].chain
    assert axes_changed(chain) == "axes normalised (non-unit: j1, j2, j3)"
