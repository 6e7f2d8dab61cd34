"""A floating-base chain's motion through time on Pinocchio's dynamics: its free flyer
(:class:`references.pinocchio.floating.PinocchioFloatingDynamics`, the project's convention), stepped by the harness.

Pinocchio steps nothing. The harness steps the project's state (position, quat_wxyz, joints; world-axes base velocity,
joint rates) with ``aba``'s acceleration converted to it: the configuration by its rate dq/dt = (v, 1/2 (0, omega) q,
joint rates) (:func:`references.common.floating_base.configuration_rate`: the quaternion in R^4), the quaternion
normalised after each step and at each stage where the dynamics is evaluated. ``pin.integrate`` is not used here: its
free-flyer exponential moves a configuration by a velocity in that configuration's own LOCAL frame, and a Runge-Kutta
combination of stage velocities taken at different configurations would not keep the scheme's order.

- ``explicit_euler``, ``semi_implicit_euler``, ``rk4``: as :mod:`references.pinocchio.joint_motion`'s (the same names,
  orders and stages) on that state.
- ``dop853`` / ``dop853_coarse``: ``scipy.integrate.solve_ivp(method="DOP853")`` at rtol 1e-13 / 1e-11 on (q, qdot)
  in R^(13 + 2n), atol the same on q and on qdot that times the larger of 1 / duration and the largest initial speed
  (a base thrown at 1 km/s carries its velocity through the base-frame terms that cancel in the joints' accelerations:
  their rounding, eps x that speed, would stall a solve asked for less), the quaternion normalised at each sample: the
  tight reference and its error floor. A non-finite state (a diverged run) makes every later one NaN.
- The joints' applied forces: the scene's constant ones (a timed torque at each stage's time); none on the base.
- Energy: kinetic 1/2 v^T M v (Pinocchio's ``crba`` turned to the project's velocity), potential
  ``computePotentialEnergy``; momentum ``computeCentroidalMomentum``; the end effector's world position by
  ``framesForwardKinematics``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from simparity.core.model.engine import BatchedRun, JointSimulation
from simparity.core.model.errors import NotBatchedError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory
from simparity.references.common import time_loads
from simparity.references.common.floating_base import BASE_V, configuration_rate, unit_quaternions
from simparity.references.pinocchio.contact import PlaneContact
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pinocchio.joint_motion import TOLERANCES, solve_piecewise

Step = Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
"""(t, q (1, 7 + n), qdot (1, 6 + n)) -> the state after dt."""


class PinocchioFloatingMotion(JointSimulation):
    """A floating-base chain stepped by the harness on Pinocchio's free flyer (the module docstring); every copy is
    stepped alone."""

    def __init__(self, scene: JointMotionScene, integrator: str, dt: float) -> None:
        self._scene, self._integrator, self._dt = scene, integrator, dt
        self._dynamics = PinocchioFloatingDynamics(scene.chain, scene.gravity_world)
        self._model, self._data = self._dynamics.model, self._dynamics.data
        self._end_frame = self._model.getFrameId(scene.chain.end_effector_name, pin.BODY)
        self._contact = None if scene.contact is None else PlaneContact(self._model, scene.chain, scene.contact)
        self.detail = f"{self._dynamics.detail}; harness-stepped on the project's state: " + (
            f"scipy solve_ivp DOP853, rtol = {TOLERANCES[integrator]:g}, on (q, qdot) with the quaternion in R^4"
            if integrator in TOLERANCES else
            f"{integrator}, q by its rate (the quaternion in R^4, normalised after each step)") + (
            "" if self._contact is None else f"; {self._contact.detail}")

    def batched(self, copies: int) -> BatchedRun:
        raise NotBatchedError("the harness steps pinocchio's aba one copy at a time from Python: no batched stepping")

    def _acceleration(self, q: np.ndarray, qdot: np.ndarray, t: float, step_start: float) -> np.ndarray:
        """(1, 6 + n) qddot at stage time t of the step starting at ``step_start``: the joints' applied forces,
        none on the base; the stage's quaternion normalised."""
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qdot))):  # a diverged run: NaN on, never a raise
            return np.full(np.shape(qdot), np.nan)
        scene = self._scene
        joints = scene.torque if scene.timed_torque is None else (
            scene.torque + time_loads.at(scene.timed_torque, t, step_start))
        tau = np.concatenate([np.zeros(BASE_V), joints])[None]
        return self._dynamics.forward_dynamics(unit_quaternions(q), qdot, tau)

    def _stepper(self) -> Step:
        dt, acceleration = self._dt, self._acceleration
        half, sixth = 0.5 * dt, dt / 6

        def explicit_euler(t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return unit_quaternions(q + dt * configuration_rate(q, v)), v + dt * acceleration(q, v, t, t)

        def semi_implicit_euler(t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            v = v + dt * acceleration(q, v, t, t)
            if self._contact is not None:
                v = v + self._impulse(q, v)[1]
            return unit_quaternions(q + dt * configuration_rate(q, v)), v

        def rk4(t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            k1, a1 = configuration_rate(q, v), acceleration(q, v, t, t)
            q2, v2 = q + half * k1, v + half * a1
            k2, a2 = configuration_rate(q2, v2), acceleration(q2, v2, t + half, t)
            q3, v3 = q + half * k2, v + half * a2
            k3, a3 = configuration_rate(q3, v3), acceleration(q3, v3, t + half, t)
            q4, v4 = q + dt * k3, v + dt * a3
            k4, a4 = configuration_rate(q4, v4), acceleration(q4, v4, t + dt, t)
            return (unit_quaternions(q + sixth * (k1 + k4 + 2.0 * (k2 + k3))),
                    v + sixth * (a1 + a4 + 2.0 * (a2 + a3)))

        return {"explicit_euler": explicit_euler, "semi_implicit_euler": semi_implicit_euler, "rk4": rk4}[
            self._integrator]

    def _impulse(self, q: np.ndarray, v_free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(impulses (S, 3) [N s] in world axes, the project's velocity change (1, 6 + n)) of the contact solve of the
        step from q (1, 7 + n) with unconstrained velocity ``v_free`` (1, 6 + n) (:class:`PlaneContact`)."""
        assert self._contact is not None
        q = unit_quaternions(q)
        impulses, change = self._contact.solve(self._dynamics.configuration(q[0]),
                                               self._dynamics.local_velocity(q, v_free))
        return impulses, self._dynamics.project_velocity(q, change)

    def contact_centres(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) [m]: the spheres' centres by Pinocchio's forward kinematics (:class:`PlaneContact`)."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        return np.array([self._contact.centres(self._dynamics.configuration(row))
                         for row in unit_quaternions(np.atleast_2d(q))])

    def contact_forces(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray) -> np.ndarray:
        """(B, S, 3) [N]: lambda / dt of the semi-implicit Euler step from each state at its time
        (:mod:`references.pinocchio.contact`)."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        out = []
        for row, rates, t in zip(np.atleast_2d(q), np.atleast_2d(qdot), times):
            state, v = row[None], rates[None]
            v_free = v + self._dt * self._acceleration(state, v, float(t), float(t))
            out.append(self._impulse(state, v_free)[0] / self._dt)
        return np.array(out)

    def run(self, n_steps: int) -> JointTrajectory:
        times = np.arange(n_steps + 1) * self._dt
        q0, qdot0 = np.asarray(self._scene.q0), np.asarray(self._scene.qdot0)
        q, qdot = np.empty((n_steps + 1,) + q0.shape), np.empty((n_steps + 1,) + qdot0.shape)
        for k in range(len(q0)):
            if self._integrator in TOLERANCES:
                q[:, k], qdot[:, k] = self._solve(q0[k], qdot0[k], times)
                continue
            step, state = self._stepper(), (q0[k:k + 1], qdot0[k:k + 1])
            q[0, k], qdot[0, k] = q0[k], qdot0[k]
            for i in range(1, n_steps + 1):
                state = step((i - 1) * self._dt, *state)
                q[i, k], qdot[i, k] = state[0][0], state[1][0]
        return JointTrajectory(times, q, qdot)

    def _solve(self, q0: np.ndarray, qdot0: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One copy by DOP853: (q, qdot) at ``times``, one solve per interval between a held torque's jumps."""
        tolerance, nq, end = TOLERANCES[self._integrator], len(q0), times[-1]

        def derivative(t: float, y: np.ndarray, interval_start: float) -> np.ndarray:
            q, v = y[None, :nq], y[None, nq:]
            return np.concatenate([configuration_rate(q, v)[0], self._acceleration(q, v, t, interval_start)[0]])

        speed = max(1.0 / end, float(np.abs(qdot0).max()))
        atol = np.concatenate([np.full(nq, tolerance), np.full(len(qdot0), tolerance * speed)])
        y = solve_piecewise(derivative, np.concatenate([q0, qdot0]), times, self._scene.timed_torque, tolerance, atol,
                            f"pinocchio {self._integrator}")
        return unit_quaternions(y[:, :nq]), y[:, nq:]

    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        kinetic = 0.5 * np.einsum("bi,bij,bj->b", qdot, self._dynamics.mass_matrix(q), qdot)
        potential = np.array([pin.computePotentialEnergy(self._model, self._data, self._dynamics.configuration(row))
                              for row in q])
        return kinetic, potential

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((len(q), 3))
        for k, row in enumerate(q):
            pin.framesForwardKinematics(self._model, self._data, self._dynamics.configuration(row))
            out[k] = self._data.oMf[self._end_frame].translation
        return out

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        linear, angular, _ = self._dynamics.centroidal_momentum(q, qdot)
        return np.concatenate([linear, angular], axis=1)
