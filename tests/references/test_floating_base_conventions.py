"""Floating bases (#43): each engine's own convention pinned at the engine's API, each adapter's conversion to the
project's convention checked against truths that need no engine, and PyBullet's n/a pinned with its reason.

The truths: at a state where the joints do not move, the floating-base M's base block is the whole robot's spatial
inertia about the base origin in world axes, summed here by hand from the file's own ``<inertial>`` elements
(ElementTree, the parallel-axis theorem); gravity's generalized force is -M[:, :3] g (the equivalence principle);
in free flight (no wrench on the base) the base rows of RNEA at ABA's acceleration vanish (the whole robot's
Newton-Euler equations)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from simparity.core.articulated.model import build
from tests.helpers import floating_states, solo12_leg
from simparity.references.common.dynamics_urdf import dynamics_urdf
from simparity.references.mujoco.floating import MujocoFloatingDynamics
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pybullet.adapter import FLOATING_BASE_WHY, PybulletEngine

ROUNDING = 1e-13
"""Relative agreement of sums of a few dozen double products of numbers of order 1 (measured <= 3e-15)."""

GRAVITY = np.array([0.3, -0.2, -9.81])
"""Tilted, so that no component of a wrongly turned gravity vanishes by symmetry."""

ENGINES = {"core": lambda chain: build(chain, "recursive", GRAVITY),
           "mujoco": lambda chain: MujocoFloatingDynamics(chain, GRAVITY),
           "pinocchio": lambda chain: PinocchioFloatingDynamics(chain, GRAVITY)}


@pytest.fixture(scope="module")
def solo():
    return solo12_leg()


def _rpy(text: str | None) -> np.ndarray:
    return Rotation.from_euler("xyz", [float(x) for x in (text or "0 0 0").split()]).as_matrix()


def _xyz(text: str | None) -> np.ndarray:
    return np.array([float(x) for x in (text or "0 0 0").split()])


def _spatial_inertia_by_hand(urdf_text: str, base: str) -> np.ndarray:
    """(6, 6) the whole robot's inertia about the base origin in base axes, (linear, angular) order, every joint at
    its zero position: each link's <inertial> placed by the <origin>s of the joints above it."""
    root = ET.fromstring(urdf_text)
    links = {link.get("name"): link for link in root.findall("link")}
    children: dict[str, list] = {}
    for joint in root.findall("joint"):
        children.setdefault(joint.find("parent").get("link"), []).append(joint)
    mass, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    stack = [(base, np.zeros(3), np.eye(3))]
    while stack:
        name, position, rotation = stack.pop()
        inertial = links[name].find("inertial")
        if inertial is not None:
            origin = inertial.find("origin")
            frame = rotation @ _rpy(None if origin is None else origin.get("rpy"))
            com = position + rotation @ _xyz(None if origin is None else origin.get("xyz"))
            m = float(inertial.find("mass").get("value"))
            e = {k: float(inertial.find("inertia").get(k)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
            own = np.array([[e["ixx"], e["ixy"], e["ixz"]], [e["ixy"], e["iyy"], e["iyz"]],
                            [e["ixz"], e["iyz"], e["izz"]]])
            mass += m
            first += m * com
            second += frame @ own @ frame.T + m * (com @ com * np.eye(3) - np.outer(com, com))
        for joint in children.get(name, []):
            origin = joint.find("origin")
            xyz, rpy = (None, None) if origin is None else (origin.get("xyz"), origin.get("rpy"))
            stack.append((joint.find("child").get("link"), position + rotation @ _xyz(xyz), rotation @ _rpy(rpy)))
    lever = np.array([[0, -first[2], first[1]], [first[2], 0, -first[0]], [-first[1], first[0], 0]])
    return np.block([[mass * np.eye(3), -lever], [lever, second]])


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_the_base_block_of_m_is_the_whole_robot_s_inertia_about_the_base_origin(engine, solo):
    """At joints 0 and a turned base, M[:6, :6] = diag(R, R) I_robot diag(R, R)^T: a linear velocity read in the
    wrong frame, an angular one in the body frame or the base's inertia dropped all move it."""
    model = ENGINES[engine](solo)
    q, _, _, _ = floating_states(solo, 3, seed=1)
    q[:, 7:] = 0.0
    truth = _spatial_inertia_by_hand(dynamics_urdf(solo), "base_link")
    for row, mass in zip(q, model.mass_matrix(q)):
        turn = Rotation.from_quat(row[3:7], scalar_first=True).as_matrix()
        both = np.kron(np.eye(2), turn)
        expected = both @ truth @ both.T
        assert np.max(np.abs(mass[:6, :6] - expected)) <= ROUNDING * np.max(np.abs(expected))


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_gravity_is_a_uniform_acceleration_of_the_base_and_free_flight_leaves_the_base_unforced(engine, solo):
    model = ENGINES[engine](solo)
    q, v, _, tau = floating_states(solo, 4, seed=2)
    weight = model.bias_forces(q, np.zeros_like(v))
    mass = model.mass_matrix(q)
    assert np.max(np.abs(weight + mass[:, :, :3] @ GRAVITY)) <= ROUNDING * np.max(np.abs(weight))
    assert np.allclose(weight[:, :3], -mass[:, 0, 0][:, None] * GRAVITY, rtol=ROUNDING, atol=0)  # -m g on the base
    free = tau.copy()
    free[:, :6] = 0.0
    acceleration = model.forward_dynamics(q, v, free)
    back = model.inverse_dynamics(q, v, acceleration)
    scale = np.max(np.abs(weight)) + np.max(np.abs(tau))
    assert np.max(np.abs(back[:, :6])) <= ROUNDING * scale
    assert np.max(np.abs(back[:, 6:] - free[:, 6:])) <= ROUNDING * scale


@pytest.mark.parametrize("engine", ["mujoco", "pinocchio"])
def test_each_engine_agrees_with_core_at_turned_movingfloating_states(engine, solo):
    core, other = ENGINES["core"](solo), ENGINES[engine](solo)
    q, v, a, tau = floating_states(solo, 5, seed=3)
    for name, args in (("mass_matrix", (q,)), ("bias_forces", (q, v)), ("inverse_dynamics", (q, v, a)),
                       ("forward_dynamics", (q, v, tau)), ("link_kinetic_energy", (q, v))):
        mine, theirs = getattr(core, name)(*args), getattr(other, name)(*args)
        assert np.max(np.abs(mine - theirs)) <= ROUNDING * np.max(np.abs(theirs)), name


def test_mujoco_s_free_joint_is_world_linear_and_body_angular_velocity(solo):
    """MuJoCo's own convention, at its API: qvel[:3] moves the base origin in world axes, qvel[3:6] turns it about its
    own (body) axes; qpos[3:7] is quat_wxyz."""
    model = MujocoFloatingDynamics(solo, None)
    m, d = model.model, model.data
    turn = Rotation.from_euler("xyz", [0.4, -0.7, 1.1])
    d.qpos[model.state_qpos[:7]] = np.r_[0.1, 0.2, 0.3, turn.as_quat(scalar_first=True)]
    d.qvel[:] = 0.0
    d.qvel[model.state_dof[:6]] = [1.0, 2.0, 3.0, 0.5, -0.25, 0.125]
    mujoco.mj_forward(m, d)
    body = int(m.jnt_bodyid[[j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE][0]])
    assert np.allclose(d.xquat[body], turn.as_quat(scalar_first=True), atol=1e-15)
    velocity = np.empty(6)  # (angular, linear) at the body origin, world axes
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, body, velocity, 0)
    assert np.allclose(velocity[3:], [1.0, 2.0, 3.0], atol=1e-14)
    assert np.allclose(velocity[:3], turn.as_matrix() @ [0.5, -0.25, 0.125], atol=1e-14)


def test_pinocchio_s_free_flyer_is_local_linear_and_angular_velocity(solo):
    """Pinocchio's own convention, at its API: q[3:7] is quat_xyzw, v[:3] and v[3:6] are in the base's LOCAL frame."""
    model = PinocchioFloatingDynamics(solo, None)
    turn = Rotation.from_euler("xyz", [0.4, -0.7, 1.1])
    q = pin.neutral(model.model)
    q[:7] = np.r_[0.1, 0.2, 0.3, turn.as_quat()]
    v = np.zeros(model.model.nv)
    v[:6] = [1.0, 2.0, 3.0, 0.5, -0.25, 0.125]
    pin.forwardKinematics(model.model, model.data, q, v)
    placement = model.data.oMi[1]
    assert np.allclose(placement.rotation, turn.as_matrix(), atol=1e-15)
    world = pin.getVelocity(model.model, model.data, 1, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    assert np.allclose(world.linear, turn.as_matrix() @ [1.0, 2.0, 3.0], atol=1e-14)
    assert np.allclose(world.angular, turn.as_matrix() @ [0.5, -0.25, 0.125], atol=1e-14)


def test_pybullet_is_n_a_on_a_floating_base_with_its_reason(solo):
    support = PybulletEngine().supports_joint_dynamics(solo, "recursive")
    assert not support.ok and support.reason == FLOATING_BASE_WHY
    assert "calculateInverseDynamics" in support.reason and "turns the base" in support.reason


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_the_robot_s_momentum_from_its_links_is_m_s_base_rows_times_qdot(engine, solo):
    """The centroidal momentum moved to the base origin: M[:6] qdot = (P, L_o) from each engine's own link velocities;
    a base sliding at v with every joint still carries P = m v and, about its own origin, L_o = m c x v."""
    model = ENGINES[engine](solo)
    q, v, _, _ = floating_states(solo, 4, seed=6)
    mass = model.mass_matrix(q)
    reported = model.momentum(q, v)
    about_base = np.concatenate([reported[:, :3], reported[:, 3:] - np.cross(q[:, :3], reported[:, :3])], axis=1)
    expected = np.einsum("bij,bj->bi", mass[:, :6, :], v)
    assert np.max(np.abs(expected - about_base)) <= ROUNDING * np.max(np.abs(expected))
    sliding = np.zeros_like(v)
    sliding[:, :3] = [0.5, -1.0, 2.0]
    total = model.mass_matrix(q)[:, 0, 0]
    assert np.allclose(model.momentum(q, sliding)[:, :3], total[:, None] * [0.5, -1.0, 2.0], rtol=ROUNDING, atol=0)


MJCF_AGREEMENT = 1e-12
"""[1, of M's largest entry] Pinocchio's and MuJoCo's M of one MJCF file: rounding of their recursions (measured 2e-15)."""


def test_an_mjcf_floating_base_is_pinocchio_s_free_flyer_too():
    """Pinocchio's MJCF parser takes a root joint only with its name, and then answers (model, constraint models): the
    MJCF ant with a floating base (a joint_dynamics scene) raised a signature error at load (a held-out trial)."""
    from simparity.comparisons.scenes.loading.scene_file import parse_scene

    chain = parse_scene({"scene": {"name": "ant", "kind": "joint_dynamics", "reference": "pinocchio"},
                         "chain": {"mjcf": "pybullet_data:mjcf/ant.xml", "base_link": "torso",
                                   "tip_link": "front_left_foot", "floating_base": True}}, "ant.toml").chain
    q, _, _, _ = floating_states(chain, 2, seed=4)
    pinocchio_m = PinocchioFloatingDynamics(chain, GRAVITY).mass_matrix(q)
    mujoco_m = MujocoFloatingDynamics(chain, GRAVITY).mass_matrix(q)
    np.testing.assert_allclose(pinocchio_m, mujoco_m, atol=MJCF_AGREEMENT * np.abs(mujoco_m).max())
