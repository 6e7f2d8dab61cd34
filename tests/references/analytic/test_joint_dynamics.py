"""The analytic engine's closed-form joint-space dynamics of planar 1- and 2-link arms (Spong's planar elbow
manipulator, the physical pendulum): against hand-computed values, the pendulum's frequency, the link energies,
its own inverse/forward round trip, Pinocchio on a chain with every phase, and its refusals."""

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.references.analytic.engine import AnalyticEngine

# Closed forms of a few terms in float64 against numbers written by hand: rounding only (cos(pi/2) ~ 6e-17).
HAND_TOL = 1e-13
# Two float64 evaluations of the same physics (closed form here, recursive algorithms in Pinocchio) on an arm of
# ~1 m, ~2 kg under ~10 m/s^2: rounding of values of order 10.
ENGINE_TOL = 1e-12
# Central difference of g(q) = m g d sin(q - q*) with step 1e-5: truncation (step^2 / 6 ~ 2e-11, relative) and
# rounding (1e-16 * 10 / 1e-5 ~ 1e-10 absolute on a slope of ~3).
SLOPE_RTOL = 1e-9
FD_STEP = 1e-5

G = 10.0  # [m/s^2], a round number for the hand computations

ENGINE = AnalyticEngine()


def _link(mass: float, com_xyz, inertia) -> LinkInertia:
    return LinkInertia(mass, np.asarray(com_xyz, dtype=float), np.asarray(inertia, dtype=float))


def _joint(name: str, link: LinkInertia, origin_xyz=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), origin_rotation=None,
           joint_type: str = "revolute", damping: float = 0.0, armature: float = 0.0) -> Joint:
    rotation = np.eye(3) if origin_rotation is None else origin_rotation
    return Joint(name, joint_type, np.asarray(axis, dtype=float), np.asarray(origin_xyz, dtype=float), rotation,
                 link=link, damping=damping, armature=armature)


def spong_arm() -> Chain:
    """Spong's planar elbow arm about +z, links along x: m1 = 1, m2 = 2 [kg], l1 = 1, lc1 = 0.5, lc2 = 0.25 [m],
    I1 = 0.1, I2 = 0.05 [kg m^2] about z through each COM."""
    return Chain("spong", (
        _joint("shoulder", _link(1.0, (0.5, 0, 0), np.diag([0.01, 0.08, 0.1]))),
        _joint("elbow", _link(2.0, (0.25, 0, 0), np.diag([0.02, 0.04, 0.05])), origin_xyz=(1.0, 0, 0)),
    ))


def phased_arm() -> Chain:
    """A planar arm in a tilted plane with every phase: joint 1's axis -z of a rotated frame off the base's origin,
    joint 2 off link 1's x axis with its frame flipped (its axis -z there: opposite to joint 1's in the world), both
    centres of mass off the link lines, products of inertia in the plane, damping and armature."""
    base = Rotation.from_rotvec([0.3, -0.5, 0.7]).as_matrix()
    flip = Rotation.from_euler("xz", [np.pi, 0.4]).as_matrix()
    inertia1 = [[0.02, 0.005, 0], [0.005, 0.03, 0], [0, 0, 0.04]]
    inertia2 = [[0.01, -0.002, 0], [-0.002, 0.015, 0], [0, 0, 0.02]]
    return Chain("phased", (
        _joint("j1", _link(1.5, (0.3, -0.1, 0), inertia1), origin_xyz=(0.1, 0.2, 0.3), axis=(0, 0, -2),
               origin_rotation=base, damping=0.3, armature=0.05),
        _joint("j2", _link(0.8, (0.2, 0.15, 0), inertia2), origin_xyz=(0.7, 0.4, 0), axis=(0, 0, -1),
               origin_rotation=flip, damping=0.1, armature=0.02),
    ))


def _model(chain: Chain, gravity):
    assert ENGINE.supports_joint_dynamics(chain, "closed_form").ok
    return ENGINE.build_joint_dynamics(chain, "closed_form", None if gravity is None else np.asarray(gravity, float))


# (q, qdot, M, C qdot, g) worked by hand from Spong's formulas with the numbers of spong_arm() and g = 10 along -y:
# M11 = I1 + I2 + m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 cos q2) = 0.4 + 2 (1.0625 + 0.5 cos q2),
# M12 = I2 + m2 (lc2^2 + l1 lc2 cos q2) = 0.175 + 0.5 cos q2, M22 = I2 + m2 lc2^2 = 0.175;
# h = -m2 l1 lc2 sin q2 = -0.5 sin q2, C qdot = (h qd2^2 + 2 h qd1 qd2, -h qd1^2);
# g1 = (m1 lc1 + m2 l1) g cos q1 + m2 lc2 g cos(q1 + q2) = 25 cos q1 + 5 cos(q1 + q2), g2 = 5 cos(q1 + q2).
HAND_STATES = [
    # q2 = pi/2: cos 0, sin 1, h = -0.5: C qdot = (-0.5 * 4 - 2 * 0.5 * 2, 0.5 * 1); g = (25, 0).
    ((0.0, np.pi / 2), (1.0, 2.0), [[2.525, 0.175], [0.175, 0.175]], (-4.0, 0.5), (25.0, 0.0)),
    # q2 = -pi/2: h = 0.5: C qdot = (0.5 * 9 + 2 * 0.5 * (-1) * 3, -0.5 * 1) = (1.5, -0.5); q1 + q2 = 0: g = (5, 5).
    ((np.pi / 2, -np.pi / 2), (-1.0, 3.0), [[2.525, 0.175], [0.175, 0.175]], (1.5, -0.5), (5.0, 5.0)),
    # q2 = pi: cos -1, h = 0: M11 = 0.4 + 2 * 0.5625 = 1.525, M12 = -0.325; q1 = 0: g = (25 - 5, -5).
    ((0.0, np.pi), (2.0, -1.0), [[1.525, -0.325], [-0.325, 0.175]], (0.0, 0.0), (20.0, -5.0)),
]


@pytest.mark.parametrize("q, qdot, mass, coriolis, gravity", HAND_STATES)
def test_two_link_arm_against_hand_values(q, qdot, mass, coriolis, gravity):
    """M, C qdot and g of Spong's arm equal the numbers worked out by hand."""
    model = _model(spong_arm(), (0.0, -G, 0.0))
    q, qdot = np.array([q]), np.array([qdot])
    np.testing.assert_allclose(model.mass_matrix(q)[0], mass, rtol=0, atol=HAND_TOL)
    no_gravity = _model(spong_arm(), None)
    np.testing.assert_allclose(no_gravity.bias_forces(q, qdot)[0], coriolis, rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(model.bias_forces(q, np.zeros_like(qdot))[0], gravity, rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(model.bias_forces(q, qdot)[0], np.add(coriolis, gravity), rtol=0, atol=HAND_TOL)


def test_physical_pendulum_frequency():
    """One link with its COM at d = 0.4 m off the axis, at a phase of 0.7 rad from the link's x axis, under gravity
    along -y: the hanging equilibrium is q* = -pi/2 - 0.7, and M(0), dg/dq there give omega_0^2 = m g d /
    (I_c + m d^2) = 3 * 10 * 0.4 / (0.02 + 3 * 0.16) = 24."""
    mass, d, phase, inertia_c = 3.0, 0.4, 0.7, 0.02
    link = _link(mass, (d * np.cos(phase), d * np.sin(phase), 0.0), np.diag([0.5, 0.6, inertia_c]))
    model = _model(Chain("pendulum", (_joint("pivot", link),)), (0.0, -G, 0.0))
    hanging = np.array([[-np.pi / 2 - phase]])
    zero = np.zeros((1, 1))
    assert abs(model.bias_forces(hanging, zero)[0, 0]) <= HAND_TOL
    slope = (model.bias_forces(hanging + FD_STEP, zero) - model.bias_forces(hanging - FD_STEP, zero))[0, 0] / (
        2 * FD_STEP)
    inertia = model.mass_matrix(zero)[0, 0, 0]
    assert inertia == pytest.approx(inertia_c + mass * d**2, abs=HAND_TOL)
    assert slope / inertia == pytest.approx(24.0, rel=SLOPE_RTOL)


def _random_states(n_joints: int, rng: np.random.Generator, count: int = 20):
    return tuple(rng.uniform(-lim, lim, size=(count, n_joints)) for lim in (np.pi, 2.0, 3.0, 5.0))


@pytest.mark.parametrize("chain", [spong_arm(), phased_arm()], ids=["spong", "phased"])
def test_energy_identity(chain):
    """1/2 qdot^T M qdot (armature aside) is the links' own kinetic energy from their velocities."""
    q, qdot, _, _ = _random_states(2, np.random.default_rng(4))
    model = _model(chain, (0.0, -G, 0.0))
    armature = np.array([j.armature for j in chain.joints])
    m = model.mass_matrix(q) - np.diag(armature)
    quadratic = 0.5 * np.einsum("bi,bij,bj->b", qdot, m, qdot)
    np.testing.assert_allclose(model.link_kinetic_energy(q, qdot), quadratic, rtol=0, atol=ENGINE_TOL)


@pytest.mark.parametrize("chain", [spong_arm(), phased_arm(), Chain("one", phased_arm().joints[:1])],
                         ids=["spong", "phased", "one-link"])
def test_inverse_forward_round_trip(chain):
    """forward(q, qdot, inverse(q, qdot, qddot)) = qddot and inverse(q, qdot, forward(q, qdot, tau)) = tau."""
    q, qdot, qddot, tau = _random_states(chain.n_joints, np.random.default_rng(5))
    model = _model(chain, (1.0, -9.0, 2.5))
    np.testing.assert_allclose(model.forward_dynamics(q, qdot, model.inverse_dynamics(q, qdot, qddot)), qddot,
                               rtol=0, atol=ENGINE_TOL)
    np.testing.assert_allclose(model.inverse_dynamics(q, qdot, model.forward_dynamics(q, qdot, tau)), tau,
                               rtol=0, atol=ENGINE_TOL)


def _pinocchio(chain: Chain, gravity: np.ndarray):
    """The chain built joint by joint in Pinocchio's own API (placements, unaligned revolute axes, inertias)."""
    model = pin.Model()
    parent = 0
    for joint in chain.joints:
        parent = model.addJoint(parent, pin.JointModelRevoluteUnaligned(joint.axis),
                                pin.SE3(np.array(joint.origin_rotation), np.array(joint.origin_xyz)), joint.name)
        link = joint.link
        assert link is not None  # every test chain has mass properties
        model.appendBodyToJoint(parent, pin.Inertia(link.mass, np.array(link.com_xyz), np.array(link.inertia_com)),
                                pin.SE3.Identity())
    model.gravity.linear = gravity
    return model, model.createData()


@pytest.mark.parametrize("chain", [phased_arm(), Chain("one", phased_arm().joints[:1])], ids=["phased", "one-link"])
def test_against_pinocchio(chain):
    """Every phase (tilted plane, negative and opposite axes, joint 2 off the link line, COMs off it, products of
    inertia in the plane) and gravity with a component along the axis: M, h, inverse and forward dynamics equal
    Pinocchio's CRBA, RNEA and ABA (armature on M's diagonal, damping D qdot added by hand)."""
    gravity = np.array([1.0, -9.0, 2.5])
    q, qdot, qddot, tau = _random_states(chain.n_joints, np.random.default_rng(6), count=5)
    model = _model(chain, gravity)
    pmodel, data = _pinocchio(chain, gravity)
    armature = np.diag([j.armature for j in chain.joints])
    damping = np.array([j.damping for j in chain.joints])
    for k in range(len(q)):
        mass = pin.crba(pmodel, data, q[k])
        mass = np.triu(mass) + np.triu(mass, 1).T + armature
        bias = pin.rnea(pmodel, data, q[k], qdot[k], np.zeros(chain.n_joints))
        np.testing.assert_allclose(model.mass_matrix(q[k:k + 1])[0], mass, rtol=0, atol=ENGINE_TOL)
        np.testing.assert_allclose(model.bias_forces(q[k:k + 1], qdot[k:k + 1])[0], bias, rtol=0, atol=ENGINE_TOL)
        torque = mass @ qddot[k] + bias + damping * qdot[k]
        np.testing.assert_allclose(model.inverse_dynamics(q[k:k + 1], qdot[k:k + 1], qddot[k:k + 1])[0], torque,
                                   rtol=0, atol=ENGINE_TOL)
        np.testing.assert_allclose(model.forward_dynamics(q[k:k + 1], qdot[k:k + 1], tau[k:k + 1])[0],
                                   np.linalg.solve(mass, tau[k] - bias - damping * qdot[k]), rtol=0, atol=ENGINE_TOL)


def test_gravity_along_the_axis_does_no_work():
    """Gravity along the joints' axis turns no joint: g(q) = 0 (the engine interface asks about support without
    gravity, so it is not refused); with gravity tilted out of the plane, only its in-plane part acts."""
    q = np.array([[0.3, -1.1]])
    zero = np.zeros((1, 2))
    np.testing.assert_allclose(_model(spong_arm(), (0.0, 0.0, -G)).bias_forces(q, zero), 0.0, rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(_model(spong_arm(), (0.0, -G, 7.0)).bias_forces(q, zero),
                               _model(spong_arm(), (0.0, -G, 0.0)).bias_forces(q, zero), rtol=0, atol=HAND_TOL)


def _refusal(chain: Chain) -> str:
    support = ENGINE.supports_joint_dynamics(chain, "closed_form")
    assert not support.ok and "\n" not in support.reason
    return support.reason


def test_refusals_name_what_does_not_fit():
    """A 3-D chain, a third joint, a tilted axis, an inertia without the axis as a principal axis, a prismatic
    joint, a link without mass properties and an unknown method are refused with a one-line reason."""
    shoulder, elbow = spong_arm().joints
    lifted = Joint("elbow", "revolute", elbow.axis, np.array([1.0, 0.0, 0.2]), elbow.origin_rotation, link=elbow.link)
    assert "the origin of joint 'elbow' is off the plane" in _refusal(Chain("3d", (shoulder, lifted)))
    assert "3 joints" in _refusal(Chain("three", (shoulder, elbow, elbow)))
    tilted = Joint("elbow", "revolute", np.array([0.0, 0.1, 1.0]), elbow.origin_xyz, elbow.origin_rotation,
                   link=elbow.link)
    assert "the axis of joint 'elbow' is not parallel" in _refusal(Chain("tilted", (shoulder, tilted)))
    skew = _link(2.0, (0.25, 0, 0), [[0.02, 0, 0.001], [0, 0.04, 0], [0.001, 0, 0.05]])
    skewed = Joint("elbow", "revolute", elbow.axis, elbow.origin_xyz, elbow.origin_rotation, link=skew)
    assert "not a principal axis of the inertia of joint 'elbow'" in _refusal(Chain("skew", (shoulder, skewed)))
    slider = Joint("elbow", "prismatic", elbow.axis, elbow.origin_xyz, elbow.origin_rotation, link=elbow.link)
    assert "'elbow' is prismatic" in _refusal(Chain("slider", (shoulder, slider)))
    bare = Joint("elbow", "revolute", elbow.axis, elbow.origin_xyz, elbow.origin_rotation)
    assert "declares no mass properties" in _refusal(Chain("bare", (shoulder, bare)))
    assert ENGINE.joint_dynamics_methods() == ("closed_form",)
    assert "no joint-dynamics method 'recursive'" in ENGINE.supports_joint_dynamics(spong_arm(), "recursive").reason
