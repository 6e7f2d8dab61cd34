"""Core's joint-space time stepping (core/articulated/stepping.py, core/articulated/motion.py): orders against a
pendulum solved here by SciPy, the implicit damping's exact one-step factor, batching and the energy read-out."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from simparity.core.articulated import stepping
from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.dynamics.tableau import TABLEAUX
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.model.scenes.joint_motion import JointMotionScene

MASS, LENGTH, G = 1.0, 1.0, 9.81
ROD = LinkInertia(MASS, np.array([LENGTH / 2, 0.0, 0.0]), np.diag([0.0, MASS * LENGTH**2 / 12, MASS * LENGTH**2 / 12]))
AXIS_INERTIA = MASS * LENGTH**2 / 3  # a rod about its end
OMEGA0_SQUARED = MASS * G * LENGTH / 2 / AXIS_INERTIA

ORDER_BAND = 0.15
"""Observed orders over dt = 0.01 .. 0.0025 on a 2 s swing of 60 degrees lie within 0.15 of theory (the next error
term at these steps; measured: explicit Euler 1.04-1.08, semi-implicit 1.003-1.006, midpoint 1.97-1.98, RK4
3.98-4.00)."""

ONE_STEP_RTOL = 1e-14
"""A single step of a linear equation reproduces its factor to rounding."""


def _rod_chain(damping: float = 0.0) -> Chain:
    joint = Joint("hinge", "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.eye(3), link=ROD, damping=damping)
    return Chain("rod", (joint,), end_effector_xyz=np.array([LENGTH, 0.0, 0.0]))


def _scene(q0: float, qdot0: float, gravity: bool = True, damping: float = 0.0, copies: int = 1,
           duration: float = 2.0) -> JointMotionScene:
    return JointMotionScene(
        name="rod", description="", reference="analytic", chain=_rod_chain(damping),
        gravity_world=np.array([0.0, -G, 0.0]) if gravity else None,
        q0=np.full((copies, 1), q0), qdot0=np.full((copies, 1), qdot0), torque=np.zeros(1),
        duration=duration, dts=(0.01,))


def _pendulum_truth(q0: float, times: np.ndarray) -> np.ndarray:
    """q(t) of the rod released at rest: theta'' = -omega0^2 sin(theta), theta = q + pi/2 from hanging (DOP853 here,
    not core)."""
    def rhs(_t, y):
        return [y[1], -OMEGA0_SQUARED * np.sin(y[0])]
    solution = solve_ivp(rhs, (0.0, times[-1]), [q0 + np.pi / 2, 0.0], method="DOP853", rtol=1e-13, atol=1e-13,
                         t_eval=times)
    return solution.y[0] - np.pi / 2


@pytest.mark.parametrize("scheme", stepping.SCHEMES)
def test_observed_order_against_an_independent_pendulum(scheme):
    q0, duration = np.pi / 3 - np.pi / 2, 2.0  # 60 degrees from hanging
    errors = []
    dts = (0.01, 0.005, 0.0025)
    for dt in dts:
        n = int(round(duration / dt))
        traj = CoreJointMotion(_scene(q0, 0.0, duration=duration), scheme, dt).run(n)
        truth = _pendulum_truth(q0, traj.times)
        errors.append(np.abs(traj.q[:, 0, 0] - truth).max())
    slopes = np.diff(np.log(errors)) / np.diff(np.log(dts))
    assert np.all(np.abs(slopes - stepping.ORDER[scheme]) <= ORDER_BAND), (scheme, slopes)


def test_implicit_damping_factor_is_one_over_one_plus_z():
    """One joint, no gravity, damping b: qdot' = qdot I / (I + dt b) exactly; explicit Euler's qdot (1 - dt b / I)."""
    b, dt = 2.5 * AXIS_INERTIA / 0.05, 0.05  # z = dt b / I = 2.5: past explicit Euler's limit
    scene = _scene(0.0, 1.0, gravity=False, damping=b)
    implicit = CoreJointMotion(scene, stepping.IMPLICIT_DAMPING, dt).run(3)
    explicit = CoreJointMotion(scene, stepping.EXPLICIT_EULER, dt).run(3)
    np.testing.assert_allclose(implicit.qdot[:, 0, 0], (1 / 3.5) ** np.arange(4), rtol=ONE_STEP_RTOL)
    np.testing.assert_allclose(explicit.qdot[:, 0, 0], (-1.5) ** np.arange(4), rtol=ONE_STEP_RTOL)
    # the position follows with the new velocity (semi-implicit)
    np.testing.assert_allclose(implicit.q[1, 0, 0], dt / 3.5, rtol=ONE_STEP_RTOL)


def test_copies_step_as_each_alone():
    rng = np.random.default_rng(28)
    q0, qdot0 = rng.uniform(-2, 2, size=(5, 1)), rng.uniform(-3, 3, size=(5, 1))
    batch = JointMotionScene(name="rod", description="", reference="analytic", chain=_rod_chain(0.3),
                             gravity_world=np.array([0.0, -G, 0.0]), q0=q0, qdot0=qdot0, torque=np.array([0.1]),
                             duration=0.5, dts=(0.01,))
    together = CoreJointMotion(batch, stepping.RK4, 0.01).run(50)
    for c in range(5):
        alone = CoreJointMotion(batch.starting_from(q0[c:c + 1], qdot0[c:c + 1], 0.5), stepping.RK4, 0.01).run(50)
        np.testing.assert_array_equal(together.q[:, c], alone.q[:, 0])


def test_energy_and_end_effector_by_hand():
    sim = CoreJointMotion(_scene(0.0, 0.0), stepping.RK4, 0.01)
    q, qdot = np.array([[0.0], [np.pi / 2]]), np.array([[2.0], [0.0]])
    kinetic, potential = sim.energy(q, qdot)
    np.testing.assert_allclose(kinetic, [0.5 * AXIS_INERTIA * 4.0, 0.0], rtol=1e-14)
    # the COM at (0.5, 0) and at (0, 0.5): potential -m g.c = 0 and m g 0.5
    np.testing.assert_allclose(potential, [0.0, MASS * G * 0.5], atol=1e-14)
    np.testing.assert_allclose(sim.end_effector_world(q), [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], atol=1e-15)


def test_unknown_scheme_is_refused():
    with pytest.raises(ValueError, match="allowed: explicit_euler"):
        stepping.stepper(_scene(0.0, 0.0), "leapfrog", 0.01)


def _rk4_by_hand(qddot, q: np.ndarray, qdot: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The classical RK4 step on (q, qdot) written out, summed as dt / 6 (k1 + 2 k2 + 2 k3 + k4)."""
    a1 = qddot(q, qdot)
    v2 = qdot + 0.5 * dt * a1
    a2 = qddot(q + 0.5 * dt * qdot, v2)
    v3 = qdot + 0.5 * dt * a2
    a3 = qddot(q + 0.5 * dt * v2, v3)
    v4 = qdot + dt * a3
    a4 = qddot(q + dt * v3, v4)
    return (q + dt / 6.0 * (qdot + 2.0 * v2 + 2.0 * v3 + v4), qdot + dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4))


def test_the_tableau_steps_sum_as_the_written_out_schemes_to_the_bit():
    """The joints' Runge-Kutta steps read the shared tableau and keep the floating-point order of the formulas they
    replaced (issue #40: results bit for bit), on a nonlinear acceleration of a random batch."""
    rng = np.random.default_rng(40)
    q, qdot = rng.normal(size=(3, 5)), rng.normal(size=(3, 5))
    dt = 0.013

    def qddot(q: np.ndarray, qdot: np.ndarray, t: float = 0.0, step_start: float = 0.0) -> np.ndarray:
        return -np.sin(q) - 0.3 * qdot * np.abs(qdot)

    rk4 = stepping.runge_kutta(TABLEAUX[stepping.RK4], qddot, dt)(0.0, q, qdot)
    assert all(np.array_equal(x, y) for x, y in zip(rk4, _rk4_by_hand(qddot, q, qdot, dt)))
    half = qdot + 0.5 * dt * qddot(q, qdot)
    midpoint = (q + dt * half, qdot + dt * qddot(q + 0.5 * dt * qdot, half))
    got = stepping.runge_kutta(TABLEAUX[stepping.MIDPOINT], qddot, dt)(0.0, q, qdot)
    assert all(np.array_equal(x, y) for x, y in zip(got, midpoint))
    got = stepping.runge_kutta(TABLEAUX[stepping.EXPLICIT_EULER], qddot, dt)(0.0, q, qdot)
    assert all(np.array_equal(x, y) for x, y in zip(got, (q + dt * qdot, qdot + dt * qddot(q, qdot))))
