"""A very tight numerical solve as the reference where no closed form exists.

The lecture's rigid-body ODE dS/dt = (v, 1/2 (0, omega) q, F, tau) with S = (x, q, P, L) per
body (quaternion form), integrated by SciPy's DOP853 (8th order, adaptive) at relative and
absolute tolerance 1e-13, and evaluated at the sample times of the step being compared. The
quaternion is normalised on output. Results name it ``tight:dop853``.
"""

from __future__ import annotations

import numpy as np
import scipy
from scipy.integrate import solve_ivp

from simparity.core.engine import Engine, KinematicsModel, Simulation, Support
from simparity.core.forces import make_wrench
from simparity.core.rigid_body import MassProperties, State, initial_state, velocities
from simparity.core.rotations import quat_wxyz_multiply, quat_wxyz_normalize
from simparity.core.scene import Chain, DynamicsScene
from simparity.core.trajectory import Trajectory

TOLERANCE = 1e-13
"""rtol = atol of the solve. Against the elliptic-function solution of a tumbling box it measured
8e-10 rad over 10 s (12 digits), so it suits scenes whose errors of interest are larger."""


class _Simulation(Simulation):
    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        self._props = MassProperties.of(scene.bodies)
        self._wrench = make_wrench(scene.forces, self._props)
        s0 = initial_state(scene.bodies, self._props, quaternion=True)
        self._y0 = self._pack(s0)
        self._b = len(scene.bodies)
        self._duration, self._dt = scene.duration, dt
        self.detail = f"SciPy {scipy.__version__} DOP853, rtol = atol = {TOLERANCE:g}, quaternion form"

    @staticmethod
    def _pack(s: State) -> np.ndarray:
        return np.concatenate(
            [s.position_world, s.orientation, s.momentum_world, s.angular_momentum_world], axis=1).ravel()

    def _unpack(self, y: np.ndarray) -> State:
        y = y.reshape(self._b, 13)
        return State(y[:, :3], y[:, 3:7], y[:, 7:10], y[:, 10:13])

    def _derivative(self, t: float, y: np.ndarray) -> np.ndarray:
        s = self._unpack(y)
        v, omega = velocities(s, self._props)
        force, torque = self._wrench(t, s.position_world, s.rotation_world, v, omega)
        zero = np.zeros((self._b, 1))
        q_dot = 0.5 * quat_wxyz_multiply(np.concatenate([zero, omega], axis=1), s.orientation)
        return np.concatenate([v, q_dot, force, torque], axis=1).ravel()

    def run(self, n_steps: int) -> Trajectory:
        times = np.arange(n_steps + 1) * self._dt
        sol = solve_ivp(self._derivative, (0.0, times[-1]), self._y0, method="DOP853", t_eval=times,
                        rtol=TOLERANCE, atol=TOLERANCE)
        if not sol.success:
            raise RuntimeError(f"DOP853 failed: {sol.message}")
        y = sol.y.T.reshape(len(times), self._b, 13)
        pos, quat, vel, omg = [], [], [], []
        for row in y:
            s = State(row[:, :3], quat_wxyz_normalize(row[:, 3:7]), row[:, 7:10], row[:, 10:13])
            v, omega = velocities(s, self._props)
            pos.append(s.position_world), quat.append(s.orientation), vel.append(v), omg.append(omega)
        return Trajectory(times, np.array(pos), np.array(quat), np.array(vel), np.array(omg))


class TightSolveEngine(Engine):
    """DOP853 at tolerance 1e-13 on the rigid-body ODE: a reference, not an engine under test."""

    name = "tight"

    def version(self) -> str:
        return f"scipy {scipy.__version__}"

    def integrators(self) -> tuple[str, ...]:
        return ("dop853",)

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        return self.check_integrator(integrator)

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return Support.no("the tight solve is a dynamics reference only")

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        raise NotImplementedError("the tight solve is a dynamics reference only")
