"""Joint motion on Pinocchio's dynamics (issue #28): the harness's fixed-step integrators and the tight DOP853
reference (:mod:`references.pinocchio.joint_motion`).

Expected values come from closed forms (a physical pendulum's period, a damped or driven joint, the lecture arm's
mass matrix and end effector, the Euler steps under constant acceleration), from physical identities (energy
conservation, observed orders of convergence over a dt ladder against DOP853) or from core's forward kinematics.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import simparity
from simparity.core.kinematics import forward_kinematics
from simparity.core.model.engine import SCHEME_KINDS
from simparity.core.model.errors import NotBatchedError
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pinocchio.joint_dynamics import chain_model

ENGINE = PinocchioEngine()
FIXED_STEP = ("explicit_euler", "semi_implicit_euler", "rk4")

RK4_ORDER = (3.7, 4.3)
"""Observed order of RK4 between successive halvings of dt (0.04 to 0.005 s over 0.4 s); measured 3.95 to 3.99
(the asymptotic regime is reached from above)."""

EULER_ORDER = (0.9, 1.1)
"""Observed order of both Euler steps (dt 4 to 1 ms over 0.4 s); measured 0.985 to 1.002."""

FLOOR_MAX = 1e-9
"""[rad, rad/s] max |dop853 - dop853_coarse| over 1 s of the lecture arm: the coarse solve's tolerance 1e-11
accumulated over its steps; measured 6e-11 in q, 5e-10 in qdot."""

FLOOR_MIN = 1e-14
"""The two solves must differ (else the runner's error floor measures nothing): measured 6e-11."""

ENERGY_RTOL = 5e-12
"""max |E(t) - E(0)| over 1 s of the undamped lecture arm under gravity, relative to its largest kinetic energy:
DOP853 at 1e-13 (measured 8e-13)."""

PERIOD_RTOL = 2e-7
"""A physical pendulum's period at amplitude 1e-3 rad against 2 pi / omega_0: the amplitude's own correction is
theta^2 / 16 = 6.25e-8 (measured 6.25e-8), DOP853's phase error ~1e-10."""

CLOSED_FORM_RTOL = 1e-10
"""A damped or driven single joint against its closed form, DOP853 at 1e-13 (rounding of exp and of the
accumulated sums; measured <= 8e-13)."""

EXACT_RTOL = 1e-12
"""Steps that are exact in exact arithmetic (constant acceleration, free spin), over <= 1000 steps of float64."""

INITIAL_ACCELERATION_RTOL = 1e-5
"""qddot at rest from 2 (q(t) - q0) / t^2 at t = 1 ms: the t^3 term vanishes at rest (dM/dt = 0, h = 0 to second
order), the t^4 term leaves (omega t)^2 ~ 1e-6 (measured 1.0e-6)."""

SPIN_AGREEMENT = 1e-9
"""[rad] RK4 at dt = 1 ms against DOP853 on a pendulum spinning over the top for 1 s, 15 rad (RK4's error ~ dt^4
times the motion's fourth derivative; measured 1e-11)."""

FK_ATOL = 1e-12
"""[m] Pinocchio's end effector against core's forward kinematics or the hand formula: float64 through <= 7 joints."""

GRAVITY = 9.81


def lecture_arm() -> Chain:
    """The lecture's planar 2-link arm (axes +z; boxes 1.0 and 0.8 m, 2 and 1.5 kg, centres at mid-length)."""
    return simparity.load_scene("lecture-2link-dynamics").chain


def pendulum(mass: float = 1.7, com_xyz=(0.45, 0.0, 0.0), inertia_zz: float = 0.06, damping: float = 0.0,
             armature: float = 0.0, limits: tuple[float, float] = (-np.inf, np.inf), yaw: float = 0.7) -> Chain:
    """One revolute joint about the joint frame's z axis (given non-unit), the frame at (0.1, 0.2, 0.3) and turned
    by ``yaw`` about z; the centre of mass at ``com_xyz``, inertia diag(0.01, 0.02, inertia_zz) about it; the end
    effector "tip" at (0.8, 0, 0) in the link. Unlimited: a continuous joint in Pinocchio."""
    link = LinkInertia(mass, np.asarray(com_xyz, dtype=float), np.diag([0.01, 0.02, inertia_zz]))
    joint = Joint("hinge", "revolute", np.array([0.0, 0.0, 3.0]), np.array([0.1, 0.2, 0.3]),
                  Rotation.from_euler("z", yaw).as_matrix(), *limits, link=link, damping=damping, armature=armature)
    return Chain("pendulum", (joint,), "tip", np.array([0.8, 0.0, 0.0]))


def scene(chain: Chain, q0, qdot0, duration: float, dts: tuple[float, ...], gravity=(0.0, -GRAVITY, 0.0),
          torque=None) -> JointMotionScene:
    """A joint-motion scene of ``chain`` (gravity (3,) [m/s^2] or None)."""
    n = chain.n_joints
    return JointMotionScene(name="test", description="test", reference="pinocchio:dop853", chain=chain,
                            gravity_world=None if gravity is None else np.asarray(gravity, dtype=float),
                            q0=np.asarray(q0, dtype=float), qdot0=np.asarray(qdot0, dtype=float),
                            torque=np.zeros(n) if torque is None else np.asarray(torque, dtype=float),
                            duration=duration, dts=dts)


def run(motion: JointMotionScene, integrator: str, dt: float):
    """The trajectory of ``integrator`` at ``dt`` over the scene's duration."""
    return ENGINE.build_joint_motion(motion, integrator, dt).run(motion.n_steps(dt))


def test_the_engine_declares_its_joint_motion_integrators():
    """Names fixed by the runner and the tolerances; every scheme a kind of SCHEME_KINDS."""
    motion = scene(lecture_arm(), [0.3, 0.5], [0.0, 0.0], 0.1, (0.01,))
    assert ENGINE.joint_motion_integrators() == FIXED_STEP + ("dop853", "dop853_coarse")
    expected = {"explicit_euler": ("explicit_euler", 1, 1), "semi_implicit_euler": ("semi_implicit_euler", 1, 1),
                "rk4": ("rk4", 4, 4), "dop853": ("adaptive", None, None), "dop853_coarse": ("adaptive", None, None)}
    for integrator, (kind, order, stages) in expected.items():
        assert kind in SCHEME_KINDS
        assert ENGINE.scheme(integrator, motion) == kind
        assert (ENGINE.theoretical_order(integrator), ENGINE.stages(integrator)) == (order, stages)
        assert ENGINE.supports_joint_motion(motion, integrator).ok
    assert not ENGINE.supports_joint_motion(motion, "euler").ok
    with pytest.raises(NotBatchedError):
        ENGINE.build_joint_motion(motion, "rk4", 0.01).batched(10)


@pytest.mark.parametrize("integrator, dts, bounds", [("rk4", (0.04, 0.02, 0.01, 0.005), RK4_ORDER),
                                                     ("semi_implicit_euler", (0.004, 0.002, 0.001), EULER_ORDER),
                                                     ("explicit_euler", (0.004, 0.002, 0.001), EULER_ORDER)])
def test_observed_order_against_dop853(integrator, dts, bounds):
    """The lecture arm falling in its plane for 0.4 s: the error at the end against DOP853 halves as dt^order."""
    motion = scene(lecture_arm(), [0.3, 0.5], [0.0, 0.0], 0.4, dts)
    reference = run(motion, "dop853", dts[0]).q[-1]
    errors = np.array([np.abs(run(motion, integrator, dt).q[-1] - reference).max() for dt in dts])
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders >= bounds[0]) & (orders <= bounds[1])), orders


def test_the_reference_and_its_coarse_solve_and_energy():
    """dop853 and dop853_coarse differ by their tolerances, not more; dop853 conserves the undamped arm's energy."""
    motion = scene(lecture_arm(), [0.3, 0.5], [0.0, 0.0], 1.0, (0.01,))
    tight, coarse = run(motion, "dop853", 0.01), run(motion, "dop853_coarse", 0.01)
    floor = max(np.abs(tight.q - coarse.q).max(), np.abs(tight.qdot - coarse.qdot).max())
    assert FLOOR_MIN < floor <= FLOOR_MAX
    kinetic, potential = ENGINE.build_joint_motion(motion, "dop853", 0.01).energy(tight.q[:, 0], tight.qdot[:, 0])
    total = kinetic + potential
    assert np.abs(total - total[0]).max() <= ENERGY_RTOL * kinetic.max()
    assert kinetic.max() > 1.0  # [J] the arm really fell


def test_a_physical_pendulum_swings_at_its_closed_form_period():
    """omega_0^2 = m g d / (I_c + m d^2); after 2 pi / omega_0 the phase of (q - q_eq, -qdot / omega_0) is back
    to 0. The link's x axis hangs along -y at q_eq = -pi/2 - yaw."""
    mass, d, i_c, yaw, amplitude = 1.7, 0.45, 0.06, 0.7, 1e-3
    omega = np.sqrt(mass * GRAVITY * d / (i_c + mass * d**2))
    period = 2 * np.pi / omega
    hanging = -np.pi / 2 - yaw
    motion = scene(pendulum(mass, (d, 0.0, 0.0), i_c, yaw=yaw), [hanging + amplitude], [0.0], period,
                   (period / 200,))
    trajectory = run(motion, "dop853", period / 200)
    phase = np.arctan2(-trajectory.qdot[-1, 0, 0] / omega, trajectory.q[-1, 0, 0] - hanging)
    assert abs(phase) / (2 * np.pi) <= PERIOD_RTOL
    assert trajectory.q[100, 0, 0] - hanging == pytest.approx(-amplitude, rel=PERIOD_RTOL)  # the other side


def test_damping_and_armature_slow_a_free_joint_exponentially():
    """No gravity: I qddot = -b qdot, so qdot = qdot0 exp(-b t / I) and q = q0 + qdot0 I / b (1 - exp(-b t / I)),
    I = I_zz + m (dx^2 + dy^2) + armature about the axis."""
    mass, com, i_zz, b, armature, qdot0 = 1.2, (0.3, -0.2, 0.1), 0.05, 0.3, 0.04, 2.0
    inertia = i_zz + mass * (com[0] ** 2 + com[1] ** 2) + armature
    motion = scene(pendulum(mass, com, i_zz, damping=b, armature=armature), [0.2], [qdot0], 2.0, (0.01,),
                   gravity=None)
    trajectory = run(motion, "dop853", 0.01)
    decay = np.exp(-b * trajectory.times / inertia)
    np.testing.assert_allclose(trajectory.qdot[:, 0, 0], qdot0 * decay, rtol=CLOSED_FORM_RTOL)
    np.testing.assert_allclose(trajectory.q[:, 0, 0], 0.2 + qdot0 * inertia / b * (1 - decay),
                               rtol=CLOSED_FORM_RTOL)


def test_the_applied_torque_drives_a_joint_and_each_step_is_as_defined():
    """Constant torque, no gravity or damping: qddot = tau / I. After k steps RK4 and DOP853 are exact; explicit
    Euler (q with the old qdot) lags by a t dt / 2, semi-implicit Euler (q with the new qdot) leads by as much."""
    mass, com, i_zz, tau, dt = 1.2, (0.3, -0.2, 0.1), 0.05, 0.7, 0.01
    acceleration = tau / (i_zz + mass * (com[0] ** 2 + com[1] ** 2))
    motion = scene(pendulum(mass, com, i_zz), [0.2], [0.5], 1.0, (dt,), gravity=None, torque=[tau])
    shift = {"explicit_euler": -0.5, "semi_implicit_euler": 0.5, "rk4": 0.0, "dop853": 0.0}
    for integrator, sign in shift.items():
        trajectory = run(motion, integrator, dt)
        t = trajectory.times
        expected = 0.2 + 0.5 * t + 0.5 * acceleration * t**2 + sign * acceleration * t * dt
        np.testing.assert_allclose(trajectory.q[:, 0, 0], expected, rtol=EXACT_RTOL, err_msg=integrator)
        np.testing.assert_allclose(trajectory.qdot[:, 0, 0], 0.5 + acceleration * t, rtol=EXACT_RTOL,
                                   err_msg=integrator)


def test_each_joint_gets_its_own_torque():
    """The lecture arm at rest, no gravity, tau = (1.5, -0.4): qddot(0) = M^-1 tau with the closed-form M of the
    planar elbow arm, read from 2 (q(t) - q0) / t^2."""
    m1, m2, l1, lc1, lc2, i1, i2 = 2.0, 1.5, 1.0, 0.5, 0.4, 0.16833333333333333, 0.0808
    q0, tau, t = np.array([0.3, 0.5]), np.array([1.5, -0.4]), 1e-3
    c2 = np.cos(q0[1])
    m12 = m2 * (lc2**2 + l1 * lc2 * c2) + i2
    mass_matrix = np.array([[m1 * lc1**2 + i1 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + i2, m12],
                            [m12, m2 * lc2**2 + i2]])
    motion = scene(lecture_arm(), q0, [0.0, 0.0], t, (t,), gravity=None, torque=tau)
    trajectory = run(motion, "dop853", t)
    np.testing.assert_allclose(2 * (trajectory.q[-1, 0] - q0) / t**2, np.linalg.solve(mass_matrix, tau),
                               rtol=INITIAL_ACCELERATION_RTOL)


def test_a_spinning_continuous_joint_has_a_continuous_angle():
    """An unlimited joint is continuous in Pinocchio (nq = 2); spinning freely at 10 rad/s its angle is
    q0 + 10 t well past pi for every integrator, and spinning over the top under gravity RK4 follows DOP853."""
    chain = pendulum()
    assert chain_model(chain, None).model.nq == 2
    free = scene(chain, [3.0], [10.0], 1.0, (0.01,), gravity=None)
    for integrator in FIXED_STEP + ("dop853",):
        trajectory = run(free, integrator, 0.01)
        np.testing.assert_allclose(trajectory.q[:, 0, 0], 3.0 + 10.0 * trajectory.times, rtol=EXACT_RTOL,
                                   err_msg=integrator)
    spinning = scene(chain, [0.0], [15.0], 1.0, (0.001,))
    rk4, tight = run(spinning, "rk4", 0.001), run(spinning, "dop853", 0.001)
    assert np.all(np.diff(tight.q[:, 0, 0]) > 0) and tight.q[-1, 0, 0] > 2 * np.pi
    assert np.abs(rk4.q - tight.q).max() <= SPIN_AGREEMENT


@pytest.mark.parametrize("integrator", ["rk4", "dop853"])
def test_copies_move_as_each_alone(integrator):
    """Three copies of the lecture arm from different states: each copy's trajectory is the one it has alone."""
    q0 = np.array([[0.3, 0.5], [-1.0, 2.0], [2.5, -0.3]])
    qdot0 = np.array([[0.0, 0.0], [1.0, -2.0], [0.5, 0.5]])
    together = run(scene(lecture_arm(), q0, qdot0, 0.3, (0.01,)), integrator, 0.01)
    for k in range(3):
        alone = run(scene(lecture_arm(), q0[k:k + 1], qdot0[k:k + 1], 0.3, (0.01,)), integrator, 0.01)
        np.testing.assert_array_equal(together.q[:, k], alone.q[:, 0])
        np.testing.assert_array_equal(together.qdot[:, k], alone.qdot[:, 0])


def test_engine_defaults_gravity_and_joint_limits():
    """Pinocchio's default gravity (0, 0, -9.81) is replaced: with None a displaced pendulum in a vertical plane
    stays at rest; aba never applies joint limits: a limited joint passes its limit."""
    chain = replace(pendulum(), joints=(replace(pendulum().joints[0], axis=np.array([0.0, 1.0, 0.0])),))
    still = run(scene(chain, [0.4], [0.0], 0.5, (0.01,), gravity=None), "rk4", 0.01)
    np.testing.assert_array_equal(still.q, 0.4)
    limited = pendulum(limits=(-0.5, 0.5))
    assert chain_model(limited, None).model.nq == 1
    passing = run(scene(limited, [0.0], [2.0], 1.0, (0.01,), gravity=None), "rk4", 0.01)
    assert passing.q[-1, 0, 0] == pytest.approx(2.0, rel=EXACT_RTOL)


def test_energy_and_end_effector_by_hand():
    """The pendulum's centre of mass c = o + R_z(yaw + q) com: V = -m g . c, T = 1/2 (I_zz + m |com_xy|^2 + a)
    qdot^2; the tip at o + R_z(yaw + q) (0.8, 0, 0). Without gravity V = 0."""
    mass, com, i_zz, armature, yaw = 1.2, np.array([0.3, -0.2, 0.1]), 0.05, 0.04, 0.7
    gravity = np.array([0.4, -GRAVITY, 0.3])
    chain = pendulum(mass, com, i_zz, armature=armature, yaw=yaw)
    q, qdot = np.array([[0.0], [1.1], [-2.5]]), np.array([[0.5], [-1.0], [3.0]])
    simulation = ENGINE.build_joint_motion(scene(chain, [0.0], [0.0], 0.1, (0.01,), gravity=gravity), "rk4", 0.01)
    turn = Rotation.from_euler("z", yaw + q).as_matrix()
    origin = np.array([0.1, 0.2, 0.3])
    kinetic, potential = simulation.energy(q, qdot)
    np.testing.assert_allclose(potential, -mass * (origin + turn @ com) @ gravity, rtol=EXACT_RTOL)
    np.testing.assert_allclose(kinetic, 0.5 * (i_zz + mass * (com[0] ** 2 + com[1] ** 2) + armature) * qdot[:, 0] ** 2,
                               rtol=EXACT_RTOL)
    np.testing.assert_allclose(simulation.end_effector_world(q), origin + turn @ np.array([0.8, 0.0, 0.0]),
                               atol=FK_ATOL)
    weightless = ENGINE.build_joint_motion(scene(chain, [0.0], [0.0], 0.1, (0.01,), gravity=None), "rk4", 0.01)
    np.testing.assert_array_equal(weightless.energy(q, qdot)[1], 0.0)


def test_end_effector_of_a_real_arm_against_core():
    """The iiwa's end effector in its base frame, Pinocchio's frame placement against core's forward kinematics."""
    chain = simparity.load_scene("iiwa-dynamics").chain
    q = np.random.default_rng(28).uniform(-2.0, 2.0, size=(5, chain.n_joints))
    motion = scene(chain, q[0], np.zeros(chain.n_joints), 0.1, (0.01,), gravity=(0.0, 0.0, -GRAVITY))
    simulation = ENGINE.build_joint_motion(motion, "rk4", 0.01)
    np.testing.assert_allclose(simulation.end_effector_world(q), forward_kinematics(chain, q).position_world[:, -1],
                               atol=FK_ATOL)
