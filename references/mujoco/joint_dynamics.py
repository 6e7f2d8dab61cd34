"""A chain's joint-space dynamics in MuJoCo: mass matrix, bias forces, inverse and forward dynamics (issue #27).

What MuJoCo is given, and each default switched off (each pinned by ``tests/references/test_joint_dynamics_engines.py``)
------------------------------------------------------------------------------------------------------------
- The model: the URDF text of :func:`references.common.dynamics_urdf.dynamics_urdf` (the chain's file, base
  subtree only, without geometry and ``<dynamics>``, held joints fixed, links without ``<inertial>`` given an
  explicit zero one; or the chain's declared mass properties), read by MuJoCo's OWN URDF importer
  (``MjSpec.from_string``). No mass property is ever taken from the chain of a file.
- Compiler: ``fusestatic`` off (fixed-joint links stay bodies, as in the file; fusing them gives the same M to
  rounding: measured 2e-16 relative on the crafted arm), ``balanceinertia`` off (it would change an inertia
  that breaks the triangle inequality), ``boundmass`` = ``boundinertia`` = 0 (the kinematics adapter bounds
  masses to ``MIN_MASS``; dynamics must not change a mass), ``inertiafromgeom`` false (an ``<inertial>`` is
  never recomputed from geometry; there is none anyway), ``discardvisual``.
- Massless links: a mass-0 ``<inertial>`` on a body welded to a moving one (the crafted arm's flange) compiles
  and weighs nothing; a moving body (one with a joint) without mass or without rotational inertia of its own
  or welded to it (a point mass included) is REFUSED by MuJoCo ("mass and inertia of moving bodies must be
  larger than mjMINVAL"), as is an inertia breaking the triangle inequality A + B >= C. Bounding the mass or
  balancing the inertia would change the model, so such a chain is not supported
  (:func:`mujoco_dynamics_problem` gives MuJoCo's message); Pinocchio takes it.
- Gravity: ``opt.gravity`` = the scene's ``gravity_world`` exactly; None is zero (MuJoCo's default is
  (0, 0, -9.81)).
- Constraints off (``mjDSBL_CONSTRAINT``): joint limits never act, so ``mj_forward`` and ``mj_inverse`` have no
  constraint force, even at a state outside a limit.
- Passive forces: ``dof_damping`` = the chain's damping, ``dof_armature`` = the chain's armature (added to M's
  diagonal by ``mj_crb``), and zero ``dof_dampingpoly``, ``jnt_stiffness``, ``jnt_stiffnesspoly`` and
  ``dof_frictionloss`` (MuJoCo's importer turns ``<dynamics friction>`` into Coulomb ``frictionloss`` and reads
  ``damping``: ``dynamics_urdf`` strips ``<dynamics>``, and the adapter sets them anyway).
- Effort limits off: the importer turns ``<limit effort>`` into the joint's ``actuatorfrcrange``, which clamps the
  force of any actuator on it; ``jnt_actfrclimited`` is 0, so the motors added for ``mjd_transitionFD``'s control
  block (:mod:`references.mujoco.joint_motion`) apply the τ they are given (the model stepped has none).
- Functions, state by state after ``mj_forward``: M = ``mj_fullM`` (armature included); h = ``qfrc_bias``
  (Coriolis, centrifugal and gravity; damping is in ``qfrc_passive``, not in it); tau = ``qfrc_inverse`` of
  ``mj_inverse`` (continuous time: ``invdiscrete`` off), which is M qacc + qfrc_bias - qfrc_passive -
  qfrc_constraint = M qddot + h + D qdot here (``qfrc_passive`` = -D qdot); qddot = ``qacc`` of ``mj_forward``
  with ``qfrc_applied`` = tau, i.e. M^-1 (tau - h - D qdot).
- Joints are mapped to MuJoCo's dofs by name (``jnt_dofadr``, ``jnt_qposadr``); a continuous joint is a hinge
  whose qpos is the angle.
- Kinetic energy from MuJoCo's own body velocities, not from M: every body's 6D velocity at its CENTRE OF MASS
  (``mj_objectVelocity`` of ``mjOBJ_BODY``, world orientation: the point is ``xipos``; ``mjOBJ_XBODY`` would
  give the body origin's), its ``body_mass`` and principal inertia ``body_inertia`` in the inertial frame
  ``ximat``: 1/2 m |v|^2 + 1/2 w_i^T diag(I) w_i with w_i = ximat^T w. Every body is part of a chain link or
  fixed to the world (moving at zero), so the sum over bodies is the sum over chain links.
- Rotated inertial origins (``<inertial><origin rpy>``): MuJoCo's URDF importer lost their rotation before a
  2026 fix; the crafted arm's rotated, off-diagonal inertials agree with Pinocchio's to rounding.
"""

from __future__ import annotations

import mujoco
import numpy as np

from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.derivatives import DynamicsDerivatives, FiniteDifferences
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact
from simparity.references.common.conventions import fmt
from simparity.references.common.dynamics_mjcf import dynamics_mjcf
from simparity.references.common.dynamics_urdf import chain_joint_names, dynamics_source, dynamics_urdf
from simparity.references.common.quiet import captured_output
from simparity.references.common.rigid_groups import summed
from simparity.references.mujoco.contact import add_contact


def _compiled(chain: Chain, gravity_world: np.ndarray | None, motors: bool = False,
              contact: ChainContact | None = None) -> mujoco.MjModel:
    """The chain's dynamics model with the compiler options of the module docstring; raises MuJoCo's error. With
    ``motors``, a motor (gear 1, no control limits) on each chain joint in the chain's order: ctrl is τ, for
    ``mjd_transitionFD``'s control block (a URDF declares no actuator)."""
    with captured_output():
        mjcf = chain.mjcf_path is not None
        spec = mujoco.MjSpec.from_string(dynamics_mjcf(chain) if mjcf else dynamics_urdf(chain))
        spec.compiler.fusestatic = False
        spec.compiler.balanceinertia = False
        spec.compiler.boundmass = 0.0
        spec.compiler.boundinertia = 0.0
        if not mjcf:  # an MJCF body without <inertial> takes its mass from its geoms (visual ones too): kept
            spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
            spec.compiler.discardvisual = True
        spec.option.gravity = np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float)
        spec.option.density = spec.option.viscosity = 0.0  # no fluid forces (an MJCF <option> may set them)
        spec.option.wind = np.zeros(3)
        spec.option.disableflags = mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # an MJCF <option> may disable more
        spec.option.enableflags = 0
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_EULER  # an MJCF file's RK4: mjd_inverseFD refuses it
        if chain.floating_base:
            spec.worldbody.first_body().add_freejoint()
        if contact is not None:
            add_contact(spec, chain, contact)
        for name in chain_joint_names(chain) if motors else ():
            motor = spec.add_actuator()
            motor.name, motor.trntype, motor.target = f"simparity_motor_{name}", mujoco.mjtTrn.mjTRN_JOINT, name
            motor.set_to_motor()
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        return spec.compile()


def mujoco_dynamics_problem(chain: Chain) -> str:
    """Why MuJoCo cannot build the chain's dynamics unchanged ("" when it can): its compiler's refusal, e.g. of a
    moving body without mass or rotational inertia, or of an inertia breaking the triangle inequality. An MJCF file is
    first compiled as it is: the text every engine is given drops what it does not need, and MuJoCo must read the
    file the user has (a held joint's zero axis, a UTF-16 file: refused there, never seen by the model)."""
    if chain.mjcf_path is not None:
        try:
            with captured_output():
                mujoco.MjModel.from_xml_path(chain.mjcf_path)
        except ValueError as error:
            return f"MuJoCo refuses the file: {' '.join(str(error).split())}"
    try:
        _compiled(chain, None)
    except ValueError as error:
        return (f"MuJoCo refuses the model (bounding a mass or balancing an inertia would change it): "
                f"{' '.join(str(error).split())}")
    return ""


class ChainModel:
    """The chain's compiled MuJoCo model as the module docstring builds it (compiler options, gravity, constraints
    off, passive forces set), shared by joint dynamics and joint motion (:mod:`references.mujoco.joint_motion`).

    Attributes
    ----------
    model : mujoco.MjModel
    dof, qpos : (n,) int ndarray
        The chain joints' dof and qpos addresses (joints mapped by name).
    detail : str
        What MuJoCo was given, for the rows' detail.
    """

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None, motors: bool = False,
                 contact: ChainContact | None = None) -> None:
        model = _compiled(chain, gravity_world, motors, contact)
        joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in chain_joint_names(chain)]
        self.dof, self.qpos = model.jnt_dofadr[joints], model.jnt_qposadr[joints]
        model.dof_damping[:] = 0.0
        model.dof_damping[self.dof] = [j.damping for j in chain.joints]
        model.dof_armature[:] = 0.0
        model.dof_armature[self.dof] = [j.armature for j in chain.joints]
        model.dof_dampingpoly[:] = 0.0
        model.dof_frictionloss[:] = 0.0
        model.jnt_stiffness[:] = 0.0
        model.jnt_stiffnesspoly[:] = 0.0
        model.jnt_actfrclimited[:] = 0  # the URDF's <limit effort> as MuJoCo's actuatorfrcrange: clamps any motor
        model.body_gravcomp[:] = 0.0  # an MJCF body's gravity compensation
        self.model = model
        gravity = "none" if gravity_world is None else fmt(gravity_world)
        importer, geoms = (("MJCF", "inertiafromgeom as the file sets it, visual geoms kept") if chain.mjcf_path
                           is not None else ("URDF", "inertiafromgeom false, visual geoms discarded"))
        self.detail = (f"MuJoCo's {importer} importer (MjSpec.from_string) on {dynamics_source(chain)}; fusestatic "
                       f"and balanceinertia off, boundmass = boundinertia = 0, {geoms}; no fluid forces, no gravity "
                       "compensation; gravity "
                       f"{gravity}; constraints (joint limits) disabled; dof_damping and dof_armature from the "
                       "chain, frictionloss and stiffness 0, the URDF's effort limits (actuatorfrcrange) off")


INVERSE_FD_STEP = 1e-6
"""mjd_inverseFD's eps for q [rad or m] (forward differences): truncation ~ eps |d2 tau| / 2, rounding ~
eps_machine |tau| / eps. For qdot it is this fraction of the state's largest |qdot| (:meth:`MujocoJointDynamics.derivatives`):
tau is quadratic in qdot, so a forward difference's relative error is ~ eps / |qdot|, and an absolute step would make it
depend on the unit of time (measured: 1000 x worse in milliseconds)."""
FORWARD_MISSING = ("MuJoCo differentiates forward dynamics only through a time step (mjd_transitionFD): no "
                   "continuous-time dqddot to compare")


class MujocoJointDynamics(JointDynamicsModel):
    """A chain's joint-space dynamics from MuJoCo's smooth dynamics (see the module docstring).

    Attributes
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
    dof, qpos : (n,) int ndarray
        The chain joints' dof and qpos addresses.
    state_dof, state_qpos : int ndarray
        The addresses of a state's velocity and configuration rows: ``dof`` and ``qpos``, a floating base's free joint
        first (:mod:`references.mujoco.floating`).
    """

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        built = ChainModel(chain, gravity_world)
        self.model, self.dof, self.qpos = built.model, built.dof, built.qpos
        self.state_dof, self.state_qpos = self.dof, self.qpos  # the state's addresses: a free joint's first if any
        self.data = mujoco.MjData(self.model)
        self.detail = (f"{built.detail}; mj_fullM, qfrc_bias, mj_inverse, mj_forward's qacc; kinetic energy from "
                       "mj_objectVelocity at each body's centre of mass")

    def _set(self, q_row: np.ndarray, qdot_row: np.ndarray, tau_row: np.ndarray | None = None) -> None:
        """Put the state (and applied joint forces, zero if None) in, and run ``mj_forward``."""
        d = self.data
        d.qpos[self.state_qpos], d.qvel[self.state_dof] = q_row, qdot_row
        d.qfrc_applied[:] = 0.0
        if tau_row is not None:
            d.qfrc_applied[self.state_dof] = tau_row
        mujoco.mj_forward(self.model, d)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        full = np.empty((self.model.nv, self.model.nv))
        dofs = self.state_dof
        out = np.empty((len(q), len(dofs), len(dofs)))
        for k, row in enumerate(q):
            self._set(row, np.zeros(len(dofs)))
            mujoco.mj_fullM(self.model, self.data, full)
            out[k] = full[np.ix_(dofs, dofs)]
        return out

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        out = np.empty(np.shape(qdot))
        for k, (row, velocity) in enumerate(zip(q, qdot)):
            self._set(row, velocity)
            out[k] = self.data.qfrc_bias[self.state_dof]
        return out

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        out = np.empty(np.shape(qdot))
        d = self.data
        for k, (row, velocity, acceleration) in enumerate(zip(q, qdot, qddot)):
            d.qpos[self.state_qpos], d.qvel[self.state_dof], d.qacc[self.state_dof] = row, velocity, acceleration
            d.qfrc_applied[:] = 0.0
            mujoco.mj_inverse(self.model, d)
            out[k] = d.qfrc_inverse[self.state_dof]
        return out

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty(np.shape(qdot))
        for k, (row, velocity, force) in enumerate(zip(q, qdot, tau)):
            self._set(row, velocity, force)
            out[k] = self.data.qacc[self.state_dof]
        return out

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        m, d = self.model, self.data
        velocity = np.empty(6)  # (angular, linear at the centre of mass), world orientation
        out = np.zeros(len(q))
        for k, (row, rates) in enumerate(zip(q, qdot)):
            self._set(row, rates)
            for body in range(1, m.nbody):
                mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, body, velocity, 0)
                omega_inertial = d.ximat[body].reshape(3, 3).T @ velocity[:3]
                out[k] += 0.5 * (m.body_mass[body] * velocity[3:] @ velocity[3:]
                                 + omega_inertial @ (m.body_inertia[body] * omega_inertial))
        return out

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        """Each chain joint's bodies (MuJoCo keeps fixed-joint links as bodies: ``fusestatic`` off) summed with the
        references' own code (:mod:`references.common.rigid_groups`): ``body_mass``, ``xipos``, ``ximat`` and the
        principal ``body_inertia`` after ``mj_kinematics``; the joint's ``xaxis`` and ``xanchor`` (its body's origin from
        a URDF file; an MJCF joint's ``pos`` moves it), a slide's moved by its own motion as the other engines' frames. Of a body's several joints (MJCF) the last carries its bodies,
        the others none (core's massless links between them)."""
        m, d = self.model, self.data
        joints = [m.dof_jntid[dof] for dof in self.dof]
        bodies = [int(m.jnt_bodyid[j]) for j in joints]
        groups: dict[int, list[int]] = {b: [] for b in bodies}
        for body in range(1, m.nbody):
            mover = body
            while mover and m.body_jntnum[mover] == 0:
                mover = int(m.body_parentid[mover])
            if mover in groups:
                groups[mover].append(body)
        # a body's several joints (MJCF): its bodies ride on the last of them, the others move nothing of their own
        last = {body: i for i, body in enumerate(bodies)}
        out = [np.empty((len(q), len(bodies)) + tail) for tail in ((), (3,), (3, 3), (3,), (3,))]
        for k, row in enumerate(q):
            d.qpos[self.qpos] = row
            mujoco.mj_kinematics(m, d)
            for i, (joint, body) in enumerate(zip(joints, bodies)):
                members = groups[body] if last[body] == i else []
                rotations = d.ximat[members].reshape(-1, 3, 3)
                inertias = rotations @ (m.body_inertia[members][:, :, None] * np.swapaxes(rotations, -1, -2))
                anchor = d.xanchor[joint]  # a slide's before its own motion: moved by it, as every engine's frame
                if m.jnt_type[joint] == mujoco.mjtJoint.mjJNT_SLIDE:
                    address = m.jnt_qposadr[joint]
                    anchor = anchor + d.xaxis[joint] * (d.qpos[address] - m.qpos0[address])
                mass, com, inertia = summed(m.body_mass[members], d.xipos[members], inertias, anchor)
                out[0][k, i], out[1][k, i], out[2][k, i] = mass, com, inertia
                out[3][k, i], out[4][k, i] = d.xaxis[joint], anchor
        return RigidGroups(*out)

    def compiled_joints(self) -> CompiledJoints:
        """``jnt_type`` (slide: prismatic) and ``jnt_range`` where ``jnt_limited``, else unlimited: the importer's
        reading of each ``<limit>`` (the adapter disables the constraints that would apply them)."""
        m = self.model
        joints = [m.dof_jntid[dof] for dof in self.dof]
        limited = np.array([bool(m.jnt_limited[j]) for j in joints])
        ranges = np.array([m.jnt_range[j] for j in joints]).reshape(-1, 2)
        return CompiledJoints(np.array([m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE for j in joints]),
                              np.where(limited, ranges[:, 0], -np.inf), np.where(limited, ranges[:, 1], np.inf))

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """``mjd_inverseFD`` (forward differences at :data:`INVERSE_FD_STEP` for q, that fraction of the largest |qdot|
        for qdot: two calls; constraints off, passive damping in qfrc_inverse) at q̈ = ``mj_forward``'s qacc of τ; its
        outputs are transposed (DfDq[j, i] = ∂f_i/∂q_j), turned back here. No forward-dynamics partials
        (:data:`FORWARD_MISSING`)."""
        by_q, by_v, _, steps = self.own_partials(q, qdot, self.forward_dynamics(q, qdot, tau))
        return DynamicsDerivatives(by_q, by_v, forward_missing=FORWARD_MISSING,
                                   differences=FiniteDifferences(False, np.full(len(q), INVERSE_FD_STEP), steps))

    def own_partials(self, q: np.ndarray, qdot: np.ndarray,
                     qddot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(∂τ/∂q, ∂τ/∂q̇, M), each (B, nv, nv) in MuJoCo's own coordinates (its q tangent, qvel), by ``mjd_inverseFD``
        at states in its own coordinates (qpos, qvel, qacc rows), and the q̇ step of each state (B,)."""
        m, d = self.model, self.data
        index = np.ix_(self.state_dof, self.state_dof)
        by_q, by_v, by_a = np.zeros((m.nv, m.nv)), np.zeros((m.nv, m.nv)), np.zeros((m.nv, m.nv))
        out = [np.empty((len(q), len(self.state_dof), len(self.state_dof))) for _ in range(3)]
        steps_qdot = np.empty(len(q))
        for k, (row, rates, acceleration) in enumerate(zip(q, qdot, qddot)):
            d.qpos[self.state_qpos], d.qvel[self.state_dof] = row, rates
            d.qacc[:] = 0.0
            d.qacc[self.state_dof] = acceleration
            d.qfrc_applied[:] = 0.0
            speed = float(np.max(np.abs(rates), initial=0.0))
            steps_qdot[k] = INVERSE_FD_STEP * (speed if speed > 0 else 1.0)
            mujoco.mjd_inverseFD(m, d, INVERSE_FD_STEP, False, by_q, None, by_a, None, None, None, None)
            mujoco.mjd_inverseFD(m, d, steps_qdot[k], False, None, by_v, None, None, None, None, None)
            out[0][k], out[1][k], out[2][k] = by_q.T[index], by_v.T[index], by_a.T[index]
        return out[0], out[1], out[2], steps_qdot
