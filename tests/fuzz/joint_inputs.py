"""Joint inputs out of range (issue #39, section 3): damping, armature, mass, centre of mass and inertia of a
chain's joints at 1e308, 5e-324, nan, inf and negative, an asymmetric joint inertia, in a scene file's
``[[chain.joint]]``, in a URDF (``<dynamics>``, ``<inertial>``, duplicated elements, ``<mimic>`` to nowhere or with a
nan multiplier) and through a ``[sweep]``. Read by ``simparity show FILE`` (the loader, nothing run); two through
``simparity run`` in a subprocess, where an overflow warning of a diverging case would reach stderr."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from tests.fuzz.files import pick, seed_of
from tests.fuzz.oracle import EITHER, REFUSED, VALID, Base, Call, Case

FAMILY = "joint_inputs"
SCENE_FILE, URDF_FILE = "fuzz-joints.toml", "fuzz-arm.urdf"
JOINTS = ("shoulder", "elbow")

JOINT = """[[chain.joint]]
name = "{name}"
type = "revolute"
axis = [0.0, 0.0, 1.0]
origin_xyz = [{x}, 0.0, 0.0]
mass = 2.0
com_xyz = [0.25, 0.0, 0.0]
inertia = [[0.001, 0.0, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.04]]
damping = 0.1
armature = 0.01
"""
HEAD = """[scene]
name = "fuzz-joints"
kind = "{kind}"
reference = "pinocchio"

[chain]
end_effector = "tip"
end_effector_xyz = [0.5, 0.0, 0.0]

"""
MOTION = """
[world]
gravity_world = [0.0, -9.81, 0.0]

[initial]
q = [0.5, -0.3]
qdot = [0.0, 0.0]

[drive]
torque = [0.0, 0.0]
damping = [0.1, 0.1]

[simulation]
duration = 0.2
dt = [0.01, 0.005]
"""
DYNAMICS = """
[world]
gravity_world = [0.0, -9.81, 0.0]

[sampling]
states = 10
seed = 39
"""


def scene_text(kind: str) -> str:
    """A valid 2-joint chain scene of ``kind`` (joint_motion or joint_dynamics) with damping and armature."""
    joints = "\n".join(JOINT.format(name=name, x=0.5 * k) for k, name in enumerate(JOINTS))
    return HEAD.format(kind=kind) + joints + (MOTION if kind == "joint_motion" else DYNAMICS)


JOINT_VALUES: dict[str, tuple[str, ...]] = {
    "damping": ("1e308", "nan", "inf", "-1.0", "-1e308"),
    "armature": ("1e308", "nan", "inf", "-1.0"),
    "mass": ("1e308", "nan", "inf", "-1.0", "5e-324"),
    "com_xyz": ("[1e308, 0.0, 0.0]", "[nan, 0.0, 0.0]", "[0.25, inf, 0.0]"),
    "inertia": ("[[5e-324, 0.0, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.04]]",
                "[[5e-324, 0.0, 0.0], [0.0, 5e-324, 0.0], [0.0, 0.0, 5e-324]]",
                "[[1e308, 0.0, 0.0], [0.0, 1e308, 0.0], [0.0, 0.0, 1e308]]",
                "[[nan, 0.0, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.04]]",
                "[[0.001, 0.0005, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.04]]",   # asymmetric
                "[[0.001, 0.0, 0.0], [0.0, 0.04, 0.0], [0.003, 0.0, 0.04]]",    # asymmetric
                "[[-0.001, 0.0, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.04]]"),
}
"""``[[chain.joint]]`` key -> values out of range (a denormal damping or armature is tried below, either way)."""

MOTION_VALUES: dict[str, tuple[str, str]] = {
    "drive damping 1e308": ("damping = [0.1, 0.1]", "damping = [0.1, 1e308]"),
    "drive damping nan": ("damping = [0.1, 0.1]", "damping = nan"),
    "drive damping negative": ("damping = [0.1, 0.1]", "damping = -1.0"),
    "drive torque 1e308": ("torque = [0.0, 0.0]", "torque = [1e308, 0.0]"),
    "initial qdot 1e308": ("qdot = [0.0, 0.0]", "qdot = [1e308, 0.0]"),
    "initial q nan": ("q = [0.5, -0.3]", "q = [nan, -0.3]"),
}
"""A joint-motion scene's [drive] and [initial] out of range: name -> (valid line, its replacement)."""

SWEEPS: dict[str, tuple[str, frozenset[int]]] = {
    "damping to 1e308": ('"chain.joint[shoulder].damping" = [0.1, 1e308]', REFUSED),
    "armature negative": ('"chain.joint[elbow].armature" = [0.01, -1.0]', REFUSED),
    "inertia made asymmetric": ('"chain.joint[shoulder].inertia[0][1]" = [0.0, 0.0005]', REFUSED),
    "inertia entry 5e-324": ('"chain.joint[elbow].inertia[0][0]" = [0.001, 5e-324]', REFUSED),
    "com to 1e308": ('"chain.joint[elbow].com_xyz[0]" = [0.25, 1e308]', REFUSED),
    "mass to 5e-324": ('"chain.joint[shoulder].mass" = [2.0, 5e-324]', REFUSED),
    "damping range to 1e308": ('"chain.joint[0].damping" = {start = 0.0, stop = 1e308, num = 3}', REFUSED),
    "drive damping nan": ('"drive.damping[1]" = [0.1, nan]', REFUSED),
    "control: damping 0.1 to 0.2": ('"chain.joint[shoulder].damping" = [0.1, 0.2]', VALID),
}

URDF = """<?xml version="1.0"?>
<robot name="fuzz_arm">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="10"/>
    <dynamics damping="0.1" friction="0.0"/>
  </joint>
  <link name="upper">
    <inertial><origin xyz="0.25 0 0" rpy="0 0 0"/><mass value="2.0"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.04"/></inertial>
  </link>
  <joint name="j2" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="10"/>
    <dynamics damping="0.1"/>
  </joint>
  <link name="fore">
    <inertial><origin xyz="0.25 0 0" rpy="0 0 0"/><mass value="1.0"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial>
  </link>
  <joint name="tip_joint" type="fixed"><parent link="fore"/><child link="tip"/><origin xyz="0.5 0 0"/></joint>
  <link name="tip"/>
  <joint name="finger_joint" type="revolute">
    <parent link="fore"/><child link="finger"/>
    <origin xyz="0.4 0.05 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="j2" multiplier="1.0" offset="0.0"/>
  </joint>
  <link name="finger">
    <inertial><origin xyz="0.02 0 0"/><mass value="0.05"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
</robot>
"""
"""A 2-joint arm with a finger (a mimic joint off the chain, held at 0 like every branch) and joint damping."""

URDF_SCENE = """[scene]
name = "fuzz-arm"
kind = "joint_dynamics"
reference = "pinocchio"

[chain]
urdf = "fuzz-arm.urdf"
tip_link = "tip"

[world]
gravity_world = [0.0, 0.0, -9.81]

[sampling]
states = 10
seed = 39
"""

URDF_EDITS: dict[str, tuple[str, str]] = {
    "dynamics damping 1e308": ('<dynamics damping="0.1"/>', '<dynamics damping="1e308"/>'),
    "dynamics damping nan": ('<dynamics damping="0.1"/>', '<dynamics damping="nan"/>'),
    "dynamics damping inf": ('<dynamics damping="0.1" friction="0.0"/>', '<dynamics damping="inf" friction="0.0"/>'),
    "dynamics damping negative": ('<dynamics damping="0.1"/>', '<dynamics damping="-1"/>'),
    "dynamics damping text": ('<dynamics damping="0.1"/>', '<dynamics damping="much"/>'),
    "mass 1e308": ('<mass value="2.0"/>', '<mass value="1e308"/>'),
    "mass nan": ('<mass value="2.0"/>', '<mass value="nan"/>'),
    "mass 5e-324": ('<mass value="1.0"/>', '<mass value="5e-324"/>'),
    "mass negative": ('<mass value="1.0"/>', '<mass value="-1.0"/>'),
    "inertia entry 5e-324": ('ixx="0.001" ixy="0" ixz="0" iyy="0.04"', 'ixx="5e-324" ixy="0" ixz="0" iyy="0.04"'),
    "inertia all 5e-324": ('ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"',
                           'ixx="5e-324" ixy="0" ixz="0" iyy="5e-324" iyz="0" izz="5e-324"'),
    "inertia 1e308": ('ixx="0.001" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"',
                      'ixx="1e308" ixy="0" ixz="0" iyy="1e308" iyz="0" izz="1e308"'),
    "inertia nan": ('ixx="0.001" ixy="0" ixz="0" iyy="0.04"', 'ixx="nan" ixy="0" ixz="0" iyy="0.04"'),
    "com 1e308": ('<origin xyz="0.25 0 0" rpy="0 0 0"/><mass value="2.0"/>',
                  '<origin xyz="1e308 0 0" rpy="0 0 0"/><mass value="2.0"/>'),
    "com nan": ('<origin xyz="0.25 0 0" rpy="0 0 0"/><mass value="1.0"/>',
                '<origin xyz="nan 0 0" rpy="0 0 0"/><mass value="1.0"/>'),
    "two <inertial>": ('<link name="upper">', '<link name="upper">\n    <inertial><mass value="5.0"/>'
                       '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'),
    "two <mass>": ('<mass value="2.0"/>', '<mass value="2.0"/><mass value="7.0"/>'),
    "two <inertia>": ('<mass value="1.0"/>', '<mass value="1.0"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                      'izz="1"/>'),
    "two <dynamics>": ('<dynamics damping="0.1"/>', '<dynamics damping="0.1"/><dynamics damping="5.0"/>'),
    "mimic to nowhere": ('<mimic joint="j2"', '<mimic joint="nowhere"'),
    "mimic multiplier nan": ('multiplier="1.0"', 'multiplier="nan"'),
    "mimic multiplier inf": ('multiplier="1.0"', 'multiplier="inf"'),
    "mimic offset nan": ('offset="0.0"', 'offset="nan"'),
    "mimic of itself": ('<mimic joint="j2"', '<mimic joint="finger_joint"'),
}
"""URDF edits: name -> (valid text, its replacement); every one is refused, naming the file."""


def _scene(text: str, names: tuple[str, ...], folder: Path, base: Base, run: bool = False) -> Call:
    path = folder / SCENE_FILE
    path.write_text(text, encoding="utf-8")
    if run:  # a subprocess: what a diverging case prints on stderr is seen
        argv = ("run", str(path), "--engines", "core", "--jobs", "1", "--quick", "--out", str(folder / "out"))
        return Call(argv=argv, names=names, subprocess=True)
    return Call(argv=("show", str(path)), names=names)


def _joint_value(key: str, value: str, seed: int, folder: Path, base: Base) -> Call:
    rng = np.random.default_rng(seed)
    kind = pick(rng, ("joint_motion", "joint_dynamics"))
    joint = int(rng.integers(len(JOINTS)))
    blocks = scene_text(kind).split("[[chain.joint]]")
    line = next(line for line in blocks[joint + 1].splitlines() if line.startswith(f"{key} = "))
    blocks[joint + 1] = blocks[joint + 1].replace(line, f"{key} = {value}")
    return _scene("[[chain.joint]]".join(blocks), (key,), folder, base)


def _motion_value(old: str, new: str, folder: Path, base: Base, run: bool = False) -> Call:
    text = scene_text("joint_motion")
    if old not in text:
        raise AssertionError(f"scene edit {old!r} does not apply")
    return _scene(text.replace(old, new, 1), (new.split(" = ")[0],), folder, base, run)


def _sweep(line: str, folder: Path, base: Base) -> Call:
    key = line.split('"')[1]
    return _scene(scene_text("joint_motion") + f"\n[sweep]\n{line}\n", (key, "sweep"), folder, base)


def _urdf(old: str, new: str, folder: Path, base: Base) -> Call:
    if old not in URDF:
        raise AssertionError(f"URDF edit {old!r} does not apply")
    (folder / URDF_FILE).write_text(URDF.replace(old, new, 1), encoding="utf-8")
    return _scene(URDF_SCENE, (URDF_FILE,), folder, base)


def cases(rng: np.random.Generator) -> list[Case]:
    found = [Case(FAMILY, f"joint {key} = {value}", partial(_joint_value, key, value, seed_of(rng)))
             for key, values in JOINT_VALUES.items() for value in values]
    found += [Case(FAMILY, f"joint {key} = 5e-324", partial(_joint_value, key, "5e-324", seed_of(rng)), EITHER,
                   note="a denormal damping or armature is > 0: in range unless a minimum is set")
              for key in ("damping", "armature")]
    found += [Case(FAMILY, name, partial(_motion_value, old, new)) for name, (old, new) in MOTION_VALUES.items()]
    found += [Case(FAMILY, f"sweep: {name}", partial(_sweep, line), accept) for name, (line, accept) in SWEEPS.items()]
    found += [Case(FAMILY, f"URDF {name}", partial(_urdf, old, new)) for name, (old, new) in URDF_EDITS.items()]
    found += [Case(FAMILY, f"control: a valid {kind} scene", partial(_scene, scene_text(kind), ()), VALID)
              for kind in ("joint_motion", "joint_dynamics")]
    found.append(Case(FAMILY, "control: a valid URDF with a mimic finger", partial(_urdf, "<robot", "<robot"), VALID))
    found += [Case(FAMILY, f"run (subprocess): joint {key} = {value}",
                   partial(_motion_value, old, new, run=True))
              for key, value, old, new in (("com_xyz", "1e308", "com_xyz = [0.25, 0.0, 0.0]",
                                            "com_xyz = [1e308, 0.0, 0.0]"),
                                           ("damping", "1e308", "damping = 0.1\narmature = 0.01\n\n[world]",
                                            "damping = 1e308\narmature = 0.01\n\n[world]"))]
    return found
