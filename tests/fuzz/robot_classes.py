"""The known classes of discrepancy between an importer and a random robot's truth, and how a discrepancy is
recognised as one (:func:`classify`).

Each class (:data:`KNOWN`) is a predicate on the model (``trigger``), a one-line explanation, its kind (importer
default, unsupported element, engine bug) and the minimised file that shows it, kept in docs/robot-findings/ beside the
model it renders from (``<class>.json``, :func:`tests.fuzz.robot_files.spec_to_json`). A class is recognised by its
counterfactual: the discrepancy goes away when the model is respelled or changed so that the class's trigger is gone
(e.g. MJCF ``fullinertia`` written as ``quat`` + ``diaginertia``) and every other applicable class's trigger is gone
too; or, for a bound class, it is within the class's bound. Any other discrepancy is unknown.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from functools import lru_cache
from itertools import combinations
from pathlib import Path

import numpy as np

from tests.fuzz.robot_files import JointSpec, LinkSpec, RandomRobot, RobotSpec, render, spec_from_json
from tests.fuzz.robot_importers import IMPORTERS, measure
from tests.fuzz.robot_parity import TOLERANCE, Discrepancy, compare

SMALL_SEED, SMALL_COUNT = 20260, 10
"""The default test run's models (a few seconds)."""
SWEEP_SEED, SWEEP_COUNT = 4400, 300
"""The sweep's models (``-m sweep``, ~70 s on one core)."""

FINDINGS = Path(__file__).resolve().parents[2] / "docs" / "robot-findings"
"""Each known class's minimised file (``<class>.urdf`` or ``.xml``) and the model it renders from (``<class>.json``)."""

@dataclass(frozen=True)
class KnownClass:
    """A known class of discrepancy: ``kind`` ("importer default", "unsupported element", "engine bug" or
    "generator bug"), the ``importers`` and ``quantities`` it shows in, a one-line ``explanation``; ``trigger``:
    whether a spec has what causes it; ``neutralise``: the spec without it (respelled, or the feature removed), or
    ``bound``: discrepancies up to this relative error are it; its minimised file (:attr:`minimal_file`, written from
    :attr:`minimal_spec`) must show a discrepancy of it in one of ``shown_by`` (any quantity if empty); ``message``:
    words the discrepancy's detail must hold (an importer's refusal names its reason)."""

    name: str
    kind: str
    importers: tuple[str, ...]
    quantities: tuple[str, ...]
    explanation: str
    trigger: Callable[[RobotSpec], bool]
    neutralise: Callable[[RobotSpec], RobotSpec] | None = None
    bound: float | None = None
    shown_by: tuple[str, ...] = ()
    message: str = ""

    @property
    def minimal_format(self) -> str:
        """"urdf" or "mjcf": the format of the importers it shows in."""
        return "urdf" if self.importers[0].endswith("/urdf") else "mjcf"

    @property
    def minimal_file(self) -> Path:
        """The minimised file that shows it."""
        return FINDINGS / f"{self.name}.{'urdf' if self.minimal_format == 'urdf' else 'xml'}"

    @property
    def minimal_spec(self) -> RobotSpec:
        """The model :attr:`minimal_file` is written from (its truth)."""
        return spec_from_json((FINDINGS / f"{self.name}.json").read_text(encoding="utf-8"))

    def text(self, spec: RobotSpec) -> str:
        """``spec``'s file in this class's format."""
        robot = rendered(spec, -1)
        return robot.urdf if self.minimal_format == "urdf" else robot.mjcf




def with_links(spec: RobotSpec, change: Callable[[LinkSpec], LinkSpec]) -> RobotSpec:
    return replace(spec, links=tuple(change(link) for link in spec.links))


def with_joints(spec: RobotSpec, change: Callable[[JointSpec], JointSpec]) -> RobotSpec:
    return replace(spec, joints=tuple(change(joint) for joint in spec.joints))


def with_style(spec: RobotSpec, **changes) -> RobotSpec:
    return replace(spec, style=replace(spec.style, **changes))


def _massless(link: LinkSpec) -> LinkSpec:
    return replace(link, mass=0.0, com=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0), moments=(0.0, 0.0, 0.0),
                   urdf_inertial="zero", mjcf_inertial="zero", shape="massless")


def _root(spec: RobotSpec) -> LinkSpec:
    return spec.links[0]


def _massless_root(spec: RobotSpec) -> RobotSpec:
    return with_links(spec, lambda link: _massless(link) if link.name == spec.root else link)


def _root_rotated(spec: RobotSpec) -> bool:
    """The root link's <inertial> frame is turned: an rpy written (a massless rotor's too; a "zero" inertial is
    written unturned)."""
    root = _root(spec)
    return root.urdf_inertial in ("rpy", "full") and any(root.rpy) and (root.mass > 0 or any(root.moments))


def _unrotate_root(spec: RobotSpec) -> RobotSpec:
    return with_links(spec, lambda link: replace(link, rpy=(0.0, 0.0, 0.0), urdf_inertial="rpy")
                       if link.name == spec.root else link)


def _has_mimic(spec: RobotSpec) -> bool:
    return any(joint.mimic for joint in spec.joints)


def _drop_mimics(spec: RobotSpec, which: Callable[[JointSpec], bool] = lambda joint: True) -> RobotSpec:
    return with_joints(spec, lambda joint: replace(joint, mimic=None) if joint.mimic and which(joint) else joint)


def _pinocchio_order(spec: RobotSpec) -> list[str]:
    """The joints in the order Pinocchio's URDF parser adds them: depth first from the root, each link's child joints
    in urdfdom's order, which is by name (its joints live in a std::map)."""
    children: dict[str, list[JointSpec]] = defaultdict(list)
    for joint in spec.joints:
        children[joint.parent].append(joint)
    order: list[str] = []

    def visit(link: str) -> None:
        for joint in sorted(children[link], key=lambda j: j.name.encode()):
            order.append(joint.name)
            visit(joint.child)

    visit(spec.root)
    return order


def _mimic_out_of_order(spec: RobotSpec, joint: JointSpec) -> bool:
    order = _pinocchio_order(spec)
    return joint.mimic is not None and order.index(joint.mimic.leader) > order.index(joint.name)


def _movable_below(spec: RobotSpec, joint: JointSpec) -> bool:
    """Whether a movable joint hangs anywhere below ``joint``'s child link."""
    stack = [joint.child]
    while stack:
        link = stack.pop()
        for child in spec.joints:
            if child.parent == link:
                if child.movable:
                    return True
                stack.append(child.child)
    return False


def _mimic_with_subtree(spec: RobotSpec, joint: JointSpec) -> bool:
    return joint.mimic is not None and _movable_below(spec, joint)


def _mimic_kinds_differ(spec: RobotSpec, joint: JointSpec) -> bool:
    """A revolute mimicking a continuous joint or the reverse: Pinocchio's q has 1 and 2 entries for them."""
    return joint.mimic is not None and (joint.type == "continuous") != (
        spec.joint(joint.mimic.leader).type == "continuous")


def _mimics_where(which: Callable[[RobotSpec, JointSpec], bool]) -> dict:
    """A class caused by the mimic joints ``which`` picks: its ``trigger`` and ``neutralise`` (those mimics dropped)."""
    return {"trigger": lambda spec: any(which(spec, joint) for joint in spec.joints),
            "neutralise": lambda spec: _drop_mimics(spec, lambda joint: which(spec, joint))}


MASSES = ("total_mass", "link_mass", "link_com", "link_inertia", "group_mass", "group_com", "group_inertia")
NUMBERS = tuple(TOLERANCE)

@lru_cache(maxsize=64)
def rendered(spec: RobotSpec, seed: int) -> RandomRobot:
    """:func:`render`, kept: the importers' counterfactuals of one model share it (and the truth it memoises)."""
    return render(spec, seed)


def _bound(robot: RandomRobot, importer: str, quantity: str) -> tuple[float, str]:
    """(the largest error a bound class applicable to ``robot`` explains for ``quantity``, its name), (0, "") if
    none applies."""
    for known in KNOWN:
        if (known.bound is not None and importer in known.importers and quantity in known.quantities
                and known.trigger(robot.spec)):
            return known.bound, known.name
    return 0.0, ""


VANISHED = 0.1
"""A discrepancy within a bound class's bound is that class unless the neutralisers remove all but this fraction of it
(then it is theirs: e.g. a small link's inertia PyBullet zeroes is 1e-7 of the model's, as large as float32 rounding,
and vanishes with the trigger)."""


def classify(robot: RandomRobot, importer: str, found: list[Discrepancy],
             remeasure: Callable[[RandomRobot], list[Discrepancy]]) -> tuple[list[tuple[Discrepancy, tuple[str, ...]]],
                                                                              list[Discrepancy]]:
    """(explained discrepancies with the known classes that explain each, unknown ones).

    The neutralising classes whose trigger ``robot`` has are all applied (``remeasure``: the importer's discrepancies
    on another model). A discrepancy is gone from a neutralised model when its error there is at most the smaller of
    the applicable bound and :data:`VANISHED` of its own. One gone when all are applied is explained by the classes
    without whose neutraliser it stays (each left out in turn); when none is alone necessary (triggers overlap), by
    the classes of the smallest sets whose neutralisers alone remove it and of which one lists its quantity
    (:func:`_smallest_sufficient`); failing both, by every applicable class. Only classes listing its quantity
    count (one that does not is no evidence: a neutraliser may remove more than its class says). Any other
    discrepancy within a bound class's bound is that class; the rest are unknown."""
    neutral = [k for k in KNOWN if k.neutralise is not None and importer in k.importers and k.trigger(robot.spec)]
    cache: dict[tuple[str, ...], dict] = {}

    def residuals(classes: list[KnownClass]) -> dict[tuple[str, str, str], float]:
        """Key -> error of the discrepancies of the model neutralised by ``classes``."""
        names = tuple(k.name for k in classes)
        if names not in cache:
            spec = robot.spec
            for known in classes:
                spec = known.neutralise(spec)
            cache[names] = {d.key: d.error for d in remeasure(rendered(spec, robot.seed))}
        return cache[names]

    def stays(d: Discrepancy, classes: list[KnownClass]) -> bool:
        return residuals(classes).get(d.key, 0.0) > min(_bound(robot, importer, d.quantity)[0] or np.inf,
                                                        VANISHED * d.error)

    explained, unknown = [], []
    for d in found:
        bound, bound_name = _bound(robot, importer, d.quantity)
        if neutral and not stays(d, neutral):
            necessary = [k for k in neutral if len(neutral) == 1 or stays(d, [o for o in neutral if o is not k])]
            if not necessary:  # the triggers overlap (a massless root has no turned inertial either)
                necessary = _smallest_sufficient(d, neutral, stays)
            names = tuple(k.name for k in (necessary or neutral) if d.quantity in k.quantities
                          and k.message in d.detail)
            if names:
                explained.append((d, names))
                continue
        if d.error <= bound:
            explained.append((d, (bound_name,)))
        else:
            unknown.append(d)
    return explained, unknown


def _smallest_sufficient(d: Discrepancy, neutral: list[KnownClass], stays: Callable) -> list[KnownClass]:
    """The classes of the smallest sets (of up to three) of ``neutral`` whose neutralisers remove ``d`` and of which
    one lists its quantity: e.g. a root body's fullinertia read as zero AND its inertial frame put at the origin
    unturned, when making the root massless (another class's neutraliser) also removes it."""
    for size in range(1, min(3, len(neutral)) + 1):
        found = [k for group in combinations(neutral, size) if not stays(d, list(group))
                 and any(d.quantity in k.quantities and k.message in d.detail for k in group) for k in group]
        if found:
            return list(dict.fromkeys(found))
    return []


@dataclass
class ModelResult:
    """One model through every importer: whether MuJoCo accepted each format (its error, "" if it did), the
    discrepancies explained (with their classes) and the unknown ones."""

    robot: RandomRobot
    mujoco_refusals: dict[str, str]
    explained: list[tuple[Discrepancy, tuple[str, ...]]]
    unknown: list[Discrepancy]


def run_model(robot: RandomRobot, folder: Path, client: int, importers: Iterable[str] = IMPORTERS) -> ModelResult:
    """Every importer on ``robot``, every discrepancy classified."""
    refusals, explained, unknown = {}, [], []
    for importer in importers:
        got = measure(robot, importer, folder, client)
        if got is None:
            continue
        measured, states = got
        if importer.startswith("mujoco/"):
            refusals[importer.split("/")[1]] = measured.refused
        found = compare(robot, importer, measured, states)
        if found:
            def remeasure(other: RandomRobot, importer: str = importer) -> list[Discrepancy]:
                again = measure(other, importer, folder, client)
                return [] if again is None else compare(other, importer, *again, details=False)

            good, bad = classify(robot, importer, found, remeasure)
            explained += good
            unknown += bad
    return ModelResult(robot, refusals, explained, unknown)


# ---------------------------------------------------------------------------------------------------------------
# The table of known classes

FLOAT32_BOUND = 1e-6
"""PyBullet's MJCF importer reads vectors (pos, quat, axis, diaginertia) and ranges as floats (btArray<float>,
BulletMJCFImporter.cpp's parseVector3 and friends; masses as doubles): each rounded to ~6e-8 relative. Measured over
600 models once every other class is neutralised: limits 1.4e-7, h 1.4e-7, axes 9e-8, centres of mass and anchors
6e-8, M 2.3e-8, inertias 9e-10 (of the model's scales); this bound leaves a factor of 7."""

_PB_MJCF = ("pybullet/mjcf", "pybullet-inertia/mjcf")
KNOWN: tuple[KnownClass, ...] = (
    KnownClass(
        "mujoco-urdf-fusestatic", "importer default", ("mujoco/urdf",), MASSES + ("link_present",),
        "MuJoCo's URDF importer fuses every body welded by a fixed joint into its parent unless the file says "
        "<mujoco><compiler fusestatic=\"false\"/></mujoco>; bodies welded to the world are fused into the world body, "
        "whose mass MuJoCo does not count (total mass short by their mass)",
        trigger=lambda spec: not spec.style.mujoco_block,
        neutralise=lambda spec: with_style(spec, mujoco_block=True)),
    KnownClass(
        "mujoco-fusestatic-drops-massless-inertia", "engine bug", ("mujoco/urdf",),
        MASSES + ("mass_matrix", "bias_forces"),
        "MuJoCo's fusestatic (the URDF importer's default) drops the rotational inertia of a fused body of mass 0 "
        "(a rotor whose mass is counted elsewhere): the parent keeps its own inertia only, so M is short (measured: "
        "0.02 instead of 0.52 kg m^2 for a 0.5 kg m^2 rotor; MJCF with fusestatic=\"true\" alike)",
        trigger=lambda spec: not spec.style.mujoco_block and any(
            link.mass == 0 and any(link.moments) for link in spec.links),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, moments=(0.0, 0.0, 0.0), rpy=(
            0.0, 0.0, 0.0)) if link.mass == 0 else link), shown_by=("mass_matrix",)),
    KnownClass(
        "pinocchio-urdf-mimic-default", "importer default", ("pinocchio/urdf",), ("mimic",),
        "pinocchio.buildModelFromXML(urdf) ignores <mimic> unless called with mimic=True: the follower is an "
        "independent joint",
        trigger=_has_mimic, neutralise=_drop_mimics),
    KnownClass(
        "pinocchio-mimic-leader-order", "engine bug", ("pinocchio-mimic/urdf",), ("load",),
        "buildModelFromXML(urdf, mimic=True) refuses a follower added before its leader (\"The parent joint of the "
        "mimic joint is not in the kinematic tree\"): it looks the leader up among the joints built so far, in its "
        "depth-first order (children by joint name)",
        **_mimics_where(_mimic_out_of_order),
        message="not in the kinematic tree"),
    KnownClass(
        "pinocchio-mimic-continuous", "unsupported element", ("pinocchio-mimic/urdf",), ("load",),
        "buildModelFromXML(urdf, mimic=True) refuses a revolute joint mimicking a continuous one or the reverse "
        "(\"Mimicking and mimicked configuration spaces have different sizes\": a continuous joint's q is (cos, sin))",
        **_mimics_where(_mimic_kinds_differ),
        message="configuration spaces have different sizes"),
    KnownClass(
        "pinocchio-mimic-crba-accumulates", "engine bug", ("pinocchio-mimic/urdf",), ("mass_matrix",),
        "pinocchio.crba (default Convention.LOCAL) on a model with a mimic joint that has moving joints below it: the "
        "first call on a Data is right, a later call on the same Data (even at the same q) returns a wrong M; "
        "Convention.WORLD and rnea are right (measured with Pinocchio 4.1.0; its crba.hxx adds the mimic's Fcrb into "
        "its parent's with se3Action<ADDTO>, never cleared)",
        **_mimics_where(_mimic_with_subtree)),
    KnownClass(
        "pinocchio-mjcf-eulerseq-extrinsic", "engine bug", ("pinocchio/mjcf",), NUMBERS,
        "Pinocchio's MJCF parser reads an upper-case (extrinsic, MuJoCo's docs and compiler) eulerseq such as \"XYZ\" "
        "as the intrinsic sequence (the minimal file's body: Rx Ry Rz to 1e-16, MuJoCo's Rz Ry Rx): every "
        "euler-spelled orientation is wrong; lower-case sequences are read right",
        trigger=lambda spec: spec.style.eulerseq.isupper(),
        neutralise=lambda spec: with_style(spec, eulerseq="zyx")),
    KnownClass(
        "pinocchio-mjcf-slide-range-degrees", "engine bug", ("pinocchio/mjcf",), ("joint_limits",),
        "Pinocchio's MJCF parser converts a slide joint's range from degrees to radians under <compiler "
        "angle=\"degree\">: prismatic limits shrink by pi/180 (MuJoCo: angle applies to hinge ranges only)",
        trigger=lambda spec: spec.style.angle == "degree" and any(j.type == "prismatic" for j in spec.joints),
        neutralise=lambda spec: with_style(spec, angle="radian")),
    KnownClass(
        "pinocchio-mjcf-no-inertial", "unsupported element", ("pinocchio/mjcf",), ("load",),
        "Pinocchio's MJCF parser refuses a body without <inertial> and without geoms (\"Cannot get inertia from geom "
        "and no inertia was found\"); MuJoCo gives it mass 0",
        trigger=lambda spec: any(link.mjcf_inertial == "none" for link in spec.links),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, mjcf_inertial="zero")
                                            if link.mjcf_inertial == "none" else link),
        message="Cannot get inertia from geom and no inertia was found"),
    KnownClass(
        "pinocchio-mjcf-equality-ignored", "importer default", ("pinocchio/mjcf",), ("mimic",),
        "pinocchio.buildModelFromMJCF(path) keeps no <equality><joint>: the follower is an independent joint",
        trigger=_has_mimic, neutralise=_drop_mimics),
    KnownClass(
        "pybullet-urdf-fixed-base-massless", "importer default", ("pybullet/urdf",), MASSES,
        "loadURDF(useFixedBase=True) makes the base link static: getDynamicsInfo(body, -1) gives mass 0 and zero "
        "inertia whatever its <inertial> (no effect on M or h: the base does not move)",
        trigger=lambda spec: _root(spec).mass > 0 or any(_root(spec).moments),
        neutralise=_massless_root),
    KnownClass(
        "pybullet-urdf-no-inertial-unit-mass", "importer default", ("pybullet/urdf",),
        MASSES + ("mass_matrix", "bias_forces"),
        "PyBullet's URDF importer gives a link without <inertial> mass 1 kg and inertia diag(1, 1, 1) even with "
        "URDF_USE_INERTIA_FROM_FILE (URDF, MuJoCo, Pinocchio and core: massless)",
        trigger=lambda spec: any(link.urdf_inertial == "none" for link in spec.links[1:]),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, urdf_inertial="zero")
                                            if link.urdf_inertial == "none" else link)),
    KnownClass(
        "pybullet-urdf-inertia-diagonalised", "engine bug", ("pybullet/urdf",),
        ("link_inertia", "group_inertia", "mass_matrix", "bias_forces"),
        "PyBullet's URDF importer diagonalises a tensor with off-diagonal terms by Jacobi rotations that stop at 1e-6 "
        "of the trace (btMatrix3x3::diagonalize, BulletUrdfImporter.cpp) and drops what is left: the inertia is off "
        "by ~1e-11 of the model's, M and h by up to ~4e-10 relative (exact when the same tensor is written as "
        "<origin rpy> + a diagonal)",
        trigger=lambda spec: any(link.urdf_inertial == "full" and link.mass > 0 and any(link.rpy)
                                 for link in spec.links),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, urdf_inertial="rpy")
                                            if link.urdf_inertial == "full" else link)),
    KnownClass(
        "pybullet-urdf-gravity-turned", "engine bug", ("pybullet/urdf",), ("bias_forces",),
        "calculateInverseDynamics takes gravity in the base's inertial frame: with a root link whose <inertial> frame "
        "is turned by R (its rpy), h is the truth's under gravity R g (measured on the minimal file to 8 digits); M "
        "is right",
        trigger=_root_rotated, neutralise=_unrotate_root),
    KnownClass(
        "pybullet-urdf-mimic-ignored", "unsupported element", ("pybullet/urdf",), ("mimic",),
        "PyBullet's URDF importer ignores <mimic>: the follower is an independent joint",
        trigger=_has_mimic, neutralise=_drop_mimics),
    KnownClass(
        "pybullet-mjcf-float32", "engine bug", _PB_MJCF, NUMBERS,
        "PyBullet's MJCF importer parses every number into a float (btArray<float>): values rounded to ~6e-8 relative",
        trigger=lambda spec: True, bound=FLOAT32_BOUND),
    KnownClass(
        "pybullet-mjcf-floating-base", "importer default", _PB_MJCF, ("fixed_base",),
        "loadMJCF never fixes a base: a root body without a joint (welded to the world in MJCF) becomes a free base "
        "unless its mass is 0; calculateInverseDynamics then refuses the body, so h is not compared",
        trigger=lambda spec: _root(spec).mass > 0,
        neutralise=_massless_root),
    KnownClass(
        "pybullet-mjcf-orientation-quat-only", "unsupported element", _PB_MJCF, NUMBERS,
        "PyBullet's MJCF importer reads a body's orientation from quat only: euler and axisangle are ignored "
        "(the body is not turned)",
        trigger=lambda spec: spec.style.orientation != "quat" and any(any(j.rpy) for j in spec.joints),
        neutralise=lambda spec: with_style(spec, orientation="quat")),
    KnownClass(
        "pybullet-mjcf-inertia-from-geoms", "importer default", ("pybullet/mjcf",), NUMBERS,
        "loadMJCF(path) without flags=URDF_USE_INERTIA_FROM_FILE takes each body's rotational inertia from its "
        "collision geoms (none here: zero), keeping <inertial>'s mass and centre of mass",
        trigger=lambda spec: any(any(link.moments) for link in spec.links),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, moments=(0.0, 0.0, 0.0), rpy=(
            0.0, 0.0, 0.0), mjcf_inertial="quat", urdf_inertial="rpy") if any(link.moments) else link)),
    KnownClass(
        "pybullet-mjcf-base-at-com", "importer default", _PB_MJCF,
        ("link_com", "link_inertia", "group_com", "group_inertia", "joint_axis", "joint_anchor", "bias_forces"),
        "loadMJCF puts the root body's inertial frame, not its body frame, at the world origin with the identity "
        "orientation (measured: getBasePositionAndOrientation (0, 0, 0), (0, 0, 0, 1); a massless rotor's too): "
        "every frame is off by the root's <inertial> pos and quat",
        trigger=lambda spec: any(_root(spec).com) or (any(_root(spec).rpy) and any(_root(spec).moments)),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, com=(0.0, 0.0, 0.0), rpy=(
            0.0, 0.0, 0.0)) if link.name == spec.root else link)),
    KnownClass(
        "pybullet-mjcf-inertial-diag-quat-only", "unsupported element", ("pybullet-inertia/mjcf",), NUMBERS,
        "PyBullet's MJCF importer reads <inertial> pos, quat, mass and diaginertia only: fullinertia gives zero "
        "inertia, euler leaves the principal axes unturned",
        trigger=lambda spec: any(link.mass > 0 and (link.mjcf_inertial == "full" or (
            link.mjcf_inertial == "euler" and any(link.rpy))) for link in spec.links),
        neutralise=lambda spec: with_links(spec, lambda link: replace(link, mjcf_inertial="quat")
                                            if link.mjcf_inertial in ("full", "euler") else link)),
    KnownClass(
        "pybullet-mjcf-range-needs-limited", "unsupported element", _PB_MJCF, ("joint_limits",),
        "PyBullet's MJCF importer reads a joint's range only with limited=\"true\" (it has no autolimits): without it "
        "the joint is unlimited",
        trigger=lambda spec: not spec.style.explicit_limited and any(
            j.type in ("revolute", "prismatic") for j in spec.joints),
        neutralise=lambda spec: with_style(spec, explicit_limited=True)),
    KnownClass(
        "pybullet-mjcf-joint-dynamics-ignored", "unsupported element", _PB_MJCF, ("joint_damping", "joint_friction"),
        "PyBullet's MJCF importer reads neither damping nor frictionloss (both 0 in getJointInfo)",
        trigger=lambda spec: any(j.damping or j.friction for j in spec.joints),
        neutralise=lambda spec: with_joints(spec, lambda j: replace(j, damping=0.0, friction=0.0))),
    KnownClass(
        "pybullet-mjcf-armature-ignored", "unsupported element", _PB_MJCF, ("mass_matrix",),
        "PyBullet's MJCF importer ignores armature (a TODO in BulletMJCFImporter.cpp): M lacks diag(armature)",
        trigger=lambda spec: any(j.armature for j in spec.joints),
        neutralise=lambda spec: with_joints(spec, lambda j: replace(j, armature=0.0))),
    KnownClass(
        "pybullet-mjcf-equality-ignored", "unsupported element", _PB_MJCF, ("mimic",),
        "PyBullet's MJCF importer ignores <equality>: the follower is an independent joint",
        trigger=_has_mimic, neutralise=_drop_mimics),
)
"""The known classes (module docstring); their minimised files (:data:`FINDINGS`) are checked by
tests/references/test_random_robot_files.py."""


def docs_table() -> str:
    """docs/robots.md's table of the known classes: name and file, kind, importers, explanation."""
    rows = ["| class (its minimised file) | kind | importers | what the importer does |", "|---|---|---|---|"]
    for known in KNOWN:
        explanation = re.sub(r"((?:<[^<>]+>)+)", r"`\1`", known.explanation).replace("|", "\\|")
        rows.append(f"| [{known.name}](robot-findings/{known.minimal_file.name}) | {known.kind} | "
                    f"{', '.join(f'`{i}`' for i in known.importers)} | {explanation} |")
    return "\n".join(rows) + "\n"
