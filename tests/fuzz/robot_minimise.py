"""The minimiser of random robot files: a model that shows a known class of importer discrepancy, shrunk to the
smallest model that still shows it (:func:`minimise`), and the sweep that finds each class and writes its minimised
file (``python -m tests.fuzz.robot_minimise --help``)."""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
from collections import defaultdict
from collections.abc import Callable, Iterable
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from simparity.references.common.quiet import captured_output
from simparity.references.pybullet.quiet import pybullet as pb
from tests.fuzz.robot_classes import (KNOWN, SWEEP_COUNT, SWEEP_SEED, KnownClass, docs_table, rendered, run_model,
                                      with_joints, with_links, with_style)
from tests.fuzz.robot_files import JointSpec, RandomRobot, RobotSpec, Style, random_robots, render, spec_to_json


def _subtree(spec: RobotSpec, link: str) -> set[str]:
    """``link`` and every link below it."""
    out, stack = set(), [link]
    while stack:
        name = stack.pop()
        out.add(name)
        stack.extend(joint.child for joint in spec.joints if joint.parent == name)
    return out


def _without_links(spec: RobotSpec, gone: set[str]) -> RobotSpec:
    """The spec without the links ``gone`` and their parent joints (mimics of removed joints dropped)."""
    joints = [joint for joint in spec.joints if joint.child not in gone]
    names = {joint.name for joint in joints}
    joints = [replace(joint, mimic=None) if joint.mimic and joint.mimic.leader not in names else joint
              for joint in joints]
    return replace(spec, links=tuple(link for link in spec.links if link.name not in gone), joints=tuple(joints))


def _spliced(spec: RobotSpec, link: str) -> RobotSpec:
    """The spec without ``link`` and its parent joint: its child joints hang from its parent, their origins composed
    with the removed joint's (at q = 0)."""
    parent = next(joint for joint in spec.joints if joint.child == link)
    r_parent = Rotation.from_euler("xyz", parent.rpy)
    joints = []
    for joint in spec.joints:
        if joint is parent:
            continue
        if joint.parent == link:
            xyz = tuple(float(v) for v in np.array(parent.xyz) + r_parent.apply(joint.xyz))
            with warnings.catch_warnings():  # at pitch +-pi/2 SciPy warns that it sets yaw to 0: the same rotation
                warnings.simplefilter("ignore", UserWarning)
                rpy = tuple(float(v) for v in (r_parent * Rotation.from_euler("xyz", joint.rpy)).as_euler("xyz"))
            joint = replace(joint, parent=parent.parent, xyz=xyz, rpy=rpy)
        joints.append(joint)
    names = {joint.name for joint in joints}
    joints = [replace(joint, mimic=None) if joint.mimic and joint.mimic.leader not in names else joint
              for joint in joints]
    return replace(spec, links=tuple(l for l in spec.links if l.name != link), joints=tuple(joints))


def _fixed(joint: JointSpec) -> JointSpec:
    return replace(joint, type="fixed", axis=(1.0, 0.0, 0.0), lower=-np.inf, upper=np.inf, damping=0.0, friction=0.0,
                   armature=0.0, mimic=None, write_axis=True)


def _round(value: float) -> float:
    return float(f"{value:.2g}")


def _reductions(spec: RobotSpec) -> Iterable[RobotSpec]:
    """Smaller or simpler specs, the most reducing first: whole subtrees, single links, joints made fixed, the
    spelling, each joint's and link's attributes, numbers rounded, names shortened."""
    by_size = sorted((link.name for link in spec.links[1:]), key=lambda n: -len(_subtree(spec, n)))
    for name in by_size:
        yield _without_links(spec, _subtree(spec, name))
    for name in by_size:
        if any(joint.parent == name for joint in spec.joints):
            yield _spliced(spec, name)
    for joint in spec.joints:
        if joint.movable:
            followers = {j.name for j in spec.joints if j.mimic and j.mimic.leader == joint.name}
            yield with_joints(spec, lambda j, joint=joint: _fixed(j) if j.name == joint.name else (
                replace(j, mimic=None) if j.name in followers else j))
    defaults = Style()
    for attribute in ("mujoco_block", "shuffle", "explicit_limited", "angle", "orientation", "eulerseq"):
        if getattr(spec.style, attribute) != getattr(defaults, attribute):
            if attribute == "eulerseq" and (spec.style.orientation == "euler" or any(
                    link.mjcf_inertial == "euler" for link in spec.links)):
                continue
            yield with_style(spec, **{attribute: getattr(defaults, attribute)})
    for joint in spec.joints:
        changes = [{"mimic": None}, {"damping": 0.0}, {"friction": 0.0}, {"armature": 0.0}, {"rpy": (0.0, 0.0, 0.0)},
                   {"xyz": (0.0, 0.0, 0.0)}, {"write_origin": True}, {"write_axis": True},
                   {"xyz": tuple(_round(v) for v in joint.xyz)}, {"rpy": tuple(_round(v) for v in joint.rpy)},
                   {"damping": _round(joint.damping)}, {"friction": _round(joint.friction)},
                   {"armature": _round(joint.armature)}]
        if joint.mimic:
            changes += [{"mimic": replace(joint.mimic, offset=0.0)},
                        {"mimic": replace(joint.mimic, multiplier=_round(joint.mimic.multiplier),
                                          offset=_round(joint.mimic.offset))}]
        if np.isfinite(joint.lower):
            changes += [{"lower": _round(joint.lower), "upper": _round(joint.upper)}]
        if joint.movable:  # every change leads one way (no cycle): toward z axes, continuous joints, round limits
            changes += [{"axis": (0.0, 0.0, 1.0)}]
        if joint.type == "revolute":
            changes += [{"type": "continuous", "lower": -np.inf, "upper": np.inf}, {"lower": -1.0, "upper": 1.0}]
        if joint.type == "prismatic":
            changes += [{"lower": -0.5, "upper": 0.5}]
        for change in changes:
            if any(getattr(joint, key) != value for key, value in change.items()):
                yield with_joints(spec, lambda j, joint=joint, change=change: replace(j, **change)
                                   if j.name == joint.name else j)
    for link in spec.links:
        mean = float(np.mean(link.moments))
        changes = [{"rpy": (0.0, 0.0, 0.0)}, {"com": (0.0, 0.0, 0.0)}, {"urdf_inertial": "rpy"},
                   {"mjcf_inertial": "quat"}, {"moments": (mean, mean, mean)},
                   {"mass": 1.0, "moments": (0.01, 0.01, 0.01), "urdf_inertial": "rpy", "mjcf_inertial": "quat",
                    "shape": "sphere"},
                   {"com": tuple(_round(v) for v in link.com)}, {"rpy": tuple(_round(v) for v in link.rpy)},
                   {"mass": _round(link.mass)}, {"moments": tuple(_round(v) for v in link.moments)}]
        if link.mass == 0 and not any(link.moments):
            changes = [{"urdf_inertial": "zero"}, {"mjcf_inertial": "zero"}] + changes[5:6]
        for change in changes:
            if any(getattr(link, key) != value for key, value in change.items()):
                yield with_links(spec, lambda l, link=link, change=change: replace(l, **change)
                                  if l.name == link.name else l)
    yield _renamed(spec)


def _renamed(spec: RobotSpec) -> RobotSpec:
    """Links named base, l1, l2, ... in tree order and joints j1, j2, ... in the order of their names (the order
    urdfdom, hence Pinocchio, walks a link's children in: kept), the file's spelling kept otherwise."""
    links = {spec.root: "base"} | {joint.child: f"l{k + 1}" for k, joint in enumerate(spec.joints)}
    width = len(str(len(spec.joints)))
    joints = {name: f"j{k + 1:0{width}d}" for k, name in enumerate(sorted((j.name for j in spec.joints),
                                                                        key=str.encode))}
    if all(links[n] == n for n in links) and all(joints[n] == n for n in joints):
        return spec
    return replace(spec, name="minimal", links=tuple(replace(link, name=links[link.name]) for link in spec.links),
                   joints=tuple(replace(joint, name=joints[joint.name], parent=links[joint.parent],
                                        child=links[joint.child], mimic=replace(joint.mimic, leader=joints[
                                            joint.mimic.leader]) if joint.mimic else None)
                                for joint in spec.joints))


def mujoco_accepts(robot: RandomRobot) -> bool:
    try:
        with captured_output():
            mujoco.MjModel.from_xml_string(robot.urdf)
            mujoco.MjModel.from_xml_string(robot.mjcf)
    except ValueError:
        return False
    return True


def shows(spec: RobotSpec, known: KnownClass, folder: Path, client: int) -> bool:
    """Whether the model of ``spec`` is accepted by MuJoCo in both formats and shows a discrepancy of ``known``."""
    robot = rendered(spec, -1)
    if not mujoco_accepts(robot):
        return False
    result = run_model(robot, folder, client, known.importers)
    return any(known.name in names and (not known.shown_by or d.quantity in known.shown_by)
               for d, names in result.explained)


def minimise(spec: RobotSpec, keeps: Callable[[RobotSpec], bool], budget: int = 4000) -> RobotSpec:
    """The smallest spec :func:`_reductions` reach from ``spec`` while ``keeps`` holds. Passes over the reductions
    in order, each one that keeps it taken at once (the pass goes on from the same position in the new spec's
    reductions), until a whole pass takes none (or ``budget`` tries are spent)."""
    tries, position, progress = 0, 0, False
    while tries < budget:
        candidates = [c for c in _reductions(spec) if c != spec]
        if position >= len(candidates):
            if not progress:
                break
            position, progress = 0, False
            continue
        tries += 1
        if keeps(candidates[position]):
            spec, progress = candidates[position], True
        else:
            position += 1
    return spec


OUT = Path(tempfile.gettempdir()) / "robotgen" / "findings"
"""Where :func:`find_and_minimise` writes by default (the adopted files live in docs/robot-findings/)."""


def _describe(known: KnownClass, robot: RandomRobot, folder: Path, client: int) -> list[str]:
    """The minimal model's discrepancies of ``known``, one line each."""
    result = run_model(robot, folder, client, known.importers)
    return [d.line() for d, names in result.explained if known.name in names]


def find_and_minimise(count: int, seeds: list[int], out: Path = OUT, candidates: int = 2) -> dict[str, RobotSpec]:
    """Sweep ``count`` models from each of ``seeds`` (the next seed only while a known class is unseen); for each
    known class, minimise the ``candidates`` smallest models that show it and keep the smallest result; write each as
    ``out/<class>.urdf`` or ``.xml`` (its spec beside it as ``.json``) and ``out/README.md``; return class -> minimal
    spec."""
    out.mkdir(parents=True, exist_ok=True)
    folder = Path(tempfile.mkdtemp(prefix="robotgen-"))
    client = pb.connect(pb.DIRECT)
    seen: dict[str, list[RandomRobot]] = defaultdict(list)
    swept = []
    for seed in seeds:
        if swept and all(known.name in seen for known in KNOWN):
            break
        swept.append(seed)
        for robot in random_robots(count, seed):
            for _, names in run_model(robot, folder, client).explained:
                for name in names:
                    if robot not in seen[name]:
                        seen[name].append(robot)
    found: dict[str, RobotSpec] = {}
    lines = ["# Random robot files: known discrepancy classes, minimised", "",
             f"Sweep: {count} models from each seed of {swept} (tests/fuzz/robot_files.py), every importer of "
             "tests/references/test_random_robot_files.py; each class minimised from its smallest models.", ""]
    for known in KNOWN:
        robots = sorted(seen.get(known.name, []), key=lambda r: (len(r.spec.links), len(r.urdf)))[:candidates]
        if not robots:
            lines += [f"## {known.name}: not seen in this sweep", ""]
            continue
        start = time.perf_counter()
        best = None
        for robot in robots:
            small = minimise(robot.spec, lambda spec, known=known: shows(spec, known, folder, client))
            size = (len(small.links), len(known.text(small)))
            if best is None or size < best[0]:
                best = (size, small, robot.seed)
        _, small, origin = best
        found[known.name] = small
        robot = render(small, -1)
        text = known.text(small)
        (out / known.minimal_file.name).write_text(text, encoding="utf-8")
        (out / f"{known.name}.json").write_text(spec_to_json(small), encoding="utf-8")
        lines += [f"## {known.name} ({known.kind}; {', '.join(known.importers)})", "", known.explanation, "",
                  f"Seen in {len(seen[known.name])} of {count * len(swept)} models; minimised from seed {origin} in "
                  f"{time.perf_counter() - start:.0f} s to {len(small.links)} links:", "", "```xml", text.rstrip(),
                  "```", "", "Its discrepancies:", ""]
        lines += [f"- {line}" for line in _describe(known, robot, folder, client)] + [""]
        print(f"{known.name}: {len(small.links)} links (from seed {origin})", flush=True)
    (out / "README.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    pb.disconnect(client)
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tests.fuzz.robot_minimise",
        description="Sweep random robot files, minimise each known class of importer discrepancy into --out (adopt "
                    "a file by copying it and its .json into docs/robot-findings/), or print docs/robots.md's table "
                    "of the known classes.")
    parser.add_argument("--count", type=int, default=SWEEP_COUNT, help="models per seed (default %(default)s)")
    parser.add_argument("--seeds", type=int, nargs="+", default=[SWEEP_SEED, 777], help="default %(default)s")
    parser.add_argument("--out", type=Path, default=OUT, help="default %(default)s")
    parser.add_argument("--docs", action="store_true", help="print the table of known classes for docs/robots.md "
                        "instead")
    args = parser.parse_args(argv)
    if args.docs:
        print(docs_table(), end="")
    else:
        find_and_minimise(args.count, args.seeds, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
