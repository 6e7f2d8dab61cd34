"""Each importer's model of a random robot file (tests/fuzz/robot_files.py), in the truth's terms.

MuJoCo (both formats), Pinocchio (both; URDF also with ``mimic=True``), PyBullet (both; MJCF also with
``URDF_USE_INERTIA_FROM_FILE``) and core (URDF, the serial path to one leaf) read the same model (:data:`IMPORTERS`);
:func:`measure` gives what each made of it (:class:`Measured`): whether it loads, its movable joints by name, whether
its base is fixed, its total mass; each body's and each rigid group's mass, centre of mass and inertia in the world
frame at q = 0; each joint's world axis, anchor, limits, damping, friction and armature; what it keeps of mimic joints;
and the joint-space mass matrix M(q) and bias forces h(q, qdot) under gravity (0, 0, -9.81) at :data:`STATES` seeded
states, joints ordered by name (MuJoCo ``mj_fullM`` / ``qfrc_bias``, Pinocchio ``crba`` with its upper triangle
symmetrised / ``rnea(q, v, 0)``, PyBullet ``calculateMassMatrix`` / ``calculateInverseDynamics(q, qdot, 0)``, core
``RecursiveDynamics`` and ``JacobianSumDynamics`` of ``chain_from_urdf``; core holds the joints off its path at 0, so
it is measured at states with those joints at 0 and at rest).
"""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

from simparity.core.articulated.model import JacobianSumDynamics, RecursiveDynamics
from simparity.core.model.errors import SimparityError
from simparity.core.urdf import chain_from_urdf
from simparity.references.common.quiet import captured_output
from simparity.references.pybullet.quiet import pybullet as pb
from tests.fuzz.robot_files import GRAVITY, RandomRobot, combine

STATES = 3
"""Seeded states (q, qdot) per model for M and h."""

URDF_IMPORTERS = ("mujoco/urdf", "pinocchio/urdf", "pinocchio-mimic/urdf", "pybullet/urdf", "core/urdf",
                  "core-jacobian_sum/urdf")
MJCF_IMPORTERS = ("mujoco/mjcf", "pinocchio/mjcf", "pybullet/mjcf", "pybullet-inertia/mjcf")
IMPORTERS = URDF_IMPORTERS + MJCF_IMPORTERS
"""``engine/format``. ``pinocchio-mimic``: ``buildModelFromXML(urdf, mimic=True)``, run on models with a mimic joint
only; ``pybullet/mjcf``: ``loadMJCF(path)`` as documented, ``pybullet-inertia/mjcf``: with
``flags=URDF_USE_INERTIA_FROM_FILE`` (without it the rotational inertia comes from the collision geoms, of which the
files have none); ``core``: core's recursive algorithms, ``core-jacobian_sum`` its sum over link Jacobians."""


@dataclass
class Measured:
    """One importer's model of one file, in the truth's terms. ``refused``: its error ("" when it loaded); ``dofs``:
    its movable joints by name; ``links`` / ``groups``: name -> (mass, centre of mass (3,), inertia about it (3, 3)) in
    the world frame at q = 0, None where not exposed (a group is named after its movable joint, "" for the base's);
    ``joints``: name -> {"axis", "anchor", "limits", "damping", "friction", "armature"} (a key left out: not exposed);
    ``mimic``: follower -> (leader, multiplier, offset) (None: mimic joints are not this importer's business, a
    multiplier NaN: not exposed); ``mass_matrices`` / ``bias``: per state, rows in ``dofs`` order (None: not
    computed)."""

    refused: str = ""
    dofs: tuple[str, ...] = ()
    fixed_base: bool = True
    total_mass: float | None = None
    links: dict | None = None
    groups: dict | None = None
    joints: dict = field(default_factory=dict)
    mimic: dict | None = None
    mass_matrices: list | None = None
    bias: list | None = None


@dataclass(frozen=True)
class State:
    """Joint positions and velocities by name (every movable joint of the model)."""

    q: dict
    qdot: dict


def _states(robot: RandomRobot, count: int = STATES) -> list[State]:
    """Seeded states: q inside the limits (continuous joints in [-pi, pi]), qdot standard normal."""
    rng = np.random.default_rng([robot.seed & 0xFFFFFFFF, 7])
    states = []
    for _ in range(count):
        q, qdot = {}, {}
        for name in robot.movable:
            joint = robot.spec.joint(name)
            low, high = (joint.lower, joint.upper) if np.isfinite(joint.lower) else (-np.pi, np.pi)
            q[name], qdot[name] = float(rng.uniform(low, high)), float(rng.normal())
        states.append(State(q, qdot))
    return states


def _core_states(robot: RandomRobot, states: list[State], path: tuple[str, ...]) -> list[State]:
    """The states with every joint off core's path at 0 and at rest (core holds them so)."""
    return [State({n: (s.q[n] if n in path else 0.0) for n in robot.movable},
                  {n: (s.qdot[n] if n in path else 0.0) for n in robot.movable}) for s in states]


def _inertia_world(rotation: np.ndarray, moments) -> np.ndarray:
    return rotation @ np.diag(moments) @ rotation.T


def _mujoco(robot: RandomRobot, fmt: str, states: list[State]) -> Measured:
    text = robot.urdf if fmt == "urdf" else robot.mjcf
    try:
        with captured_output():
            model = mujoco.MjModel.from_xml_string(text)
    except ValueError as error:
        return Measured(refused=" ".join(str(error).split()))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    hinge_slide = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
    dof_joints = [j for j in range(model.njnt) if model.jnt_type[j] in hinge_slide]
    names = {j: model.joint(j).name for j in dof_joints}
    links, body_group = {}, {0: ""}
    for b in range(model.nbody):
        links[model.body(b).name] = (float(model.body_mass[b]), data.xipos[b].copy(),
                                     _inertia_world(data.ximat[b].reshape(3, 3), model.body_inertia[b]))
        if b:
            jnt = model.body_jntadr[b]
            body_group[b] = names.get(jnt, "?") if model.body_jntnum[b] else body_group[model.body_parentid[b]]
    groups = _grouped(links, {model.body(b).name: g for b, g in body_group.items()})
    joints = {}
    for j in dof_joints:
        dof = model.jnt_dofadr[j]
        limits = tuple(model.jnt_range[j]) if model.jnt_limited[j] else (-np.inf, np.inf)
        joints[names[j]] = {"axis": data.xaxis[j].copy(), "anchor": data.xanchor[j].copy(), "limits": limits,
                            "damping": float(model.dof_damping[dof]), "friction": float(model.dof_frictionloss[dof]),
                            "armature": float(model.dof_armature[dof])}
    mimic = {}
    for e in range(model.neq):
        if model.eq_type[e] == int(mujoco.mjtEq.mjEQ_JOINT):
            poly = model.eq_data[e, :5]
            mimic[model.joint(model.eq_obj1id[e]).name] = (model.joint(model.eq_obj2id[e]).name, float(poly[1]),
                                                           float(poly[0]) if not np.any(poly[2:]) else np.nan)
    dofs = tuple(names[j] for j in dof_joints)
    qadr, vadr = model.jnt_qposadr[dof_joints], model.jnt_dofadr[dof_joints]
    matrices, bias = [], []
    full = np.zeros((model.nv, model.nv))
    for state in states:
        data.qpos[:] = model.qpos0
        data.qvel[:] = 0.0
        data.qpos[qadr] = [state.q.get(n, 0.0) for n in dofs]
        data.qvel[vadr] = [state.qdot.get(n, 0.0) for n in dofs]
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, full)
        matrices.append(full[np.ix_(vadr, vadr)].copy())
        bias.append(data.qfrc_bias[vadr].copy())
    return Measured(dofs=dofs, total_mass=float(model.body_mass.sum()), links=links, groups=groups, joints=joints,
                    mimic=mimic, mass_matrices=matrices, bias=bias)


def _grouped(links: dict, group_of: dict) -> dict:
    """Rigid group -> the combined (mass, com, inertia) of its links (``group_of``: link -> group)."""
    members: dict[str, list] = defaultdict(list)
    for name, value in links.items():
        members[group_of[name]].append(value)
    return {group: combine(parts) for group, parts in members.items()}


def _pin_axis(model, data, joint) -> np.ndarray:
    """A joint's world axis: its column of the world-frame joint Jacobian (Pinocchio's Python bindings expose no
    axis for an unbounded unaligned joint): the angular part of a rotation, the linear part of a slide."""
    jacobian = np.asarray(pin.getJointJacobian(model, data, joint.id, pin.ReferenceFrame.WORLD)).reshape(6, -1)
    column = jacobian[:, joint.idx_v]  # (6, nv); a model of one dof comes back as a vector
    return column[3:] if np.linalg.norm(column[3:]) > 0.5 else column[:3]


def _pinocchio(robot: RandomRobot, fmt: str, states: list[State], folder: Path, mimic: bool = False) -> Measured:
    try:
        with captured_output():
            if fmt == "urdf":
                model = pin.buildModelFromXML(robot.urdf, mimic=mimic)
            else:
                path = _fresh(folder, "xml")
                path.write_text(robot.mjcf, encoding="utf-8")
                model = pin.buildModelFromMJCF(str(path))
    except (ValueError, RuntimeError) as error:
        return Measured(refused=_reason(error))
    data = model.createData()
    neutral = pin.neutral(model)
    pin.computeJointJacobians(model, data, neutral)
    groups, joints, dofs, followers = {}, {}, [], {}
    for i in range(model.njoints):
        inertia, placement = model.inertias[i], data.oMi[i]
        rotation = placement.rotation
        name = model.names[i] if i else ""
        groups[name] = (float(inertia.mass), placement.act(inertia.lever),
                        rotation @ inertia.inertia @ rotation.T)
        if not i:
            continue
        joint = model.joints[i]
        if "Mimic" in joint.shortname():
            followers[name] = i
            continue
        dofs.append(name)
        unbounded = joint.nq == 2
        limits = ((-np.inf, np.inf) if unbounded else
                  tuple(_unbounded(v) for v in (model.lowerPositionLimit[joint.idx_q],
                                                model.upperPositionLimit[joint.idx_q])))
        joints[name] = {"axis": _pin_axis(model, data, joint), "anchor": placement.translation.copy(), "limits": limits,
                        "damping": float(model.damping[joint.idx_v]), "friction": float(model.friction[joint.idx_v]),
                        "armature": float(model.armature[joint.idx_v])}
    mimics = {}
    for follower, leader in zip(model.mimicking_joints, model.mimicked_joints):
        mimics[model.names[follower]] = (model.names[leader], np.nan, np.nan)
    matrices, bias = [], []
    for state in states:
        q, v = neutral.copy(), np.zeros(model.nv)
        for name in dofs:
            joint = model.joints[model.getJointId(name)]
            if joint.nq == 2:
                q[joint.idx_q:joint.idx_q + 2] = np.cos(state.q.get(name, 0.0)), np.sin(state.q.get(name, 0.0))
            else:
                q[joint.idx_q] = state.q.get(name, 0.0)
            v[joint.idx_v] = state.qdot.get(name, 0.0)
        upper = np.array(pin.crba(model, data, q))
        full = np.triu(upper) + np.triu(upper, 1).T
        order = [model.joints[model.getJointId(name)].idx_v for name in dofs]
        matrices.append(full[np.ix_(order, order)])
        bias.append(np.array(pin.rnea(model, data, q, v, np.zeros(model.nv)))[order])
    if mimic:  # q = 0 of the reduced model puts each follower at its offset: no frame of it is the truth's q = 0
        groups, joints = None, {}
    return Measured(dofs=tuple(dofs), total_mass=float(sum(model.inertias[i].mass for i in range(model.njoints))),
                    groups=groups, joints=joints, mimic=mimics, mass_matrices=matrices, bias=bias)


def _reason(error: Exception) -> str:
    """An importer's refusal on one line: from Pinocchio's "message:" on (its exceptions open with the file, function
    and template arguments), else all of it."""
    text = " ".join(str(error).split())
    return text[text.index("message:"):] if "message:" in text else text


def _unbounded(value: float) -> float:
    """A limit of magnitude 1e300 or more is no limit (Pinocchio writes the largest double for none)."""
    return float(np.sign(value) * np.inf) if abs(value) >= 1e300 else float(value)


_FILES = Counter()


def _fresh(folder: Path, suffix: str) -> Path:
    """A file name not used before in ``folder`` (PyBullet caches files by path)."""
    _FILES[folder] += 1
    return folder / f"model_{_FILES[folder]}.{suffix}"


def _quat_matrix(xyzw) -> np.ndarray:
    """PyBullet's (x, y, z, w) unit quaternion as a rotation matrix."""
    x, y, z, w = xyzw
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _pybullet(robot: RandomRobot, fmt: str, states: list[State], folder: Path, client: int,
              inertia_flag: bool = False) -> Measured:
    path = _fresh(folder, "urdf" if fmt == "urdf" else "xml")
    path.write_text(robot.urdf if fmt == "urdf" else robot.mjcf, encoding="utf-8")
    kw = {"physicsClientId": client}
    try:
        with captured_output():
            pb.resetSimulation(**kw)
            pb.setPhysicsEngineParameter(enableFileCaching=0, **kw)  # it keeps a file's first text by its path
            if fmt == "urdf":
                body = pb.loadURDF(str(path), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE, **kw)
            else:
                bodies = pb.loadMJCF(str(path), flags=pb.URDF_USE_INERTIA_FROM_FILE if inertia_flag else 0, **kw)
                if len(bodies) != 1:
                    return Measured(refused=f"loadMJCF made {len(bodies)} bodies")
                body = bodies[0]
    except pb.error as error:
        return Measured(refused=str(error))
    pb.setGravity(*GRAVITY, **kw)
    n = pb.getNumJoints(body, **kw)
    infos = [pb.getJointInfo(body, i, **kw) for i in range(n)]
    movable = [i for i in range(n) if infos[i][2] in (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC)]
    names = {i: infos[i][1].decode() for i in range(n)}
    links, group_of, frames = {}, {}, {}
    base = pb.getBodyInfo(body, **kw)[0].decode()
    dynamics = pb.getDynamicsInfo(body, -1, **kw)
    com, orn = pb.getBasePositionAndOrientation(body, **kw)
    links[base] = (float(dynamics[0]), np.array(com), _inertia_world(_quat_matrix(orn), dynamics[2]))
    group_of[base] = ""
    for i in range(n):
        dynamics = pb.getDynamicsInfo(body, i, **kw)
        state = pb.getLinkState(body, i, computeForwardKinematics=1, **kw)
        link = infos[i][12].decode()
        r_com = _quat_matrix(state[1])
        links[link] = (float(dynamics[0]), np.array(state[0]), _inertia_world(r_com, dynamics[2]))
        # the link frame from the inertial frame (double) and the local inertial frame, not from getLinkState's
        # worldLinkFrame (float32); getJointInfo's jointAxis is in the inertial frame (measured: 2e-16 so, 0.5 in
        # the link frame when the inertial frame is turned)
        r_local = _quat_matrix(dynamics[4])
        r_link = r_com @ r_local.T
        frames[i] = (r_link, np.array(state[0]) - r_link @ np.array(dynamics[3]), r_com)
        group_of[link] = names[i] if i in movable else group_of[(infos[infos[i][16]][12].decode()
                                                                 if infos[i][16] >= 0 else base)]
    joints = {}
    for i in movable:
        lower, upper = infos[i][8], infos[i][9]
        joints[names[i]] = {"axis": frames[i][2] @ np.array(infos[i][13]), "anchor": frames[i][1],
                            "limits": (lower, upper) if lower <= upper else (-np.inf, np.inf),
                            "damping": float(infos[i][6]), "friction": float(infos[i][7])}
    dofs = tuple(names[i] for i in movable)
    matrices, bias = [], []
    fixed = None
    for state in states:
        q = [state.q.get(name, 0.0) for name in dofs]
        qdot = [state.qdot.get(name, 0.0) for name in dofs]
        with captured_output():
            m = np.array(pb.calculateMassMatrix(body, q, **kw))
        fixed = m.shape[0] == len(dofs) if fixed is None else fixed
        matrices.append(m if fixed else m[6:, 6:])
        if fixed:
            with captured_output():
                bias.append(np.array(pb.calculateInverseDynamics(body, q, qdot, [0.0] * len(dofs), **kw)))
    return Measured(dofs=dofs, fixed_base=fixed is not False, total_mass=float(sum(v[0] for v in links.values())),
                    links=links, groups=_grouped(links, group_of), joints=joints, mimic={},
                    mass_matrices=matrices, bias=bias if fixed is not False else None)


def _core(robot: RandomRobot, states: list[State], method: str) -> Measured | None:
    """Core's chain from the root to :meth:`RandomRobot.core_path`'s leaf; None when the model has no such path."""
    found = robot.core_path()
    if found is None:
        return None
    tip, _ = found
    try:
        chain = chain_from_urdf(robot.urdf, base_link=robot.spec.root, tip_link=tip, dynamics=True)
    except SimparityError as error:  # core's refusal (a SceneError naming the element) is the finding
        return Measured(refused=f"{type(error).__name__}: {' '.join(str(error).split())[:300]}")
    model = (RecursiveDynamics if method == "recursive" else JacobianSumDynamics)(chain, GRAVITY)
    dofs = tuple(joint.name for joint in chain.joints)
    q = np.array([[s.q[n] for n in dofs] for s in states])
    qdot = np.array([[s.qdot[n] for n in dofs] for s in states])
    joints = {joint.name: {"damping": float(joint.damping), "armature": float(joint.armature)}
              for joint in chain.joints}
    return Measured(dofs=dofs, joints=joints, mass_matrices=list(model.mass_matrix(q)),
                    bias=list(model.bias_forces(q, qdot)))


def measure(robot: RandomRobot, importer: str, folder: Path, client: int) -> tuple[Measured, list[State]] | None:
    """``importer``'s model of ``robot`` and the states it was evaluated at; None where it does not apply (core
    without a path, ``pinocchio-mimic`` without a mimic joint)."""
    engine, fmt = importer.split("/")
    states = _states(robot)
    if engine == "mujoco":
        return _mujoco(robot, fmt, states), states
    if engine == "pinocchio":
        return _pinocchio(robot, fmt, states, folder), states
    if engine == "pinocchio-mimic":
        if not any(joint.mimic for joint in robot.spec.joints):
            return None
        return _pinocchio(robot, fmt, _mimic_states(robot, states), folder, mimic=True), _mimic_states(robot, states)
    if engine in ("pybullet", "pybullet-inertia"):
        return _pybullet(robot, fmt, states, folder, client, inertia_flag=engine == "pybullet-inertia"), states
    found = robot.core_path()
    if found is None:
        return None
    states = _core_states(robot, states, found[1])
    measured = _core(robot, states, "recursive" if engine == "core" else "jacobian_sum")
    return measured, states


def _mimic_states(robot: RandomRobot, states: list[State]) -> list[State]:
    """The states with each follower at multiplier q_leader + offset and its rate at multiplier qdot_leader."""
    out = []
    for state in states:
        q, qdot = dict(state.q), dict(state.qdot)
        for joint in robot.spec.joints:
            if joint.mimic:
                q[joint.name] = joint.mimic.multiplier * q[joint.mimic.leader] + joint.mimic.offset
                qdot[joint.name] = joint.mimic.multiplier * qdot[joint.mimic.leader]
        out.append(State(q, qdot))
    return out

