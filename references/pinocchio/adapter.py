"""Pinocchio behind the shared engine interface.

Pinocchio computes dynamics but has no time stepper: the harness steps the accelerations
of ``pin.aba`` itself, and the results say so ("harness-stepped").

Conversions (each pinned by a test in ``tests/references/pinocchio/test_adapter.py``)
------------------------------------------------------------------------
- Free-flyer ``q[3:7]`` is (x, y, z, w): reordered here.
- Free-flyer ``v[0:3]`` and ``v[3:6]`` are in the LOCAL (body) frame: v_world = R v[0:3],
  omega_world = R v[3:6]. The joint frame is the COM (lever 0), so v[0:3] is the COM's.
- ``aba`` returns the SPATIAL acceleration; the classical acceleration of the origin is
  a[0:3] + omega x v[0:3] (both local).
- ``euler``: the engines' first-order scheme (as MuJoCo Euler): v_world += dt R a_classical,
  omega_local += dt a[3:6], then p += dt v_world and R = R exp(dt omega_local).
- ``rk4``: RK4 on the same accelerations, the rotation by RKMK in the body frame with
  Pinocchio's own Lie-group functions: R = R0 exp3(u), du/dt = Jlog3(exp3(u)) w (the inverse
  of the right Jacobian of exp). Stepping ``pin.integrate`` on the local twist instead
  would follow an SE(3) screw and drift from the others (0.25 m after 2 s of free fall).
- Forces other than gravity (``model.gravity``) enter ``aba`` as ``fext``, as Pinocchio
  users give them: per joint a spatial force about the joint origin (the COM) in the LOCAL
  frame. A force f at a body point p is ``SE3(I, p).act(Force(R^T f, 0))`` (Pinocchio
  computes its moment); drag and wind (:mod:`references.common.external_forces`, independent of
  core) are (R^T F, R^T tau) at the COM.
- Chains: the chain's URDF text (:func:`references.common.urdf_export.chain_urdf`: a URDF file
  without its visual and collision geometry, or the adapter's export) read by
  ``buildModelFromXML``; fixed base. A ``continuous`` joint has nq = 2 (cos, sin). Joint
  frames are the child links' frames; Jacobians are LOCAL_WORLD_ALIGNED; poses are
  re-expressed in the chain's base link (:mod:`references.common.base_frame`).
- Contact of free bodies: a dynamics scene with contact is n/a (:data:`NO_CONTACT`): its restitution, friction and
  rest speed have no piece in Pinocchio. (A chain's frictionless spheres on a plane, in a joint-motion scene, are
  stepped by the harness's loop on Pinocchio's point contacts and ADMM: :mod:`references.pinocchio.contact`.)
  Pinocchio 4.1 has the pieces of ONE contact problem (``PointContactConstraintModel`` with a ``CoulombFrictionCone``, Delassus
  operators, ``PGSConstraintSolver`` / ``ADMMConstraintSolver`` for a single conic problem,
  ``constraintDynamics`` for bilateral rigid constraints, ``impulseDynamics`` with a restitution
  coefficient for bilateral impacts) but no time-stepping contact simulation; assembling one
  here would be the harness's own contact method, not Pinocchio's.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pinocchio as pin

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
from simparity.core.model.errors import NotBatchedError
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import FramePoses, Trajectory, piece_bounds
from simparity.references.common import contact_params, external_forces, time_loads
from simparity.references.pinocchio import ik as pinocchio_ik
from simparity.references.common.base_frame import BaseFrame
from simparity.references.common.conventions import matrix_to_quat_wxyz, quat_wxyz_to_matrix
from simparity.references.common.quiet import captured_output
from simparity.references.pinocchio.joints import configuration
from simparity.references.common.urdf_export import UrdfChains, chain_export, chain_source, chain_urdf, urdf_support
from simparity.references.pinocchio import joint_motion
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pinocchio.floating_motion import PinocchioFloatingMotion
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics, pinocchio_dynamics_problem
from simparity.references.common.scene_inputs import derives_own_inputs


def free_body_model(body, gravity_world: np.ndarray | None) -> pin.Model:
    """One free-flyer joint attached to the universe, with the body's mass and inertia about its COM.

    Each body of a scene gets its own model: the bodies are independent, and a model holding B free
    flyers makes ``createData`` allocate nv x nv matrices and larger (measured: 13 GiB at B = 100).
    """
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"{body.name}_free")
    model.appendBodyToJoint(jid, pin.Inertia(body.mass, np.zeros(3), body.inertia_body), pin.SE3.Identity())
    model.gravity = pin.Motion(np.zeros(3) if gravity_world is None else gravity_world, np.zeros(3))
    return model


NO_CONTACT = (
    "Pinocchio 4.1 has no time-stepping contact simulation: it solves single contact problems "
    "(PointContactConstraintModel with one CoulombFrictionCone mu per contact, Delassus operators and the "
    "PGSConstraintSolver/ADMMConstraintSolver conic solvers; constraintDynamics for bilateral rigid "
    "constraints; impulseDynamics with a restitution coefficient for bilateral impacts only), but nothing "
    "that detects the plane contacts step by step, applies Newton restitution in a unilateral frictional "
    "impact, separates static from kinetic friction or applies the rest speed; stepping those pieces would "
    "be the harness's own contact integrator, not Pinocchio's"
)
"""Why a dynamics scene with contact is n/a for Pinocchio (checked against ``dir(pinocchio)`` of 4.1)."""

INTEGRATORS = ("euler", "rk4")
"""Harness-side steppers of aba's accelerations: the engines' first-order scheme, and RK4 (RKMK on SO(3))."""

# Classical RK4 tableau.
_RK4_A = ((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0))
_RK4_B = (1 / 6, 1 / 3, 1 / 3, 1 / 6)
_RK4_C = (0.0, 0.5, 0.5, 1.0)
"""The stages' times as fractions of the step (each row's sum of _RK4_A): where timed loads are evaluated."""


class _Simulation(PieceSimulation):
    """Free bodies stepped by the harness on aba's accelerations.

    State per body: COM position p and velocity v (world), rotation R, angular velocity w
    in the LOCAL frame (Pinocchio's). ``euler``: the engines' scheme (velocities first, then
    p += dt v, R = R exp(dt w)). ``rk4``: classical RK4 on (p, v, w) with the rotation by
    Runge-Kutta-Munthe-Kaas in the body frame, R = R0 exp(u), du/dt = dexp^-1_{-u}(w).

    The step is a Python loop around Pinocchio's calls (``aba``, ``exp3``, ``Jlog3`` take one body each; its one
    batched dynamics call, ``abaInParallel``, takes one model and no ``fext``): the vectors (p, v, w) travel
    stacked as one (3, B, 3) array, the RK4 stage derivatives as one (4, B, 3) array (dp, dv, dw, du), so that each
    stage costs a few NumPy calls whatever the body count, each the same float operation on the same operands as
    one vector at a time.
    """

    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        models: dict[bytes, tuple[pin.Model, pin.Data]] = {}  # bodies of one mass and inertia share a model
        self._models = []
        for body in scene.bodies:
            key = np.append(body.mass, body.inertia_body).tobytes()
            if key not in models:
                model = free_body_model(body, scene.forces.gravity_world)
                models[key] = (model, model.createData())
            self._models.append(models[key])
        rotation0 = quat_wxyz_to_matrix(np.stack([b.quat_wxyz for b in scene.bodies]))
        omega_local0 = np.einsum("bji,bj->bi", rotation0, np.stack([b.angular_velocity_world for b in scene.bodies]))
        self._state0 = (np.stack([np.stack([b.position_world for b in scene.bodies]),
                                  np.stack([b.velocity_world for b in scene.bodies]), omega_local0]), rotation0)
        self._tau = np.zeros(6)
        self._forces = scene.forces
        self._drag = external_forces.has_drag(scene.forces) or external_forces.has_angular_drag(scene.forces)
        self._external = self._drag or bool(scene.forces.applied) or bool(scene.forces.timed)
        # aba's fext per body (universe, then its joint): the joint's entry is rewritten at every call.
        self._fext = [pin.StdVec_Force([pin.Force.Zero(), pin.Force.Zero()]) for _ in scene.bodies]
        self._at_points = [pin.SE3(np.eye(3), applied.point_body) for applied in scene.forces.applied]
        self._step = self._rk4 if integrator == "rk4" else self._euler
        self._dt = dt
        self.detail = ("harness-stepped: pin.aba accelerations, "
                       + ("RK4 with RKMK on SO(3)" if integrator == "rk4" else "engines' semi-implicit Euler on SO(3)")
                       + ("; applied forces as aba fext at their body points (SE3.act)" if scene.forces.applied else "")
                       + (f"; {external_forces.DETAIL}, as aba fext" if self._drag else "")
                       + ("; loads that change with time as aba fext at each stage's time t + c dt (a held load as "
                          "seen from inside the step)" if scene.forces.timed else ""))

    def batched(self, copies: int) -> BatchedRun:
        """The harness calls aba body by body: NotBatchedError."""
        raise NotBatchedError("the harness steps pinocchio's aba one body at a time from Python: no batched "
                              "stepping")

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        dt, b = self._dt, len(self._models)
        state = self._state0
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            pos, rot, vel, omg = (np.empty((stop - start, b) + s) for s in ((3,), (3, 3), (3,), (3,)))
            for j, i in enumerate(range(start, stop)):
                if i:
                    state = self._step(state, dt, (i - 1) * dt)
                (p, v, w), r = state
                pos[j], rot[j], vel[j], omg[j] = p, r, v, np.einsum("bij,bj->bi", r, w)
            yield Trajectory(np.arange(start, stop) * dt, pos, matrix_to_quat_wxyz(rot), vel, omg)

    def _set_fext(self, r: np.ndarray, v: np.ndarray, w_local: np.ndarray, t: float, step_start: float) -> None:
        """aba's external force on each body's joint: LOCAL frame, about the COM; timed loads at stage time t [s] of
        the step starting at ``step_start``."""
        b = len(r)
        force, torque = np.zeros((b, 3)), np.zeros((b, 3))
        if self._drag:
            force = external_forces.drag_force_world(self._forces, v)
            torque = external_forces.drag_torque_world(self._forces, np.einsum("bij,bj->bi", r, w_local))
        per_body = [pin.Force(r[k].T @ force[k], r[k].T @ torque[k]) for k in range(b)]
        for applied, at_point in zip(self._forces.applied, self._at_points):
            k = applied.body
            per_body[k] = per_body[k] + at_point.act(pin.Force(r[k].T @ applied.force_world, _NO_TORQUE))
        for load in self._forces.timed:
            k = load.body
            force_world, torque_world = time_loads.load_world(load, t, r[k], step_start)
            at_point = pin.SE3(np.eye(3), load.point_body)
            per_body[k] = per_body[k] + at_point.act(pin.Force(r[k].T @ force_world, r[k].T @ torque_world))
        for fext, spatial in zip(self._fext, per_body):
            fext[1] = spatial

    def _accelerations(self, s: np.ndarray, r: np.ndarray, out: np.ndarray, t: float, step_start: float) -> None:
        """(dv/dt world, dw/dt local) into ``out`` (2, B, 3), from aba at the state ``s`` = (p, v, w_local) (3, B, 3)
        and rotations ``r`` (B, 3, 3) at stage time t [s] of the step starting at ``step_start``; the scene's
        non-gravity forces as fext."""
        p, v, w_local = s
        v_local = np.einsum("bji,bj->bi", r, v)
        qd = np.concatenate([v_local, w_local], axis=1)
        if self._external:
            self._set_fext(r, v, w_local, t, step_start)
        a = np.empty((len(p), 6))
        for k, (model, data) in enumerate(self._models):
            q = pin.SE3ToXYZQUAT(pin.SE3(r[k], p[k]))
            a[k] = (pin.aba(model, data, q, qd[k], self._tau, self._fext[k]) if self._external
                    else pin.aba(model, data, q, qd[k], self._tau))
        # aba's linear part is the spatial acceleration; the COM's classical one adds w x v.
        out[0] = np.einsum("bij,bj->bi", r, a[:, :3] + _spin_cross(qd))
        out[1] = a[:, 3:]

    def _euler(self, state, dt, t):
        s, r = state
        stepped = np.empty_like(s)
        self._accelerations(s, r, stepped[1:], t, t)
        stepped[1:] = s[1:] + dt * stepped[1:]
        stepped[0] = s[0] + dt * stepped[1]
        return stepped, r @ _exp3(dt * stepped[2])

    def _rk4(self, state, dt, t):
        s, r = state
        ks = []  # (dp, dv, dw, du) per stage, (4, B, 3)
        for a_row, c in zip(_RK4_A, _RK4_C):
            inc = np.zeros((4,) + s.shape[1:])
            for a, k in zip(a_row, ks):
                inc = inc + (dt * a) * k
            stage, u = s + inc[:3], inc[3]
            rotation = _exp3(u)
            k = np.empty_like(inc)
            k[0] = stage[1]
            self._accelerations(stage, r @ rotation, k[1:3], t + c * dt, t)
            k[3] = _dexp_inverse(rotation, stage[2])
            ks.append(k)
        total = sum((dt * b) * k for b, k in zip(_RK4_B, ks))
        return s + total[:3], r @ _exp3(total[3])


_NO_TORQUE = np.zeros(3)
"""The moment about its own point of a force applied at a point (``SE3.act`` moves it to the COM)."""


def _spin_cross(twist: np.ndarray) -> np.ndarray:
    """w x v of twists (v, w), (B, 6) -> (B, 3): ``np.cross(w, v)``'s products and differences, in two gathers."""
    products = twist.take(_W_FIRST, axis=1) * twist.take(_V_SECOND, axis=1)
    return products[:, :3] - products[:, 3:]


_W_FIRST, _V_SECOND = np.array([4, 5, 3, 5, 3, 4]), np.array([2, 0, 1, 1, 2, 0])
"""Component i of w x v is w[i+1] v[i+2] - w[i+2] v[i+1] (indices mod 3), w at columns 3-5 of a twist, v at 0-2:
the first factors of the six products, then the second."""


def _exp3(rotvec: np.ndarray) -> np.ndarray:
    """Pinocchio's exp3 per body: (B, 3) rotation vectors -> (B, 3, 3)."""
    return np.array([pin.exp3(u) for u in rotvec])


def _dexp_inverse(rotation: np.ndarray, w_local: np.ndarray) -> np.ndarray:
    """du/dt of R = R0 exp3(u) with body angular velocity w: Jlog3(exp3(u)) w, given exp3(u) (B, 3, 3) and w
    (B, 3) -> (B, 3)."""
    return np.array([pin.Jlog3(e) @ wk for e, wk in zip(rotation, w_local)])


class PinocchioChain(KinematicsModel):
    """A fixed-base chain in Pinocchio: its URDF file without geometry when it has one, else the adapter's export.

    Attributes
    ----------
    model, data : pinocchio.Model, pinocchio.Data
    end_frame : int
        Frame id of the end effector (the BODY frame of the link of that name).
    idx_v : list of int
        Velocity index of each chain joint (a URDF file may have joints off the chain).
    base : BaseFrame
        The chain's base link in Pinocchio's world.
    """

    def __init__(self, chain: Chain) -> None:
        with captured_output():
            self.model = pin.buildModelFromXML(chain_urdf(chain))
        self.data = self.model.createData()
        joints = [self.model.joints[self.model.getJointId(j.name)] for j in chain.joints]
        self._idx_q = [j.idx_q for j in joints]
        self.idx_v = [j.idx_v for j in joints]
        self._continuous = [j.nq == 2 for j in joints]
        # A joint's frame is its child link's frame (URDF); the end effector is a link.
        self._frames = [self.model.getFrameId(j.name, pin.JOINT) for j in chain.joints]
        self.end_frame = self.model.getFrameId(chain.end_effector_name, pin.BODY)
        self._frames.append(self.end_frame)
        self.base = BaseFrame()
        if chain.base_link is not None:
            pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
            placement = self.data.oMf[self.model.getFrameId(chain.base_link, pin.BODY)]
            self.base = BaseFrame(placement.translation.copy(), placement.rotation.copy())
        self.detail = (f"buildModelFromXML of {chain_source(chain)}; forwardKinematics + updateFramePlacements; "
                       "computeFrameJacobian LOCAL_WORLD_ALIGNED")

    def configuration(self, q_row: np.ndarray) -> np.ndarray:
        """Pinocchio configuration (nq,) of joint values (n,): (cos, sin) for continuous joints."""
        return configuration(self.model, self._idx_q, self._continuous, q_row)

    def joint_values(self, configuration: np.ndarray) -> np.ndarray:
        """Joint values (n,) of a configuration; atan2(sin, cos) in (-pi, pi] for continuous joints."""
        return np.array([np.arctan2(configuration[at + 1], configuration[at]) if continuous else configuration[at]
                         for at, continuous in zip(self._idx_q, self._continuous)])

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        q = np.atleast_2d(q)
        n = len(self._frames)
        pos, rot = np.empty((len(q), n, 3)), np.empty((len(q), n, 3, 3))
        for k, row in enumerate(q):
            pin.framesForwardKinematics(self.model, self.data, self.configuration(row))
            for f, fid in enumerate(self._frames):
                pos[k, f] = self.data.oMf[fid].translation
                rot[k, f] = self.data.oMf[fid].rotation
        return FramePoses(*self.base.frames(pos, rot))

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        out = np.empty((len(q), 6, len(self.idx_v)))
        for k, row in enumerate(q):
            jac = pin.computeFrameJacobian(self.model, self.data, self.configuration(row), self.end_frame,
                                           pin.LOCAL_WORLD_ALIGNED)
            out[k] = jac[:, self.idx_v]
        return self.base.jacobian(out)


def _dynamics_support(chain: Chain) -> Support:
    """Whether Pinocchio's dynamics model can hold ``chain``: mass properties that URDF can express."""
    problem = chain.dynamics_problem()
    if problem:
        return Support.no(problem)
    expressible = urdf_support(chain) if chain.robot_file is None else Support.yes()
    if not expressible.ok:
        return expressible
    refused = pinocchio_dynamics_problem(chain)
    return Support.no(refused) if refused else Support.yes()


CONTACT_SCHEME_WHY = ("Pinocchio's contact is solved at the velocity level once per step (impulses by its ADMM, then q from "
                      "the new velocity: Moreau-Jean time stepping, references.pinocchio.contact): only semi_implicit_euler "
                      "steps a scene with contact")
"""Why Pinocchio's rows with another integrator are n/a on a scene with contact."""


@derives_own_inputs
class PinocchioEngine(UrdfChains, Engine):
    """Pinocchio: kinematics from a chain's URDF; dynamics from aba, stepped by the harness."""

    name = "pinocchio"

    def version(self) -> str:
        return pin.__version__

    def integrators(self) -> tuple[str, ...]:
        return INTEGRATORS

    def theoretical_order(self, integrator: str) -> int | None:
        """The harness's steppers: the engines' first-order scheme, classical RK4; on a chain's joints explicit and
        semi-implicit Euler (1), RK4 (4), the DOP853 solves none (:mod:`references.pinocchio.joint_motion`)."""
        return {"euler": 1, "rk4": 4}.get(integrator, joint_motion.ORDERS.get(integrator))

    def stages(self, integrator: str) -> int | None:
        """``pin.aba`` calls per body (or copy of a chain) and step: once for an Euler step, once per stage of RK4;
        None for the DOP853 solves (their steps vary)."""
        return {"euler": 1, "rk4": 4}.get(integrator, joint_motion.STAGES.get(integrator))

    def scheme(self, integrator: str, scene) -> str:
        """The harness's steppers on Pinocchio's dynamics: the engines' Euler step and RK4; its IK (``clik``,
        ``clik-documented``) is the closed-loop IK of its documentation, damped least squares on the SE(3) log."""
        if isinstance(scene, IKScene):
            return "damped_least_squares" if integrator in pinocchio_ik.SOLVERS else ""
        if isinstance(scene, JointDynamicsScene):
            return integrator if integrator in self.joint_dynamics_methods() else ""
        if isinstance(scene, JointMotionScene):
            return joint_motion.SCHEMES.get(integrator, "")
        return {"euler": "engine_euler", "rk4": "rk4"}.get(integrator, "")

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        if scene.contact is not None:
            return Support.no(NO_CONTACT)
        return self.check_integrator(integrator)

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, integrator, dt)

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return PinocchioChain(chain)

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        """Pinocchio's recursive algorithms: crba, nle, rnea, aba (:mod:`references.pinocchio.joint_dynamics`)."""
        return ("recursive",)

    def supports_joint_dynamics(self, chain: Chain, method: str) -> Support:
        """A chain with mass properties that URDF can express; armature is Pinocchio's own, damping added."""
        named = super().supports_joint_dynamics(chain, method)
        return _dynamics_support(chain) if named.ok else named

    def build_joint_dynamics(self, chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
        return (PinocchioFloatingDynamics(chain, gravity_world) if chain.floating_base
                else PinocchioJointDynamics(chain, gravity_world))

    def joint_motion_integrators(self) -> tuple[str, ...]:
        """The harness's steppers of ``pin.aba`` and the DOP853 solves (:mod:`references.pinocchio.joint_motion`)."""
        return joint_motion.INTEGRATORS

    def supports_joint_motion(self, scene: JointMotionScene, integrator: str) -> Support:
        """The chains of :meth:`supports_joint_dynamics`."""
        named = super().supports_joint_motion(scene, integrator)
        if named.ok and scene.contact is not None and integrator != "semi_implicit_euler":
            return Support.no(CONTACT_SCHEME_WHY)
        return _dynamics_support(scene.chain) if named.ok else named

    def chain_contact(self, scene: JointMotionScene) -> Support:
        """Its point contacts and ADMM in the harness's semi-implicit Euler (:mod:`references.pinocchio.contact`);
        plastic, so a rigid contact only with restitution 0."""
        return contact_params.plastic_only(scene, "the harness's Moreau-Jean loop is plastic (an impulse stops a pushed sphere)")

    def build_joint_motion(self, scene: JointMotionScene, integrator: str, dt: float) -> JointSimulation:
        if scene.chain.floating_base:
            return PinocchioFloatingMotion(scene, integrator, dt)
        return joint_motion.PinocchioJointMotion(scene, integrator, dt)

    def ik_solvers(self) -> tuple[str, ...]:
        return pinocchio_ik.SOLVERS

    def build_ik(self, chain: Chain, solver: str, options: IKTolerances) -> IKModel:
        return pinocchio_ik.PinocchioIK(PinocchioChain(chain), chain, solver, options)

    def export(self, scene, integrator, dt) -> str:
        if not isinstance(scene, DynamicsScene):
            return chain_export(scene.chain, "pinocchio.buildModelFromXML (fixed base)")
        integrator, dt = self._export_settings(scene, integrator, dt)
        models = [free_body_model(body, scene.forces.gravity_world) for body in scene.bodies]
        inertias = "".join(f"{m.names[1]}: {m.inertias[1]}\n" for m in models)
        external = [n for n in scene.forces.names() if n != "gravity"]
        gravity = models[0].gravity.linear if models else scene.forces.gravity_world
        return (
            f"# Pinocchio models built in code (no file): one model with one free-flyer per body.\n"
            f"# gravity: {gravity}; stepped by the harness ({integrator}, dt = {dt!r} s)\n"
            + (f"# each step, aba's fext (local frame, about the COM): {', '.join(external)}"
               + (" (timed loads at each stage's time)" if scene.forces.timed else "") + "\n" if external else "")
            + (f"# contact: n/a, not simulated: {NO_CONTACT}\n" if scene.contact is not None else "")
            + (f"{models[0]}\n" if models else "") + inertias
        )
