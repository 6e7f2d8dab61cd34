"""MuJoCo stepping a chain through time (references/mujoco/joint_motion.py).

Truths: the closed-form planar 2-link dynamics (references/analytic/joint_dynamics.py) solved by SciPy's DOP853 at
a tight tolerance, hand values of single-joint motion (the exact one-step amplification of each scheme on
qddot = -(b/I) qdot, constant acceleration under a constant torque), energy conservation, and the observed order
of convergence over a dt ladder. Nothing here is derived from the module under test.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest
from scipy.integrate import cumulative_simpson, solve_ivp

import simparity
from simparity.core.model.errors import DivergedError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.references.analytic import joint_dynamics as closed_form
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.joint_dynamics import MujocoJointDynamics

SCENES = "comparisons/scenes"
GRAVITY_PLANE = np.array([0.0, -9.81, 0.0])  # in the 2-link arm's plane (its joints turn about z)

ORDER_TOLERANCE = 0.2
"""Observed minus theoretical order on the ladders below: the arm's motion over 1 s is smooth, but the ladders are
not exactly asymptotic (measured 0.98 to 1.01 for the first-order schemes, 3.99 for RK4); a wrong order (2 for 1,
3 or 5 for 4) is off by a whole unit."""

AGREEMENT = 1e-6
"""[rad] RK4 at dt = 2.5 ms against the closed form's tight solve over 1 s: the scheme's error (~C dt^4, measured
1.1e-8) and the solve's (~1e-11 at rtol 1e-12); a model difference (a wrong mass, lever arm, damping or torque) shows
at 1e-3 or more."""

ENERGY_DRIFT = 1e-7
"""Relative energy drift of undamped RK4 on the iiwa at dt = 1 ms over 1 s: RK4's local error ~ (omega dt)^5 per step
with omega ~ 10 rad/s, ~1e-8 summed (measured 4e-9); a wrong potential sign or scale drifts by order 1."""

POWER_BALANCE = 1e-6
"""Relative mismatch of the iiwa's energy loss and Simpson's integral of qdot^T D qdot over the 1 ms samples: the
quadrature's error and RK4's own energy error (measured 7e-8 together; the trapezoid's would be 5e-6); damping missing
or doubled is off by order 1 (the loss is 36 % of the scale)."""

EXACT = 1e-12
"""Relative rounding of a few dozen float64 operations on O(1) numbers: for values a scheme gives exactly."""


def _chain(name: str, damping: float | None = None, joints: int | None = None):
    """The chain of a scene file, optionally with every joint's damping set and cut to its first ``joints``."""
    chain = simparity.load_scene(f"{SCENES}/{name}.toml").chain
    if joints is not None:
        chain = dataclasses.replace(chain, joints=chain.joints[:joints])
    if damping is not None:
        chain = dataclasses.replace(chain, joints=tuple(dataclasses.replace(j, damping=damping) for j in chain.joints))
    return chain


def _scene(chain, q0, qdot0, gravity=None, torque=None, duration=1.0, dt=0.01) -> JointMotionScene:
    n = chain.n_joints
    return JointMotionScene(name="t", description="test", reference="mujoco", chain=chain, gravity_world=gravity,
                            q0=np.asarray(q0, float), qdot0=np.asarray(qdot0, float),
                            torque=np.zeros(n) if torque is None else np.asarray(torque, float),
                            duration=duration, dts=(dt,))


def _run(scene: JointMotionScene, integrator: str, dt: float):
    simulation = MujocoEngine().build_joint_motion(scene, integrator, dt)
    return simulation, simulation.run(scene.n_steps(dt))


# --- The two-link arm: a single link about the shoulder (box 1.0 x 0.1 x 0.1 m, 2 kg, COM at 0.5 m) -----------
SHOULDER_INERTIA = 2.0 / 12 * (1.0**2 + 0.1**2) + 2.0 * 0.5**2  # [kg m^2] about the joint axis (z): 0.66833
L1, LC1, LC2, L2 = 1.0, 0.5, 0.4, 0.8  # [m] link 1, the COMs, the tip offset from the elbow
M1, M2 = 2.0, 1.5  # [kg]


def _truth(scene: JointMotionScene, times: np.ndarray) -> np.ndarray:
    """(T, n) joint values of the scene's first copy by the closed-form 2-link dynamics, DOP853 at rtol 1e-12."""
    model = closed_form.build(scene.chain, scene.gravity_world)
    n = scene.chain.n_joints

    def rhs(_t, y):
        qddot = model.forward_dynamics(y[None, :n], y[None, n:], scene.torque[None])[0]
        return np.concatenate([y[n:], qddot])

    y0 = np.concatenate([scene.q0[0], scene.qdot0[0]])
    solution = solve_ivp(rhs, (0.0, times[-1]), y0, method="DOP853", rtol=1e-12, atol=1e-12, t_eval=times)
    return solution.y[:n].T


@pytest.fixture(scope="module")
def arm_scene() -> JointMotionScene:
    """The 2-link arm under gravity in its plane, damped (0.3 N m s), with constant joint torques, 1 s."""
    return _scene(_chain("lecture-2link-dynamics", damping=0.3), [0.3, 0.5], [0.4, -0.2], gravity=GRAVITY_PLANE,
                  torque=[1.0, -0.5])


@pytest.mark.parametrize("integrator", MujocoEngine().joint_motion_integrators())
def test_observed_order_is_the_theoretical_one(arm_scene, integrator):
    """Errors against the closed form's tight solve at 20 ms samples over a ladder of halvings give the order the
    engine declares: 4 for RK4, 1 for every Euler-like scheme."""
    engine = MujocoEngine()
    ladder = (0.01, 0.005, 0.0025) if integrator == "rk4" else (0.005, 0.0025, 0.00125)
    sample_times = np.arange(51) * 0.02
    truth = _truth(arm_scene, sample_times)
    errors = []
    for dt in ladder:
        trajectory = _run(arm_scene, integrator, dt)[1]
        every = int(round(0.02 / dt))
        errors.append(np.abs(trajectory.q[::every, 0] - truth).max())
    observed = np.log2(np.array(errors[:-1]) / errors[1:])
    assert engine.theoretical_order(integrator) == (4 if integrator == "rk4" else 1)
    assert np.all(np.abs(observed - engine.theoretical_order(integrator)) < ORDER_TOLERANCE), (errors, observed)
    if integrator == "rk4":
        assert errors[-1] < AGREEMENT, errors


def _iiwa_energy(damping: float):
    """(total energy (T,) [J], dissipated power qdot^T D qdot (T,) [W], the energy's scale [J], dt [s]) along RK4 at
    1 ms over 1 s of the iiwa under gravity with every joint's damping set, from a seeded state."""
    chain = _chain("iiwa-dynamics", damping=damping)
    rng = np.random.default_rng(28)
    scene = _scene(chain, rng.uniform(-1, 1, 7), rng.uniform(-1, 1, 7), gravity=np.array([0.0, 0.0, -9.81]))
    simulation, trajectory = _run(scene, "rk4", 0.001)
    kinetic, potential = simulation.energy(trajectory.q[:, 0], trajectory.qdot[:, 0])
    assert np.ptp(potential) > 0.1 * np.ptp(kinetic + potential)  # kinetic and potential exchange energy
    scale = np.abs(kinetic).max() + np.abs(potential - potential[0]).max()
    return kinetic + potential, damping * (trajectory.qdot[:, 0] ** 2).sum(axis=1), scale, 0.001


def test_rk4_conserves_energy_of_an_undamped_chain():
    """The iiwa under gravity, no damping and no torque: kinetic + potential from the engine's own energy() stays
    constant along RK4 at a small step while energy moves between kinetic and potential."""
    total, _, scale, _ = _iiwa_energy(0.0)
    assert np.abs(total - total[0]).max() < ENERGY_DRIFT * scale


def test_damping_dissipates_the_power_balance():
    """The iiwa's own damping (0.5 N m s per joint): the energy lost is the integral of qdot^T D qdot (Simpson)."""
    total, power, scale, dt = _iiwa_energy(0.5)
    dissipated = np.concatenate([[0.0], cumulative_simpson(power, dx=dt)])
    assert dissipated[-1] > 0.1 * scale  # damping matters here
    assert np.abs(total - total[0] + dissipated).max() < POWER_BALANCE * scale


def test_energy_of_the_arm_is_the_hand_value():
    """Kinetic 1/2 qdot^T M qdot with M the closed form's; potential m g y of the two COMs (gravity -9.81 y)."""
    scene = _scene(_chain("lecture-2link-dynamics"), [0.3, 0.5], [0.0, 0.0], gravity=GRAVITY_PLANE)
    simulation = MujocoEngine().build_joint_motion(scene, "rk4", 0.01)
    q, qdot = np.array([[0.3, 0.5], [-1.2, 2.0]]), np.array([[0.7, -1.1], [0.0, 2.5]])
    kinetic, potential = simulation.energy(q, qdot)
    mass = closed_form.build(scene.chain, None).mass_matrix(q)
    assert np.allclose(kinetic, 0.5 * np.einsum("bi,bij,bj->b", qdot, mass, qdot), rtol=EXACT, atol=0)
    y1 = LC1 * np.sin(q[:, 0])
    y2 = L1 * np.sin(q[:, 0]) + LC2 * np.sin(q[:, 0] + q[:, 1])
    assert np.allclose(potential, 9.81 * (M1 * y1 + M2 * y2), rtol=EXACT, atol=0)
    no_gravity = MujocoEngine().build_joint_motion(dataclasses.replace(scene, gravity_world=None), "rk4", 0.01)
    assert np.array_equal(no_gravity.energy(q, qdot)[1], np.zeros(2))


def test_kinetic_energy_includes_armature():
    """On the armature arm (a prismatic joint among revolute ones), energy()'s kinetic term is the links' own
    kinetic energy (body velocities, part 1) plus 1/2 sum armature qdot^2."""
    chain = _chain("armature-arm-dynamics")
    n = chain.n_joints
    rng = np.random.default_rng(3)
    q, qdot = rng.uniform(-1, 1, (4, n)), rng.uniform(-1, 1, (4, n))
    scene = _scene(chain, q[0], qdot[0])
    kinetic = MujocoEngine().build_joint_motion(scene, "rk4", 0.01).energy(q, qdot)[0]
    armature = np.array([j.armature for j in chain.joints])
    assert np.any(armature > 0)
    links = MujocoJointDynamics(chain, None).link_kinetic_energy(q, qdot)
    assert np.allclose(kinetic, links + 0.5 * (armature * qdot**2).sum(axis=1), rtol=1e-10, atol=0)


def test_end_effector_is_the_arms_tip():
    """The tip at l1 (cos q1, sin q1) + 0.8 (cos(q1 + q2), sin(q1 + q2)) in the base frame."""
    scene = _scene(_chain("lecture-2link-dynamics"), [0.3, 0.5], [0.0, 0.0])
    q = np.array([[0.3, 0.5], [-2.0, 1.0]])
    tip = MujocoEngine().build_joint_motion(scene, "euler", 0.01).end_effector_world(q)
    expected = np.stack([L1 * np.cos(q[:, 0]) + L2 * np.cos(q.sum(1)), L1 * np.sin(q[:, 0]) + L2 * np.sin(q.sum(1)),
                         np.zeros(2)], axis=1)
    assert np.allclose(tip, expected, rtol=0, atol=EXACT)


# --- One joint, no gravity: qddot = (tau - b qdot) / I, each scheme's step in closed form -------------------------
STIFF = 2.5  # b dt / I
_Z = -STIFF
VELOCITY_FACTOR = {
    "euler": 1 / (1 + STIFF),  # eulerdamp: (I + dt b) qdot' = I qdot
    "implicitfast": 1 / (1 + STIFF),
    "implicit": 1 / (1 + STIFF),  # no Coriolis force on one joint: as implicitfast
    "euler_explicit_damping": 1 - STIFF,  # -1.5: grows
    "rk4": 1 + _Z + _Z**2 / 2 + _Z**3 / 6 + _Z**4 / 24,  # RK4's stability function R(-2.5) = 0.648
}


@pytest.mark.parametrize("integrator", sorted(VELOCITY_FACTOR))
def test_stiff_damping_each_schemes_amplification(integrator):
    """b dt / I = 2.5 on one joint: every step multiplies qdot by the scheme's factor, so implicit damping decays
    (1/3.5) while explicit damping grows (|1 - 2.5| = 1.5)."""
    dt = 0.01
    chain = _chain("lecture-2link-dynamics", damping=STIFF * SHOULDER_INERTIA / dt, joints=1)
    trajectory = _run(_scene(chain, [0.2], [1.0], duration=10 * dt, dt=dt), integrator, dt)[1]
    qdot = trajectory.qdot[:, 0, 0]
    assert np.allclose(qdot, VELOCITY_FACTOR[integrator] ** np.arange(11), rtol=1e-10, atol=0)
    grows = abs(VELOCITY_FACTOR[integrator]) > 1
    assert (abs(qdot[-1]) > 50) if grows else (abs(qdot[-1]) < 0.02)


def test_explicit_damping_blowing_up_raises_instead_of_resetting():
    """Growing by 1.5 a step, qdot passes MuJoCo's 1e10 within 60 steps: it would reset the state and carry on; the
    adapter raises DivergedError."""
    dt = 0.01
    chain = _chain("lecture-2link-dynamics", damping=STIFF * SHOULDER_INERTIA / dt, joints=1)
    scene = _scene(chain, [[0.2], [0.0]], [[0.0], [1.0]], duration=100 * dt, dt=dt)  # the second copy diverges
    with pytest.raises(DivergedError, match="unstable"):
        _run(scene, "euler_explicit_damping", dt)
    assert _run(scene, "euler", dt)[1].is_finite()


@pytest.mark.parametrize("integrator", MujocoEngine().joint_motion_integrators())
def test_applied_torque_accelerates_the_joint(integrator):
    """A torque tau on one joint at rest, no gravity nor damping: qdot = tau t / I exactly for every scheme (constant
    acceleration), and q = tau t^2 / (2 I) for RK4."""
    dt, tau = 0.01, 3.0
    chain = _chain("lecture-2link-dynamics", joints=1)
    trajectory = _run(_scene(chain, [0.0], [0.0], torque=[tau], duration=20 * dt, dt=dt), integrator, dt)[1]
    t = trajectory.times
    assert np.allclose(trajectory.qdot[:, 0, 0], tau * t / SHOULDER_INERTIA, rtol=EXACT, atol=EXACT)
    if integrator == "rk4":
        assert np.allclose(trajectory.q[:, 0, 0], tau * t**2 / (2 * SHOULDER_INERTIA), rtol=EXACT, atol=EXACT)


def test_copies_step_as_each_alone(arm_scene):
    """Three copies in one run give bit for bit what each gives alone; batched(copies) steps the first state as
    run() does; every run() starts again from the initial states."""
    q0 = np.array([[0.3, 0.5], [-1.0, 2.0], [2.5, -0.3]])
    qdot0 = np.array([[0.4, -0.2], [0.0, 0.0], [-3.0, 1.0]])
    scene = dataclasses.replace(arm_scene, q0=q0, qdot0=qdot0)
    simulation, together = _run(scene, "rk4", 0.01)
    for k in range(3):
        alone = _run(dataclasses.replace(scene, q0=q0[k], qdot0=qdot0[k]), "rk4", 0.01)[1]
        assert np.array_equal(together.q[:, k], alone.q[:, 0]) and np.array_equal(together.qdot[:, k], alone.qdot[:, 0])
    assert np.array_equal(simulation.run(100).q, together.q)
    states = simulation.batched(4)(100)  # (copies, steps, nstate): time, qpos, qvel
    assert states.shape[:2] == (4, 100)
    for copy in states:
        assert np.array_equal(copy[:, 1:3], together.q[1:, 0])


@pytest.mark.parametrize("integrator", MujocoEngine().joint_motion_integrators())
def test_defaults_are_pinned(integrator):
    """Gravity exactly the scene's, the chain's damping and armature, no frictionloss, stiffness, actuators,
    fluid or gravity compensation; constraints off; eulerdamp off only for euler_explicit_damping; sleeping off."""
    chain = _chain("armature-arm-dynamics")
    n = chain.n_joints
    gravity = np.array([0.1, -0.2, -9.80665])
    scene = _scene(chain, np.zeros(n), np.zeros(n), gravity=gravity, dt=0.002)
    model = MujocoEngine().build_joint_motion(scene, integrator, 0.002).model
    assert np.array_equal(model.opt.gravity, gravity)
    assert model.opt.timestep == 0.002
    expected = {"euler": "mjINT_EULER", "euler_explicit_damping": "mjINT_EULER", "rk4": "mjINT_RK4",
                "implicit": "mjINT_IMPLICIT", "implicitfast": "mjINT_IMPLICITFAST"}[integrator]
    assert model.opt.integrator == getattr(mujoco.mjtIntegrator, expected)
    flags = mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | (
        mujoco.mjtDisableBit.mjDSBL_EULERDAMP if integrator == "euler_explicit_damping" else 0)
    assert model.opt.disableflags == flags
    assert model.opt.enableflags == 0
    assert np.array_equal(model.dof_damping, [j.damping for j in chain.joints])
    assert np.array_equal(model.dof_armature, [j.armature for j in chain.joints])
    assert not np.any(model.dof_frictionloss) and not np.any(model.jnt_stiffness) and not np.any(model.dof_dampingpoly)
    assert model.nu == 0 and not np.any(model.body_gravcomp)
    assert model.opt.density == 0 and model.opt.viscosity == 0 and not np.any(model.opt.wind)
    no_gravity = MujocoEngine().build_joint_motion(dataclasses.replace(scene, gravity_world=None), integrator, 0.002)
    assert np.array_equal(no_gravity.model.opt.gravity, np.zeros(3))


def test_schemes_stages_and_free_body_answers():
    """Joint-motion schemes by scene type; the free-body answers of the same names are unchanged."""
    engine = MujocoEngine()
    scene = _scene(_chain("lecture-2link-dynamics"), [0.0, 0.0], [0.0, 0.0])
    assert {i: engine.scheme(i, scene) for i in engine.joint_motion_integrators()} == {
        "euler": "implicit_damping", "euler_explicit_damping": "semi_implicit_euler",
        "implicitfast": "implicit_damping", "implicit": "implicit_velocity", "rk4": "rk4"}
    assert {i: engine.stages(i) for i in engine.joint_motion_integrators()} == {
        "euler": 1, "euler_explicit_damping": 1, "implicitfast": 1, "implicit": 1, "rk4": 4}
    free_body = simparity.load_scene(f"{SCENES}/dzhanibekov.toml")
    assert engine.scheme("euler", free_body) == "engine_euler"
    assert engine.scheme("implicitfast", free_body) == "implicit_damping"
    assert engine.supports_joint_motion(scene, "rk4").ok
    assert not engine.supports_joint_motion(scene, "semi_implicit").ok
