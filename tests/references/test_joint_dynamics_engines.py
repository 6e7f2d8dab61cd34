"""Joint-space dynamics of a chain in MuJoCo and Pinocchio (issue #27): each engine's own identities, each default
that has bitten users pinned, and the two engines against each other on the crafted arm and real arms.

Expected values come from the other engine (two independent URDF parsers and recursions), from closed forms (a
pendulum by hand), or from identities between an engine's functions (never from its code path being re-run).
"""

from __future__ import annotations

import os
from dataclasses import replace
from importlib.metadata import distribution

import mujoco
import numpy as np
import pinocchio as pin
import pybullet_data
import pytest

from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia, sample_configurations
from simparity.core.urdf import chain_from_urdf
from simparity.references.common.dynamics_urdf import dynamics_urdf
from simparity.references.common.urdf_export import original_without_geometry
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.pinocchio.adapter import PinocchioEngine

CROSS_ENGINE_RTOL = 1e-12
"""max|A - B| / max|B| per state between MuJoCo and Pinocchio: both evaluate the same rigid-body model in float64
through <= 7 links; measured over 50 states per arm <= 4e-14 (forward dynamics: M's condition number times eps),
<= 3e-15 for M, h, tau and the kinetic energy."""

IDENTITY_RTOL = 1e-12
"""An engine's own identities (inverse vs M qddot + h + D qdot, forward after inverse, kinetic energy vs
1/2 qdot^T M qdot): float64 recursions and one solve of M; measured <= 5e-14 on the crafted arm (Pinocchio's aba
after rnea; 2e-13 on xarm7 over 50 states)."""

CLOSED_FORM_RTOL = 1e-14
"""A one-link pendulum against its hand-computed M and g: a handful of float64 operations."""

ROBOTS_DIR = str(distribution("example-robot-data").locate_file("cmeel.prefix/share/example-robot-data/robots"))
CRAFTED = os.path.join(os.path.dirname(__file__), "..", "..", "comparisons", "scenes", "urdf", "crafted-arm.urdf")
CRAFTED_DAMPING = {"j1": 0.3, "j2": 1.5}  # the file's <dynamics damping>
CRAFTED_ARMATURE = {"j1": 0.02, "j2": 0.5, "j3": 0.003}  # declared as a TOML scene would (the file has none)
GRAVITY = np.array([0.4, -0.3, -9.81])  # [m/s^2] not the engines' default (0, 0, -9.81)
ENGINES = (MujocoEngine(), PinocchioEngine())

STAND_IN = LinkInertia(1.0, np.zeros(3), np.eye(3))
"""Until core's parser fills ``Joint.link`` from the file, a stand-in marks the chain as having mass properties;
no adapter reads it for a chain with a file (:func:`test_file_chain_mass_properties_come_from_the_file`)."""


def _file_chain(path: str, base: str | None, tip: str | None, held: tuple[str, ...], damping=None, armature=None,
                link: LinkInertia = STAND_IN) -> Chain:
    """The chain core reads from ``path`` with its held joints, each link's stand-in mass properties, and the
    joints' damping and armature (name -> value)."""
    chain = chain_from_urdf(path, base, tip)
    joints = tuple(replace(j, link=link, damping=(damping or {}).get(j.name, 0.0),
                           armature=(armature or {}).get(j.name, 0.0)) for j in chain.joints)
    return replace(chain, joints=joints, held_joints=held)


def crafted(armature=None) -> Chain:
    """The crafted arm to its flange, the finger held, the file's damping; with ``armature`` (name -> value)."""
    return _file_chain(CRAFTED, None, "flange", ("finger",), CRAFTED_DAMPING, armature)


ARMS = {  # name -> chain; the real arms' damping and armature are 0 (the files' <dynamics> is not read yet)
    "crafted": crafted(CRAFTED_ARMATURE),
    "iiwa": _file_chain(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf"), None, None, ()),
    "panda-tcp": _file_chain(f"{ROBOTS_DIR}/panda_description/urdf/panda.urdf", "panda_link0", "panda_hand_tcp",
                             ("panda_finger_joint1", "panda_finger_joint2")),
    "panda-link8": _file_chain(f"{ROBOTS_DIR}/panda_description/urdf/panda.urdf", "panda_link0", "panda_link8",
                               ("panda_finger_joint1", "panda_finger_joint2")),
    "ur5": _file_chain(f"{ROBOTS_DIR}/ur_description/urdf/ur5_robot.urdf", "base_link", "tool0", ()),
    "xarm7": _file_chain(f"{ROBOTS_DIR}/xarm_description/urdf/xarm7.urdf", None, None, ()),  # nobody tuned to it
}


def states(chain: Chain, count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(q, qdot, qddot, tau), each (count, n): q within the limits, the rest uniform in [-1, 1]."""
    rng = np.random.default_rng(seed)
    q = sample_configurations(chain, count, rng)
    qd, qdd, tau = (rng.uniform(-1.0, 1.0, size=q.shape) for _ in range(3))
    return q, qd, qdd, tau


def relative(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """max|a - b| / max|b| per state (leading axis)."""
    axes = tuple(range(1, np.ndim(b)))
    return np.max(np.abs(a - b), axis=axes) / np.max(np.abs(b), axis=axes)


def build(engine, chain: Chain, gravity=GRAVITY):
    assert engine.supports_joint_dynamics(chain, "recursive").ok
    return engine.build_joint_dynamics(chain, "recursive", gravity)


# -- each engine's own identities on the crafted arm (damping, armature, held finger, rotated inertials) -------

@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_identities_on_the_crafted_arm(engine):
    """RNEA(q, 0, 0) = g(q); RNEA(q, 0, e_i) - g = M e_i; tau = M qddot + h + D qdot; forward(inverse(qddot)) =
    qddot; M symmetric positive definite; 1/2 qdot^T M qdot = kinetic energy + 1/2 sum a_i qdot_i^2."""
    chain = ARMS["crafted"]
    model = build(engine, chain)
    q, qd, qdd, _ = states(chain, 6, seed=1)
    zero = np.zeros_like(q)
    mass = model.mass_matrix(q)
    gravity = model.bias_forces(q, zero)
    assert np.all(relative(model.inverse_dynamics(q, zero, zero), gravity) <= IDENTITY_RTOL)
    for i in range(chain.n_joints):
        unit = np.zeros_like(q)
        unit[:, i] = 1.0
        assert np.all(relative(model.inverse_dynamics(q, zero, unit) - gravity, mass[:, :, i]) <= IDENTITY_RTOL)
    damping = np.array([j.damping for j in chain.joints])
    tau = model.inverse_dynamics(q, qd, qdd)
    expected = np.einsum("bij,bj->bi", mass, qdd) + model.bias_forces(q, qd) + damping * qd
    assert np.all(relative(tau, expected) <= IDENTITY_RTOL)
    assert np.all(relative(model.forward_dynamics(q, qd, tau), qdd) <= IDENTITY_RTOL)
    np.testing.assert_array_equal(mass, np.swapaxes(mass, 1, 2))
    assert np.all(np.linalg.eigvalsh(mass) > 0)
    armature = np.array([j.armature for j in chain.joints])
    quadratic = 0.5 * np.einsum("bi,bij,bj->b", qd, mass, qd)
    kinetic = model.link_kinetic_energy(q, qd) + 0.5 * np.sum(armature * qd**2, axis=1)
    assert np.all(np.abs(kinetic - quadratic) <= IDENTITY_RTOL * quadratic)


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_armature_adds_to_the_diagonal_of_m_only(engine):
    """MuJoCo's mj_crb and Pinocchio 4.1's crba add the armature to M's diagonal (and aba and rnea use it:
    test_identities_on_the_crafted_arm); the link kinetic energy does not see it."""
    q, qd, _, _ = states(crafted(), 4, seed=2)
    plain, geared = build(engine, crafted()), build(engine, crafted(CRAFTED_ARMATURE))
    added = geared.mass_matrix(q) - plain.mass_matrix(q)
    expected = np.broadcast_to(np.diag([CRAFTED_ARMATURE[j] for j in ("j1", "j2", "j3")]), added.shape)
    assert np.all(relative(added, expected) <= IDENTITY_RTOL)
    np.testing.assert_allclose(geared.link_kinetic_energy(q, qd), plain.link_kinetic_energy(q, qd), rtol=IDENTITY_RTOL)


# -- gravity: exactly the scene's -----------------------------------------------------------------------------

@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_gravity_is_the_scenes_and_holding_it_gives_no_acceleration(engine):
    """tau = g(q) gives qddot = 0; gravity along +x and -x give opposite g(q); no gravity gives g = 0 (the engines'
    default is (0, 0, -9.81))."""
    chain = ARMS["crafted"]
    q, _, _, _ = states(chain, 5, seed=3)
    zero = np.zeros_like(q)
    model = build(engine, chain)
    hold = model.bias_forces(q, zero)
    falling = model.forward_dynamics(q, zero, zero)
    assert np.max(np.abs(model.forward_dynamics(q, zero, hold))) <= IDENTITY_RTOL * np.max(np.abs(falling))
    plus_x, minus_x = (build(engine, chain, np.array([s * 9.81, 0.0, 0.0])).bias_forces(q, zero) for s in (1, -1))
    assert np.all(np.abs(plus_x) > 0)
    np.testing.assert_array_equal(plus_x, -minus_x)
    np.testing.assert_array_equal(build(engine, chain, None).bias_forces(q, zero), zero)


PENDULUM_INERTIA = np.diag([0.01, 0.02, 0.03])
"""[kg m^2] about the pendulum's centre of mass (MuJoCo refuses a moving body without rotational inertia)."""


def pendulum(mass: float, length: float, armature: float = 0.0) -> Chain:
    """A declared one-link chain (no file): a revolute joint about +y at the origin, the centre of mass at
    (length, 0, 0), :data:`PENDULUM_INERTIA` about it."""
    link = LinkInertia(mass, np.array([length, 0.0, 0.0]), PENDULUM_INERTIA)
    joint = Joint("hinge", "revolute", np.array([0.0, 1.0, 0.0]), np.zeros(3), np.eye(3), -3.0, 3.0, link=link,
                  armature=armature)
    return Chain("pendulum", (joint,), "tip", np.array([length, 0.0, 0.0]))


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_pendulum_against_hand_computation(engine):
    """The centre of mass sits at (L cos q, 0, -L sin q): M = m L^2 + I_yy + a; V = -m (g . x) gives
    g(q) = m L (gx sin q + gz cos q) for gravity (gx, 0, gz): under -z the arm held horizontal needs -m 9.81 L,
    under +x it needs m 9.81 L sin q."""
    m, length, armature = 1.3, 0.7, 0.05
    chain = pendulum(m, length, armature)
    q = np.array([[0.0], [0.4], [np.pi / 2], [-1.1]])
    for gravity in ([0.0, 0.0, -9.81], [9.81, 0.0, 0.0], [-9.81, 0.0, 0.0]):
        model = build(engine, chain, np.array(gravity))
        expected_g = m * length * (gravity[0] * np.sin(q) + gravity[2] * np.cos(q))
        np.testing.assert_allclose(model.bias_forces(q, np.zeros_like(q)), expected_g, rtol=CLOSED_FORM_RTOL,
                                   atol=CLOSED_FORM_RTOL * m * length * 9.81)
        expected_m = m * length**2 + PENDULUM_INERTIA[1, 1] + armature
        np.testing.assert_allclose(model.mass_matrix(q)[:, 0, 0], expected_m, rtol=CLOSED_FORM_RTOL)


# -- MuJoCo's defaults ------------------------------------------------------------------------------------------

def _mujoco(chain: Chain, gravity=GRAVITY):
    return build(ENGINES[0], chain, gravity)


def test_mujoco_passive_forces_are_the_chains_only():
    """dof_damping and dof_armature are the chain's; frictionloss, stiffness and nonlinear damping are 0, although
    MuJoCo's importer reads the file's <dynamics friction=0.7> as frictionloss and its damping (shown on the
    file itself)."""
    model = _mujoco(crafted(CRAFTED_ARMATURE)).model
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in model.dof_jntid]
    np.testing.assert_array_equal(model.dof_damping, [CRAFTED_DAMPING.get(n, 0.0) for n in names])
    np.testing.assert_array_equal(model.dof_armature, [CRAFTED_ARMATURE[n] for n in names])
    for zero in (model.dof_frictionloss, model.dof_dampingpoly, model.jnt_stiffness, model.jnt_stiffnesspoly):
        assert not np.any(zero)
    spec = mujoco.MjSpec.from_string(original_without_geometry(CRAFTED))
    spec.compiler.fusestatic = False
    raw = spec.compile()
    j1 = raw.jnt_dofadr[mujoco.mj_name2id(raw, mujoco.mjtObj.mjOBJ_JOINT, "j1")]
    assert (raw.dof_frictionloss[j1], raw.dof_damping[j1]) == (0.7, 0.3)


def test_mujoco_masses_are_the_files_and_gravity_the_scenes():
    """No mass bounded (the kinematics adapter's MIN_MASS is not applied): the massless base and flange weigh 0,
    the total is the file's (base subtree, finger included); opt.gravity is the scene's; constraints disabled."""
    model = _mujoco(crafted()).model
    mass = {model.body(b).name: model.body_mass[b] for b in range(model.nbody)}
    assert mass["base_link"] == mass["flange"] == 0.0
    assert mass["finger_link"] == 0.15 and mass["payload"] == 0.6
    assert mass["link0"] == 0.0  # welded to the base by a fixed joint: it never moves, not part of the model
    assert sum(mass.values()) == pytest.approx(1.7 + 1.1 + 0.8 + 0.6 + 0.15, rel=1e-15)
    np.testing.assert_array_equal(model.opt.gravity, GRAVITY)
    assert model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONSTRAINT


def test_mujoco_joint_limits_do_not_act():
    """Outside j1's limit (2.5 rad) MuJoCo's forward and inverse dynamics still agree with Pinocchio's (which has
    no limits); with constraints enabled, MuJoCo's limit force would change qacc."""
    chain = crafted()
    q = np.array([[3.0, 0.35, 4.0]])  # j1 and j2 beyond their upper limits, j3 (continuous) beyond pi
    qd, tau = np.array([[0.5, -0.2, 1.0]]), np.array([[0.3, -2.0, 0.05]])
    mj, pn = _mujoco(chain), build(ENGINES[1], chain)
    assert np.all(relative(mj.forward_dynamics(q, qd, tau), pn.forward_dynamics(q, qd, tau)) <= CROSS_ENGINE_RTOL)
    qdd = pn.forward_dynamics(q, qd, tau)
    assert np.all(relative(mj.inverse_dynamics(q, qd, qdd), tau) <= CROSS_ENGINE_RTOL)
    mj.model.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    assert relative(mj.forward_dynamics(q, qd, tau), qdd)[0] > 1e-3


def test_mujoco_fusestatic_would_not_change_m():
    """fusestatic is off (fixed links stay bodies); MuJoCo fusing them gives the same M to rounding."""
    chain = crafted()
    q, _, _, _ = states(chain, 3, seed=4)
    spec = mujoco.MjSpec.from_string(dynamics_urdf(chain))
    spec.compiler.fusestatic = True
    spec.compiler.boundmass = spec.compiler.boundinertia = 0.0
    fused = spec.compile()
    assert fused.nbody < _mujoco(chain).model.nbody
    data, full = mujoco.MjData(fused), np.empty((3, 3))
    for row, adapter in zip(q, _mujoco(chain).mass_matrix(q)):
        data.qpos[:] = row
        mujoco.mj_forward(fused, data)
        mujoco.mj_fullM(fused, data, full)
        assert relative(full[None], adapter[None])[0] <= CROSS_ENGINE_RTOL


def test_mujoco_refuses_a_moving_body_without_mass_and_pinocchio_takes_it():
    """MuJoCo will not compile a moving body with no mass of its own nor welded to it (mjMINVAL); bounding it would
    change the model, so the chain is not supported, with MuJoCo's reason. Pinocchio's M is the closed form."""
    massless = Joint("a", "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.eye(3), -3.0, 3.0,
                     link=LinkInertia.massless())
    carried = pendulum(2.0, 0.5).joints[0]
    chain = Chain("massless-first", (massless, replace(carried, origin_xyz=np.array([0.3, 0.0, 0.0]))), "tip")
    assert not chain.dynamics_problem()
    support = ENGINES[0].supports_joint_dynamics(chain, "recursive")
    assert not support.ok and "mjMINVAL" in support.reason
    mass = build(ENGINES[1], chain, None).mass_matrix(np.zeros((1, 2)))[0]
    # joint a about z carries the centre of mass at (0.8, 0, 0), joint b about y has it at 0.5 in x; the
    # inertia is diagonal, and the two centre-of-mass velocities (along y and -z) are orthogonal
    inertia = PENDULUM_INERTIA
    expected = [[2.0 * 0.8**2 + inertia[2, 2], 0.0], [0.0, 2.0 * 0.5**2 + inertia[1, 1]]]
    np.testing.assert_allclose(mass, expected, rtol=CLOSED_FORM_RTOL, atol=CLOSED_FORM_RTOL)


# -- Pinocchio's defaults ---------------------------------------------------------------------------------------

def test_pinocchio_model_has_no_file_damping_or_friction_and_the_scenes_gravity():
    """The file's <dynamics damping=0.3 friction=0.7> is stripped (model.damping, model.friction 0: rnea and aba
    ignore them; the adapter adds D qdot); armature is the chain's; gravity the scene's."""
    chain = crafted(CRAFTED_ARMATURE)
    model = build(ENGINES[1], chain).model
    assert not np.any(model.damping) and not np.any(model.friction)
    names = [model.names[i] for i in range(1, model.njoints)]
    np.testing.assert_array_equal(model.armature, [CRAFTED_ARMATURE[n] for n in names])
    np.testing.assert_array_equal(model.gravity.linear, GRAVITY)
    raw = pin.buildModelFromXML(original_without_geometry(CRAFTED))
    assert (raw.damping[0], raw.friction[0]) == (0.3, 0.7)


# -- both engines ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_file_chain_mass_properties_come_from_the_file(engine):
    """A chain with a file: the chain's own LinkInertia is never read (another stand-in changes nothing)."""
    chain = crafted()
    other = _file_chain(CRAFTED, None, "flange", ("finger",), CRAFTED_DAMPING,
                        link=LinkInertia(7.0, np.ones(3), 2 * np.eye(3)))
    q, qd, _, _ = states(chain, 3, seed=5)
    np.testing.assert_array_equal(build(engine, chain).mass_matrix(q), build(engine, other).mass_matrix(q))
    np.testing.assert_array_equal(build(engine, chain).bias_forces(q, qd), build(engine, other).bias_forces(q, qd))


@pytest.mark.parametrize("arm", ARMS)
def test_mujoco_and_pinocchio_agree(arm):
    """M, h, tau and qddot (and the link kinetic energy) of MuJoCo and Pinocchio at the same seeded states: two
    URDF parsers and two sets of recursions on the same file (the crafted arm's rotated, off-diagonal inertials,
    payload beyond the tip and held finger included)."""
    chain = ARMS[arm]
    q, qd, qdd, tau = states(chain, 5, seed=6)
    q[0, -1] = 4.0 if arm == "crafted" else q[0, -1]  # the continuous j3 beyond pi: (cos, sin) in Pinocchio
    mj, pn = (build(engine, chain) for engine in ENGINES)
    pairs = {
        "M": (mj.mass_matrix(q), pn.mass_matrix(q)),
        "h": (mj.bias_forces(q, qd), pn.bias_forces(q, qd)),
        "tau": (mj.inverse_dynamics(q, qd, qdd), pn.inverse_dynamics(q, qd, qdd)),
        "qddot": (mj.forward_dynamics(q, qd, tau), pn.forward_dynamics(q, qd, tau)),
        "kinetic energy": (mj.link_kinetic_energy(q, qd)[:, None], pn.link_kinetic_energy(q, qd)[:, None]),
    }
    for name, (a, b) in pairs.items():
        assert np.max(relative(a, b)) <= CROSS_ENGINE_RTOL, name


def test_declared_chain_gives_the_same_m_in_both():
    """A chain without a file (declared mass properties, written as URDF with the COM as inertial origin and the
    full tensor): MuJoCo's and Pinocchio's M, h and qddot agree."""
    rng = np.random.default_rng(7)
    joints = []
    for i, (kind, axis) in enumerate((("revolute", [0, 0, 1]), ("prismatic", [0.6, 0, 0.8]), ("revolute", [1, 1, 0]))):
        turn = pin.rpy.rpyToMatrix(*rng.uniform(-np.pi, np.pi, 3))  # principal moments obey A + B >= C
        inertia = turn @ np.diag(rng.uniform(0.01, 0.02, 3)) @ turn.T
        joints.append(Joint(f"j{i}", kind, np.array(axis, dtype=float), rng.uniform(-0.3, 0.3, 3),
                            pin.rpy.rpyToMatrix(*rng.uniform(-1, 1, 3)), -1.0, 1.0,
                            link=LinkInertia(rng.uniform(0.5, 2.0), rng.uniform(-0.1, 0.1, 3),
                                             inertia),
                            damping=rng.uniform(0, 1), armature=rng.uniform(0, 0.1)))
    chain = Chain("declared", tuple(joints), "tool", np.array([0.1, 0.0, 0.0]))
    q, qd, _, tau = states(chain, 4, seed=8)
    mj, pn = (build(engine, chain) for engine in ENGINES)
    assert np.all(relative(mj.mass_matrix(q), pn.mass_matrix(q)) <= CROSS_ENGINE_RTOL)
    assert np.all(relative(mj.bias_forces(q, qd), pn.bias_forces(q, qd)) <= CROSS_ENGINE_RTOL)
    assert np.all(relative(mj.forward_dynamics(q, qd, tau), pn.forward_dynamics(q, qd, tau)) <= CROSS_ENGINE_RTOL)


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_support(engine):
    """One method, "recursive"; a chain without mass properties is refused with Chain.dynamics_problem's reason."""
    assert engine.joint_dynamics_methods() == ("recursive",)
    assert not engine.supports_joint_dynamics(crafted(), "jacobian_sum").ok
    bare = replace(crafted(), joints=tuple(replace(j, link=None) for j in crafted().joints))
    support = engine.supports_joint_dynamics(bare, "recursive")
    assert not support.ok and support.reason == bare.dynamics_problem()
