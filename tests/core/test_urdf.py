"""URDF import: the serial chain matches Pinocchio's model, and unsupported input is rejected."""

from __future__ import annotations

import os
import re

import numpy as np
import pinocchio as pin
import pybullet_data
import pytest

from simparity.core.model.errors import SceneError
from simparity.core.kinematics import joint_frames
from simparity.core.model.files import MAX_XML_DEPTH
from simparity.core.urdf import MAX_URDF_JOINTS, chain_from_urdf
from simparity.references.common.urdf_export import original_without_geometry

IIWA_PATH = os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf")

# FK agreement with Pinocchio: both multiply the same float64 transforms in a different
# order, so they differ by rounding only (~1e-15 on a 1 m arm).
FK_TOLERANCE = 1e-12
N_CONFIGURATIONS = 100

# A serial chain with fixed joints before, between and after the movable ones, an
# unaligned axis and a prismatic joint; every movable joint has limits so Pinocchio
# builds one scalar joint per movable joint.
MIXED_URDF = """
<robot name="mixed">
  <link name="world"/><link name="base"/><link name="l1"/><link name="l1b"/>
  <link name="l2"/><link name="l3"/><link name="tool"/>
  <joint name="mount" type="fixed">
    <parent link="world"/><child link="base"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.2 0.9"/>
  </joint>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.25" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="spacer" type="fixed">
    <parent link="l1"/><child link="l1b"/>
    <origin xyz="0.05 0 0.1" rpy="1.2 0.1 -0.4"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="l1b"/><child link="l2"/>
    <origin xyz="0.3 0.02 0" rpy="-0.5 0.7 0.2"/>
    <axis xyz="0.3 -0.5 0.8"/><limit lower="-1.5" upper="1.5" effort="1" velocity="1"/>
  </joint>
  <joint name="j3" type="prismatic">
    <parent link="l2"/><child link="l3"/>
    <origin xyz="0.2 0 0.1" rpy="0 1.57 0"/>
    <axis xyz="1 0 0"/><limit lower="-0.1" upper="0.4" effort="1" velocity="1"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="l3"/><child link="tool"/>
    <origin xyz="0 0.04 0.12" rpy="0.1 0.2 0.3"/>
  </joint>
</robot>
"""

_JOINT = """<joint name="{name}" type="{type}"><parent link="{parent}"/><child link="{child}"/>
<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/>{extra}</joint>"""


def _robot(*joints: str, links=("a", "b", "c")) -> str:
    return "<robot name='r'>" + "".join(f"<link name='{n}'/>" for n in links) + "".join(joints) + "</robot>"


def _joint(name, parent, child, type="revolute", extra="") -> str:
    return _JOINT.format(name=name, type=type, parent=parent, child=child, extra=extra)


def _pinocchio_poses(model, q: np.ndarray, frame_names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    data = model.createData()
    ids = [model.getFrameId(name) for name in frame_names]
    positions = np.empty((len(q), len(ids), 3))
    rotations = np.empty((len(q), len(ids), 3, 3))
    for b, qb in enumerate(q):
        pin.framesForwardKinematics(model, data, qb)
        for f, frame_id in enumerate(ids):
            positions[b, f] = data.oMf[frame_id].translation
            rotations[b, f] = data.oMf[frame_id].rotation
    return positions, rotations


def _assert_fk_matches_pinocchio(chain, model, link_names, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(chain.lower, chain.upper, size=(N_CONFIGURATIONS, chain.n_joints))
    positions, rotations, _ = joint_frames(chain, q)
    ref_p, ref_r = _pinocchio_poses(model, q, link_names)
    np.testing.assert_allclose(positions, ref_p, rtol=0, atol=FK_TOLERANCE)
    np.testing.assert_allclose(rotations, ref_r, rtol=0, atol=FK_TOLERANCE)


def test_iiwa_loads_as_seven_joint_chain():
    """The pybullet_data KUKA iiwa is a 7-joint revolute chain with its URDF limits."""
    chain = chain_from_urdf(IIWA_PATH)
    assert chain.name == "lbr_iiwa"
    assert chain.n_joints == 7
    assert [j.name for j in chain.joints] == [f"lbr_iiwa_joint_{i}" for i in range(1, 8)]
    assert all(j.type == "revolute" for j in chain.joints)
    assert chain.end_effector_name == "lbr_iiwa_link_7"
    np.testing.assert_array_equal(chain.upper, [2.96705972839, 2.09439510239, 2.96705972839, 2.09439510239,
                                                2.96705972839, 2.09439510239, 3.05432619099])
    np.testing.assert_array_equal(chain.lower, -chain.upper)


def test_iiwa_fk_matches_pinocchio():
    """Every link frame of the iiwa matches Pinocchio's buildModelFromUrdf at 100 configurations."""
    chain = chain_from_urdf(IIWA_PATH)
    model = pin.buildModelFromUrdf(IIWA_PATH)
    links = [f"lbr_iiwa_link_{i}" for i in range(1, 8)] + ["lbr_iiwa_link_7"]
    _assert_fk_matches_pinocchio(chain, model, links, seed=1)


def test_fixed_joints_are_collapsed():
    """Fixed joints before, between and after movable ones fold into origins and the tool frame."""
    chain = chain_from_urdf(MIXED_URDF)
    assert [j.name for j in chain.joints] == ["j1", "j2", "j3"]
    assert [j.type for j in chain.joints] == ["revolute", "revolute", "prismatic"]
    assert chain.end_effector_name == "tool"
    model = pin.buildModelFromXML(MIXED_URDF)
    _assert_fk_matches_pinocchio(chain, model, ["l1", "l2", "l3", "tool"], seed=2)


def test_sub_chain_between_named_links():
    """base_link / tip_link select a sub-chain whose FK is the relative transform of the full one."""
    full = chain_from_urdf(IIWA_PATH)
    sub = chain_from_urdf(IIWA_PATH, base_link="lbr_iiwa_link_2", tip_link="lbr_iiwa_link_5")
    assert [j.name for j in sub.joints] == ["lbr_iiwa_joint_3", "lbr_iiwa_joint_4", "lbr_iiwa_joint_5"]
    rng = np.random.default_rng(3)
    q = rng.uniform(full.lower, full.upper, size=(N_CONFIGURATIONS, 7))
    p, r, _ = joint_frames(full, q)
    sp, sr, _ = joint_frames(sub, q[:, 2:5])
    base_r = r[:, 1]  # link 2 frame
    expected_p = np.einsum("bji,bj->bi", base_r, p[:, 4] - p[:, 1])
    expected_r = np.swapaxes(base_r, 1, 2) @ r[:, 4]
    np.testing.assert_allclose(sp[:, -1], expected_p, rtol=0, atol=FK_TOLERANCE)
    np.testing.assert_allclose(sr[:, -1], expected_r, rtol=0, atol=FK_TOLERANCE)


def test_continuous_joint_is_unlimited_revolute():
    """A continuous joint becomes a revolute joint with infinite limits (its <limit> ignored)."""
    chain = chain_from_urdf(_robot(_joint("j", "a", "b", type="continuous"), links=("a", "b")))
    assert chain.joints[0].type == "revolute"
    assert chain.lower[0] == -np.inf and chain.upper[0] == np.inf


def test_off_path_mimic_joint_is_ignored():
    """A mimic joint off the selected path does not move the chain and is accepted."""
    text = _robot(_joint("j1", "a", "b"), _joint("finger", "a", "c", extra="<mimic joint='j1'/>"))
    chain = chain_from_urdf(text, tip_link="b")
    assert [j.name for j in chain.joints] == ["j1"]


def test_text_and_file_give_the_same_chain(tmp_path):
    """A URDF passed as text and as a file path gives the same chain; errors name the file."""
    path = tmp_path / "mixed.urdf"
    path.write_text(MIXED_URDF)
    from_file, from_text = chain_from_urdf(path), chain_from_urdf(MIXED_URDF)
    for a, b in zip(from_file.joints, from_text.joints):
        np.testing.assert_array_equal(a.origin_rotation, b.origin_rotation)
    bad = tmp_path / "bad.urdf"
    bad.write_text(MIXED_URDF.replace('xyz="0.3 -0.5 0.8"', 'xyz="0.3 -0.5"'))
    with pytest.raises(SceneError, match=str(bad)):
        chain_from_urdf(bad)


# (case, URDF text, tip_link, key the error must name). One row per unsupported or
# malformed element; the key is the element's path in the document.
REJECTED = [
    ("mimic", _robot(_joint("j1", "a", "b"), _joint("j3", "b", "c", extra="<mimic joint='j1'/>")), None,
     "robot/joint[@name='j3']/mimic"),
    ("floating", _robot(_joint("j1", "a", "b", type="floating"), _joint("j2", "b", "c")), None,
     "robot/joint[@name='j1']/@type"),
    ("planar", _robot(_joint("j1", "a", "b"), _joint("j2", "b", "c", type="planar")), None,
     "robot/joint[@name='j2']/@type"),
    ("unknown type", _robot(_joint("j1", "a", "b", type="ball")), None, "robot/joint[@name='j1']/@type"),
    ("two parents", _robot(_joint("j1", "a", "c"), _joint("j2", "b", "c")), None, "robot/link[@name='c']"),
    ("missing link", _robot(_joint("j1", "a", "ghost")), None, "robot/joint[@name='j1']/child/@link"),
    ("malformed number", _robot(_joint("j1", "a", "b").replace('xyz="0 0 0.1"', 'xyz="0 0 abc"')), None,
     "robot/joint[@name='j1']/origin/@xyz"),
    ("wrong count", _robot(_joint("j1", "a", "b").replace('xyz="0 0 1"', 'xyz="0 1"')), None,
     "robot/joint[@name='j1']/axis/@xyz"),
    ("non-finite", _robot(_joint("j1", "a", "b").replace('upper="1"', 'upper="nan"')), None,
     "robot/joint[@name='j1']/limit/@upper"),
    ("no limit", _robot(_joint("j1", "a", "b").replace('<limit lower="-1" upper="1"/>', "")), None,
     "robot/joint[@name='j1']/limit"),
    ("zero axis", _robot(_joint("j1", "a", "b").replace('xyz="0 0 1"', 'xyz="0 0 0"')), None,
     "robot/joint[@name='j1']/axis/@xyz"),
    ("several leaves", _robot(_joint("j1", "a", "b"), _joint("j2", "a", "c")), None, "tip_link"),
    ("unknown tip", _robot(_joint("j1", "a", "b"), _joint("j2", "b", "c")), "d", "tip_link"),
    ("two roots", _robot(_joint("j1", "a", "b")), None, "robot/link"),
    ("not xml", "<robot><link name='a'></robot>", None, "robot"),
]


@pytest.mark.parametrize("case, text, tip, key", REJECTED, ids=[row[0] for row in REJECTED])
def test_unsupported_or_malformed_input_is_rejected(case, text, tip, key):
    """Each unsupported or malformed element raises a SceneError whose message names it."""
    with pytest.raises(SceneError) as info:
        chain_from_urdf(text, tip_link=tip, source="test.urdf")
    assert info.value.key == key
    assert key in str(info.value) and "test.urdf" in str(info.value)


def test_closed_loop_through_the_tip_is_rejected():
    """A cycle of links (each with one parent) reached from the tip raises instead of looping."""
    text = _robot(_joint("j0", "r", "a"), _joint("j1", "b", "c"), _joint("j2", "c", "b"), links=("r", "a", "b", "c"))
    with pytest.raises(SceneError, match="closed loop"):
        chain_from_urdf(text, tip_link="c")


# Numbers and names on the chain are held to the physical ranges (core.model.ranges) and the name rule
# (core.model.names); off the chain only what the engines' importers need is checked.
ON_PATH_REJECTED = [
    ("huge limit", _joint("j1", "a", "b").replace('lower="-1"', 'lower="-1e308"'), "j1']/limit/@lower", "physical range"),
    ("huge origin", _joint("j1", "a", "b").replace('xyz="0 0 0.1"', 'xyz="1e308 0 0"'), "j1']/origin/@xyz",
     "physical range"),
    ("huge rpy", _joint("j1", "a", "b").replace('<origin xyz="0 0 0.1"/>', '<origin rpy="1e300 0 0"/>'),
     "j1']/origin/@rpy", "physical range"),
    ("tiny axis", _joint("j1", "a", "b").replace('xyz="0 0 1"', 'xyz="0 0 1e-200"'), "j1']/axis/@xyz", "usable range"),
    ("huge axis", _joint("j1", "a", "b").replace('xyz="0 0 1"', 'xyz="1e200 1e200 1e200"'), "j1']/axis/@xyz",
     "usable range"),
    ("inverted limits", _joint("j1", "a", "b").replace('lower="-1" upper="1"', 'lower="1" upper="-1"'), "j1']/limit",
     "above upper"),
    ("injected name", _joint('j1&quot;/&gt;&lt;x', "a", "b"), "robot/joint[@name='j1\"/><x']", "allowed set"),
]


@pytest.mark.parametrize("case, joint, key, words", ON_PATH_REJECTED, ids=[row[0] for row in ON_PATH_REJECTED])
def test_numbers_and_names_on_the_chain_are_held_to_their_ranges(case, joint, key, words):
    """Each refusal names the element and what is allowed; nothing is normalised to NaN or sampled to overflow."""
    with pytest.raises(SceneError) as info:
        chain_from_urdf(_robot(joint, links=("a", "b")), source="test.urdf")
    assert key in info.value.key and words in info.value.problem and info.value.allowed


def test_the_same_joints_off_the_chain_are_ignored():
    """A side branch with an immovable joint, a limit of 1e16 (as iris.urdf's propellers) and an odd name loads."""
    side = (_joint("odd name!", "a", "c").replace('lower="-1" upper="1"', 'lower="-1e16" upper="1e16"')
            + _joint("stuck", "c", "d").replace('lower="-1" upper="1"', 'lower="0" upper="0"'))
    chain = chain_from_urdf(_robot(_joint("j1", "a", "b"), side, links=("a", "b", "c", "d")), tip_link="b")
    assert [j.name for j in chain.joints] == ["j1"]


def test_robot_name_follows_the_name_rule():
    with pytest.raises(SceneError, match="allowed set") as info:
        chain_from_urdf(_robot(_joint("j1", "a", "b"), links=("a", "b")).replace("name='r'", "name='r&lt;x'"))
    assert info.value.key == "robot/@name"


def test_too_many_joints_are_refused_before_reading_them():
    """Movable joints beyond the limit (Pinocchio's data grows steeply) and joint elements beyond the fixed cap."""
    links = [f"l{i}" for i in range(201)]
    movable = [_joint(f"j{i}", f"l{i}", f"l{i + 1}", type="continuous") for i in range(200)]
    with pytest.raises(SceneError, match="200 movable joints") as info:
        chain_from_urdf(_robot(*movable, links=links))
    assert "--max-joints" in info.value.allowed
    assert chain_from_urdf(_robot(*movable, links=links), max_joints=200).n_joints == 200
    links = [f"l{i}" for i in range(MAX_URDF_JOINTS + 2)]
    fixed = [_joint(f"j{i}", f"l{i}", f"l{i + 1}", type="fixed") for i in range(MAX_URDF_JOINTS + 1)]
    with pytest.raises(SceneError, match="<joint> elements"):
        chain_from_urdf(_robot(*fixed, links=links))


def test_a_loop_cut_off_from_the_root_is_rejected_whatever_the_base():
    """A base link chosen on a loop below no root used to walk the loop forever."""
    text = _robot(_joint("j0", "r", "a"), _joint("j1", "b", "c"), _joint("j2", "c", "b"), links=("r", "a", "b", "c"))
    for base, tip in (("b", None), ("b", "c")):
        with pytest.raises(SceneError, match="closed loop"):
            chain_from_urdf(text, base_link=base, tip_link=tip)


@pytest.mark.parametrize("encoding, codec", [("ISO-8859-1", "latin-1"), ("UTF-16", "utf-16")])
def test_a_declared_encoding_is_honoured(tmp_path, encoding, codec):
    """The file is parsed from bytes, so its XML declaration decides the encoding (a comment in Latin-1 too)."""
    text = f'<?xml version="1.0" encoding="{encoding}"?>\n<!-- Müller -->' + _robot(_joint("j1", "a", "b"), links=("a", "b"))
    (tmp_path / "r.urdf").write_bytes(text.encode(codec))
    assert chain_from_urdf(tmp_path / "r.urdf").joints[0].name == "j1"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_files_that_are_not_regular_are_never_opened(tmp_path):
    os.mkfifo(tmp_path / "fifo.urdf")
    for path in (tmp_path / "fifo.urdf", tmp_path, "/dev/zero"):
        with pytest.raises(SceneError, match="not a regular file"):
            chain_from_urdf(str(path))


def nested_urdf(depth: int) -> str:
    """A valid one-joint robot whose link 'b' holds elements nested down to ``depth`` levels (<robot> is 1)."""
    inner = "<a>" * (depth - 2) + "</a>" * (depth - 2)
    return _robot(_joint("j1", "a", "b"), links=("a", "b")).replace("<link name='b'/>", f"<link name='b'>{inner}</link>")


def _with_doctype(doctype: str, reference: str) -> str:
    """The one-joint robot headed by ``doctype``, with ``reference`` (an entity, or nothing) as link a's text."""
    robot = _robot(_joint("j1", "a", "b"), links=("a", "b"))
    return doctype + robot.replace("<link name='a'/>", f"<link name='a'>{reference}</link>")


_LAUGHS = "<!ENTITY l0 'ha'>" + "".join(f"<!ENTITY l{i} '{f'&l{i - 1};' * 10}'>" for i in range(1, 10))
DOCTYPE_URDF = [
    ("internal entity", _with_doctype("<!DOCTYPE robot [<!ENTITY e 'x'>]>", "&e;")),
    ("parameter entity", _with_doctype("<!DOCTYPE robot [<!ENTITY % p \"<!ENTITY e 'x'>\"> %p;]>", "&e;")),
    ("billion laughs", _with_doctype(f"<!DOCTYPE robot [{_LAUGHS}]>", "&l9;")),
    ("external DTD", _with_doctype("<!DOCTYPE robot SYSTEM 'file:///etc/passwd'>", "")),
    ("external entity", _with_doctype("<!DOCTYPE robot [<!ENTITY e SYSTEM 'file:///etc/passwd'>]>", "&e;")),
    ("bare DOCTYPE", _with_doctype("<!DOCTYPE robot>", "")),
]
"""URDF with a document type declaration: every one refused before any declaration in it is read."""
DEEP_URDF = [(f"nested {depth:,} deep", nested_urdf(depth)) for depth in (1_000, 5_000)]
"""URDF nested deeper than ElementTree's writer (and Python's stack) can recurse (issue #25)."""


@pytest.mark.parametrize("case, text", DOCTYPE_URDF, ids=[row[0] for row in DOCTYPE_URDF])
def test_a_doctype_is_refused_before_its_entities_are_read(case, text):
    with pytest.raises(SceneError) as info:
        chain_from_urdf(text, source="test.urdf")
    assert info.value.key == "<!DOCTYPE robot>" and "test.urdf" in str(info.value) and "\n" not in str(info.value)
    assert "document type declaration" in info.value.problem and "never expanded or fetched" in info.value.allowed


@pytest.mark.parametrize("case, text", DEEP_URDF, ids=[row[0] for row in DEEP_URDF])
def test_deep_nesting_is_refused_at_the_first_element_too_deep(tmp_path, case, text):
    """From a file, or handed to the exporter as if the file changed after loading: a SceneError, never a
    RecursionError."""
    path = tmp_path / "deep.urdf"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        chain_from_urdf(path)
    assert info.value.key == f"<a> at depth {MAX_XML_DEPTH + 1}" and info.value.source == str(path)
    assert f"more than {MAX_XML_DEPTH} levels" in info.value.problem and f"at most {MAX_XML_DEPTH}" in info.value.allowed
    with pytest.raises(SceneError, match="levels deep"):
        original_without_geometry(str(path))


def test_nesting_up_to_the_limit_loads_and_exports(tmp_path):
    path = tmp_path / "deepest.urdf"
    path.write_text(nested_urdf(MAX_XML_DEPTH))
    assert [joint.name for joint in chain_from_urdf(path).joints] == ["j1"]
    assert len(re.findall(r"<a\b", original_without_geometry(str(path)))) == MAX_XML_DEPTH - 2
    with pytest.raises(SceneError, match=f"<a> at depth {MAX_XML_DEPTH + 1}"):
        chain_from_urdf(nested_urdf(MAX_XML_DEPTH + 1))
