"""A very tight numerical solve as the reference where no closed form exists.

The rigid-body ODE, written here from the physics and sharing no code with core's
integrators, forces or rotations (a reference must not borrow the code it checks). Per
body the state is (x, q, P, L): centre of mass [m], orientation quaternion (w, x, y, z),
linear momentum [kg m/s] and angular momentum about the COM [kg m^2/s], both world axes:

    dx/dt = P / m
    dq/dt = 1/2 (0, omega) * q          omega = R I_body^-1 R^T L,  R = R(q / |q|)
    dP/dt = m g + F_drag + sum f_i + sum F_k(t)
    dL/dt = tau_drag + sum (R p_i) x f_i + sum tau_k(t) + (R p_k) x F_k(t)

Drag and the applied forces come from :mod:`simparity.references.common.external_forces`, loads that change with
time (F_k(t), tau_k(t)) from :mod:`simparity.references.common.time_loads`, evaluated at the solver's own times.
SciPy's DOP853 (8th order, adaptive) integrates it at relative tolerance 1e-13 (absolute: 1e-13 in each body's own
scales, :func:`absolute_tolerance`) and
is evaluated at the sample times of the step being compared; the quaternion is normalised
on output. A held load jumps at its sample instants: the solve stops at each and starts again from there (an
adaptive solver stepping across a jump would lose its order and its error estimate there). Results name it
``tight:dop853``.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import scipy
from scipy.integrate import solve_ivp

from simparity.core.model.engine import Engine, KinematicsModel, PieceSimulation, Simulation, Support
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory, piece_bounds
from simparity.references.common import external_forces, time_loads
from simparity.references.common.scene_inputs import derives_own_inputs

TOLERANCE = 1e-13
"""rtol of the solve, and its atol in the scene's own units (:func:`absolute_tolerance`). Against the elliptic-function solution of a tumbling box it measured
8e-10 rad over 10 s (12 digits), so it suits scenes whose errors of interest are larger."""

_STATE = 13  # x 3, q 4, P 3, L 3 per body


def _matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (B, 3, 3) of quaternions (B, 4) (w, x, y, z), normalised first."""
    w, x, y, z = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)


def _quaternion_rate(q: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """dq/dt = 1/2 (0, omega) * q (Hamilton product, world-frame omega). (B, 4) x (B, 3) -> (B, 4)."""
    w, v = q[:, :1], q[:, 1:]
    return 0.5 * np.concatenate([-np.sum(omega * v, axis=1, keepdims=True), w * omega + np.cross(omega, v)], axis=1)


def absolute_tolerance(bodies, duration: float) -> np.ndarray:
    """DOP853's atol per component of the state (B * 13,): :data:`TOLERANCE` times each body's own scale of the
    component, its radius of gyration r = sqrt(tr I / 2m) for lengths, its mass m and the run's duration T: x by r,
    q by 1, P by m r / T, L by m r^2 / T. A scene written in other units (a metamorphic rescale) is then solved with
    the same steps, where an atol of 1e-13 in every unit moved the reference by ~1e-13 under a change of units
    (driven-tumbler, 0.36 s: invariance ratio 1.9)."""
    scales = []
    for body in bodies:
        r = float(np.sqrt(np.trace(body.inertia_body) / (2.0 * body.mass)))
        m = body.mass
        scales.append(np.concatenate([np.full(3, r), np.ones(4), np.full(3, m * r / duration),
                                      np.full(3, m * r * r / duration)]))
    return TOLERANCE * np.concatenate(scales)


class _Simulation(PieceSimulation):
    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        bodies = scene.bodies
        self._forces = scene.forces
        self._mass = np.array([b.mass for b in bodies])
        self._inertia_inv = np.linalg.inv(np.stack([b.inertia_body for b in bodies]))
        gravity = np.zeros(3) if scene.forces.gravity_world is None else scene.forces.gravity_world
        self._weight = self._mass[:, None] * gravity
        quat = np.stack([b.quat_wxyz for b in bodies])
        rotation = _matrix(quat)
        inertia_world = rotation @ np.stack([b.inertia_body for b in bodies]) @ np.swapaxes(rotation, 1, 2)
        omega = np.stack([b.angular_velocity_world for b in bodies])
        self._y0 = np.concatenate([
            np.stack([b.position_world for b in bodies]), quat,
            self._mass[:, None] * np.stack([b.velocity_world for b in bodies]),
            np.einsum("bij,bj->bi", inertia_world, omega)], axis=1).ravel()
        self._dt = dt
        self._atol = absolute_tolerance(bodies, scene.duration)
        self._jumps = time_loads.jump_times([f for load in scene.forces.timed for f in load.functions()],
                                            scene.duration)
        self.detail = (f"SciPy {scipy.__version__} DOP853, rtol = {TOLERANCE:g}, atol {TOLERANCE:g} in each body's own "
                       "scales (radius of gyration, mass, duration), on its own right-hand side "
                       "(x, q, P, L)" + ("; " + external_forces.DETAIL if external_forces.has_drag(scene.forces)
                                         or external_forces.has_angular_drag(scene.forces) else "")
                       + (f"; loads that change with time at the solver's own times, restarted at {len(self._jumps)} "
                          "sample instants of held loads" if scene.forces.timed else ""))

    def _velocities(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(v (B, 3), omega (B, 3), R (B, 3, 3)) of the state rows y (B, 13)."""
        rotation = _matrix(y[:, 3:7])
        inertia_world_inv = rotation @ self._inertia_inv @ np.swapaxes(rotation, 1, 2)
        omega = np.einsum("bij,bj->bi", inertia_world_inv, y[:, 10:13])
        return y[:, 7:10] / self._mass[:, None], omega, rotation

    def _derivative(self, t: float, flat: np.ndarray, interval_start: float) -> np.ndarray:
        """dy/dt at time t inside the interval between two jumps of the held loads that starts at
        ``interval_start`` (a held load is what it is inside that interval)."""
        y = flat.reshape(-1, _STATE)
        v, omega, rotation = self._velocities(y)
        applied_force, applied_torque = external_forces.applied_wrench_world(self._forces, rotation)
        force = self._weight + external_forces.drag_force_world(self._forces, v) + applied_force
        torque = external_forces.drag_torque_world(self._forces, omega) + applied_torque
        for load in self._forces.timed:
            f, tau = time_loads.load_wrench_world(load, t, rotation[load.body], interval_start)
            force[load.body] += f
            torque[load.body] += tau
        return np.concatenate([v, _quaternion_rate(y[:, 3:7], omega), force, torque], axis=1).ravel()

    def _solve(self, end: float):
        """The dense solutions of the run to ``end`` [s], one per interval between jumps of the held loads, and the
        intervals' starts."""
        starts = np.concatenate([[0.0], self._jumps[self._jumps < end]])
        solutions, y0 = [], self._y0
        for a, b in zip(starts, np.append(starts[1:], end)):
            sol = solve_ivp(self._derivative, (a, b), y0, method="DOP853", dense_output=True, rtol=TOLERANCE,
                            atol=self._atol, args=(a,))
            if not sol.success:
                raise RuntimeError(f"DOP853 failed: {sol.message}")
            solutions.append(sol.sol)
            y0 = sol.y[:, -1]
        return solutions, starts

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        """One DOP853 solve over the run (one per interval between the held loads' jumps); each piece's samples
        from its dense output (the interpolant of the step each time falls in, as ``t_eval`` would pick it: the
        same values), so memory grows with DOP853's steps, not the run's."""
        solutions, starts = self._solve(n_steps * self._dt)
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            times = np.arange(start, stop) * self._dt
            interval = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(starts) - 1)
            flat = np.empty((len(times), len(self._y0)))
            for k in np.unique(interval):
                flat[interval == k] = solutions[k](times[interval == k]).T
            y = flat.reshape(len(times), -1, _STATE)
            samples = [self._velocities(row) for row in y]
            quat = y[..., 3:7] / np.linalg.norm(y[..., 3:7], axis=-1, keepdims=True)
            yield Trajectory(times, y[..., :3], quat, np.array([v for v, _, _ in samples]),
                             np.array([w for _, w, _ in samples]))


@derives_own_inputs
class TightSolveEngine(Engine):
    """DOP853 at tolerance 1e-13 on the rigid-body ODE: a reference, not an engine under test."""

    name = "tight"

    def version(self) -> str:
        return f"scipy {scipy.__version__}"

    def integrators(self) -> tuple[str, ...]:
        return ("dop853",)

    def scheme(self, integrator: str, scene) -> str:
        """DOP853 at a tight tolerance: a truth, not a scheme users pick."""
        return "adaptive"

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        if scene.contact is not None:
            return Support.no("the tight solve has no contact: its bodies would fly through the planes")
        return self.check_integrator(integrator)

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return Support.no("the tight solve is a dynamics reference only")

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        raise NotImplementedError("the tight solve is a dynamics reference only")
