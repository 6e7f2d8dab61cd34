"""The analytic engine's closed-form joint motion of one-joint chains (the physical pendulum through Jacobi elliptic
functions, a damped joint under constant forces): against the equation of motion by finite differences, the
period 4 K(k) / omega0 from zero crossings, the small-amplitude limit, energy conservation, hand values, a DOP853
solve of the test's own right-hand side, and its refusals."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation
from scipy.special import ellipk

from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.references.analytic.engine import AnalyticEngine

ENGINE = AnalyticEngine()
INTEGRATOR = "closed_form"

# Closed forms against numbers written by hand, values of order 10: float64 rounding only.
HAND_TOL = 1e-12
# Energy along the closed form, relative to m |g_perp| d: the kinetic and potential terms (~5 J) each carry a
# few ulps, and the elliptic functions satisfy sn^2 + cn^2 = 1 to rounding.
ENERGY_RTOL = 1e-13
# DOP853 at rtol = atol = 1e-13 over two periods of a 170 degree swing or two turns: its own error, measured
# ~2e-11 rad at 1e-13 and falling with its tolerance (6e-12 at 1e-14) toward the closed form.
ODE_TOL = 1e-10
ODE_RTOL = 1e-13
# Central differences with step 2e-6 s: truncation h^2 |q'''| / 6 <= 4e-12 * 1.5e3 / 6 ~ 1e-9 (|q''''| of the
# 170 degree swing <= omega0^2 (theta'^2 + omega0^2) ~ 1.5e3) and rounding eps |q| / h ~ 1e-16 * 10 / 2e-6 ~ 5e-10.
FD_STEP = 2e-6
FD_TOL = 1e-8
# Zero crossings found by brentq to xtol 1e-14 s on a period of ~4 s.
PERIOD_RTOL = 1e-12
# The stable equilibrium as the root of the test's own gravity torque (slope ~5 N m/rad, rounding ~1e-15 N m),
# found by brentq to xtol 1e-15 rad.
EQUILIBRIUM_TOL = 1e-12

G = 9.81  # [m/s^2]


def _link(mass: float, com_xyz, inertia) -> LinkInertia:
    return LinkInertia(mass, np.asarray(com_xyz, dtype=float), np.asarray(inertia, dtype=float))


def _chain(link: LinkInertia, axis=(0.0, 0.0, 1.0), origin_xyz=(0.0, 0.0, 0.0), origin_rotation=None,
           joint_type: str = "revolute", damping: float = 0.0, armature: float = 0.0,
           end_effector_xyz=(1.0, 0.0, 0.0)) -> Chain:
    rotation = np.eye(3) if origin_rotation is None else origin_rotation
    joint = Joint("j", joint_type, np.asarray(axis, dtype=float), np.asarray(origin_xyz, dtype=float), rotation,
                  link=link, damping=damping, armature=armature)
    return Chain("one", (joint,), end_effector_xyz=np.asarray(end_effector_xyz, dtype=float))


def _scene(chain: Chain, gravity, q0, qdot0, torque=0.0, duration: float = 1.0) -> JointMotionScene:
    n = chain.n_joints
    return JointMotionScene(
        name="one", description="", reference="analytic", chain=chain,
        gravity_world=None if gravity is None else np.asarray(gravity, dtype=float),
        q0=np.asarray(q0, dtype=float).reshape(-1, n), qdot0=np.asarray(qdot0, dtype=float).reshape(-1, n),
        torque=np.full(n, torque), duration=duration, dts=(min(0.01, duration),))


def _at(scene: JointMotionScene, times) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot), each (T, B), of the closed form at arbitrary times: one step of dt = t each."""
    samples = [ENGINE.build_joint_motion(scene, INTEGRATOR, t).run(1) for t in times]
    return np.stack([s.q[-1, :, 0] for s in samples]), np.stack([s.qdot[-1, :, 0] for s in samples])


# The planar pendulum: about +z at the origin, its centre of mass 0.5 m along the link's x, gravity along -y.
# I = 0.03 + 1 * 0.5^2 = 0.28 kg m^2, omega0^2 = 1 * 9.81 * 0.5 / 0.28; it hangs at q = -pi/2.
PLANAR = _chain(_link(1.0, (0.5, 0, 0), np.diag([0.01, 0.02, 0.03])))
PLANAR_GRAVITY = (0.0, -G, 0.0)
PLANAR_OMEGA0 = np.sqrt(G * 0.5 / 0.28)
PLANAR_DOWN = -np.pi / 2


# The tilted pendulum: a skew axis in a rotated frame off the origin, the centre of mass off the plane of motion
# (a component along the axis), a full inertia tensor, armature, gravity with a component along the axis.
TILTED_AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
TILTED_ROTATION = Rotation.from_rotvec([0.3, -0.5, 0.7]).as_matrix()
TILTED_COM = np.array([0.3, -0.1, 0.2])
TILTED_INERTIA = np.array([[0.02, 0.004, -0.003], [0.004, 0.03, 0.002], [-0.003, 0.002, 0.025]])
TILTED_MASS, TILTED_ARMATURE = 1.5, 0.05
TILTED = _chain(_link(TILTED_MASS, TILTED_COM, TILTED_INERTIA), axis=TILTED_AXIS, origin_xyz=(0.1, 0.2, 0.3),
                origin_rotation=TILTED_ROTATION, armature=TILTED_ARMATURE)
TILTED_GRAVITY = np.array([1.0, -2.0, -9.5])


def _tilted_com_offset(q: float) -> np.ndarray:
    """The tilted link's centre of mass from the joint origin at q [m]: R0 Rot(a, q) c (rotations composed in the
    joint frame, SciPy's rotation vectors)."""
    return TILTED_ROTATION @ Rotation.from_rotvec(TILTED_AXIS * q).apply(TILTED_COM)


def _tilted_inertia() -> float:
    """a^T (I_c + m (|c|^2 1 - c c^T)) a + armature: the inertia about the axis line through the joint origin
    (the tensor transported to the origin), in the link frame [kg m^2]."""
    transported = TILTED_INERTIA + TILTED_MASS * (TILTED_COM @ TILTED_COM * np.eye(3) - np.outer(TILTED_COM, TILTED_COM))
    return float(TILTED_AXIS @ transported @ TILTED_AXIS) + TILTED_ARMATURE


def _tilted_torque(q: float) -> float:
    """Gravity's torque about the axis at q [N m]: n . (r x m g), n = R0 a."""
    return float((TILTED_ROTATION @ TILTED_AXIS) @ np.cross(_tilted_com_offset(q), TILTED_MASS * TILTED_GRAVITY))


def _tilted_down() -> float:
    """The stable equilibrium [rad]: the root of the gravity torque next to the minimum of the test's own potential
    -m g . r(q) on a grid over one turn."""
    grid = np.linspace(-np.pi, np.pi, 721)
    start = grid[int(np.argmin([-TILTED_MASS * TILTED_GRAVITY @ _tilted_com_offset(q) for q in grid]))]
    return float(brentq(_tilted_torque, start - 0.01, start + 0.01, xtol=1e-15, rtol=1e-15))


def _dop853(q0: float, qdot0: float, times: np.ndarray) -> np.ndarray:
    """(T, 2) q, qdot of the tilted pendulum by DOP853 on I q'' = n . (r(q) x m g)."""
    inertia = _tilted_inertia()
    solution = solve_ivp(lambda t, y: [y[1], _tilted_torque(y[0]) / inertia], (0.0, times[-1]), [q0, qdot0],
                         method="DOP853", rtol=ODE_RTOL, atol=ODE_RTOL, t_eval=times)
    return solution.y.T


def test_the_engine_offers_the_closed_form_for_joint_motion():
    assert ENGINE.joint_motion_integrators() == ("closed_form",)
    scene = _scene(PLANAR, PLANAR_GRAVITY, 0.0, 0.0)
    assert ENGINE.scheme(INTEGRATOR, scene) == "closed_form"
    assert ENGINE.theoretical_order(INTEGRATOR) is None and ENGINE.stages(INTEGRATOR) is None
    assert ENGINE.supports_joint_motion(scene, INTEGRATOR).ok
    assert "no joint-motion integrator 'rk4'" in ENGINE.supports_joint_motion(scene, "rk4").reason


def test_the_planar_pendulum_rests_hanging_down_and_swings_about_it():
    scene = _scene(PLANAR, PLANAR_GRAVITY, [PLANAR_DOWN, PLANAR_DOWN + 0.3], [0.0, 0.0], duration=3.0)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01).run(300)
    assert np.max(np.abs(trajectory.q[:, 0, 0] - PLANAR_DOWN)) <= HAND_TOL
    assert np.max(np.abs(trajectory.qdot[:, 0, 0])) <= HAND_TOL
    swing = trajectory.q[:, 1, 0] - PLANAR_DOWN
    assert np.max(swing) == pytest.approx(0.3, abs=1e-3) and np.min(swing) == pytest.approx(-0.3, abs=1e-3)


def test_the_tilted_pendulum_rests_at_the_minimum_of_its_potential():
    down = _tilted_down()
    scene = _scene(TILTED, TILTED_GRAVITY, down, 0.0, duration=2.0)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01).run(200)
    assert np.max(np.abs(trajectory.q[:, 0, 0] - down)) <= EQUILIBRIUM_TOL
    assert np.max(np.abs(trajectory.qdot[:, 0, 0])) <= EQUILIBRIUM_TOL * 10


@pytest.mark.parametrize("qdot0", [-1.0, 9.0], ids=["swinging", "turning"])
def test_the_closed_form_satisfies_the_equation_of_motion(qdot0):
    down = _tilted_down()
    scene = _scene(TILTED, TILTED_GRAVITY, down + np.radians(170), qdot0)
    times = np.linspace(0.05, 2.0, 17)
    q, qdot = _at(scene, times)
    q_plus, qdot_plus = _at(scene, times + FD_STEP)
    q_minus, qdot_minus = _at(scene, times - FD_STEP)
    np.testing.assert_allclose((q_plus - q_minus)[:, 0] / (2 * FD_STEP), qdot[:, 0], rtol=0, atol=FD_TOL)
    torque = np.array([_tilted_torque(value) for value in q[:, 0]])
    acceleration = (qdot_plus - qdot_minus)[:, 0] / (2 * FD_STEP)
    np.testing.assert_allclose(_tilted_inertia() * acceleration, torque, rtol=0, atol=FD_TOL * _tilted_inertia())


def _crossings(scene: JointMotionScene, level: float, count: int, dt: float) -> np.ndarray:
    """The first ``count`` times at which q crosses ``level`` [s], sign changes on a dt grid refined by brentq."""
    steps = 2000
    samples = ENGINE.build_joint_motion(scene, INTEGRATOR, dt).run(steps).q[:, 0, 0] - level
    brackets = np.flatnonzero(np.diff(samples >= 0))[:count]
    assert len(brackets) == count
    offset = lambda t: _at(scene, [t])[0][0, 0] - level  # noqa: E731
    return np.array([brentq(offset, i * dt, (i + 1) * dt, xtol=1e-14, rtol=1e-15) for i in brackets])


@pytest.mark.parametrize("amplitude_deg", [170.0, 120.0, 30.0])
def test_the_period_is_four_quarter_periods_over_omega0(amplitude_deg):
    amplitude = np.radians(amplitude_deg)
    scene = _scene(PLANAR, PLANAR_GRAVITY, PLANAR_DOWN + amplitude, 0.0)
    expected = 4 * ellipk(np.sin(amplitude / 2) ** 2) / PLANAR_OMEGA0
    crossings = _crossings(scene, PLANAR_DOWN, 3, expected / 997)
    assert crossings[2] - crossings[0] == pytest.approx(expected, rel=PERIOD_RTOL)
    # From the turning point a quarter period to the bottom.
    assert crossings[0] == pytest.approx(expected / 4, rel=PERIOD_RTOL)


def test_a_turn_of_the_rotating_pendulum_takes_two_quarter_periods_of_the_modulus_one_over_k():
    # Through the bottom at 2.1 omega0 rad/s: k = 1.05, one turn 2 K(1 / k^2) / (k omega0).
    k = 1.05
    scene = _scene(PLANAR, PLANAR_GRAVITY, PLANAR_DOWN, 2 * k * PLANAR_OMEGA0)
    expected = 2 * ellipk(1 / k**2) / (k * PLANAR_OMEGA0)
    crossings = [_crossings(scene, PLANAR_DOWN + 2 * np.pi * turn, 1, expected / 499)[0] for turn in (1, 2)]
    assert crossings[0] == pytest.approx(expected, rel=PERIOD_RTOL)
    assert crossings[1] == pytest.approx(2 * expected, rel=PERIOD_RTOL)


def test_a_small_swing_is_the_harmonic_oscillator_at_omega0():
    amplitude, duration = 1e-4, 3.0
    scene = _scene(PLANAR, PLANAR_GRAVITY, PLANAR_DOWN + amplitude, 0.0, duration=duration)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01).run(300)
    harmonic = amplitude * np.cos(PLANAR_OMEGA0 * trajectory.times)
    # The period is longer by amplitude^2 / 16 (a phase lag omega0 t amplitude^2 / 16) and the third harmonic is
    # amplitude^3 / 192: bound both by amplitude^3 (omega0 t + 1) / 16.
    bound = amplitude**3 * (PLANAR_OMEGA0 * duration + 1) / 16
    assert np.max(np.abs(trajectory.q[:, 0, 0] - PLANAR_DOWN - harmonic)) <= bound
    # And a 0.3 rad swing is not harmonic (the check can fail): it lags by ~omega0 t 0.3^2 / 16.
    wide = ENGINE.build_joint_motion(_scene(PLANAR, PLANAR_GRAVITY, PLANAR_DOWN + 0.3, 0.0, duration=duration),
                                     INTEGRATOR, 0.01).run(300)
    assert np.max(np.abs(wide.q[:, 0, 0] - PLANAR_DOWN - 0.3 * np.cos(PLANAR_OMEGA0 * wide.times))) > 1e-3


@pytest.mark.parametrize("qdot0", [0.0, 9.0], ids=["170 degrees", "turning"])
def test_energy_is_conserved_along_the_closed_form(qdot0):
    scene = _scene(PLANAR, PLANAR_GRAVITY, PLANAR_DOWN + np.radians(170), qdot0, duration=5.0)
    simulation = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01)
    trajectory = simulation.run(500)
    kinetic, potential = simulation.energy(trajectory.q[:, 0], trajectory.qdot[:, 0])
    scale = 1.0 * G * 0.5
    assert np.ptp(kinetic + potential) <= ENERGY_RTOL * scale
    assert np.ptp(kinetic) > scale  # energy does move between the two terms


def test_energy_and_end_effector_against_hand_values():
    scene = _scene(PLANAR, PLANAR_GRAVITY, 0.0, 0.0)
    simulation = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01)
    q, qdot = np.array([[0.0], [np.pi / 2]]), np.array([[2.0], [-1.0]])
    kinetic, potential = simulation.energy(q, qdot)
    # 1/2 0.28 qdot^2; the centre of mass at (0.5, 0, 0) then (0, 0.5, 0): -m g.c = 0, then 9.81 * 0.5.
    np.testing.assert_allclose(kinetic, [0.56, 0.14], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(potential, [0.0, G * 0.5], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(simulation.end_effector_world(q), [[1, 0, 0], [0, 1, 0]], rtol=0, atol=HAND_TOL)


# Copies of the tilted pendulum (omega0 ~2.9 rad/s), from its stable equilibrium: swings of 170 degrees from rest
# (the second a turn lower), a turning one each way, swinging ones starting each way (k^2 ~0.42 and ~0.28).
TILTED_THETA0 = np.array([np.radians(170), np.radians(170) - 2 * np.pi, 0.5, 2.0, 1.0, -0.2])
TILTED_THETADOT0 = np.array([0.0, 0.0, 12.0, -10.0, -2.5, 3.0])


def test_every_copy_starts_from_its_initial_state():
    down = _tilted_down()
    scene = _scene(TILTED, TILTED_GRAVITY, down + TILTED_THETA0, TILTED_THETADOT0)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01).run(1)
    np.testing.assert_allclose(trajectory.q[0, :, 0], scene.q0[:, 0], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(trajectory.qdot[0, :, 0], scene.qdot0[:, 0], rtol=0, atol=HAND_TOL)


@pytest.mark.slow  # ~2 s of CPU: DOP853 at a tight tolerance
def test_the_tilted_pendulum_matches_dop853_at_large_amplitude_and_turning():
    down = _tilted_down()
    q0, qdot0 = down + TILTED_THETA0, TILTED_THETADOT0
    duration = 4.0
    scene = _scene(TILTED, TILTED_GRAVITY, q0, qdot0, duration=duration)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.01).run(400)
    for copy in range(len(q0)):
        solved = _dop853(q0[copy], qdot0[copy], trajectory.times)
        np.testing.assert_allclose(trajectory.q[:, copy, 0], solved[:, 0], rtol=0, atol=ODE_TOL)
        np.testing.assert_allclose(trajectory.qdot[:, copy, 0], solved[:, 1], rtol=0, atol=ODE_TOL * 10)
    turned = trajectory.q[-1, :, 0] - trajectory.q[0, :, 0]
    assert turned[2] > 4 * np.pi and turned[3] < -4 * np.pi  # two copies turn over and over, each its way


def test_a_damped_driven_joint_without_gravity_torque_against_hand_values():
    # Revolute, the centre of mass on the axis (gravity exerts no torque): I = 0.5 + armature 1.5 = 2, b = 0.5,
    # tau = 1: qdot = 2 + (3 - 2) e^(-t / 4), q = 0.2 + 2 t + 4 (1 - e^(-t / 4)).
    chain = _chain(_link(1.0, (0, 0, 0.4), np.diag([0.1, 0.2, 0.5])), damping=0.5, armature=1.5)
    scene = _scene(chain, (0.0, -G, 0.0), 0.2, 3.0, torque=1.0, duration=8.0)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 4.0).run(2)
    decay = np.exp(-trajectory.times / 4)
    np.testing.assert_allclose(trajectory.qdot[:, 0, 0], 2 + decay, rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(trajectory.q[:, 0, 0], 0.2 + 2 * trajectory.times + 4 * (1 - decay), rtol=0,
                               atol=HAND_TOL)


def test_a_pendulum_under_gravity_along_its_axis_accelerates_uniformly():
    # Gravity along +z = the axis: no torque. I = 0.03 + 0.25 = 0.28, tau = 0.14: qddot = 0.5 exactly.
    scene = _scene(PLANAR, (0.0, 0.0, -G), 1.0, -2.0, torque=0.14, duration=2.0)
    trajectory = ENGINE.build_joint_motion(scene, INTEGRATOR, 1.0).run(2)
    t = trajectory.times
    np.testing.assert_allclose(trajectory.q[:, 0, 0], 1.0 - 2.0 * t + 0.25 * t**2, rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(trajectory.qdot[:, 0, 0], -2.0 + 0.5 * t, rtol=0, atol=HAND_TOL)


def test_a_prismatic_joint_feels_gravity_along_its_axis_as_a_constant_force():
    # Mass 2 + armature 0.5 = 2.5 kg along +z; gravity's force m g.n = -19.62 N, tau = 4.62 N: qddot = -6 m/s^2.
    chain = _chain(_link(2.0, (0.1, 0.2, 0.3), np.diag([0.1, 0.1, 0.1])), joint_type="prismatic", armature=0.5)
    scene = _scene(chain, (3.0, -1.0, -G), 0.5, 1.0, torque=4.62, duration=2.0)
    simulation = ENGINE.build_joint_motion(scene, INTEGRATOR, 0.5)
    trajectory = simulation.run(4)
    t = trajectory.times
    np.testing.assert_allclose(trajectory.q[:, 0, 0], 0.5 + t - 3.0 * t**2, rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(trajectory.qdot[:, 0, 0], 1.0 - 6.0 * t, rtol=0, atol=HAND_TOL)
    # Its end effector (1, 0, 0) slides along z: (1, 0, q).
    np.testing.assert_allclose(simulation.end_effector_world(np.array([[0.7]])), [[1.0, 0.0, 0.7]], atol=HAND_TOL)


def _two_joints() -> Chain:
    link = _link(1.0, (0.5, 0, 0), np.diag([0.01, 0.02, 0.03]))
    joints = tuple(Joint(name, "revolute", np.array([0.0, 0, 1]), np.array([x, 0, 0]), np.eye(3), link=link)
                   for name, x in (("shoulder", 0.0), ("elbow", 1.0)))
    return Chain("two", joints)


@pytest.mark.parametrize("scene, words", [
    (_scene(_two_joints(), PLANAR_GRAVITY, [0.1, 0.2], [0.0, 0.0]), "the chain has 2 joints"),
    (_scene(_chain(_link(1.0, (0.5, 0, 0), np.eye(3)), damping=0.1), PLANAR_GRAVITY, 0.3, 0.0),
     "no closed form for a damped pendulum"),
    (_scene(PLANAR, PLANAR_GRAVITY, 0.3, 0.0, torque=0.2), "no closed form for a driven pendulum"),
    (_scene(PLANAR, PLANAR_GRAVITY, [PLANAR_DOWN, PLANAR_DOWN + np.pi], [0.0, 0.0]), "copy 1 starts with the energy"),
    (_scene(_chain(_link(1.0, (0, 0, 0.3), np.zeros((3, 3)))), None, 0.0, 1.0), "moves no inertia"),
], ids=["two joints", "damped pendulum", "driven pendulum", "separatrix", "no inertia"])
def test_refusals_name_the_reason(scene, words):
    support = ENGINE.supports_joint_motion(scene, INTEGRATOR)
    assert not support.ok and words in support.reason
