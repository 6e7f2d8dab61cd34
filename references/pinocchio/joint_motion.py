"""A chain's motion through time on Pinocchio's dynamics (issue #28), and the tight reference of joint motion.

Pinocchio computes dynamics but steps nothing: the harness steps the accelerations of ``pin.aba``, and the rows'
``detail`` says so ("harness-stepped").

What Pinocchio is given, and each default handled (each pinned by ``tests/references/pinocchio/test_joint_motion.py``)
------------------------------------------------------------------------------------------------------
- The model of joint-space dynamics, :func:`references.pinocchio.joint_dynamics.chain_model`: the chain's dynamics
  URDF read by Pinocchio's own parser, ``model.gravity`` exactly the scene's (zero for None, where Pinocchio's
  default is (0, 0, -9.81)), the chain's armature as ``model.armature`` (``aba`` and ``crba`` include it), no
  ``<dynamics>`` (``aba`` ignores ``model.damping`` and ``model.friction`` anyway).
- qddot = ``aba``(q, v, tau - D v): the scene's constant joint forces tau (plus its timed torque at each stage's own
  time t + c dt, :mod:`references.common.time_loads`, a held one as seen from inside the step) minus the chain's
  damping D = diag(damping), evaluated at every stage. The DOP853 solves stop and restart at each jump of a held
  torque. Pinocchio's ``aba`` never applies joint or velocity limits.
- Configurations: a continuous joint (a revolute joint without limits) has nq = 2, (cos q, sin q); the fixed-step
  schemes move the configuration with ``pin.integrate`` and give angles unwrapped: a continuous joint's angle
  accumulates each step's increment ``pin.difference`` (a spinning joint's q is continuous, never wrapped to
  (-pi, pi]); every other joint's value is read from the configuration.
- Integrators (the harness's, on (q, qdot); :data:`SCHEMES`, :data:`ORDERS`, :data:`STAGES`):
  ``explicit_euler`` (q and qdot both from the start of the step), ``semi_implicit_euler`` (qdot first, then q
  with the new qdot), ``rk4`` (classical RK4, the configuration stages by ``pin.integrate`` from the start of the
  step); ``dop853`` / ``dop853_coarse``: ``scipy.integrate.solve_ivp(method="DOP853")`` at rtol 1e-13 /
  1e-11 (atol the same on the angles, and per the scene's duration on qdot: the same solve in any unit of time) on
  (angles, qdot) with ``aba`` as the right-hand side, sampled at k dt by ``t_eval``: the tight reference
  (none of core's code), and its own error floor (the runner takes |dop853 - dop853_coarse|).
- B copies: each copy is stepped (or solved) alone, one after the other; no batched stepping.
- Energy from Pinocchio: kinetic 1/2 v^T M v with M = ``crba`` (armature included), potential
  ``computePotentialEnergy`` (-sum m g . c, with the model's gravity). The end effector is Pinocchio's frame
  placement (``framesForwardKinematics``, ``oMf``) of the chain's end-effector link (its BODY frame); the model's
  root is the chain's base link, so its world is the base frame.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from simparity.core.model.engine import BatchedRun, JointSimulation
from simparity.core.model.errors import DivergedError, NotBatchedError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.time_functions import TimeFunction
from simparity.core.model.trajectory import JointTrajectory
from simparity.references.common import time_loads
from simparity.references.pinocchio.contact import PlaneContact
from simparity.references.pinocchio.joint_dynamics import ChainModel, chain_model
from simparity.references.pinocchio.mass import mass_matrix

SCHEMES = {
    "explicit_euler": "explicit_euler",
    "semi_implicit_euler": "semi_implicit_euler",
    "rk4": "rk4",
    "dop853": "adaptive",
    "dop853_coarse": "adaptive",
}
"""Each joint-motion integrator's kind of scheme (:data:`core.model.engine.SCHEME_KINDS`)."""

INTEGRATORS = tuple(SCHEMES)
"""The joint-motion integrators, the fixed-step ones first."""

ORDERS = {"explicit_euler": 1, "semi_implicit_euler": 1, "rk4": 4}
"""Global order of the fixed-step integrators (the adaptive solves have none)."""

STAGES = {"explicit_euler": 1, "semi_implicit_euler": 1, "rk4": 4}
"""``aba`` calls per step of the fixed-step integrators (the adaptive solves vary from step to step)."""

TOLERANCES = {"dop853": 1e-13, "dop853_coarse": 1e-11}
"""rtol of each DOP853 solve, and its atol on the joint values (on their rates: per the scene's duration): the
reference, and the coarser solve that measures its error floor."""

State = tuple[np.ndarray, np.ndarray]
"""(Pinocchio configuration (nq,), velocity (nv,))."""


def solve_piecewise(derivative: Callable[[float, np.ndarray, float], np.ndarray], y0: np.ndarray, times: np.ndarray,
                    timed: TimeFunction | None, tolerance: float, atol: np.ndarray, label: str) -> np.ndarray:
    """(T, len(y0)): y at ``times`` (T,) [s] by DOP853 at rtol ``tolerance`` and ``atol``, one solve per interval
    between the jumps of a held torque ``timed`` (none: one solve), each from where the one before ended;
    ``derivative(t, y, interval_start)``. A failed solve raises :class:`DivergedError` naming ``label``."""
    end = times[-1]
    jumps = time_loads.jump_times([timed] if timed is not None else [], end)
    starts = np.concatenate([[0.0], jumps])
    y = np.empty((len(times), len(y0)))
    for a, b in zip(starts, np.append(jumps, end)):
        last = b == end
        inside = (times >= a) & ((times < b) | last)
        t_eval = times[inside] if last else np.append(times[inside], b)  # a jump's instant: where the next starts
        sol = solve_ivp(derivative, (a, b), y0, method="DOP853", t_eval=t_eval, rtol=tolerance, atol=atol, args=(a,))
        if not sol.success:
            raise DivergedError(f"{label}: DOP853 failed: {sol.message}")
        y[inside] = sol.y.T if last else sol.y[:, :-1].T
        y0 = sol.y[:, -1]
    return y


class PinocchioJointMotion(JointSimulation):
    """A chain stepped by the harness on ``pin.aba`` (fixed step), or solved by DOP853 on it (see the module
    docstring). Every copy of the scene is stepped alone."""

    def __init__(self, scene: JointMotionScene, integrator: str, dt: float) -> None:
        self._scene, self._integrator, self._dt = scene, integrator, dt
        self._chain: ChainModel = chain_model(scene.chain, scene.gravity_world)
        self._model = self._chain.model
        self._data = self._model.createData()
        self._tau = self._chain.velocity(np.asarray(scene.torque))
        self._timed = scene.timed_torque
        self._damping = self._chain.velocity(self._chain.damping)
        self._end_frame = self._model.getFrameId(scene.chain.end_effector_name, pin.BODY)
        self._contact = None if scene.contact is None else PlaneContact(self._model, scene.chain, scene.contact)
        continuous = np.array(self._chain.continuous, dtype=bool)
        self._cont_n = np.flatnonzero(continuous)
        self._cont_v = self._chain.idx_v[continuous]
        self._lin_n = np.flatnonzero(~continuous)
        self._lin_q = np.array(self._chain.idx_q, dtype=int)[~continuous]
        self.detail = f"{self._chain.source}; harness-stepped: " + (
            f"scipy solve_ivp DOP853, rtol = {TOLERANCES[integrator]:g}, atol the same on q and per duration on qdot, "
            "on (q, qdot) with qddot = "
            "pin.aba(q, v, tau - D v), sampled at k dt (t_eval)" if integrator in TOLERANCES else
            f"{integrator} on (q, qdot), qddot = pin.aba(q, v, tau - D v), q by pin.integrate "
            "(continuous joints' angles unwrapped)") + (
            "" if self._contact is None else f"; {self._contact.detail}")

    def batched(self, copies: int) -> BatchedRun:
        """The harness calls aba copy by copy from Python: NotBatchedError."""
        raise NotBatchedError("the harness steps pinocchio's aba one copy at a time from Python: no batched stepping")

    def run(self, n_steps: int) -> JointTrajectory:
        times = np.arange(n_steps + 1) * self._dt
        b, n = self._scene.q0.shape
        q, qdot = np.empty((n_steps + 1, b, n)), np.empty((n_steps + 1, b, n))
        for k in range(b):
            if self._integrator in TOLERANCES:
                q[:, k], qdot[:, k] = self._solve(self._scene.q0[k], self._scene.qdot0[k], times)
            else:
                self._step_copy(self._scene.q0[k], self._scene.qdot0[k], q[:, k], qdot[:, k])
        return JointTrajectory(times, q, qdot)

    def _acceleration(self, configuration: np.ndarray, v: np.ndarray, t: float, step_start: float) -> np.ndarray:
        """(nv,) qddot = aba(q, v, tau(t) - D v) [rad/s^2 or m/s^2] at stage time t [s] of the step starting at
        ``step_start`` (a copy: ``aba`` returns its own array)."""
        tau = self._tau if self._timed is None else (
            self._tau + self._chain.velocity(time_loads.at(self._timed, t, step_start)))
        return pin.aba(self._model, self._data, configuration, v, tau - self._damping * v)

    def _step_copy(self, q0: np.ndarray, qdot0: np.ndarray, q_out: np.ndarray, qdot_out: np.ndarray) -> None:
        """Step one copy from (q0, qdot0) ((n,) each) into q_out, qdot_out ((T, n) each, T - 1 steps)."""
        step = self._stepper()
        configuration, v = self._chain.configuration(q0), self._chain.velocity(qdot0)
        idx_v, model = self._chain.idx_v, self._model
        angles = np.array(q0, dtype=float)
        q_out[0], qdot_out[0] = q0, qdot0
        for i in range(1, len(q_out)):
            new_configuration, v = step((i - 1) * self._dt, configuration, v)
            angles[self._lin_n] = new_configuration[self._lin_q]
            if len(self._cont_n):
                angles[self._cont_n] += pin.difference(model, configuration, new_configuration)[self._cont_v]
            configuration = new_configuration
            q_out[i], qdot_out[i] = angles, v[idx_v]

    def _stepper(self) -> Callable[[float, np.ndarray, np.ndarray], State]:
        """One step of the fixed-step integrator from time t: (t, configuration, v) -> (configuration, v) after dt."""
        model, dt, acceleration = self._model, self._dt, self._acceleration
        half, sixth = 0.5 * dt, dt / 6

        def explicit_euler(t: float, q: np.ndarray, v: np.ndarray) -> State:
            return pin.integrate(model, q, dt * v), v + dt * acceleration(q, v, t, t)

        def semi_implicit_euler(t: float, q: np.ndarray, v: np.ndarray) -> State:
            v = v + dt * acceleration(q, v, t, t)
            if self._contact is not None:
                v = v + self._contact.solve(q, v)[1]
            return pin.integrate(model, q, dt * v), v

        def rk4(t: float, q: np.ndarray, v: np.ndarray) -> State:
            a1 = acceleration(q, v, t, t)
            v2 = v + half * a1
            a2 = acceleration(pin.integrate(model, q, half * v), v2, t + half, t)
            v3 = v + half * a2
            a3 = acceleration(pin.integrate(model, q, half * v2), v3, t + half, t)
            v4 = v + dt * a3
            a4 = acceleration(pin.integrate(model, q, dt * v3), v4, t + dt, t)
            return (pin.integrate(model, q, sixth * (v + v4 + 2.0 * (v2 + v3))),
                    v + sixth * (a1 + a4 + 2.0 * (a2 + a3)))

        return {"explicit_euler": explicit_euler, "semi_implicit_euler": semi_implicit_euler, "rk4": rk4}[
            self._integrator]

    def _derivative(self, t: float, y: np.ndarray, interval_start: float) -> np.ndarray:
        """d/dt (angles, qdot) ((2n,)) = (qdot, aba) for DOP853, inside the interval between a held torque's jumps
        that starts at ``interval_start``."""
        n = len(y) // 2
        v = self._chain.velocity(y[n:])
        return np.concatenate([y[n:], self._acceleration(self._chain.configuration(y[:n]), v, t,
                                                         interval_start)[self._chain.idx_v]])

    def _solve(self, q0: np.ndarray, qdot0: np.ndarray, times: np.ndarray) -> State:
        """One copy by DOP853 from (q0, qdot0) ((n,) each): (q, qdot), (T, n) each at ``times`` (T,) [s]; one solve
        per interval between a held torque's jumps, each from where the one before ended."""
        tolerance = TOLERANCES[self._integrator]
        n = len(q0)
        y = solve_piecewise(self._derivative, np.concatenate([q0, qdot0]), times, self._timed, tolerance,
                            self._absolute_tolerance(tolerance, n, times[-1]), f"pinocchio {self._integrator}")
        return y[:, :n], y[:, n:]

    @staticmethod
    def _absolute_tolerance(tolerance: float, n: int, duration: float) -> np.ndarray:
        """DOP853's atol per component of (q, qdot) ((2n,)): ``tolerance`` on the joint values and ``tolerance`` per
        ``duration`` [s] on their rates, so that the solve's error control is the same in any unit of time (a scene in
        milliseconds, whose rates are a thousandth, is solved as closely as in seconds)."""
        return np.concatenate([np.full(n, tolerance), np.full(n, tolerance / duration)])

    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic 1/2 v^T M v (``crba``, armature included) and ``computePotentialEnergy``, (B,) each [J]."""
        kinetic, potential = np.empty(len(q)), np.empty(len(q))
        for k, (row, rates) in enumerate(zip(q, qdot)):
            configuration, v = self._chain.configuration(row), self._chain.velocity(rates)
            kinetic[k] = 0.5 * v @ mass_matrix(self._model, self._data, configuration) @ v
            potential[k] = pin.computePotentialEnergy(self._model, self._data, configuration)
        return kinetic, potential

    def contact_centres(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) [m]: the spheres' centres by Pinocchio's forward kinematics (:class:`PlaneContact`)."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        return np.array([self._contact.centres(self._chain.configuration(row)) for row in np.atleast_2d(q)])

    def contact_forces(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray) -> np.ndarray:
        """(B, S, 3) [N]: lambda / dt of the semi-implicit Euler step from each state at its time (the module
        docstring of :mod:`references.pinocchio.contact`)."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        out = []
        for row, rates, t in zip(np.atleast_2d(q), np.atleast_2d(qdot), times):
            configuration, v = self._chain.configuration(row), self._chain.velocity(rates)
            v_free = v + self._dt * self._acceleration(configuration, v, float(t), float(t))
            out.append(self._contact.solve(configuration, v_free)[0] / self._dt)
        return np.array(out)

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        """(B, 3) [m]: Pinocchio's placement of the end-effector link's frame in the model's world, the base frame."""
        out = np.empty((len(q), 3))
        for k, row in enumerate(q):
            pin.framesForwardKinematics(self._model, self._data, self._chain.configuration(row))
            out[k] = self._data.oMf[self._end_frame].translation
        return out
