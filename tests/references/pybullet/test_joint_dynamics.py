"""Joint-space dynamics of a chain in PyBullet (issue #27): its identities, its two paths (the inverse-dynamics
library and one step of the simulator) against each other, each PyBullet default that has bitten users pinned, and
PyBullet against Pinocchio on the crafted arm and real arms.

Expected values come from Pinocchio (its own URDF parser and recursions: crba, nle, rnea, here in the test), from
identities between the model's functions, or from a raw PyBullet body that differs from the adapter's in one setting.
"""

from __future__ import annotations

import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import replace
from importlib.metadata import distribution

import numpy as np
import pinocchio as pin
import pybullet_data
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.model.scenes.chain import Chain, sample_configurations
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.urdf import chain_from_urdf
from simparity.references.common.dynamics_urdf import dynamics_urdf
from simparity.references.common.quiet import captured_output
from simparity.references.pybullet.adapter import PybulletEngine
from simparity.references.pybullet.joint_dynamics import STEP, unit_axes
from simparity.references.pybullet.quiet import pybullet
from tests.helpers import builtin

ROUNDING_RTOL = 1e-13
"""max|A - B| / max|B| per state where both sides are float64 recursions of the same inertias: PyBullet against
Pinocchio on arms whose URDF inertias are diagonal (iiwa, UR5; measured over 50 states <= 3.6e-15 for M, h, tau,
qddot), PyBullet's two paths against each other (one step of STEP s against M^-1 (tau - h - D qdot) from its
inverse-dynamics library; <= 4.2e-15 on every arm) and its kinetic energy against 1/2 qdot^T M qdot (<= 1.5e-15)."""

JACOBI_RTOL = 1e-9
"""PyBullet against Pinocchio for M, h, tau on arms with off-diagonal URDF inertias (crafted arm, Panda): Bullet
diagonalises each tensor by Jacobi rotations (btMatrix3x3::diagonalize, stopping once the largest off-diagonal term
is below 1e-6 of the trace, after one more rotation) and drops what is left off the diagonal. The tensors it uses
are off by up to 8e-9 relative (panda_link1; 1.3e-9 crafted link3); over 50 states M by <= 1.3e-10 (Panda) and
3.4e-12 (crafted), h and tau by <= 8e-12: 7x the worst."""

JACOBI_FORWARD_RTOL = 2e-8
"""The same inertia errors through M^-1 (qddot): measured over 50 states <= 1.7e-9 (Panda, cond(M) <= 930) and
3.8e-10 (crafted): 10x the worst."""

EFFECT = 1e-3
"""A default left on must move the result by more than this (relative): each measured >= 0.1 (far above every
rounding and Jacobi bound)."""

ROBOTS_DIR = str(distribution("example-robot-data").locate_file("cmeel.prefix/share/example-robot-data/robots"))
CRAFTED = os.path.join(os.path.dirname(__file__), "..", "..", "..", "comparisons", "scenes", "urdf", "crafted-arm.urdf")
GRAVITY = np.array([0.4, -0.3, -9.81])  # [m/s^2] not along an axis: a turned or flipped gravity shows
ENGINE = PybulletEngine()

CRAFTED_CHAIN = chain_from_urdf(CRAFTED, tip_link="flange")
"""The crafted arm to its flange: core's parser reads its damping (j1 0.3, j2 1.5) and holds the finger."""
ARMS = {
    "crafted": CRAFTED_CHAIN,
    "iiwa": chain_from_urdf(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf")),
    "panda": chain_from_urdf(f"{ROBOTS_DIR}/panda_description/urdf/panda.urdf", tip_link="panda_hand_tcp"),
    "ur5": chain_from_urdf(f"{ROBOTS_DIR}/ur_description/urdf/ur5_robot.urdf", tip_link="tool0"),
}
AGREEMENT = {"crafted": (JACOBI_RTOL, JACOBI_FORWARD_RTOL), "panda": (JACOBI_RTOL, JACOBI_FORWARD_RTOL),
             "iiwa": (ROUNDING_RTOL, ROUNDING_RTOL), "ur5": (ROUNDING_RTOL, ROUNDING_RTOL)}
"""Arm -> bounds of (M, h, tau) and of qddot against Pinocchio: Jacobi where the file has off-diagonal inertias."""


def states(chain: Chain, count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(q, qdot, qddot, tau), each (count, n): q within the limits, the rest uniform in [-1, 1]."""
    rng = np.random.default_rng(seed)
    q = sample_configurations(chain, count, rng)
    qd, qdd, tau = (rng.uniform(-1.0, 1.0, size=q.shape) for _ in range(3))
    return q, qd, qdd, tau


def rel(a: np.ndarray, b: np.ndarray) -> float:
    """Worst over states of max|a - b| / max|b| (per state, over its last axes)."""
    axes = tuple(range(1, np.ndim(b)))
    return float(np.max(np.max(np.abs(a - b), axis=axes) / np.max(np.abs(b), axis=axes)))


class Pinocchio:
    """The reference: Pinocchio's model of the same URDF text (its own parser), per state."""

    def __init__(self, chain: Chain, gravity: np.ndarray | None, text: str | None = None) -> None:
        self.model = pin.buildModelFromXML(text or dynamics_urdf(chain))
        self.model.gravity.linear = np.zeros(3) if gravity is None else gravity
        self.data = self.model.createData()
        self.joints = [self.model.joints[self.model.getJointId(j.name)] for j in chain.joints]
        self.damping = np.array([j.damping for j in chain.joints])
        assert self.model.nv == len(self.joints)

    def _q(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio's configuration: a continuous joint has nq = 2 (cos, sin)."""
        out = pin.neutral(self.model)
        for joint, value in zip(self.joints, q):
            out[joint.idx_q:joint.idx_q + joint.nq] = (np.cos(value), np.sin(value)) if joint.nq == 2 else value
        return out

    def _v(self, v: np.ndarray) -> np.ndarray:
        out = np.zeros(self.model.nv)
        out[[j.idx_v for j in self.joints]] = v
        return out

    def _chain(self, values: np.ndarray) -> np.ndarray:
        return values[[j.idx_v for j in self.joints]]

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        m = pin.crba(self.model, self.data, self._q(q))
        m = np.triu(m) + np.triu(m, 1).T
        columns = [j.idx_v for j in self.joints]
        return m[np.ix_(columns, columns)]

    def bias_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return self._chain(pin.nle(self.model, self.data, self._q(q), self._v(qd)))

    def inverse_dynamics(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        return self._chain(pin.rnea(self.model, self.data, self._q(q), self._v(qd), self._v(qdd))) + self.damping * qd

    def forward_dynamics(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return np.linalg.solve(self.mass_matrix(q), tau - self.bias_forces(q, qd) - self.damping * qd)


@pytest.fixture(scope="module")
def crafted():
    """PyBullet's model of the crafted arm under GRAVITY."""
    return ENGINE.build_joint_dynamics(CRAFTED_CHAIN, "recursive", GRAVITY)


def tree_forward(model, q, qd, tau, damping) -> np.ndarray:
    """M^-1 (tau - h - D qdot) from the model's calculateMassMatrix / calculateInverseDynamics path."""
    rhs = tau - model.bias_forces(q, qd) - damping * qd
    return np.linalg.solve(model.mass_matrix(q), rhs[..., None])[..., 0]


# --- the engine's hooks ---------------------------------------------------------------------------------------


def test_supports_recursive_and_refuses_armature_missing_mass_and_other_methods():
    assert ENGINE.joint_dynamics_methods() == ("recursive",)
    assert ENGINE.supports_joint_dynamics(CRAFTED_CHAIN, "recursive").ok
    assert "jacobian_sum" in ENGINE.supports_joint_dynamics(CRAFTED_CHAIN, "jacobian_sum").reason
    armed = replace(CRAFTED_CHAIN, joints=tuple(replace(j, armature=0.01 * (j.name == "j2"))
                                                for j in CRAFTED_CHAIN.joints))
    support = ENGINE.supports_joint_dynamics(armed, "recursive")
    assert not support.ok and "armature" in support.reason and "'j2'" in support.reason
    bare = replace(CRAFTED_CHAIN, joints=tuple(replace(j, link=None) for j in CRAFTED_CHAIN.joints))
    support = ENGINE.supports_joint_dynamics(bare, "recursive")
    assert not support.ok and support.reason == bare.dynamics_problem()
    scene = JointDynamicsScene("s", "", "pinocchio", CRAFTED_CHAIN, GRAVITY, 2, 0)
    assert ENGINE.scheme("recursive", scene) == "recursive"


# --- identities and the two paths ------------------------------------------------------------------------------


def test_identities_on_the_crafted_arm(crafted):
    q, qd, qdd, _ = states(CRAFTED_CHAIN, 8, seed=1)
    n = q.shape[1]
    damping = np.array([j.damping for j in CRAFTED_CHAIN.joints])
    m = crafted.mass_matrix(q)
    g = crafted.bias_forces(q, np.zeros_like(q))
    assert rel(crafted.inverse_dynamics(q, np.zeros_like(q), np.zeros_like(q)), g) < ROUNDING_RTOL
    for i in range(n):  # RNEA(q, 0, e_i) - g = M e_i
        column = crafted.inverse_dynamics(q, np.zeros_like(q), np.tile(np.eye(n)[i], (len(q), 1))) - g
        assert rel(column, m[:, :, i]) < ROUNDING_RTOL
    assert np.allclose(m, np.swapaxes(m, 1, 2), rtol=0, atol=0)
    assert np.all(np.linalg.eigvalsh(m) > 0)
    tau = crafted.inverse_dynamics(q, qd, qdd)
    assert rel(crafted.forward_dynamics(q, qd, tau), qdd) < ROUNDING_RTOL
    assert rel(tau, np.einsum("bij,bj->bi", m, qdd) + crafted.bias_forces(q, qd) + damping * qd) < ROUNDING_RTOL
    kinetic = 0.5 * np.einsum("bi,bij,bj->b", qd, m, qd)
    assert rel(crafted.link_kinetic_energy(q, qd)[:, None], kinetic[:, None]) < ROUNDING_RTOL


def test_gravity_sign_holding_torque_gives_no_acceleration_and_none_means_zero(crafted):
    q, _, _, _ = states(CRAFTED_CHAIN, 5, seed=2)
    zero = np.zeros_like(q)
    holding = crafted.bias_forces(q, zero)
    assert np.max(np.abs(holding)) > 1.0  # the arm does weigh on its joints
    # the stepped world's gravity against the library's: a flipped or turned one accelerates by 2 M^-1 g or more
    assert np.max(np.abs(crafted.forward_dynamics(q, zero, holding))) < ROUNDING_RTOL * np.max(np.abs(holding))
    weightless = ENGINE.build_joint_dynamics(CRAFTED_CHAIN, "recursive", None)
    assert np.max(np.abs(weightless.bias_forces(q, zero))) == 0.0
    assert np.max(np.abs(weightless.forward_dynamics(q, zero, zero))) == 0.0


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_against_pinocchio_and_the_two_paths(arm):
    chain = ARMS[arm]
    model = ENGINE.build_joint_dynamics(chain, "recursive", GRAVITY)
    reference = Pinocchio(chain, GRAVITY)
    q, qd, qdd, tau = states(chain, 10, seed=3)
    damping = np.array([j.damping for j in chain.joints])
    bound, forward_bound = AGREEMENT[arm]
    mass_matrix = model.mass_matrix(q)
    assert rel(mass_matrix, np.stack([reference.mass_matrix(x) for x in q])) < bound
    assert rel(model.bias_forces(q, qd), np.stack([reference.bias_forces(*s) for s in zip(q, qd)])) < bound
    assert rel(model.inverse_dynamics(q, qd, qdd),
               np.stack([reference.inverse_dynamics(*s) for s in zip(q, qd, qdd)])) < bound
    stepped = model.forward_dynamics(q, qd, tau)
    assert rel(stepped, np.stack([reference.forward_dynamics(*s) for s in zip(q, qd, tau)])) < forward_bound
    assert rel(stepped, tree_forward(model, q, qd, tau, damping)) < ROUNDING_RTOL
    kinetic = 0.5 * np.einsum("bi,bij,bj->b", qd, mass_matrix, qd)
    assert rel(model.link_kinetic_energy(q, qd)[:, None], kinetic[:, None]) < ROUNDING_RTOL


# --- PyBullet's defaults, each pinned ---------------------------------------------------------------------------


def _load(text: str, client: int, flags: int = pybullet.URDF_USE_INERTIA_FROM_FILE) -> int:
    """loadURDF of ``text`` (written to a temporary file) as a fixed-base body."""
    with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False, encoding="utf-8") as handle:
        handle.write(text)
    try:
        with captured_output():
            return pybullet.loadURDF(handle.name, useFixedBase=True, flags=flags, physicsClientId=client)
    finally:
        os.unlink(handle.name)


class Raw:
    """A PyBullet body of the crafted arm configured as the adapter does, except the defaults named in ``keep``."""

    JOINTS = (1, 2, 3)  # j1, j2, j3 (mount is joint 0)

    def __init__(self, keep: tuple[str, ...] = (), text: str | None = None) -> None:
        self.client = pybullet.connect(pybullet.DIRECT)
        c = self.client
        pybullet.setGravity(*GRAVITY, physicsClientId=c)
        pybullet.setTimeStep(STEP, physicsClientId=c)
        self.body = b = _load(text or unit_axes(dynamics_urdf(CRAFTED_CHAIN)), c)
        names = [pybullet.getJointInfo(b, j, physicsClientId=c)[1].decode() for j in self.JOINTS]
        assert names == ["j1", "j2", "j3"]
        if "link damping" not in keep:
            pybullet.changeDynamics(b, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)
        if "velocity cap" not in keep:
            pybullet.changeDynamics(b, -1, maxJointVelocity=1e9, physicsClientId=c)
        for j, joint in zip(self.JOINTS, CRAFTED_CHAIN.joints):
            if "joint damping" not in keep:
                pybullet.changeDynamics(b, j, jointDamping=joint.damping, physicsClientId=c)
            if "limits" not in keep:
                pybullet.changeDynamics(b, j, jointLimitForce=0.0, physicsClientId=c)
        if "motors" not in keep:
            pybullet.setJointMotorControlArray(b, self.JOINTS, pybullet.VELOCITY_CONTROL, forces=[0.0] * 3,
                                               physicsClientId=c)

    def __del__(self) -> None:
        pybullet.disconnect(physicsClientId=self.client)

    def qddot(self, q, qd, tau) -> np.ndarray:
        """One step from (q, qd) under ``tau``: (qd' - qd) / STEP."""
        for j, a, v in zip(self.JOINTS, q, qd):
            pybullet.resetJointState(self.body, j, a, v, physicsClientId=self.client)
        pybullet.setJointMotorControlArray(self.body, self.JOINTS, pybullet.TORQUE_CONTROL, forces=list(tau),
                                           physicsClientId=self.client)
        pybullet.stepSimulation(physicsClientId=self.client)
        return (np.array([s[1] for s in pybullet.getJointStates(self.body, self.JOINTS, physicsClientId=self.client)])
                - qd) / STEP


ON_THE_LIMIT = (np.array([2.6, 0.1, 0.0]), np.array([0.5, 0.4, 0.8]))
"""j1 beyond its upper limit 2.5 rad: a limit constraint pushes back."""
FAST = (np.array([0.3, 0.1, -0.5]), np.array([0.5, -0.2, 150.0]))
"""j3 at 150 rad/s: above PyBullet's 100 rad/s cap."""
PLAIN = (np.array([0.3, 0.1, -0.5]), np.array([0.5, -0.2, 0.8]))


@pytest.mark.parametrize("default, state", [("link damping", PLAIN), ("motors", PLAIN), ("joint damping", PLAIN),
                                            ("limits", ON_THE_LIMIT), ("velocity cap", FAST)])
def test_each_stepping_default_moves_the_step_and_the_model_switches_it_off(crafted, default, state):
    q, qd = state
    tau = np.array([0.4, -0.3, 0.2])
    expected = tree_forward(crafted, q, qd, tau, np.array([j.damping for j in CRAFTED_CHAIN.joints]))[0]
    assert rel(crafted.forward_dynamics(q, qd, tau)[0], expected) < ROUNDING_RTOL
    assert rel(Raw().qddot(q, qd, tau), expected) < ROUNDING_RTOL  # Raw reproduces the model's settings
    assert rel(Raw(keep=(default,)).qddot(q, qd, tau), expected) > EFFECT


def test_default_gravity_is_zero():
    client = pybullet.connect(pybullet.DIRECT)
    try:
        parameters = pybullet.getPhysicsEngineParameters(physicsClientId=client)
        assert (parameters["gravityAccelerationX"], parameters["gravityAccelerationY"],
                parameters["gravityAccelerationZ"]) == (0.0, 0.0, 0.0)
    finally:
        pybullet.disconnect(physicsClientId=client)


def test_inertia_from_file_and_a_link_without_inertial_is_massless(crafted):
    tree = crafted._tree
    flange = next(link for link in tree.links
                  if pybullet.getJointInfo(tree.body, link, physicsClientId=tree.client)[12] == b"flange")
    assert pybullet.getDynamicsInfo(tree.body, flange, physicsClientId=tree.client)[:3:2] == (0.0, (0.0, 0.0, 0.0))
    root = ET.fromstring(dynamics_urdf(CRAFTED_CHAIN))
    for link in root.iter("link"):
        if link.get("name") == "flange":
            link.remove(link.find("inertial"))  # as in the file: no <inertial>
    raw = Raw(text=ET.tostring(root, encoding="unicode"))
    assert pybullet.getDynamicsInfo(raw.body, flange, physicsClientId=raw.client)[:3:2] == (1.0, (1.0, 1.0, 1.0))
    without_flag = pybullet.connect(pybullet.DIRECT)
    try:
        body = _load(unit_axes(dynamics_urdf(CRAFTED_CHAIN)), without_flag, flags=0)
        moments = pybullet.getDynamicsInfo(body, 0, physicsClientId=without_flag)[2]  # link0: 0.01 in the file
        assert max(moments) < 1e-5  # recomputed from (absent) collision shapes
    finally:
        pybullet.disconnect(physicsClientId=without_flag)


def test_off_diagonal_inertias_become_principal_axes_within_jacobi(crafted):
    """PyBullet moves each link's inertial frame to principal axes: R diag(I) R^T is the file's tensor (turned by
    its <origin rpy>) up to the dropped remainder of its Jacobi iteration."""
    tree = crafted._tree
    mass, _, moments, _, quat_xyzw = pybullet.getDynamicsInfo(tree.body, 1, physicsClientId=tree.client)[:5]
    x, y, z, w = quat_xyzw
    rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    roll, pitch, yaw = 0.3, -0.5, 0.7  # link1's <inertial><origin rpy>
    rx = np.array([[1, 0, 0], [0, np.cos(roll), -np.sin(roll)], [0, np.sin(roll), np.cos(roll)]])
    ry = np.array([[np.cos(pitch), 0, np.sin(pitch)], [0, 1, 0], [-np.sin(pitch), 0, np.cos(pitch)]])
    rz = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    urdf = np.array([[0.021, 0.0031, -0.0022], [0.0031, 0.034, 0.0017], [-0.0022, 0.0017, 0.027]])
    turned = rz @ ry @ rx @ urdf @ (rz @ ry @ rx).T
    assert mass == 1.7 and not np.allclose(moments, np.diag(urdf), rtol=1e-3)
    assert rel((rotation @ np.diag(moments) @ rotation.T)[None], turned[None]) < JACOBI_RTOL


def test_unit_axes_the_simulator_moves_a_non_unit_axis_by_its_length():
    """j1's axis is (0, 0, -2): PyBullet's simulator turns link1 at 2 qdot unless the axis is normalised."""
    q, qd = np.zeros(3), np.array([0.7, 0.0, 0.0])
    for text, rate in ((dynamics_urdf(CRAFTED_CHAIN), 2.0), (unit_axes(dynamics_urdf(CRAFTED_CHAIN)), 1.0)):
        raw = Raw(text=text)
        for j, a, v in zip(raw.JOINTS, q, qd):
            pybullet.resetJointState(raw.body, j, a, v, physicsClientId=raw.client)
        omega = pybullet.getLinkState(raw.body, 1, computeLinkVelocity=1, physicsClientId=raw.client)[7]
        assert np.linalg.norm(omega) == pytest.approx(rate * 0.7, rel=1e-14)


def test_joint_damping_is_the_chains_and_the_inverse_dynamics_library_ignores_it(crafted):
    stepped = crafted._stepped
    info = [pybullet.getJointInfo(stepped.body, j, physicsClientId=stepped.client) for j in stepped.joints]
    # the URDF's <dynamics> (j1: damping 0.3, friction 0.7; j2: damping 1.5) is stripped: no Coulomb friction, and
    # the damping PyBullet applies is the changeDynamics jointDamping (which getJointInfo does not report)
    assert [(i[6], i[7]) for i in info] == [(0.0, 0.0)] * 3
    q, qd = PLAIN
    undamped = Raw(keep=("joint damping",))
    library = pybullet.calculateInverseDynamics(undamped.body, list(q), list(qd), [0.0] * 3,
                                                physicsClientId=undamped.client)
    assert np.array_equal(crafted.bias_forces(q, qd)[0], library)  # the same with and without jointDamping
    tau = crafted.bias_forces(q, qd)[0] + np.array([0.3, 1.5, 0.0]) * qd  # h + D qdot holds the arm
    assert np.max(np.abs(crafted.forward_dynamics(q, qd, tau))) < ROUNDING_RTOL * np.max(np.abs(tau))


def test_the_inverse_dynamics_library_is_cached_at_its_first_call():
    """calculateMassMatrix runs on a tree PyBullet builds at the first call and keeps: a mass changed after it does
    not reach M (the adapter configures each body before its first call)."""
    q = [0.3, 0.1, -0.5]
    stale, fresh = Raw(), Raw()
    before = np.array(pybullet.calculateMassMatrix(stale.body, q, physicsClientId=stale.client))
    for raw in (stale, fresh):
        pybullet.changeDynamics(raw.body, 3, mass=5.0, physicsClientId=raw.client)
    assert np.array_equal(np.array(pybullet.calculateMassMatrix(stale.body, q, physicsClientId=stale.client)), before)
    after = np.array(pybullet.calculateMassMatrix(fresh.body, q, physicsClientId=fresh.client))
    assert np.max(np.abs(after - before)) > EFFECT


def test_a_rotated_root_inertial_turns_the_librarys_gravity_and_the_model_never_has_one(tmp_path):
    """The library's root is Bullet's base inertial frame and it takes the world's gravity in that frame: the file's
    root with a rotated inertial turns gravity in PyBullet; the model gives the base (welded: it never moves) the
    explicit zero inertial, so its gravity is the world's."""
    root = ET.fromstring(dynamics_urdf(CRAFTED_CHAIN))
    base = next(link for link in root.iter("link") if link.get("name") == "base_link")
    base.find("inertial").find("origin").set("rpy", "0.7 -0.4 1.2")
    base.find("inertial").find("mass").set("value", "3")
    base.find("inertial").find("inertia").set("ixx", "0.5")
    path = tmp_path / "turned-root.urdf"
    path.write_text(ET.tostring(root, encoding="unicode"), encoding="utf-8")
    chain = chain_from_urdf(str(path), tip_link="flange")
    q, qd, _, _ = states(chain, 4, seed=4)
    reference = np.stack([Pinocchio(chain, GRAVITY).bias_forces(*s) for s in zip(q, qd)])
    model = ENGINE.build_joint_dynamics(chain, "recursive", GRAVITY)
    assert rel(model.bias_forces(q, qd), reference) < JACOBI_RTOL
    raw = Raw(text=unit_axes(path.read_text(encoding="utf-8")))
    library = np.stack([pybullet.calculateInverseDynamics(raw.body, list(a), list(v), [0.0] * 3,
                                                          physicsClientId=raw.client) for a, v in zip(q, qd)])
    assert rel(library, reference) > EFFECT


def test_link_frames_are_float32_and_the_kinetic_energy_uses_the_double_inertial_frames(crafted):
    tree = crafted._tree
    tree.reset(*PLAIN)
    states_ = pybullet.getLinkStates(tree.body, tree.links, computeLinkVelocity=1, computeForwardKinematics=1,
                                     physicsClientId=tree.client)
    link_frames = np.array([s[5] for s in states_])  # worldLinkFrameOrientation: the client's float32 b3Transform
    inertial_frames = np.array([s[1] for s in states_])  # linkWorldOrientation: the server's double
    assert np.array_equal(link_frames.astype(np.float32).astype(float), link_frames)
    assert not np.array_equal(inertial_frames.astype(np.float32).astype(float), inertial_frames)


def test_an_unlimited_prismatic_joint_is_n_a_as_in_every_urdf_engine():
    """URDF has no unlimited prismatic joint: PyBullet said "Cannot load URDF file." (a failed case, found by a
    held-out check) where MuJoCo and Pinocchio say n/a; now all three say why."""
    scene = builtin("damped-joint")
    joint = replace(scene.chain.joints[0], type="prismatic", axis=np.array([1.0, 0.0, 0.0]))
    chain = replace(scene.chain, joints=(joint,))
    assert not joint.limited
    for name in ("pybullet", "mujoco", "pinocchio"):
        engine = make_engine(name)
        support = engine.supports_joint_dynamics(chain, engine.joint_dynamics_methods()[0])
        assert not support.ok and "unlimited prismatic joint 'hinge'" in support.reason, (name, support.reason)


def test_a_non_physical_tensor_is_zeroed_by_pybullet_and_its_dynamics_are_n_a_naming_the_link():
    """PyBullet's URDF importer replaces a tensor that breaks the triangle inequality by zero, with a console warning
    only ('Bad inertia tensor properties, setting inertia to zero'; pybullet_data's xarm6_robot.urdf, issue #45's
    corpus): its model is not the file's, so its rows are n/a naming the link; Pinocchio computes with the file's."""
    with open(CRAFTED, encoding="utf-8") as handle:
        moving = '<inertia ixx="0.021" ixy="0.0031" ixz="-0.0022" iyy="0.034" iyz="0.0017" izz="0.027"/>'
        text = handle.read().replace(moving, '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="3e-3"/>')
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bad.urdf")
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
        chain = chain_from_urdf(path, tip_link="flange", dynamics=True, refuse_mass=False)
        assert "triangle inequality" in chain.mass_problem and "inertial/inertia" in chain.mass_problem
        client = pybullet.connect(pybullet.DIRECT)
        try:
            body = _load(dynamics_urdf(chain), client)
            moments = [pybullet.getDynamicsInfo(body, i, physicsClientId=client)[2]
                       for i in range(pybullet.getNumJoints(body, physicsClientId=client))]
        finally:
            pybullet.disconnect(client)
        assert (0.0, 0.0, 0.0) in moments  # zeroed, not the file's (1e-3, 1e-3, 3e-3)
        support = ENGINE.supports_joint_dynamics(chain, "recursive")
        assert not support.ok and "sets the inertia of 1 link(s) to zero" in support.reason
        core = make_engine("core").supports_joint_dynamics(chain, "recursive")
        assert not core.ok and core.reason.startswith("core refuses the file's mass properties:")
        assert make_engine("pinocchio").supports_joint_dynamics(chain, "recursive").ok
