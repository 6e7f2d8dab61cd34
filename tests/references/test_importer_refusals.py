"""Issue #43: where an engine's importer cannot read a robot file, its rows are n/a in the importer's own words (MuJoCo's
compiler: tests/references/test_joint_dynamics_engines.py), never a traceback or a failed case."""

from __future__ import annotations

import pinocchio as pin

from simparity.comparisons.scenes import library
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pybullet.adapter import _loader_support

BROKEN = ("<robot name='broken'><link name='a'/><joint name='j' type='revolute'><parent link='a'/>"
          "<child link='missing'/></joint></robot>")


def test_pybullet_s_refusal_is_quoted():
    support = _loader_support(BROKEN)
    assert not support.ok and support.reason == "PyBullet's URDF loader refuses the file: Cannot load URDF file."


def test_pinocchio_s_refusal_is_quoted(monkeypatch):
    chain = library.load(["crafted-arm-dynamics"])[0].chain

    def refuse(*args, **kwargs):
        raise ValueError("The parent link of joint 'j2' is\nmissing")  # as urdfdom words a broken tree

    monkeypatch.setattr(pin, "buildModelFromXML", refuse)
    support = PinocchioEngine().supports_joint_dynamics(chain, "recursive")
    assert not support.ok
    assert support.reason == "Pinocchio's URDF parser refuses the file: The parent link of joint 'j2' is missing"


def test_urdfdom_s_own_words_reach_the_row(tmp_path):
    """A <limit> without effort: core's parser takes it, Pinocchio's urdfdom refuses it and says why on stderr."""
    from simparity.core.urdf import chain_from_urdf
    from simparity.references.pinocchio.joint_dynamics import pinocchio_dynamics_problem

    urdf = tmp_path / "no_effort.urdf"
    urdf.write_text('<robot name="a"><link name="b"/><link name="c"><inertial><mass value="1"/><inertia ixx="1" '
                    'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" type="revolute">'
                    '<parent link="b"/><child link="c"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>'
                    "</robot>", encoding="utf-8")
    problem = pinocchio_dynamics_problem(chain_from_urdf(str(urdf), dynamics=True))
    assert problem.startswith("Pinocchio's URDF parser refuses the file:") and "limit has no effort" in problem
