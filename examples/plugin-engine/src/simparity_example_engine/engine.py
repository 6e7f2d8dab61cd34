"""A simparity engine written as a user would write one, with the bug simparity is there to catch.

:class:`ExampleEngine` simulates free rigid bodies under the forces of a dynamics scene that act on the
centre of mass (gravity, wind, linear and quadratic drag), rotating torque-free. It presents one
integrator, ``rk4``, and claims its order, 4. But its RK4 has a bug (:func:`buggy_rk4_step`): it
computes all four stages and then weights the first one four times, so every step is explicit
Euler's, y + dt k1 — first order. Nothing looks wrong when it runs: the trajectories are smooth and
close to the truth at small steps. ``simparity run --engines core,example --check`` finds it: the
observed order of convergence is 1 where the shipped tolerances hold ``rk4*`` to 4 ± 0.5.

It imports only simparity's data model (``simparity.core.engine``, ``.scene``, ``.trajectory``,
``.errors``): an engine that borrowed core's integrators would agree with their bugs. Conventions
(simparity's): SI units, float64, quaternions (w, x, y, z) body to world, velocities in world axes,
body origin at the centre of mass, a leading batch axis B over the scene's bodies.
"""

from __future__ import annotations

import numpy as np

from simparity.core.engine import Engine, KinematicsModel, Simulation, Support
from simparity.core.errors import SimparityError
from simparity.core.scene import Chain, DynamicsScene
from simparity.core.trajectory import Trajectory
from simparity_example_engine import __version__

INTEGRATOR = "rk4"
"""The one integrator offered, named for the scheme it claims to be (the shipped tolerances' ``rk4*``)."""

CLAIMED_ORDER = 4
"""The global order RK4 has in theory; reports draw it beside the observed one."""

TORQUES = ("angular_linear_drag", "angular_quadratic_drag", "applied_force")
"""Forces of :class:`simparity.core.scene.Forces` this engine cannot apply (it has no torques)."""

RK4_NODES = (0.0, 0.5, 0.5, 1.0)
"""Where in the step each stage is evaluated (the classical Butcher tableau's c)."""
RK4_WEIGHTS = (1.0, 2.0, 2.0, 1.0)
"""The stages' weights, over 6 (the tableau's b, times 6)."""


class ExampleEngine(Engine):
    """Free rigid bodies under centre-of-mass forces, torque-free rotation, one (buggy) ``rk4``."""

    name = "example"

    def version(self) -> str:
        return __version__

    def integrators(self) -> tuple[str, ...]:
        return (INTEGRATOR,)

    def theoretical_order(self, integrator: str) -> int | None:
        return CLAIMED_ORDER if integrator == INTEGRATOR else None

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        named = self.check_integrator(integrator)
        if not named.ok:
            return named
        if scene.contact is not None:
            return Support.no("the example engine has no contact; the scene has planes")
        torques = [force for force in scene.forces.names() if force in TORQUES]
        if torques:
            return Support.no(f"the example engine applies no torque; the scene has {', '.join(torques)}")
        return Support.yes()

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _FreeBodies(scene, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return Support.no("the example engine does dynamics only")

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        raise SimparityError("the example engine does dynamics only (allowed: dynamics scenes)")


def buggy_rk4_step(derivative, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    """One step of "classical RK4" of y' = derivative(t, y), as written with the bug this example demonstrates.

    THE BUG: the weighted sum takes ``stages[0]`` where ``stage`` belongs, so every stage is weighted as the
    first: (1 + 2 + 2 + 1) / 6 = 1 times k1, i.e. y + dt k1, explicit Euler, first order, at four times
    its cost. The fix is ``weight * stage``.

    Parameters
    ----------
    derivative : callable (t [s], y (B, 13)) -> (B, 13)
    t : float
        [s].
    y : (B, 13) ndarray
    dt : float
        [s].
    """
    stages = []
    for node in RK4_NODES:
        state = y if not stages else y + node * dt * stages[-1]
        stages.append(derivative(t + node * dt, state))
    return y + dt / 6.0 * sum(weight * stages[0] for weight, stage in zip(RK4_WEIGHTS, stages))


class _FreeBodies(Simulation):
    """The scene's bodies, each state y = (x [m], v [m/s], q (w, x, y, z), L [kg m^2/s]) in world axes:
    a row of 13 numbers per body, (B, 13)."""

    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        bodies, forces = scene.bodies, scene.forces
        self._dt = dt
        self._mass = np.array([b.mass for b in bodies])[:, None]                       # (B, 1) [kg]
        inertia_body = np.stack([b.inertia_body for b in bodies])                      # (B, 3, 3) [kg m^2]
        self._inverse_inertia_body = np.linalg.inv(inertia_body)                       # (B, 3, 3)
        no_drag = np.zeros(len(bodies))
        self._gravity = np.zeros(3) if forces.gravity_world is None else np.array(forces.gravity_world)
        self._wind = np.zeros(3) if forces.air_velocity_world is None else np.array(forces.air_velocity_world)
        self._linear_drag = (no_drag if forces.linear_drag is None else np.array(forces.linear_drag))[:, None]
        self._quadratic_drag = (no_drag if forces.quadratic_drag is None else np.array(forces.quadratic_drag))[:, None]
        quat = np.stack([b.quat_wxyz for b in bodies])
        rotation = _rotation_matrix(quat)
        inertia_world = rotation @ inertia_body @ rotation.transpose(0, 2, 1)
        omega = np.stack([b.angular_velocity_world for b in bodies])
        self._y0 = np.concatenate([np.stack([b.position_world for b in bodies]), np.stack([b.velocity_world for b in bodies]),
                                   quat, np.einsum("bij,bj->bi", inertia_world, omega)], axis=1)
        self.detail = ("example engine: 'rk4' that weights every stage as the first (explicit Euler, first order: "
                       "the deliberate bug); quaternion renormalised each step")

    def _omega(self, quat: np.ndarray, momentum: np.ndarray) -> np.ndarray:
        """Angular velocity (..., B, 3) [rad/s] from the orientation (..., B, 4) and angular momentum (..., B, 3),
        world axes: omega = R I_body^-1 R^T L."""
        rotation = _rotation_matrix(quat)
        return np.einsum("...ij,...jk,...lk,...l->...i", rotation, self._inverse_inertia_body, rotation, momentum)

    def _derivative(self, t: float, y: np.ndarray) -> np.ndarray:
        """y' (B, 13): (v, F / m, q' = (0, omega) q / 2, L' = 0: no torque)."""
        velocity, quat, momentum = y[:, 3:6], y[:, 6:10], y[:, 10:13]
        air = velocity - self._wind
        force = (self._mass * self._gravity - self._linear_drag * air
                 - self._quadratic_drag * np.linalg.norm(air, axis=1, keepdims=True) * air)
        omega = self._omega(quat, momentum)
        quat_rate = 0.5 * _quat_multiply(np.concatenate([np.zeros((len(y), 1)), omega], axis=1), quat)
        return np.concatenate([velocity, force / self._mass, quat_rate, np.zeros_like(momentum)], axis=1)

    def run(self, n_steps: int) -> Trajectory:
        states = np.empty((n_steps + 1,) + self._y0.shape)                             # (T, B, 13)
        states[0] = y = self._y0
        for i in range(n_steps):
            y = buggy_rk4_step(self._derivative, i * self._dt, y, self._dt)
            y[:, 6:10] /= np.linalg.norm(y[:, 6:10], axis=1, keepdims=True)
            states[i + 1] = y
        quat, momentum = states[..., 6:10], states[..., 10:13]
        return Trajectory(np.arange(n_steps + 1) * self._dt, states[..., 0:3], quat, states[..., 3:6],
                          self._omega(quat, momentum))


def _rotation_matrix(quat: np.ndarray) -> np.ndarray:
    """Body-to-world rotation matrices (..., 3, 3) of unit quaternions (..., 4), (w, x, y, z)."""
    w, x, y, z = np.moveaxis(quat, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)


def _quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a b (B, 4) of quaternions (B, 4), (w, x, y, z)."""
    aw, av, bw, bv = a[:, :1], a[:, 1:], b[:, :1], b[:, 1:]
    return np.concatenate([aw * bw - np.sum(av * bv, axis=1, keepdims=True),
                           aw * bv + bw * av + np.cross(av, bv)], axis=1)
