"""The robot corpus (issue #45): every robot description the dependencies' wheels ship, one scene per file in the
``robots`` suite, each file through every engine's own importer; the report's table of robots x engines."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.scenes import library
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene

ROBOT_SCENES = sorted(name for name in library.builtin_paths() if name.startswith("robot-"))
SAME_ROBOT = {"robot-panda-pybullet": "robot-panda", "robot-a1-pybullet": "robot-a1",
              "robot-anymal-kinova": "robot-anymal-b", "robot-b1-z1": "robot-b1",
              "robot-humanoid-symmetric": "robot-humanoid-mjcf", "robot-striker": "robot-pusher"}
"""Files of a robot already in the corpus (another package's copy, or the robot with an arm on it): counted once."""
DISTINCT_ROBOTS = 40
"""What the issue asks the corpus to cover: distinct robots with at least 2 movable joints each."""


MJCF_FILES = 7
"""MJCF robot files in the corpus (pybullet_data's that MuJoCo 4 reads; docs/robots.md)."""


def _movable_joints(path: str) -> int:
    """A URDF file's joints that are not fixed, or an MJCF file's hinge and slide joints (a joint's type defaults to
    hinge; none of these files sets it through a default class)."""
    root = ET.parse(path).getroot()
    if root.tag == "mujoco":
        return sum(joint.get("type", "hinge") in ("hinge", "slide") for joint in root.iter("joint"))
    return sum(joint.get("type") != "fixed" for joint in root.findall("joint"))


@pytest.mark.slow  # it loads the 63 scene files and their robots: ~3 s of CPU
def test_the_corpus_covers_forty_distinct_robots_each_a_file_of_two_or_more_movable_joints():
    scenes = library.load(ROBOT_SCENES)
    assert all(isinstance(s, JointDynamicsScene) and "robots" in s.suites for s in scenes)
    files = {s.chain.robot_file for s in scenes}
    assert len(files) == len(scenes), "one scene per file"
    assert sum(s.chain.mjcf_path is not None for s in scenes) == MJCF_FILES
    assert all(_movable_joints(path) >= 2 for path in files)
    assert len({SAME_ROBOT.get(s.name, s.name) for s in scenes}) >= DISTINCT_ROBOTS
    assert {s.name for s in library.suite("robots")} == set(ROBOT_SCENES)


@pytest.mark.slow
def test_the_report_tables_each_robot_by_engine_with_each_refusal_said_once(tmp_path, capsys):
    """A file every engine reads alike, and one whose link tensor breaks the triangle inequality (pybullet_data's
    TwoJointRobot): core declines it, MuJoCo refuses it, PyBullet zeroes it (n/a, each reason a note), Pinocchio
    computes; the gate passes."""
    out = tmp_path / "run"
    assert main(["run", "robot-cartpole", "robot-two-joint-robot", "--quick", "--check", "--out", str(out)]) == 0
    report = (out / "report.md").read_text(encoding="utf-8")
    table = report.split("## Robot files × engines", 1)[1].split("\n## ", 1)[0]
    rows = {line.split(" | ")[0].strip("| "): line for line in table.splitlines() if line.startswith("| robot-")}
    assert set(rows) == {"robot-cartpole", "robot-two-joint-robot"}
    # core, MuJoCo, PyBullet and Pinocchio compile the cart-pole; the analytic engine (a closed form) compiles none
    assert rows["robot-cartpole"].count("model ") == 4 and rows["robot-cartpole"].count("n/a [") == 1
    assert rows["robot-two-joint-robot"].count("n/a [") == 4
    notes = [line for line in table.splitlines() if line.startswith("- [")]
    assert any("core refuses the file's mass properties" in n and "triangle inequality" in n for n in notes)
    assert any("inertia must satisfy A + B >= C" in n for n in notes)
    assert any("sets the inertia of" in n and "to zero" in n for n in notes)
