"""A chain stepped through time by MuJoCo's own integrators (issue #28).

What MuJoCo is given (each pinned by ``tests/references/mujoco/test_joint_motion.py``)
---------------------------------------------------------------------------
- The joint-dynamics model (the builder both share, :class:`references.mujoco.joint_dynamics.ChainModel`):
  MuJoCo's URDF importer on :func:`references.common.dynamics_urdf.dynamics_urdf`, gravity exactly the scene's
  (None is zero), constraints disabled (joint limits never act), ``dof_damping`` and ``dof_armature`` the chain's,
  frictionloss, stiffness and polynomial damping 0. The model has no actuator, no contact and no fluid
  (``density`` = ``viscosity`` = 0, no wind), no gravity compensation, and sleeping is off (``enableflags`` 0).
- ``opt.timestep`` = dt and ``opt.integrator`` as :data:`INTEGRATORS` says. MuJoCo's Euler takes joint damping
  implicitly unless ``eulerdamp`` is disabled: ``euler`` keeps MuJoCo's default (velocity update with M + dt D),
  ``euler_explicit_damping`` disables it (plain semi-implicit Euler, damping explicit). ``implicitfast`` linearises
  the damping implicitly and drops the Coriolis derivatives; ``implicit`` keeps them. ``rk4`` is the classical
  Runge-Kutta of ``mj_RungeKutta`` (damping explicit, four ``mj_forward`` per step).
- Applied joint forces: ``qfrc_applied`` = the scene's constant torque on the chain's dofs, given to
  ``mujoco.rollout`` as a control of spec ``mjSTATE_QFRC_APPLIED`` (one row, held over every step and stage). A
  timed torque (:mod:`references.common.time_loads`) is added at every stage by MuJoCo's control callback at the
  stage's ``d.time`` (:mod:`references.mujoco.stage_loads`), in an ``mj_step`` loop per copy instead of the rollout.
- Stepping: ``mujoco.rollout`` from the B initial states (``mjSTATE_FULLPHYSICS``: time, qpos, qvel) in one call on
  the calling thread, bit-identical to an ``mj_step`` loop; its rows are the states AFTER each step, the initial
  state is prepended and the samples are at k dt. qpos and qvel are read at the chain joints' addresses (mapped by
  name; a continuous joint is a hinge, its qpos the unwrapped angle).
- Velocities: MuJoCo clips nothing. A state it finds bad (NaN or a magnitude above ``mjMAXVAL`` = 1e10 in qpos,
  qvel or qacc) it would reset to the model's initial one and carry on; every MuJoCo warning while stepping raises
  :class:`DivergedError` with MuJoCo's message instead (a chain without contact, constraints or actuators has no
  other runtime warning).
- Energy from MuJoCo's own model after ``mj_fwdPosition``: kinetic 1/2 qvel^T M qvel with ``mj_mulM`` (armature
  in M), potential -sum_b body_mass_b gravity . xipos_b (MuJoCo's ``mj_energyPos`` convention, which would add
  spring energies: there are none). Every body belongs to a chain link or is welded to the base, massless.
- End effector: MuJoCo's forward kinematics (``mj_kinematics``), the origin ``xpos`` of the body named after the
  chain's end effector (kept as a body: ``fusestatic`` off). The base link is MuJoCo's world frame.
- A floating base: the builder's free joint on the root body (:mod:`references.mujoco.floating`); its qpos is the
  project's (position, quat_wxyz), its qvel (v in world axes, R^T omega in the body frame): the angular part is turned
  in and out (:mod:`references.common.floating_base`). MuJoCo integrates the free joint's quaternion by its own
  exponential map in the body frame; momentum from ``mj_subtreeVel`` (:class:`MujocoFloatingDynamics`). No step
  Jacobian yet.
"""

from __future__ import annotations

import mujoco
import numpy as np
from mujoco import rollout

from simparity.core.model.derivatives import FiniteDifferences, StepJacobian
from simparity.core.model.engine import BatchedRun, JointSimulation
from simparity.core.model.errors import DivergedError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory
from simparity.references.common.conventions import fmt
from simparity.references.common import time_loads
from simparity.references.common.floating_base import base_rotations, turned_base
from simparity.references.mujoco.contact import ContactReader, detail as contact_detail
from simparity.references.mujoco.floating import MujocoFloatingDynamics
from simparity.references.mujoco.joint_dynamics import ChainModel
from simparity.references.mujoco.stage_loads import DETAIL as STAGE_DETAIL
from simparity.references.mujoco.stage_loads import StepClock, stage_callback

_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS
TRANSITION_FD_STEP = 1e-6
"""``mjd_transitionFD``'s eps, centred: truncation eps^2 / 6 |d3 x'| ~ 1e-13, rounding eps_machine |x'| / eps ~ 1e-10
of the step's scale."""

INTEGRATORS = {
    "euler": (mujoco.mjtIntegrator.mjINT_EULER, 0),
    "euler_explicit_damping": (mujoco.mjtIntegrator.mjINT_EULER, int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)),
    "implicitfast": (mujoco.mjtIntegrator.mjINT_IMPLICITFAST, 0),
    "implicit": (mujoco.mjtIntegrator.mjINT_IMPLICIT, 0),
    "rk4": (mujoco.mjtIntegrator.mjINT_RK4, 0),
}
"""simparity's joint-motion integrator -> (``opt.integrator``, disable bits added to ``opt.disableflags``)."""

SCHEMES = {
    "euler": "implicit_damping",
    "euler_explicit_damping": "semi_implicit_euler",
    "implicitfast": "implicit_damping",
    "implicit": "implicit_velocity",
    "rk4": "rk4",
}
"""The kind of scheme (``SCHEME_KINDS``) each integrator is on a chain: Euler with eulerdamp and implicitfast take
the joint damping implicitly (implicitfast's other implicit terms, actuators and tendons, are absent here), implicit
also linearises the Coriolis and centrifugal forces."""

ORDERS = {"euler": 1, "euler_explicit_damping": 1, "implicitfast": 1, "implicit": 1, "rk4": 4}
"""Global order of each integrator (MuJoCo's docs, "Numerical integration")."""

STAGES = {"euler": 1, "euler_explicit_damping": 1, "implicitfast": 1, "implicit": 1, "rk4": 4}
"""``mj_forward`` evaluations per step (the implicit ones, eulerdamp included, also factor M + dt D once a step)."""


class MujocoJointMotion(JointSimulation):
    """A joint-motion scene in MuJoCo for one integrator and time step (see the module docstring).

    Attributes
    ----------
    model : mujoco.MjModel
    detail : str
    """

    def __init__(self, scene: JointMotionScene, integrator: str, dt: float) -> None:
        self._scene, self._integrator = scene, integrator
        built = ChainModel(scene.chain, scene.gravity_world, contact=scene.contact)
        self.model, self._dof, self._qpos = built.model, built.dof, built.qpos
        self._contact = ContactReader(self.model, scene.contact) if scene.contact is not None else None
        self._floating = MujocoFloatingDynamics(scene.chain, scene.gravity_world) if scene.chain.floating_base else None
        if self._floating is not None:
            self._dof, self._qpos = self._floating.state_dof, self._floating.state_qpos
        kind, disabled = INTEGRATORS[integrator]
        self.model.opt.integrator, self.model.opt.timestep = kind, dt
        self.model.opt.disableflags |= disabled
        self._data = mujoco.MjData(self.model)
        self._end_effector = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, scene.chain.end_effector_name)
        self._control = np.zeros((1, 1, self.model.nv))
        self._control[0, 0, self._dof[len(self._dof) - scene.chain.n_joints:]] = scene.torque
        self._timed = scene.timed_torque
        self._clock = StepClock()
        self._qpos_at = mujoco.mj_stateSize(self.model, mujoco.mjtState.mjSTATE_TIME)
        self._qvel_at = self._qpos_at + self.model.nq
        self._initial = self._states(scene.q0, scene.qdot0)
        self._dt = dt
        damping = ("eulerdamp disabled: damping explicit" if disabled else
                   "eulerdamp on (MuJoCo's default): damping implicit" if integrator == "euler" else "")
        self.detail = (f"{built.detail}; integrator {kind.name} at timestep {dt:g} s"
                       + (f", {damping}" if damping else "")
                       + (f"; qfrc_applied {fmt(scene.torque)} held constant (rollout control mjSTATE_QFRC_APPLIED); "
                          "stepped by mujoco.rollout" if self._timed is None else
                          f"; qfrc_applied {fmt(scene.torque)} plus the timed torque, {STAGE_DETAIL}; mj_step loop")
                       + "; no velocity clipping; a MuJoCo warning (bad state, reset) raises "
                       "DivergedError; energy by mj_mulM and -sum m g.xipos; end effector by mj_kinematics"
                       + ("; the base a free joint, its body-frame angular velocity turned to world axes; momentum "
                          "by mj_subtreeVel" if self._floating is not None else "")
                       + (f"; {contact_detail(scene.contact)}" if scene.contact is not None else ""))

    def _own(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """MuJoCo's qvel rows of the project's (B, nv): a floating base's angular velocity turned into its body frame
        (qdot itself on a fixed base)."""
        return qdot if self._floating is None else turned_base(base_rotations(q), qdot, False, True, inverse=True)

    def _states(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, nstate) full-physics states at time 0 with the chain's joints at ``q`` and ``qdot`` ((B, nq), (B, nv))."""
        template = np.empty(mujoco.mj_stateSize(self.model, _STATE))
        mujoco.mj_getState(self.model, mujoco.MjData(self.model), template, _STATE)
        states = np.repeat(template[None], len(q), axis=0)
        states[:, self._qpos_at + self._qpos] = q
        states[:, self._qvel_at + self._dof] = self._own(q, qdot)
        return states

    def _rollout(self, initial: np.ndarray, n_steps: int) -> np.ndarray:
        """(R, n_steps, nstate): the states after each step from each of the R initial states, one rollout call (an
        ``mj_step`` loop per state under a timed torque)."""
        if self._timed is not None:
            with stage_callback(self._stage_torque):
                return np.stack([self._loop(state, n_steps) for state in initial])
        states, _ = rollout.rollout(self.model, self._data, initial, self._control,
                                    control_spec=mujoco.mjtState.mjSTATE_QFRC_APPLIED, nstep=n_steps)
        return states

    def _stage_torque(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """MuJoCo's control callback: qfrc_applied = the constant torque plus the timed one at the stage's time."""
        assert self._timed is not None  # installed only with a timed torque
        d.qfrc_applied[:] = self._control[0, 0]
        d.qfrc_applied[self._dof[len(self._dof) - self._scene.chain.n_joints:]] += time_loads.at(self._timed, self._clock.stage_time(d.time),
                                                   self._clock.step_start)

    def _loop(self, initial: np.ndarray, n_steps: int) -> np.ndarray:
        """(n_steps, nstate): the states after each of ``n_steps`` mj_steps from the state ``initial``."""
        m, d = self.model, self._data
        mujoco.mj_setState(m, d, initial, _STATE)
        states = np.empty((n_steps, len(initial)))
        for i in range(n_steps):
            self._clock.start(i, self._dt, d.time)
            mujoco.mj_step(m, d)
            mujoco.mj_getState(m, d, states[i], _STATE)
        return states

    def run(self, n_steps: int) -> JointTrajectory:
        for warning in self._data.warning:  # MuJoCo reports a warning only while its counter is 0
            warning.number = 0
        messages: list[str] = []
        mujoco.set_mju_user_warning(messages.append)
        try:
            stepped = self._rollout(self._initial, n_steps)
        finally:
            mujoco.set_mju_user_warning(None)
        if messages:
            raise DivergedError(f"MuJoCo warned while stepping (it resets an unstable simulation): {messages[0]}")
        states = np.concatenate([self._initial[:, None], stepped], axis=1).transpose(1, 0, 2)  # (T, B, nstate)
        q, qvel = states[..., self._qpos_at + self._qpos], states[..., self._qvel_at + self._dof]
        if self._floating is not None:  # the body-frame angular velocity turned to world axes
            flat_q = q.reshape(-1, q.shape[-1])
            qvel = turned_base(base_rotations(flat_q), qvel.reshape(-1, qvel.shape[-1]), False, True).reshape(
                qvel.shape)
        return JointTrajectory(np.arange(n_steps + 1) * self._dt, q, qvel)

    def step_jacobian(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> StepJacobian:
        """``mjd_transitionFD`` (centred differences at :data:`TRANSITION_FD_STEP` of the state and the controls) on
        the same model, integrator and timestep with a motor on each chain joint (``ChainModel(motors=True)``: ctrl
        is τ; the stepping model has none), at B states with qfrc_applied 0: A's and B's rows and columns of the
        chain's dofs (MuJoCo's x = (the q tangent, qvel): a hinge's or slide's tangent is its qpos)."""
        kind, disabled = INTEGRATORS[self._integrator]
        if self._contact is not None:
            raise NotImplementedError("the step Jacobian with contact is not compared yet (mjd_transitionFD would "
                                      "differentiate MuJoCo's soft contact, which no other engine shares)")
        if self._floating is not None:
            raise NotImplementedError("the step Jacobian of a floating base (its quaternion's tangent) is not "
                                      "converted yet")
        if kind == mujoco.mjtIntegrator.mjINT_RK4:
            raise NotImplementedError("MuJoCo's mjd_transitionFD does not differentiate its RK4 step (\"RK4 "
                                      "integrator is not supported\")")
        built = ChainModel(self._scene.chain, self._scene.gravity_world, motors=True)
        m = built.model
        m.opt.integrator, m.opt.timestep = kind, self._dt
        m.opt.disableflags |= disabled
        d = mujoco.MjData(m)
        index = np.r_[built.dof, m.nv + built.dof]
        by_state, by_force = np.zeros((2 * m.nv, 2 * m.nv)), np.zeros((2 * m.nv, m.nu))
        out = np.empty((len(q), len(index), len(index))), np.empty((len(q), len(index), len(built.dof)))
        for k, (row, rates, force) in enumerate(zip(q, qdot, tau)):
            d.qpos[built.qpos], d.qvel[built.dof], d.ctrl[:] = row, rates, force
            d.qfrc_applied[:] = 0.0
            mujoco.mjd_transitionFD(m, d, TRANSITION_FD_STEP, True, by_state, by_force, None, None)
            out[0][k], out[1][k] = by_state[np.ix_(index, index)], by_force[index]
        steps = np.full(len(q), TRANSITION_FD_STEP)
        return StepJacobian(out[0], out[1], FiniteDifferences(True, steps, steps))

    def batched(self, copies: int) -> BatchedRun:
        """``copies`` rollouts of the first initial state in one ``mujoco.rollout`` call, as :meth:`run` makes; it
        returns the (copies, n_steps, nstate) states after each step."""
        initial = np.repeat(self._initial[:1], copies, axis=0)
        return lambda n_steps: self._rollout(initial, n_steps)

    def _position(self, q_row: np.ndarray, qdot_row: np.ndarray) -> mujoco.MjData:
        """Data at the state, after ``mj_fwdPosition`` (kinematics, centres of mass, M with armature)."""
        d = self._data
        d.qpos[:], d.qvel[:] = self.model.qpos0, 0.0
        d.qpos[self._qpos], d.qvel[self._dof] = q_row, qdot_row
        mujoco.mj_fwdPosition(self.model, d)
        return d

    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        kinetic, potential = np.empty(len(q)), np.empty(len(q))
        m_qvel = np.empty(self.model.nv)
        for k, (row, rates) in enumerate(zip(q, self._own(q, qdot))):
            d = self._position(row, rates)
            mujoco.mj_mulM(self.model, d, m_qvel, d.qvel)
            kinetic[k] = 0.5 * d.qvel @ m_qvel
            potential[k] = -self.model.body_mass @ (d.xipos @ self.model.opt.gravity)
        return kinetic, potential

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((len(q), 3))
        d = self._data
        for k, row in enumerate(q):
            d.qpos[:] = self.model.qpos0
            d.qpos[self._qpos] = row
            mujoco.mj_kinematics(self.model, d)
            out[k] = d.xpos[self._end_effector]
        return out

    def contact_centres(self, q: np.ndarray) -> np.ndarray:
        """The sphere geoms' centres (:class:`references.mujoco.contact.ContactReader`)."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        return self._contact.centres(self._qpos, self._dof, np.asarray(q, dtype=float))

    def contact_forces(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray) -> np.ndarray:
        """MuJoCo's contact forces on the spheres at each state (:class:`references.mujoco.contact.ContactReader`),
        under ``qfrc_applied`` as the run had it at each time: its soft contact's force balances the applied forces
        too."""
        if self._contact is None:
            raise NotImplementedError("the scene has no contact")
        q = np.asarray(q, dtype=float)
        applied = np.repeat(self._control[0, :1], len(q), axis=0)
        if self._timed is not None:
            joints = self._dof[len(self._dof) - self._scene.chain.n_joints:]
            applied[:, joints] += np.array([time_loads.at(self._timed, float(t)) for t in times])
        return self._contact.forces(self._qpos, self._dof, q, self._own(q, np.asarray(qdot, dtype=float)), applied)

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """A floating base's: :meth:`MujocoFloatingDynamics.centroidal_momentum` (``mj_subtreeVel``)."""
        if self._floating is None:
            raise NotImplementedError("a fixed base's momentum is not conserved: it is not reported")
        linear, angular, _ = self._floating.centroidal_momentum(q, qdot)
        return np.concatenate([linear, angular], axis=1)
