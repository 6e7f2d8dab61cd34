"""Core's joint-space dynamics (core/articulated): the recursive algorithms and the lecture's Jacobian sum
against each other, closed forms, identities and Pinocchio."""

from __future__ import annotations

import numpy as np
import pytest
from simparity.core.inhouse import InHouseEngine
from simparity.core.kinematics import joint_frames
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.rotations import rpy_to_matrix

METHODS = ("recursive", "jacobian_sum")

AGREE = 1e-12
"""Relative: the two methods compute the same exact quantities by different float64 roundings (~1e-15 each)."""

CLOSED_FORM = 1e-12
"""Relative: a closed form evaluated in float64 against the methods (both ~1e-15)."""

PINOCCHIO = 1e-12
"""Relative: Pinocchio's C++ against the methods on the same model (both ~1e-15)."""

FINITE_DIFFERENCE = 1e-7
"""Relative: central differences with step 1e-5: truncation ~step^2 ~ 1e-10, roundoff ~eps / step ~ 1e-11, on
quantities of order 1; the bound leaves room for the derivatives' size."""

BATCH_ROWS = 1e-14
"""Relative: a state's row computed alone or within a batch (BLAS may round a small product differently)."""

GRAVITY = np.array([0.4, -0.7, -9.81])


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(actual - expected)) / np.max(np.abs(expected)))


def random_inertia(rng: np.random.Generator) -> np.ndarray:
    """A valid inertia about a centre of mass with off-diagonal entries: R diag(principal) R^T."""
    a, b = rng.uniform(0.02, 0.2, size=2)
    principal = np.array([a, b, rng.uniform(abs(a - b) + 0.01, a + b)])  # triangle inequality
    rotation = rpy_to_matrix(rng.uniform(-np.pi, np.pi, size=3))
    return rotation @ np.diag(principal) @ rotation.T


def random_chain(seed: int, n: int = 6) -> Chain:
    """A 3-D chain: revolute and prismatic joints, non-unit axes, rotated frames, off-diagonal inertias,
    armature and damping."""
    rng = np.random.default_rng(seed)
    joints = []
    for i in range(n):
        kind = "prismatic" if i in (1, 4) else "revolute"
        joints.append(Joint(
            f"j{i}", kind, axis=rng.normal(size=3) * rng.uniform(0.5, 3.0), origin_xyz=rng.uniform(-0.3, 0.3, 3),
            origin_rotation=rpy_to_matrix(rng.uniform(-np.pi, np.pi, 3)), lower=-2.0, upper=2.0,
            link=LinkInertia(rng.uniform(0.5, 3.0), rng.uniform(-0.2, 0.2, 3), random_inertia(rng)),
            damping=rng.uniform(0.0, 0.8), armature=rng.uniform(0.0, 0.3)))
    return Chain("random", tuple(joints))


def states(chain: Chain, count: int, seed: int) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    return tuple(rng.uniform(-1.5, 1.5, (count, chain.n_joints)) for _ in range(4))


def build(chain: Chain, method: str, gravity: np.ndarray | None = GRAVITY):
    return InHouseEngine().build_joint_dynamics(chain, method, gravity)


@pytest.fixture(scope="module")
def chain() -> Chain:
    return random_chain(seed=7)


def test_the_engine_offers_both_methods_on_chains_with_mass_properties(chain: Chain) -> None:
    engine = InHouseEngine()
    assert engine.joint_dynamics_methods() == METHODS
    assert all(engine.supports_joint_dynamics(chain, m).ok for m in METHODS)
    assert not engine.supports_joint_dynamics(chain, "closed_form").ok
    bare = Chain("bare", tuple(Joint(j.name, j.type, j.axis, j.origin_xyz, j.origin_rotation) for j in chain.joints))
    refused = engine.supports_joint_dynamics(bare, "recursive")
    assert not refused.ok and "mass properties" in refused.reason
    assert "CRBA for M, RNEA for h and tau, ABA for qddot" in build(chain, "recursive").detail
    assert "Jdot in closed form" in build(chain, "jacobian_sum").detail


def test_recursive_and_jacobian_sum_agree_on_a_3d_chain(chain: Chain) -> None:
    q, qd, qdd, tau = states(chain, 20, seed=1)
    recursive, lecture = build(chain, "recursive"), build(chain, "jacobian_sum")
    assert relative_error(recursive.mass_matrix(q), lecture.mass_matrix(q)) <= AGREE
    assert relative_error(recursive.bias_forces(q, qd), lecture.bias_forces(q, qd)) <= AGREE
    assert relative_error(recursive.inverse_dynamics(q, qd, qdd), lecture.inverse_dynamics(q, qd, qdd)) <= AGREE
    assert relative_error(recursive.forward_dynamics(q, qd, tau), lecture.forward_dynamics(q, qd, tau)) <= AGREE
    assert relative_error(recursive.link_kinetic_energy(q, qd), lecture.link_kinetic_energy(q, qd)) <= AGREE


def planar_arm(l1: float, lc1: float, lc2: float, m1: float, m2: float, i1: float, i2: float) -> Chain:
    """Two revolute joints about z in the x-y plane, each link's centre of mass on its x axis."""
    def link(mass: float, com: float, izz: float) -> LinkInertia:
        return LinkInertia(mass, np.array([com, 0.0, 0.0]), np.diag([0.3, 0.2, izz]))
    return Chain("planar", (
        Joint("j1", "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.eye(3), link=link(m1, lc1, i1)),
        Joint("j2", "revolute", np.array([0.0, 0.0, 1.0]), np.array([l1, 0.0, 0.0]), np.eye(3),
              link=link(m2, lc2, i2))))


@pytest.mark.parametrize("method", METHODS)
def test_the_planar_two_link_arm_has_spongs_closed_form(method: str) -> None:
    l1, lc1, lc2, m1, m2, i1, i2, g = 0.9, 0.4, 0.35, 2.0, 1.3, 0.15, 0.08, 9.81
    model = build(planar_arm(l1, lc1, lc2, m1, m2, i1, i2), method, np.array([0.0, -g, 0.0]))
    q, qd, _, _ = states(planar_arm(l1, lc1, lc2, m1, m2, i1, i2), 8, seed=2)
    c2, s2 = np.cos(q[:, 1]), np.sin(q[:, 1])
    # Spong, Hutchinson & Vidyasagar, Robot Modeling and Control, section 7.4.2 (q measured from the x axis).
    m11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + i1 + i2
    m12 = m2 * (lc2**2 + l1 * lc2 * c2) + i2
    m22 = np.full_like(m11, m2 * lc2**2 + i2)
    expected_m = np.stack([np.stack([m11, m12], -1), np.stack([m12, m22], -1)], -2)
    h = m2 * l1 * lc2 * s2
    gravity = np.stack([(m1 * lc1 + m2 * l1) * g * np.cos(q[:, 0]) + m2 * lc2 * g * np.cos(q.sum(1)),
                        m2 * lc2 * g * np.cos(q.sum(1))], -1)
    coriolis = np.stack([-h * (2 * qd[:, 0] * qd[:, 1] + qd[:, 1] ** 2), h * qd[:, 0] ** 2], -1)
    assert relative_error(model.mass_matrix(q), expected_m) <= CLOSED_FORM
    assert relative_error(model.bias_forces(q, np.zeros_like(qd)), gravity) <= CLOSED_FORM
    assert relative_error(model.bias_forces(q, qd), coriolis + gravity) <= CLOSED_FORM


@pytest.mark.parametrize("method", METHODS)
def test_a_physical_pendulum_swings_at_its_closed_form_frequency(method: str) -> None:
    """omega_0^2 = m g d / (I_c + m d^2) from M and dg/dq at the hanging equilibrium; the axis is given
    non-unit and the joint frame rotated about it, the centre of mass at d along the link's x axis."""
    mass, d, i_c, g = 1.7, 0.45, 0.06, 9.81
    chain = Chain("pendulum", (Joint("hinge", "revolute", np.array([0.0, 0.0, 3.0]), np.array([0.1, 0.2, 0.3]),
                                     rpy_to_matrix(np.array([0.0, 0.0, 0.7])),
                                     link=LinkInertia(mass, np.array([d, 0.0, 0.0]), np.diag([0.01, 0.02, i_c]))),))
    model = build(chain, method, np.array([0.0, -g, 0.0]))
    hanging = np.array([[-np.pi / 2 - 0.7]])  # the link's x axis along -y
    step = 1e-5
    stiffness = (model.bias_forces(hanging + step, np.zeros((1, 1)))
                 - model.bias_forces(hanging - step, np.zeros((1, 1)))) / (2 * step)
    omega_squared = stiffness[0, 0] / model.mass_matrix(hanging)[0, 0, 0]
    assert abs(model.bias_forces(hanging, np.zeros((1, 1)))[0, 0]) <= CLOSED_FORM * mass * g * d
    assert omega_squared == pytest.approx(mass * g * d / (i_c + mass * d**2), rel=FINITE_DIFFERENCE)


def potential_gradient(chain: Chain, q: np.ndarray, gravity: np.ndarray, step: float = 1e-5) -> np.ndarray:
    """dV/dq by central differences of V = -sum m_i g . p_ci, the centres of mass from core's FK."""
    links = [j.link for j in chain.joints if j.link is not None]
    masses = np.array([link.mass for link in links])
    coms = np.array([link.com_xyz for link in links])

    def potential(x: np.ndarray) -> np.ndarray:
        positions, rotations, _ = joint_frames(chain, x)
        com = positions[:, :-1] + np.einsum("bikl,il->bik", rotations[:, :-1], coms)
        return -np.einsum("i,bik,k->b", masses, com, gravity)

    columns = []
    for i in range(chain.n_joints):
        dq = np.zeros(chain.n_joints)
        dq[i] = step
        columns.append((potential(q + dq) - potential(q - dq)) / (2 * step))
    return np.stack(columns, -1)


@pytest.mark.parametrize("method", METHODS)
def test_the_equations_of_motion_keep_their_identities(chain: Chain, method: str) -> None:
    model = build(chain, method)
    q, qd, qdd, _ = states(chain, 6, seed=3)
    zero = np.zeros_like(q)
    gravity = model.inverse_dynamics(q, zero, zero)
    assert relative_error(gravity, potential_gradient(chain, q, GRAVITY)) <= FINITE_DIFFERENCE
    assert relative_error(model.bias_forces(q, zero), gravity) <= AGREE
    m = model.mass_matrix(q)
    for i in range(chain.n_joints):
        unit = np.zeros_like(q)
        unit[:, i] = 1.0
        assert relative_error(model.inverse_dynamics(q, zero, unit) - gravity, m[:, :, i]) <= AGREE
    tau = model.inverse_dynamics(q, qd, qdd)
    assert relative_error(model.forward_dynamics(q, qd, tau), qdd) <= AGREE
    assert np.array_equal(m, np.swapaxes(m, 1, 2)) or relative_error(m, np.swapaxes(m, 1, 2)) <= AGREE
    assert np.all(np.linalg.eigvalsh(m) > 0)
    armature = np.array([j.armature for j in chain.joints])
    energy = 0.5 * np.einsum("bi,bij,bj->b", qd, m, qd) - 0.5 * np.sum(armature * qd**2, axis=1)
    assert relative_error(model.link_kinetic_energy(q, qd), energy) <= AGREE
    step = 1e-5
    m_rate = (model.mass_matrix(q + step * qd) - model.mass_matrix(q - step * qd)) / (2 * step)
    coriolis = model.bias_forces(q, qd) - gravity
    assert relative_error(np.einsum("bi,bij,bj->b", qd, m_rate, qd),
                          2 * np.einsum("bi,bi->b", qd, coriolis)) <= FINITE_DIFFERENCE


@pytest.mark.parametrize("method", METHODS)
def test_a_state_alone_or_in_a_batch_gives_the_same_row(chain: Chain, method: str) -> None:
    model = build(chain, method)
    q, qd, qdd, tau = states(chain, 5, seed=4)
    batched = (model.mass_matrix(q), model.bias_forces(q, qd), model.inverse_dynamics(q, qd, qdd),
               model.forward_dynamics(q, qd, tau), model.link_kinetic_energy(q, qd))
    for b in range(len(q)):
        alone = (model.mass_matrix(q[b:b + 1]), model.bias_forces(q[b:b + 1], qd[b:b + 1]),
                 model.inverse_dynamics(q[b:b + 1], qd[b:b + 1], qdd[b:b + 1]),
                 model.forward_dynamics(q[b:b + 1], qd[b:b + 1], tau[b:b + 1]),
                 model.link_kinetic_energy(q[b:b + 1], qd[b:b + 1]))
        for one, many in zip(alone, batched):
            assert one.shape == many[b:b + 1].shape
            assert relative_error(one, many[b:b + 1]) <= BATCH_ROWS


def urdf_of(chain: Chain) -> str:
    """The chain as URDF text, written from its own numbers (rpy from the rotations)."""
    def rpy(r: np.ndarray) -> str:  # URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll)
        pitch = np.arcsin(-r[2, 0])
        return xyz(np.array([np.arctan2(r[2, 1], r[2, 2]), pitch, np.arctan2(r[1, 0], r[0, 0])]))

    def xyz(v: np.ndarray) -> str:
        return " ".join(repr(float(x)) for x in v)

    parts = ['<robot name="test"><link name="base"/>']
    parent = "base"
    for joint in chain.joints:
        link = joint.link
        assert link is not None
        i = np.vectorize(lambda x: repr(float(x)))(link.inertia_com)
        parts.append(
            f'<link name="{joint.name}_link"><inertial><origin xyz="{xyz(link.com_xyz)}" rpy="0 0 0"/>'
            f'<mass value="{link.mass!r}"/><inertia ixx="{i[0, 0]}" ixy="{i[0, 1]}" ixz="{i[0, 2]}" '
            f'iyy="{i[1, 1]}" iyz="{i[1, 2]}" izz="{i[2, 2]}"/></inertial></link>'
            f'<joint name="{joint.name}" type="{joint.type}"><parent link="{parent}"/>'
            f'<child link="{joint.name}_link"/>'
            f'<origin xyz="{xyz(joint.origin_xyz)}" rpy="{rpy(joint.origin_rotation)}"/>'
            f'<axis xyz="{xyz(joint.axis)}"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>')
        parent = f"{joint.name}_link"
    return "".join(parts) + "</robot>"


@pytest.mark.parametrize("method", METHODS)
def test_pinocchio_computes_the_same_dynamics(chain: Chain, method: str) -> None:
    pin = pytest.importorskip("pinocchio")
    pin_model = pin.buildModelFromXML(urdf_of(chain))
    pin_model.gravity.linear = GRAVITY
    pin_model.armature[:] = [j.armature for j in chain.joints]
    data = pin_model.createData()
    damping = np.array([j.damping for j in chain.joints])  # Pinocchio's algorithms have no joint damping
    model = build(chain, method)
    q, qd, qdd, tau = states(chain, 4, seed=5)
    for b in range(len(q)):
        m = pin.crba(pin_model, data, q[b])
        m = np.triu(m) + np.triu(m, 1).T
        assert relative_error(model.mass_matrix(q[b:b + 1])[0], m) <= PINOCCHIO
        assert relative_error(model.bias_forces(q[b:b + 1], qd[b:b + 1])[0],
                              pin.nonLinearEffects(pin_model, data, q[b], qd[b])) <= PINOCCHIO
        expected_tau = pin.rnea(pin_model, data, q[b], qd[b], qdd[b]) + damping * qd[b]
        assert relative_error(model.inverse_dynamics(q[b:b + 1], qd[b:b + 1], qdd[b:b + 1])[0],
                              expected_tau) <= PINOCCHIO
        expected_qdd = pin.aba(pin_model, data, q[b], qd[b], tau[b] - damping * qd[b])
        assert relative_error(model.forward_dynamics(q[b:b + 1], qd[b:b + 1], tau[b:b + 1])[0],
                              expected_qdd) <= PINOCCHIO
