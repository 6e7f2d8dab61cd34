"""MuJoCo behind the shared engine interface.

Conversions (each pinned by a test in ``tests/references/mujoco/test_adapter.py``)
----------------------------------------------------------------------
- ``qpos[3:7]`` and MJCF ``quat`` are (w, x, y, z): no reordering.
- Free-joint ``qvel[0:3]`` is the world-frame velocity of the body ORIGIN; the body origin
  is the centre of mass here (``<inertial pos="0 0 0">``), so it is the COM velocity.
- Free-joint ``qvel[3:6]`` is the angular velocity in the BODY frame: world = R qvel[3:6].
- Stepping uses ``mujoco.rollout`` (bit-identical to an ``mj_step`` loop), whose state
  rows are the state AFTER each step; the initial state is prepended.
- Forces, the way MuJoCo users apply them: linear drag and linear angular drag are
  MuJoCo's own ``dof_damping`` on the free joint (translational damping acts on the
  world-frame origin velocity = COM velocity, rotational on the local angular velocity;
  isotropic, so both equal the scene's drag), with ``eulerdamp`` disabled so that Euler
  treats damping explicitly, as every other engine does (the implicit integrators keep it
  implicit, by design). Wind adds the constant force b w, passed to rollout as
  ``xfrc_applied``. A force at a body point is applied at the point's WORLD position with
  ``mj_applyFT`` (MuJoCo computes its torque). Quadratic drags, which MuJoCo does not
  model, come from :mod:`references.common.external_forces` (independent of core) as
  ``xfrc_applied``. Both are set from the state at the start of each step (positions
  updated by ``mj_kinematics`` and ``mj_comPos`` first) and held over the step by an
  ``mj_step`` loop; its RK4 then sees them as constant within a step.
- Loads that change with time (:mod:`references.common.time_loads`, independent of core) are evaluated at every
  stage: MuJoCo calls its control callback (``mjcb_control``) in each ``mj_forward`` of a step, RK4's four with
  ``d.time`` at the stage's time t + c dt (:mod:`references.mujoco.stage_loads`); the callback adds each load to
  that step's ``qfrc_applied`` with ``mj_applyFT`` at the stage's body pose.
- Instability: MuJoCo does not return NaN; it warns ("Nan, Inf or huge value in QACC") and
  RESETS the state to the model's initial one, so the trajectory stays finite and wrong.
  The adapter counts ``mjWARN_BADQACC``, ``mjWARN_BADQPOS`` and ``mjWARN_BADQVEL`` over the
  run and raises ``DivergedError`` with MuJoCo's message instead (captured, not printed).
- Kinematics: ``mj_kinematics`` then ``mj_comPos`` before ``mj_jacSite`` (the Jacobian is
  silently zero without ``mj_comPos``). A chain read from a URDF file is that file without
  its visual and collision geometry (:func:`references.common.urdf_export.chain_urdf`), compiled by
  MuJoCo's own URDF importer with ``fusestatic`` off (by default MuJoCo merges fixed-joint
  links away, and the end effector may be one), ``boundmass`` / ``boundinertia`` so that a
  kinematics-only file without ``<inertial>`` compiles (masses play no part in
  kinematics), and a site added at the tip link; poses are re-expressed in the chain's base
  link (:mod:`references.common.base_frame`). Other chains come from the adapter's MJCF.
- Contact (a scene with ``contact``; model in :mod:`references.mujoco.mjcf`, parameters and their
  reasons in :mod:`references.common.contact_params`): planes and shapes as geoms, one explicit
  contact pair per body geom and plane with that pair's material, elliptic cone. What MuJoCo
  cannot give the scene: a restitution coefficient (a damped contact spring whose damping
  ratio is derived from k; the restitution it produces is measured, not assumed), static
  friction above kinetic (one coefficient, mu_k), the rest speed (no such rule: small bounces
  decay inside the soft contact), and rigid non-penetration (a soft contact penetrates, about
  2 v dt during an impact at speed v). The detail of every row says so.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import mujoco
import numpy as np
from mujoco import rollout

from simparity.core.model.engine import (
    BatchedRun,
    Engine,
    IKModel,
    JointDynamicsModel,
    JointSimulation,
    KinematicsModel,
    PieceSimulation,
    Simulation,
    Support,
)
from simparity.core.model.errors import DivergedError, NotBatchedError
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.scenes.bodies import Forces
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import FramePoses, Trajectory, piece_bounds
from simparity.references.common import contact_params, external_forces, time_loads
from simparity.references.mujoco import ik as mujoco_ik
from simparity.references.mujoco import joint_motion
from simparity.references.common.base_frame import BaseFrame
from simparity.references.common.conventions import fmt, quat_wxyz_to_matrix
from simparity.references.mujoco.mjcf import INTEGRATORS, arena_kib, chain_mjcf, dynamics_mjcf
from simparity.references.mujoco.stage_loads import DETAIL as STAGE_DETAIL
from simparity.references.mujoco.stage_loads import StepClock, stage_callback
from simparity.references.common.quiet import captured_output
from simparity.references.common.urdf_export import chain_export, chain_source, chain_urdf, urdf_support
from simparity.references.mujoco.floating import MujocoFloatingDynamics
from simparity.references.mujoco.joint_dynamics import MujocoJointDynamics, mujoco_dynamics_problem
from simparity.references.common.scene_inputs import derives_own_inputs

_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS
_RESET_WARNINGS = (mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL)
"""Warnings on which MuJoCo resets the simulation to its initial state (and carries on)."""

MIN_MASS, MIN_INERTIA = 1e-3, 1e-6  # [kg], [kg m^2]
"""``boundmass`` / ``boundinertia`` of chains read from URDF: a link without ``<inertial>``
gets these instead of MuJoCo's refusal; kinematics does not depend on them."""


def _native_damping(forces: Forces, n_bodies: int) -> np.ndarray:
    """(n_bodies, 6) dof_damping: linear drag on the 3 translational dofs, angular on the rotational."""
    damping = np.zeros((n_bodies, 6))
    if forces.linear_drag is not None:
        damping[:, :3] = forces.linear_drag[:, None]
    if forces.angular_linear_drag is not None:
        damping[:, 3:] = forces.angular_linear_drag[:, None]
    return damping


def _quadratic_drags(forces: Forces) -> Forces | None:
    """The drags MuJoCo has no model for (quadratic, relative to the wind), or None."""
    if forces.quadratic_drag is None and forces.angular_quadratic_drag is None:
        return None
    return Forces(air_velocity_world=forces.air_velocity_world, quadratic_drag=forces.quadratic_drag,
                  angular_quadratic_drag=forces.angular_quadratic_drag)


def _wind_force(forces: Forces) -> np.ndarray | None:
    """(B, 3) constant force b w [N] completing the native damping -b v to -b (v - w), or None."""
    if forces.air_velocity_world is None or forces.linear_drag is None:
        return None
    return forces.linear_drag[:, None] * forces.air_velocity_world


class _Simulation(PieceSimulation):
    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        self.model = mujoco.MjModel.from_xml_string(dynamics_mjcf(scene, integrator, dt))
        self._n_bodies = len(scene.bodies)
        forces = scene.forces
        self.model.dof_damping[:] = _native_damping(forces, self._n_bodies).ravel()
        self._data = mujoco.MjData(self.model)
        self._xfrc = np.zeros((self.model.nbody, 6))  # world body first
        wind = _wind_force(forces)
        if wind is not None:
            self._xfrc[1:, :3] = wind
        self._drags = _quadratic_drags(forces)
        self._applied = forces.applied
        self._timed = forces.timed
        self._clock = StepClock()
        self._qfrc_step = np.zeros(self.model.nv)
        qvel = self._data.qvel.reshape(self._n_bodies, 6)
        for k, body in enumerate(scene.bodies):
            qvel[k, :3] = body.velocity_world
            qvel[k, 3:] = quat_wxyz_to_matrix(body.quat_wxyz).T @ body.angular_velocity_world
        self._state0 = np.empty(mujoco.mj_stateSize(self.model, _STATE))
        mujoco.mj_getState(self.model, self._data, self._state0, _STATE)
        self._qpos_at = mujoco.mj_stateSize(self.model, mujoco.mjtState.mjSTATE_TIME)
        self._dt = dt
        native = [n for n in ("linear_drag", "angular_linear_drag") if n in forces.names()]
        stepwise = (["mj_applyFT at each applied force's world point"] if self._applied else []) + (
            [f"quadratic drag as xfrc_applied ({external_forces.DETAIL})"] if self._drags else []) + (
            [STAGE_DETAIL] if self._timed else [])
        self.detail = (
            f"MuJoCo integrator {INTEGRATORS[integrator]}; explicit inertia; "
            + (f"contact disabled, arena {arena_kib(scene)} KiB (MuJoCo's default grows as nv^2)"
               if scene.contact is None else contact_detail(scene, dt))
            + ("" if forces.gravity_world is not None else "; gravity disabled")
            + (f"; {' and '.join(native)} as dof_damping, eulerdamp disabled" if native else "")
            + ("; wind as constant xfrc_applied b w" if wind is not None else "")
            + ("; stepped by mujoco.rollout" if not self._stepwise else
               "; " + "; ".join(stepwise) + ", from the state at each step start, mj_step loop")
        )

    @property
    def _stepwise(self) -> bool:
        return bool(self._applied) or self._drags is not None or bool(self._timed)

    def _stage_loads(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """MuJoCo's control callback: the step's qfrc_applied plus each timed load at the stage's time, applied at
        the load's point of the stage's body pose (:mod:`references.mujoco.stage_loads`)."""
        d.qfrc_applied[:] = self._qfrc_step
        for load in self._timed:
            body = load.body + 1
            rotation = d.xmat[body].reshape(3, 3)
            force, torque = time_loads.load_world(load, self._clock.stage_time(d.time), rotation,
                                                  self._clock.step_start)
            point = d.xpos[body] + rotation @ load.point_body  # mj_applyFT adds the force's moment about the COM
            mujoco.mj_applyFT(m, d, force, torque, point, body, d.qfrc_applied)

    def _rollout(self, initial: np.ndarray, n_steps: int) -> np.ndarray:
        """The states after each of ``n_steps`` steps from each initial state, (R, n_steps, nstate), by one
        ``mujoco.rollout`` call on this thread (R = len(initial)); wind as constant ``xfrc_applied``."""
        if not np.any(self._xfrc):
            states, _ = rollout.rollout(self.model, self._data, initial, nstep=n_steps)
        else:
            states, _ = rollout.rollout(self.model, self._data, initial, self._xfrc.ravel()[None, None],
                                        control_spec=mujoco.mjtState.mjSTATE_XFRC_APPLIED, nstep=n_steps)
        return states

    def batched(self, copies: int) -> BatchedRun:
        """``copies`` rollouts of this model and options from its initial state, in one ``mujoco.rollout`` call
        on one thread, as :meth:`run` makes one. NotBatchedError when the adapter applies forces from Python at
        every step (an ``mj_step`` loop), which a rollout cannot apply."""
        if self._stepwise:
            stepwise = (["applied forces (mj_applyFT)"] if self._applied else []) + (
                ["quadratic drag (xfrc_applied)"] if self._drags else []) + (
                ["loads that change with time (its control callback)"] if self._timed else [])
            raise NotBatchedError(f"the adapter sets {' and '.join(stepwise)} from Python at every step, which "
                                  "mujoco.rollout cannot apply: no batched timing of this scene")
        initial = np.repeat(self._state0[None], copies, axis=0)
        return lambda n_steps: self._rollout(initial, n_steps)

    def _apply_forces(self) -> None:
        """Set xfrc_applied and qfrc_applied from the current state (positions updated first)."""
        m, d, b = self.model, self._data, self._n_bodies
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        d.xfrc_applied[:] = self._xfrc
        if self._drags is not None:
            qvel = d.qvel.reshape(b, 6)
            omega = np.array([d.xmat[k + 1].reshape(3, 3) @ qvel[k, 3:] for k in range(b)])
            d.xfrc_applied[1:, :3] += external_forces.drag_force_world(self._drags, qvel[:, :3])
            d.xfrc_applied[1:, 3:] += external_forces.drag_torque_world(self._drags, omega)
        d.qfrc_applied[:] = 0.0
        for applied in self._applied:
            body = applied.body + 1
            point = d.xpos[body] + d.xmat[body].reshape(3, 3) @ applied.point_body
            mujoco.mj_applyFT(m, d, applied.force_world, np.zeros(3), point, body, d.qfrc_applied)
        self._qfrc_step = d.qfrc_applied.copy()

    def _loop(self, n_steps: int, first_step: int) -> np.ndarray:
        """The states after each of ``n_steps`` further steps of the data as it stands, the first of them step
        ``first_step`` of the run, (n_steps, nstate)."""
        m, d = self.model, self._data
        states = np.empty((n_steps, len(self._state0)))
        for i in range(n_steps):
            self._apply_forces()
            self._clock.start(first_step + i, self._dt, d.time)
            mujoco.mj_step(m, d)
            mujoco.mj_getState(m, d, states[i], _STATE)
        return states

    def _steps(self, initial: np.ndarray, n_steps: int, first: bool, first_step: int = 0) -> np.ndarray:
        """The states after each of ``n_steps`` steps from the state ``initial`` (the data's own state unless
        ``first``: the mj_step loop carries on), the first of them step ``first_step`` of the run, (n_steps,
        nstate); raises DivergedError when MuJoCo reset the simulation."""
        warnings = [self._data.warning[w] for w in _RESET_WARNINGS]
        for warning in warnings:
            warning.number = 0
        messages: list[str] = []
        mujoco.set_mju_user_warning(messages.append)
        try:
            if self._stepwise and first:
                mujoco.mj_setState(self.model, self._data, initial, _STATE)
            if self._stepwise:
                with stage_callback(self._stage_loads if self._timed else None):
                    stepped = self._loop(n_steps, first_step)
            else:
                stepped = self._rollout(initial[None], n_steps)[0] if n_steps else np.empty((0, len(initial)))
        finally:
            mujoco.set_mju_user_warning(None)
        if any(warning.number for warning in warnings):
            raise DivergedError(f"MuJoCo reset the unstable simulation: {messages[0] if messages else 'bad state'}")
        return stepped

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        """Each piece's steps from the last state of the one before (``mujoco.rollout`` from that full physics
        state, or the mj_step loop carried on)."""
        state = self._state0
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            stepped = self._steps(state, stop - max(start, 1), start == 0, max(start, 1) - 1)
            states = np.concatenate([self._state0[None], stepped], axis=0) if start == 0 else stepped
            state = states[-1]
            nq, b = self.model.nq, self._n_bodies
            qpos = states[:, self._qpos_at : self._qpos_at + nq].reshape(-1, b, 7)
            qvel = states[:, self._qpos_at + nq : self._qpos_at + nq + self.model.nv].reshape(-1, b, 6)
            quat = qpos[..., 3:]
            omega_world = np.einsum("tbij,tbj->tbi", quat_wxyz_to_matrix(quat), qvel[..., 3:])
            yield Trajectory(np.arange(start, stop) * self._dt, qpos[..., :3], quat, qvel[..., :3], omega_world)


def contact_detail(scene: DynamicsScene, dt: float) -> str:
    """What MuJoCo's contact model is given for a contact scene, and what it cannot express."""
    contact = scene.contact
    assert contact is not None  # called for contact scenes only (both callers check scene.contact)
    k = sorted({float(v) for v in np.ravel(contact.restitution)})
    solrefs = ", ".join(f"k {v:g} -> zeta {contact_params.damping_ratio(v):.4g}, solref "
                        f"{fmt(contact_params.mujoco_solref(v, dt))}" for v in k)
    static = contact_params.static_friction_note(contact)
    return (f"contact: {len(contact.planes)} plane geom(s), one <pair> per body geom and plane (no body-body "
            f"contact), elliptic cone, condim 3 with friction mu_k (condim 1 where mu_k = 0); soft contact: direct "
            f"solref (-K, -b), K = (1/(2 dt))^2 (MuJoCo's refsafe limit), b = 2 zeta/(2 dt) with zeta = -ln k / "
            f"sqrt(pi^2 + ln^2 k) ({solrefs}); solreffriction {fmt(contact_params.mujoco_solreffriction(dt))}; "
            f"solimp {fmt(contact_params.SOLIMP)} (constant impedance); points as spheres of "
            f"{contact_params.POINT_RADIUS:g} m with pair margin -{contact_params.POINT_RADIUS:g} m (contact at the "
            f"centre); MuJoCo has no restitution coefficient: the restitution is measured, not imposed (the damping above is derived from k); rest_speed {contact.rest_speed:g} m/s not "
            f"modelled (no rest rule; small bounces decay in the soft contact); penetration up to ~2 v dt in an "
            f"impact at speed v" + (f"; {static}" if static else ""))


def _chain_model(chain: Chain) -> mujoco.MjModel:
    """The chain's MuJoCo model: its URDF file without geometry (fixed links kept, a site at the
    tip link, masses bounded), or the MJCF export."""
    with captured_output():
        if chain.urdf_path is None:
            return mujoco.MjModel.from_xml_string(chain_mjcf(chain))
        spec = mujoco.MjSpec.from_string(chain_urdf(chain))
        spec.compiler.fusestatic = False  # keep fixed-joint links: the end effector may be one
        spec.compiler.boundmass, spec.compiler.boundinertia = MIN_MASS, MIN_INERTIA
        spec.body(chain.end_effector_name).add_site(name=chain.end_effector_name)
        return spec.compile()


class MujocoChain(KinematicsModel):
    """A chain in MuJoCo: the model, its data and the chain's joint and site indices.

    Attributes
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
    qpos_adr, dof_adr : (n,) int ndarray
        qpos and dof addresses of the chain's joints.
    bodies : (n,) int ndarray
        Body of each joint (its child link).
    site : int
        The end-effector site.
    base : BaseFrame
        The chain's base link in MuJoCo's world (identity unless a URDF chain starts below
        the file's root link).
    """

    def __init__(self, chain: Chain) -> None:
        self.model = _chain_model(chain)
        self.data = mujoco.MjData(self.model)
        joints = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, j.name) for j in chain.joints]
        self.qpos_adr = self.model.jnt_qposadr[joints]
        self.dof_adr = self.model.jnt_dofadr[joints]
        self.bodies = self.model.jnt_bodyid[joints]
        self.site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, chain.end_effector_name)
        self.base = self._base_frame(chain)
        origin = (f"MuJoCo's URDF importer on {chain_source(chain)}, fusestatic off" if chain.urdf_path
                  else "the adapter's MJCF")
        self.detail = f"{origin}; mj_kinematics + mj_comPos; mj_jacSite at the end-effector site"

    def _base_frame(self, chain: Chain) -> BaseFrame:
        """The base link body's pose at qpos0 (MuJoCo's world body, the identity, if it merged into it)."""
        body = -1 if chain.base_link is None else mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY,
                                                                      chain.base_link)
        if body <= 0:
            return BaseFrame()
        mujoco.mj_kinematics(self.model, self.data)
        return BaseFrame(self.data.xpos[body].copy(), self.data.xmat[body].reshape(3, 3).copy())

    def set(self, q_row: np.ndarray) -> None:
        """Put the joints at ``q_row`` (n,) and update kinematics and COM positions."""
        self.data.qpos[self.qpos_adr] = q_row
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        q = np.atleast_2d(q)
        n = len(self.bodies)
        pos, rot = np.empty((len(q), n + 1, 3)), np.empty((len(q), n + 1, 3, 3))
        for k, row in enumerate(q):
            self.set(row)
            pos[k, :n] = self.data.xpos[self.bodies]
            rot[k, :n] = self.data.xmat[self.bodies].reshape(n, 3, 3)
            pos[k, n] = self.data.site_xpos[self.site]
            rot[k, n] = self.data.site_xmat[self.site].reshape(3, 3)
        return FramePoses(*self.base.frames(pos, rot))

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        jacp, jacr = np.empty((3, self.model.nv)), np.empty((3, self.model.nv))
        out = np.empty((len(q), 6, len(self.bodies)))
        for k, row in enumerate(q):
            self.set(row)
            mujoco.mj_jacSite(self.model, self.data, jacp, jacr, self.site)
            out[k, :3], out[k, 3:] = jacp[:, self.dof_adr], jacr[:, self.dof_adr]
        return self.base.jacobian(out)


@derives_own_inputs
class MujocoEngine(Engine):
    """MuJoCo, built from MJCF the adapter writes (see :mod:`references.mujoco.mjcf`) or from a chain's URDF file."""

    name = "mujoco"

    def version(self) -> str:
        return mujoco.__version__

    def integrators(self) -> tuple[str, ...]:
        return tuple(INTEGRATORS)

    def theoretical_order(self, integrator: str) -> int | None:
        """Euler (semi-implicit), implicit and implicitfast are first order, RK4 fourth (MuJoCo's docs,
        "Numerical integration"); on a chain also Euler with explicit damping (:data:`joint_motion.ORDERS`)."""
        return {"euler": 1, "implicit": 1, "implicitfast": 1, "rk4": 4}.get(integrator,
                                                                             joint_motion.ORDERS.get(integrator))

    def stages(self, integrator: str) -> int | None:
        """Force evaluations per ``mj_step``: one ``mj_forward`` for Euler, implicit and implicitfast (the implicit
        ones also take the derivative of the velocity-dependent forces and factor M - dt D once per step: work
        beyond the count), four for RK4 (``mj_RungeKutta``: the step's ``mj_forward`` and three more). Forces the
        adapter sets from Python at each step's start are evaluated once per step whatever the integrator. On a
        chain, Euler with explicit damping too is one (:data:`joint_motion.STAGES`)."""
        return {"euler": 1, "implicit": 1, "implicitfast": 1, "rk4": 4}.get(integrator,
                                                                             joint_motion.STAGES.get(integrator))

    def scheme(self, integrator: str, scene) -> str:
        """MuJoCo's Euler is semi-implicit with the orientation advanced by the exponential map (eulerdamp is
        disabled, so damping is explicit); implicit and implicitfast take velocity-dependent forces implicitly;
        with planes, its soft contact drives them. Its IK (``dls``) is damped least squares. On a chain
        (a joint-motion scene) Euler keeps eulerdamp, so it and implicitfast take the joint damping implicitly
        (:data:`joint_motion.SCHEMES`)."""
        if isinstance(scene, JointMotionScene):
            kind = joint_motion.SCHEMES.get(integrator, "")
            # a free joint's RK4 moves the quaternion by mj_integratePos at every stage: on a spinning base its error
            # constant differs from RK4 on the quaternion in R^4 (Go1 at 3.9 rad/s: end effector 1.3 x core's)
            return "engine_rk4" if kind == "rk4" and scene.chain.floating_base else kind
        if isinstance(scene, IKScene):
            return "damped_least_squares" if integrator in mujoco_ik.SOLVERS else ""
        if isinstance(scene, JointDynamicsScene):
            return integrator if integrator in self.joint_dynamics_methods() else ""
        kind = {"euler": "engine_euler", "rk4": "rk4", "implicit": "implicit_damping",
                "implicitfast": "implicit_damping"}.get(integrator, "")
        return f"soft+{kind}" if kind and isinstance(scene, DynamicsScene) and scene.contact is not None else kind

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        return self.check_integrator(integrator)

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, integrator, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return Support.yes()

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return MujocoChain(chain)

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        """MuJoCo's smooth dynamics: CRB for M, RNE for the bias and inverse dynamics, a factorisation of M for
        the forward (:mod:`references.mujoco.joint_dynamics`)."""
        return ("recursive",)

    def supports_joint_dynamics(self, chain: Chain, method: str) -> Support:
        """A chain with mass properties that URDF can express and MuJoCo compiles unchanged (it refuses a moving
        body without mass or rotational inertia, and an inertia breaking the triangle inequality); armature and
        damping are MuJoCo's own."""
        named = super().supports_joint_dynamics(chain, method)
        return _dynamics_support(chain) if named.ok else named

    def build_joint_dynamics(self, chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
        return (MujocoFloatingDynamics(chain, gravity_world) if chain.floating_base
                else MujocoJointDynamics(chain, gravity_world))

    def joint_motion_integrators(self) -> tuple[str, ...]:
        """MuJoCo's integrators stepping the joint-dynamics model (:mod:`references.mujoco.joint_motion`), Euler
        twice: with its default implicit joint damping and with eulerdamp disabled."""
        return tuple(joint_motion.INTEGRATORS)

    def supports_joint_motion(self, scene: JointMotionScene, integrator: str) -> Support:
        """As joint dynamics: a chain MuJoCo compiles unchanged from URDF."""
        named = super().supports_joint_motion(scene, integrator)
        return _dynamics_support(scene.chain) if named.ok else named

    def build_joint_motion(self, scene: JointMotionScene, integrator: str, dt: float) -> JointSimulation:
        return joint_motion.MujocoJointMotion(scene, integrator, dt)

    def chain_contact(self, scene: JointMotionScene) -> Support:
        """MuJoCo's soft contact on sphere and plane geoms (:mod:`references.mujoco.contact`); not a rigid contact."""
        if scene.contact is not None and scene.contact.rigid:
            return Support.no("MuJoCo's contact is soft (solref, solimp): a sphere sinks into the plane and its rebound "
                              "follows from solref's damping, so it has no rigid contact with a restitution")
        return Support.yes()

    def ik_solvers(self) -> tuple[str, ...]:
        return mujoco_ik.SOLVERS

    def build_ik(self, chain: Chain, solver: str, options: IKTolerances) -> IKModel:
        return mujoco_ik.MujocoIK(MujocoChain(chain), chain, solver, options)

    def export(self, scene, integrator, dt) -> str:
        if not isinstance(scene, DynamicsScene):
            if scene.chain.urdf_path:
                return chain_export(scene.chain, f"MjSpec.from_string (MuJoCo's URDF importer), fusestatic off, "
                                    f"boundmass {MIN_MASS:g}, boundinertia {MIN_INERTIA:g}, a site at the tip link")
            return chain_mjcf(scene.chain)
        integrator, dt = self._export_settings(scene, integrator, dt)
        velocities = "".join(
            f"<!-- initial qvel of {b.name}: linear (world) {fmt(b.velocity_world)}, "
            f"angular (body) {fmt(quat_wxyz_to_matrix(b.quat_wxyz).T @ b.angular_velocity_world)} -->\n"
            for b in scene.bodies
        )
        damping = _native_damping(scene.forces, len(scene.bodies))
        extra = (f"<!-- set after compiling: dof_damping = {fmt(damping)} (per body: 3 translational, "
                 "3 rotational) -->\n" if np.any(damping) else "")
        wind = _wind_force(scene.forces)
        if wind is not None:
            extra += f"<!-- constant xfrc_applied force (wind, b w) per body: {fmt(wind)} N -->\n"
        drags = _quadratic_drags(scene.forces)
        if drags is not None:
            extra += (f"<!-- each step, xfrc_applied from the state at its start: "
                      f"{', '.join(n for n in drags.names() if n != 'wind')} -->\n")
        for applied in scene.forces.applied:
            extra += (f"<!-- each step, mj_applyFT of {fmt(applied.force_world)} N at body point "
                      f"{fmt(applied.point_body)} m (world position from the state at the step's start), "
                      f"body {applied.body + 1} -->\n")
        for load in scene.forces.timed:
            extra += (f"<!-- every stage (mjcb_control at d.time): mj_applyFT of a load that changes with time, "
                      f"{load.frame} axes, at body point {fmt(load.point_body)} m, body {load.body + 1} -->\n")
        if scene.contact is not None:
            extra += f"<!-- {contact_detail(scene, dt)} -->\n"
        return dynamics_mjcf(scene, integrator, dt) + velocities + extra


def _dynamics_support(chain: Chain) -> Support:
    """Whether MuJoCo builds the chain's dynamics model unchanged: mass properties that URDF can express and that
    MuJoCo compiles without bounding a mass or balancing an inertia."""
    problem = chain.dynamics_problem()
    if problem:
        return Support.no(problem)
    expressible = urdf_support(chain) if chain.robot_file is None else Support.yes()
    if not expressible.ok:
        return expressible
    problem = mujoco_dynamics_problem(chain)
    return Support.no(problem) if problem else Support.yes()


class BatchRollout:
    """B identical free bodies as B rollouts of one single-body model, stepped by ``mujoco.rollout``'s batch
    API on ``nthread`` threads: MuJoCo's fastest way through a batch (a benchmark's workload, not a scene
    engine). The bodies must share mass, inertia and forces; each rollout starts from its body's state,
    converted as in the scene adapter (angular velocity to body axes)."""

    def __init__(self, scene: DynamicsScene, integrator: str, dt: float, nthread: int) -> None:
        first = scene.bodies[0]
        if any(b.mass != first.mass or not np.array_equal(b.inertia_body, first.inertia_body) for b in scene.bodies):
            raise ValueError("a batch rollout needs bodies of one mass and inertia")
        single = _Simulation(replace(scene, bodies=(first,), forces=_first_body_forces(scene.forces)), integrator, dt)
        if scene.forces.applied or single._stepwise or np.any(single._xfrc):
            raise ValueError("a batch rollout steps without per-step forces (no applied forces, wind or "
                             "quadratic drag)")
        self._single, self._nthread = single, nthread
        qpos_at, nq = single._qpos_at, single.model.nq
        self._states0 = np.repeat(single._state0[None], len(scene.bodies), axis=0)
        for k, body in enumerate(scene.bodies):
            self._states0[k, qpos_at:qpos_at + 3] = body.position_world
            self._states0[k, qpos_at + 3:qpos_at + 7] = body.quat_wxyz
            self._states0[k, qpos_at + nq:qpos_at + nq + 3] = body.velocity_world
            self._states0[k, qpos_at + nq + 3:qpos_at + nq + 6] = (quat_wxyz_to_matrix(body.quat_wxyz).T
                                                                    @ body.angular_velocity_world)
        self._datas = [mujoco.MjData(single.model) for _ in range(nthread)]
        self.detail = f"{single.detail}; {len(scene.bodies)} rollouts of a single-body model on {nthread} threads"

    def run(self, n_steps: int) -> Trajectory:
        """The B bodies' trajectory, (n_steps + 1, B, k) arrays like a scene adapter's."""
        m = self._single.model
        with rollout.Rollout(nthread=self._nthread) as runner:
            stepped, _ = runner.rollout([m] * len(self._states0), self._datas, self._states0, nstep=n_steps)
        states = np.concatenate([self._states0[:, None], stepped], axis=1).transpose(1, 0, 2)  # (T, B, nstate)
        at, nq = self._single._qpos_at, m.nq
        qpos, qvel = states[..., at:at + nq], states[..., at + nq:at + nq + m.nv]
        omega_world = np.einsum("tbij,tbj->tbi", quat_wxyz_to_matrix(qpos[..., 3:]), qvel[..., 3:])
        return Trajectory(np.arange(n_steps + 1) * self._single._dt, qpos[..., :3], qpos[..., 3:], qvel[..., :3],
                          omega_world)


def _first_body_forces(forces: Forces) -> Forces:
    """The forces of body 0 alone (per-body arrays cut to their first entry)."""
    def first(values):
        return None if values is None else values[:1]
    return replace(forces, linear_drag=first(forces.linear_drag), quadratic_drag=first(forces.quadratic_drag),
                   angular_linear_drag=first(forces.angular_linear_drag),
                   angular_quadratic_drag=first(forces.angular_quadratic_drag), applied=())
