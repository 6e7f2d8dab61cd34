"""A chain stepped through time by PyBullet (issue #28): the step it takes, its order, its energy, how joint damping
and applied torques reach it, copies stepped together, and each default that would change the motion.

Expected values come from the closed form of the lecture's planar 2-link arm (Spong, Hutchinson and Vidyasagar's
planar elbow manipulator, written here from the scene file's numbers), a DOP853 solve of that closed form, Pinocchio
(its own URDF parser), or physical identities (energy conservation, the observed order over a dt ladder).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

import simparity
from simparity.core.model.errors import SimparityError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.references.common.dynamics_urdf import dynamics_urdf
from simparity.references.pybullet.adapter import PybulletEngine
from simparity.references.pybullet.joint_dynamics import ChainBodies
from simparity.references.pybullet.quiet import pybullet

ROUNDING_RTOL = 1e-13
"""Relative to the quantity's scale: PyBullet's float64 recursions against the closed form of the same arm (measured
<= 2e-15 for one step, the energies and M; 50x the worst)."""

FLOAT32_POSITION = 1e-6  # [m]
"""getLinkState's link frames are float32 (~6e-8 m on an arm of 1.8 m; the adapter's LINK_STATE_RESOLUTION)."""

ORDER_TOL = 0.1
"""Observed order of the global error at t = 0.5 s over dt = 4, 2, 1 ms against 1: measured 0.99-1.00 (arm)."""

DRIFT_RATIO = (1.8, 2.2)
"""Energy drift of an undamped chain per halving of dt, first order: measured 2.02-2.03 (iiwa, 0.5 s)."""

JACOBI_RTOL = 1e-9
"""PyBullet's kinetic energy against Pinocchio's on the Panda: Bullet diagonalises its off-diagonal inertia tensors
by a Jacobi iteration and drops the remainder, M off by up to 1.3e-10 relative (tests/references/pybullet/test_joint_dynamics)."""

SLEEP_RTOL = 1e-6
"""A slowly pushed arm's velocity against the rigid push T M^-1 tau: its motion (1e-4 rad) changes M by ~1e-8
relative (measured 1.2e-8); the same arm loaded with URDF_ENABLE_SLEEPING is asleep at 3 s (velocity 0)."""

ENGINE = PybulletEngine()
ARM = simparity.load_scene("comparisons/scenes/lecture-2link-dynamics.toml").chain
IIWA = simparity.load_scene("comparisons/scenes/iiwa-dynamics.toml").chain
PANDA = simparity.load_scene("comparisons/scenes/panda-dynamics.toml").chain
ARMATURE = simparity.load_scene("comparisons/scenes/armature-arm-dynamics.toml").chain
GRAVITY = np.array([3.0, -9.81, 0.5])  # [m/s^2]: in the arm's plane but off its axes, and a part along the joints

# The arm's numbers (comparisons/scenes/lecture-2link-dynamics.toml): masses, lengths, centres of mass, inertias
# about the centres of mass around z.
M1, M2, L1, LC1, LC2, TIP = 2.0, 1.5, 1.0, 0.5, 0.4, 0.8
I1, I2 = 2.0 / 12 * (1.0 + 0.01), 1.5 / 12 * (0.64 + 0.0064)


def damped(chain, damping):
    """``chain`` with joint damping ``damping`` (n,) [N m s/rad]."""
    return replace(chain, joints=tuple(replace(j, damping=float(b)) for j, b in zip(chain.joints, damping)))


def scene(chain=ARM, q0=(0.3, -0.4), qdot0=(0.5, -1.0), gravity=GRAVITY, torque=None, duration=0.5, dt=0.01):
    """A joint-motion scene of ``chain`` (the lecture's arm by default)."""
    return JointMotionScene(name="motion", description="", reference="pinocchio", chain=chain,
                            gravity_world=None if gravity is None else np.asarray(gravity, dtype=float),
                            q0=np.asarray(q0, dtype=float), qdot0=np.asarray(qdot0, dtype=float),
                            torque=np.zeros(chain.n_joints) if torque is None else np.asarray(torque, dtype=float),
                            duration=duration, dts=(dt,))


def run(s: JointMotionScene, dt: float | None = None):
    """(simulation, trajectory) of ``s`` at its first dt (or ``dt``)."""
    dt = s.dts[0] if dt is None else dt
    sim = ENGINE.build_joint_motion(s, "euler", dt)
    return sim, sim.run(s.n_steps(dt))


# --- the arm's closed form --------------------------------------------------------------------------------------


def arm_mass_matrix(q: np.ndarray) -> np.ndarray:
    """M (2, 2) at q (2,)."""
    c2 = np.cos(q[1])
    m22 = M2 * LC2**2 + I2
    m12 = m22 + M2 * L1 * LC2 * c2
    m11 = M1 * LC1**2 + I1 + M2 * (L1**2 + LC2**2 + 2 * L1 * LC2 * c2) + I2
    return np.array([[m11, m12], [m12, m22]])


def arm_coms(q: np.ndarray) -> np.ndarray:
    """Centres of mass (2, 3) [m] at q (2,)."""
    a, b = q[0], q[0] + q[1]
    return np.array([[LC1 * np.cos(a), LC1 * np.sin(a), 0.0],
                     [L1 * np.cos(a) + LC2 * np.cos(b), L1 * np.sin(a) + LC2 * np.sin(b), 0.0]])


def arm_bias(q: np.ndarray, qd: np.ndarray, gravity) -> np.ndarray:
    """h(q, qdot) (2,): Coriolis, centrifugal and gravity forces; ``gravity`` (3,) or None."""
    s2 = np.sin(q[1])
    coriolis = M2 * L1 * LC2 * s2 * np.array([-(2 * qd[0] * qd[1] + qd[1] ** 2), qd[0] ** 2])
    if gravity is None:
        return coriolis
    g = np.asarray(gravity)[:2]
    a, b = q[0], q[0] + q[1]
    d1, d2 = np.array([-np.sin(a), np.cos(a)]), np.array([-np.sin(b), np.cos(b)])  # d(direction)/d(angle)
    weight2 = -M2 * LC2 * (g @ d2)
    return coriolis + np.array([-(M1 * LC1 + M2 * L1) * (g @ d1) + weight2, weight2])


def arm_energy(q: np.ndarray, qd: np.ndarray, gravity) -> tuple[float, float]:
    """(kinetic, potential) [J] at one state."""
    potential = 0.0 if gravity is None else -np.array([M1, M2]) @ (arm_coms(q) @ np.asarray(gravity))
    return 0.5 * qd @ arm_mass_matrix(q) @ qd, potential


def arm_tip(q: np.ndarray) -> np.ndarray:
    a, b = q[0], q[0] + q[1]
    return np.array([L1 * np.cos(a) + TIP * np.cos(b), L1 * np.sin(a) + TIP * np.sin(b), 0.0])


def arm_step(q, qd, dt, tau=(0.0, 0.0), gravity=GRAVITY):
    """Semi-implicit Euler with the closed form (undamped): qdot' = qdot + dt qddot(q, qdot), q' = q + dt qdot'."""
    qdd = np.linalg.solve(arm_mass_matrix(q), np.asarray(tau) - arm_bias(q, qd, gravity))
    qd1 = qd + dt * qdd
    return q + dt * qd1, qd1


def arm_solve(q0, qd0, duration, gravity=GRAVITY) -> np.ndarray:
    """The arm's exact state (4,) at ``duration`` by DOP853 on the closed form (rtol 1e-13)."""
    def rhs(_, y):
        return np.concatenate([y[2:], np.linalg.solve(arm_mass_matrix(y[:2]), -arm_bias(y[:2], y[2:], gravity))])
    return solve_ivp(rhs, (0.0, duration), np.concatenate([q0, qd0]), method="DOP853", rtol=1e-13,
                     atol=1e-13).y[:, -1]


# --- the engine's hooks ---------------------------------------------------------------------------------------


def test_hooks_name_bullets_step_and_refuse_armature():
    s = scene()
    assert ENGINE.joint_motion_integrators() == ENGINE.integrators() == ("euler",)
    assert ENGINE.scheme("euler", s) == "semi_implicit_euler"
    assert (ENGINE.theoretical_order("euler"), ENGINE.stages("euler")) == (1, 1)
    assert ENGINE.supports_joint_motion(s, "euler").ok
    assert "rk4" in ENGINE.supports_joint_motion(s, "rk4").reason
    support = ENGINE.supports_joint_motion(scene(chain=ARMATURE, q0=np.zeros(3), qdot0=np.zeros(3)), "euler")
    assert not support.ok and "armature" in support.reason and "'shoulder'" in support.reason


# --- the step, its order and its energy -------------------------------------------------------------------------


def test_one_step_is_semi_implicit_euler_with_the_scenes_gravity():
    """qdot' = qdot + dt qddot(q, qdot) and q' = q + dt qdot' (the new velocity; the old one would put q off by
    dt^2 qddot, 0.18 rad here)."""
    _, trajectory = run(scene(dt=0.1), 0.1)
    q1, qd1 = arm_step(np.array([0.3, -0.4]), np.array([0.5, -1.0]), 0.1)
    assert np.max(np.abs(trajectory.qdot[1, 0] - qd1)) < ROUNDING_RTOL * np.max(np.abs(qd1))
    assert np.max(np.abs(trajectory.q[1, 0] - q1)) < ROUNDING_RTOL
    np.testing.assert_allclose(trajectory.times, [0.0, 0.1, 0.2, 0.3, 0.4, 0.5], rtol=0, atol=1e-15)
    assert trajectory.q.shape == (6, 1, 2)


def test_observed_order_is_one_against_the_closed_forms_tight_solve():
    q0, qd0 = np.array([0.3, -0.4]), np.array([0.5, -1.0])
    exact = arm_solve(q0, qd0, 0.5)
    errors = []
    for dt in (0.004, 0.002, 0.001):
        _, trajectory = run(scene(dt=dt), dt)
        errors.append(np.max(np.abs(np.concatenate([trajectory.q[-1, 0], trajectory.qdot[-1, 0]]) - exact)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 1.0) < ORDER_TOL), orders


def test_energy_drift_of_an_undamped_arm_halves_with_dt():
    drifts = []
    for dt in (0.002, 0.001, 0.0005):
        s = scene(chain=damped(IIWA, np.zeros(7)), q0=np.full(7, 0.3), qdot0=np.full(7, 0.2),
                  gravity=(0.0, 0.0, -9.81), dt=dt)
        sim, trajectory = run(s, dt)
        kinetic, potential = sim.energy(trajectory.q[:, 0], trajectory.qdot[:, 0])
        total = kinetic + potential
        drifts.append(np.max(np.abs(total - total[0])))
    ratios = np.array(drifts[:-1]) / np.array(drifts[1:])
    assert np.all((DRIFT_RATIO[0] < ratios) & (ratios < DRIFT_RATIO[1])), ratios


def test_energy_and_end_effector_against_the_closed_form():
    sim = ENGINE.build_joint_motion(scene(), "euler", 0.01)
    weightless = ENGINE.build_joint_motion(scene(gravity=None), "euler", 0.01)
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-3, 3, size=(6, 2)), rng.uniform(-2, 2, size=(6, 2))
    kinetic, potential = sim.energy(q, qd)
    expected = np.array([arm_energy(a, v, GRAVITY) for a, v in zip(q, qd)])
    assert np.max(np.abs(kinetic - expected[:, 0])) < ROUNDING_RTOL * np.max(expected[:, 0])
    assert np.max(np.abs(potential - expected[:, 1])) < ROUNDING_RTOL * np.max(np.abs(expected[:, 1]))
    assert np.array_equal(weightless.energy(q, qd)[1], np.zeros(6))
    tips = np.array([arm_tip(a) for a in q])
    assert np.max(np.abs(sim.end_effector_world(q) - tips)) < FLOAT32_POSITION


def test_energy_of_a_3d_arm_with_welded_links_against_pinocchio():
    """The Panda: off-diagonal inertias, links welded to the chain (link8, the hand and its fingers held at 0)."""
    gravity = np.array([0.4, -0.3, -9.81])
    sim = ENGINE.build_joint_motion(scene(chain=PANDA, q0=np.zeros(7), qdot0=np.zeros(7), gravity=gravity),
                                    "euler", 0.01)
    model = pin.buildModelFromXML(dynamics_urdf(PANDA))
    model.gravity.linear = gravity
    data = model.createData()
    rng = np.random.default_rng(6)
    q, qd = rng.uniform(-1, 1, size=(4, 7)), rng.uniform(-1, 1, size=(4, 7))
    kinetic, potential = sim.energy(q, qd)
    assert model.nq == 7  # the fingers are welded by the dynamics URDF
    for k in range(4):
        reference_kinetic = pin.computeKineticEnergy(model, data, q[k], qd[k])
        assert abs(kinetic[k] - reference_kinetic) < JACOBI_RTOL * reference_kinetic
        reference_potential = pin.computePotentialEnergy(model, data, q[k])  # -sum m g.c, as the scene's
        assert abs(potential[k] - reference_potential) < ROUNDING_RTOL * max(1.0, abs(reference_potential))


# --- damping and torque -----------------------------------------------------------------------------------------


def test_joint_damping_is_explicit():
    """The elbow alone moving at q = 0 (no Coriolis force there) with damping b: one step changes qdot by
    -dt b w M^-1 e2 (explicit); implicit damping would give -dt (M + dt D)^-1 D qdot, 1/3 smaller here."""
    b, w = 4.0, 1.5
    m = arm_mass_matrix(np.zeros(2))
    dt = 0.5 / (b * np.linalg.inv(m)[1, 1])  # dt b (M^-1)_22 = 0.5: explicit and implicit far apart
    s = scene(chain=damped(ARM, (0.0, b)), q0=(0.0, 0.0), qdot0=(0.0, w), gravity=None, duration=dt, dt=dt)
    _, trajectory = run(s)
    change = trajectory.qdot[1, 0] - np.array([0.0, w])
    explicit = -dt * b * w * np.linalg.inv(m)[:, 1]
    implicit = -dt * np.linalg.solve(m + dt * np.diag([0.0, b]), np.array([0.0, b * w]))
    assert np.max(np.abs(change - explicit)) < ROUNDING_RTOL * w
    assert np.max(np.abs(change - implicit)) > 0.1 * w


def test_the_torque_acts_on_every_step_and_pybullet_clears_it_after_each():
    tau, q0, dt = np.array([0.5, -0.2]), np.array([0.3, -0.4]), 0.05
    _, trajectory = run(scene(q0=q0, qdot0=np.zeros(2), gravity=None, torque=tau, duration=2 * dt, dt=dt))
    q1, qd1 = arm_step(q0, np.zeros(2), dt, tau=tau, gravity=None)
    q2, qd2 = arm_step(q1, qd1, dt, tau=tau, gravity=None)
    assert np.max(np.abs(trajectory.qdot[1:, 0] - [qd1, qd2])) < ROUNDING_RTOL * np.max(np.abs(qd2))
    assert np.max(np.abs(trajectory.q[1:, 0] - [q1, q2])) < ROUNDING_RTOL
    # raw PyBullet: TORQUE_CONTROL sent once acts on the first step only
    raw = ChainBodies(ARM, None, time_step=dt)
    raw.reset(q0, np.zeros(2))
    pybullet.setJointMotorControlArray(raw.body, raw.joints, pybullet.TORQUE_CONTROL, forces=tau.tolist(),
                                       physicsClientId=raw.client)
    for _ in range(2):
        pybullet.stepSimulation(physicsClientId=raw.client)
    once = np.array([s[1] for s in pybullet.getJointStates(raw.body, raw.joints, physicsClientId=raw.client)])
    _, unforced = arm_step(q1, qd1, dt, gravity=None)
    assert np.max(np.abs(once - unforced)) < ROUNDING_RTOL * np.max(np.abs(unforced))


# --- copies -----------------------------------------------------------------------------------------------------


def test_copies_in_one_world_move_as_each_alone_and_batched_steps_the_first():
    q0 = np.array([[0.3, -0.4], [2.0, 1.0], [-1.0, 0.2]])
    qd0 = np.array([[0.5, -1.0], [0.0, 0.0], [3.0, -2.0]])
    chain, tau = damped(ARM, (0.3, 0.1)), np.array([1.0, -0.5])
    sim, together = run(scene(chain=chain, q0=q0, qdot0=qd0, torque=tau))
    assert together.q.shape == (51, 3, 2)
    for k in range(3):
        _, alone = run(scene(chain=chain, q0=q0[k], qdot0=qd0[k], torque=tau))
        np.testing.assert_array_equal(together.q[:, k], alone.q[:, 0])
        np.testing.assert_array_equal(together.qdot[:, k], alone.qdot[:, 0])
    again = sim.run(50)  # every call from the start
    np.testing.assert_array_equal(again.q, together.q)
    batched = sim.batched(4)(50)
    assert batched.q.shape == (51, 4, 2)
    np.testing.assert_array_equal(batched.q, np.repeat(together.q[:, :1], 4, axis=1))


# --- PyBullet's defaults ----------------------------------------------------------------------------------------


def test_time_step_substeps_and_gravity_are_the_scenes():
    for gravity, expected in ((GRAVITY, GRAVITY), (None, np.zeros(3))):
        sim = ENGINE.build_joint_motion(scene(gravity=gravity), "euler", 0.004)
        for world in (sim._world, sim._model):
            read = pybullet.getPhysicsEngineParameters(physicsClientId=world.client)
            assert [read[f"gravityAcceleration{a}"] for a in "XYZ"] == expected.tolist()
        read = pybullet.getPhysicsEngineParameters(physicsClientId=sim._world.client)
        assert (read["fixedTimeStep"], read["numSubSteps"]) == (0.004, 0)


def test_a_free_spin_keeps_its_speed_through_the_joint_limit():
    """At q2 = 0 without gravity the arm spins rigidly: qdot stays (150, 0) exactly and q1 = 150 t. PyBullet's
    velocity cap (100 rad/s), link damping (0.04), braking motors and the shoulder's limit at pi would each slow it."""
    dt = 0.01
    _, trajectory = run(scene(q0=(0.0, 0.0), qdot0=(150.0, 0.0), gravity=None, duration=10 * dt, dt=dt))
    assert np.array_equal(trajectory.qdot[:, 0], np.tile([150.0, 0.0], (11, 1)))
    assert np.max(np.abs(trajectory.q[:, 0, 0] - 150.0 * dt * np.arange(11))) < ROUNDING_RTOL * 15.0
    assert trajectory.q[-1, 0, 0] > 4 * np.pi and np.all(trajectory.q[:, 0, 1] == 0.0)


def test_a_slowly_pushed_arm_never_sleeps():
    """Bullet puts a body whose velocities stay below its thresholds for 2 s to sleep unless it may not (URDF bodies
    are loaded without URDF_ENABLE_SLEEPING): pushed from rest by a tiny torque, the arm keeps accelerating."""
    tau, duration = np.array([1e-5, 0.0]), 3.0
    _, trajectory = run(scene(q0=(0.0, 0.0), qdot0=(0.0, 0.0), gravity=None, torque=tau, duration=duration,
                              dt=0.01))
    rigid = duration * np.linalg.solve(arm_mass_matrix(np.zeros(2)), tau)
    assert np.max(np.abs(trajectory.qdot[-1, 0] - rigid)) < SLEEP_RTOL * np.max(np.abs(rigid))


def test_a_blown_up_run_is_reported_not_clamped():
    """Explicit damping at dt b / I > 2 (the iiwa's last link: I = 1e-3 kg m^2, b = 0.5 N m s at dt 5 ms) grows
    without bound; the run ends non-finite or raises, never clamped at a finite cap."""
    s = scene(chain=IIWA, q0=np.full(7, 0.3), qdot0=np.full(7, 0.5), gravity=(0.0, 0.0, -9.81), duration=1.0,
              dt=0.005)
    try:
        _, trajectory = run(s)
    except SimparityError as error:
        assert "cap" in str(error)
    else:
        assert not trajectory.is_finite()
