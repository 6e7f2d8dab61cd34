"""PyBullet behind the shared engine interface.

Conversions and overridden defaults (each pinned by a test in ``tests/references/pybullet/test_adapter.py``)
-----------------------------------------------------------------------------------------------
- Quaternions are (x, y, z, w) in PyBullet: reordered here.
- ``getBasePositionAndOrientation`` / ``resetBasePositionAndOrientation`` speak of the
  base's INERTIAL frame (COM, principal axes). The URDF puts the principal axes at
  ``Q`` in the body frame, so R_inertial = R_body Q and R_body = R_inertial Q^T.
- ``getBaseVelocity`` is the COM velocity and the angular velocity, both world frame.
- Inertia is taken from the URDF (``URDF_USE_INERTIA_FROM_FILE``): by default PyBullet
  recomputes it from collision shapes.
- Linear and angular damping default to 0.04 on every link: set to 0.
- Gravity defaults to 0: always set explicitly (to the scene's, or zero).
- Sleeping (deactivation of slow bodies) is disabled.
- ``maxJointVelocity`` (Bullet clamps velocities at 100 rad/s by default) is raised to 1e9,
  far above any scene's; a run that still reaches it has blown up and raises DivergedError.
- A chain read from a URDF file is loaded from that file without its visual and collision
  geometry (:func:`references.common.urdf_export.chain_urdf`; ``useFixedBase``), so PyBullet opens
  no mesh; poses are re-expressed in the chain's base link (:mod:`references.common.base_frame`;
  the base link's pose comes from ``getLinkState``, float32, when it is not the root).
  Other chains from the adapter's URDF. What PyBullet prints while loading is kept off the
  console (:mod:`references.common.quiet`).
- ``getLinkState`` positions and orientations are FLOAT32 (errors ~1e-7); the Jacobian
  from ``calculateJacobian`` is double.
- PyBullet has one integrator (semi-implicit Euler, velocity then position); time step = dt,
  no sub-steps.
- Forces other than gravity, from the state at the start of each step, the way PyBullet
  users apply them: a force at a body point with ``applyExternalForce`` at the point's
  WORLD position (the base pose's ``getMatrixFromQuaternion``, double; PyBullet's
  ``multiplyTransforms`` would round it to float32; PyBullet computes the torque);
  drag and wind (:mod:`references.common.external_forces`, independent of core) as a world-frame
  force at the COM and a world-frame torque (``applyExternalTorque``). All with
  WORLD_FRAME (in 3.2.7 both honour the flag, which bullet3 #1949 once had swapped for the
  base); PyBullet clears them after every step.
- Contact (a scene with ``contact``; shared parameters in :mod:`references.common.contact_params`):
  every plane is a static multibody with a ``GEOM_PLANE`` shape of normal N placed at -d N;
  every body keeps its URDF inertia (``URDF_USE_INERTIA_FROM_FILE``) and gets collision
  spheres: a sphere of radius r + POINT_RADIUS, a point (each of "points", each box corner)
  a sphere of POINT_RADIUS, with ``contactSlop`` = POINT_RADIUS (Bullet's multibody solver
  adds the slop to every contact distance), so every shape touches exactly where the scene
  says (a box with its corners, as box-plane contact is; no box margin to round them).
  Collision groups let bodies touch planes only. Bullet MULTIPLIES the two objects'
  restitution and lateral friction: planes get 1, each body its k and mu_k (one lateral
  friction coefficient: mu_k), rolling and spinning friction 0; a body whose material
  differs between planes is n/a. Bullet's multibody contact (Bullet 3.2.7 source,
  btMultiBodyConstraintSolver) works on velocities: restitution makes the normal velocity
  -k times the approach velocity; a contact found before the bodies touch ("speculative",
  distance D > 0) lets the body approach by at most D/dt; a penetration is pushed out by
  contactERP (adds D erp / dt to the rebound, which inflates restitution: measured 0.63 for
  k = 0.5 at dt = 0.01 with erp 0.2) and split impulse is NOT implemented for multibodies
  (commented out there; ``useSplitImpulse`` changes nothing, which a test pins). Hence:
  ``contactERP`` = 0; a body with k = 0 gets speculative contacts (contactProcessingThreshold
  1e9 m: it stops exactly on the plane, no penetration); a body with k > 0 only contacts at
  distance <= POINT_RADIUS (contactProcessingThreshold 0, the maintainers' advice when
  restitution matters, bullet3 #1701 and #3096; pybullet ignores a negative one: a speculative
  contact would replace the bounce by k|v| - D/dt, measured e = 0.02 instead of 0.5), so an
  impact leaves a penetration of at most v dt until the body leaves. ``restitutionVelocityThreshold``
  is the scene's rest rule on Bullet's terms: Bullet drops restitution when the APPROACH speed
  is below it, the scene when the REBOUND k |v| is below ``rest_speed``, so the threshold is
  rest_speed / k (the largest k > 0 of the scene when bodies differ). Generated contacts:
  ``contactBreakingThreshold`` (Bullet's factor of each body's bounding radius) 1e5, so that a
  contact is generated at least 1.7 m ahead (capped by Bullet's AABB overflow check, see
  :data:`BREAKING_FACTOR`); it is a PROCESS-GLOBAL variable in Bullet, set again before every
  run. ``numSolverIterations`` 100 (PGS sweeps; a box rests on 4 corners),
  ``solverResidualThreshold`` 1e-12 (:data:`SOLVER_RESIDUAL`), ``globalCFM`` 0,
  ``deterministicOverlappingPairs`` 1.
- What Bullet's time stepping does with the rest rule: the approach speed it sees includes the
  g dt gained in the step, so a body with k > 0 resting on a plane hops by about k |g| dt^2 every
  step unless rest_speed / k exceeds |g| dt (measured 3.3e-6 m at k = 0.5, dt = 1e-3), and
  bounces settle at a rebound speed k |g| dt / (1 - k) instead of dying out (hard-zeno, k = 0.9,
  dt = 0.01: still bouncing ~7 cm high at the end).

Over 600 lines: one engine's adapter. Every conversion to and from PyBullet is here by the architecture's
rule (conversions live in the engine's adapter), with the defaults it overrides listed above.
"""

from __future__ import annotations

import importlib.metadata
import os
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from typing import cast

import numpy as np

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
from simparity.core.model.files import parse_xml
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import FramePoses, Trajectory, piece_bounds
from simparity.references.common import contact_params, external_forces, time_loads
from simparity.references.pybullet import ik as pybullet_ik
from simparity.references.common.base_frame import BaseFrame
from simparity.references.common.conventions import (
    fmt,
    matrix_to_quat_wxyz,
    principal_axes,
    quat_wxyz_to_matrix,
    wxyz_from_xyzw,
    xyzw_from_wxyz,
)
from simparity.references.pybullet.floating_body import massless_base
from simparity.references.pybullet.quiet import pybullet
from simparity.references.common.quiet import captured_output
from simparity.references.common.dynamics_mjcf import WORLD, dynamics_mjcf
from simparity.references.common.dynamics_urdf import chain_joint_names, dynamics_urdf
from simparity.references.common.forked import asked_in_child
from simparity.references.common.urdf_export import (
    UrdfChains,
    body_urdf,
    chain_export,
    chain_source,
    chain_urdf,
    movable_joints_above_base,
    urdf_support,
)
from simparity.references.common.scene_inputs import derives_own_inputs

_MAX_VELOCITY = 1e9  # [rad/s or m/s]: effectively no clamping
_CLAMPED = 0.999 * _MAX_VELOCITY  # a velocity this large has hit the cap: the run blew up


def _load_urdf(client: int, text: str, **kwargs) -> int:
    """loadURDF needs a file: write the text to a temporary one; what PyBullet prints is kept off the console."""
    with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False, encoding="utf-8") as f:
        f.write(text)
        path = f.name
    try:
        with captured_output():
            return pybullet.loadURDF(path, flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client, **kwargs)
    finally:
        os.unlink(path)


FIXED_BASE_JOINT = {"name": "simparity_fixed_base", "type": "fixed", "pos": "0 0 0", "axis": "0 0 1", "limited": "false",
                    "armature": "0", "damping": "0", "stiffness": "0"}
"""PyBullet's own MJCF extension that fixes a body to the world (pybullet_data's humanoid_fixed.xml): MJCF has no fixed
joint, and PyBullet's MJCF importer makes a root body without one free (measured: the ant's M 8 x 8 for 2 hinges).
Every attribute is written: without ``limited`` PyBullet 3.2.7's parser aborts the process (std::logic_error)."""


def pybullet_mjcf(chain: Chain) -> str:
    """The MJCF text PyBullet reads for a chain from an MJCF file: :func:`references.common.dynamics_mjcf.dynamics_mjcf`
    with :data:`FIXED_BASE_JOINT` on its base body."""
    root = ET.fromstring(dynamics_mjcf(chain))
    world = cast(ET.Element, root.find("worldbody"))
    body = list(world)[0]  # the base body, or (the world as the base) the root body or the frame around it
    if chain.base_link == WORLD and body.get("name") != WORLD:  # the root body's joints move it: anchor it to the world
        world.remove(body)
        anchor = ET.SubElement(world, "body", name="simparity_world")
        anchor.append(body)
        body = anchor
    body.insert(0, ET.Element("joint", FIXED_BASE_JOINT))
    return ET.tostring(root, encoding="unicode")


def _load_mjcf(client: int, text: str) -> int:
    """loadMJCF needs a file: the text written to a temporary one, PyBullet's output kept off the console; the one body
    it makes (a file of :func:`pybullet_mjcf` has one root body)."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "model.xml")
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
        with captured_output():
            bodies = pybullet.loadMJCF(path, physicsClientId=client)
    if len(bodies) != 1:
        raise pybullet.error(f"loadMJCF made {len(bodies)} bodies of one root body")
    return int(bodies[0])


def _mjcf_loader_support(text: str, names: tuple[str, ...]) -> Support:
    """No, in PyBullet's words, when its MJCF loader refuses ``text`` or crashes on it, or when the body it makes lacks
    a chain joint of ``names`` (its importer drops a joint written without ``type`` or inheriting one from a
    ``childclass``): asked in a forked child, since PyBullet 3.2.7's MJCF parser aborts the process on some input
    (:data:`FIXED_BASE_JOINT`)."""

    def question() -> str:
        client = _Client()  # kept: a client let go disconnects
        try:
            body = _load_mjcf(client.id, text)
        except Exception as err:  # noqa: BLE001 - reported to the parent as text
            return f"refuses the file: {' '.join(str(err).split()) or type(err).__name__}"
        made = {pybullet.getJointInfo(body, j, physicsClientId=client.id)[1].decode()
                for j in range(pybullet.getNumJoints(body, physicsClientId=client.id))
                if pybullet.getJointInfo(body, j, physicsClientId=client.id)[2] != pybullet.JOINT_FIXED}
        dropped = [name for name in names if name not in made]
        return (f"loads the file, but its body lacks the chain's joints {dropped[:3]} (it drops the joints it does not "
                "read: written without type, taking it from a default class, or inside a <frame>)") if dropped else ""

    said, signal = asked_in_child(question)
    if signal is not None:
        return Support.no(f"PyBullet's MJCF loader crashes on the file (signal {signal})")
    return Support.no(f"PyBullet's MJCF loader {said}") if said else Support.yes()


CONTACT_ERP = 0.0
"""contactERP: no position correction by velocity (it adds energy to bounces; see the module docstring)."""
SOLVER_ITERATIONS = 100
"""numSolverIterations (Bullet's PGS sweeps; default 50): simultaneous contacts (a box on 4 corners)."""
SOLVER_RESIDUAL = 1e-12
"""solverResidualThreshold: PGS stops early below this residual. Bullet's 1e-7 stops it too early for a box resting
on its corners, which then sinks steadily (there is no position correction: contactERP 0): measured 1e-5 m/s;
1e-12 lets it run its sweeps, 1e-7 m/s."""
BREAKING_FACTOR = 1e5
"""contactBreakingThreshold, Bullet's RELATIVE threshold: a contact is generated within this factor times the
shape's bounding radius, at least 1e5 sqrt(3) POINT_RADIUS = 1.7 m for the smallest shape (a point), so a body
with k = 0 is caught before it touches unless it moves more than that in one step. Bullet also widens every
object's AABB by the factor itself (in metres) and silently stops simulating an object whose AABB exceeds
1e6 m (btCollisionWorld::updateSingleAabb: a factor 1e6 let a point fall through the plane), so 1e5."""
SPECULATIVE_RANGE = 1e9  # [m]
"""contactProcessingThreshold of a body with k = 0 against every plane: all its contacts are solved, also before
touching, so it stops on the plane without penetrating. Bodies with k > 0 get 0 (module docstring)."""
MAX_FRICTION = 10.0
"""Bullet clamps a combined friction coefficient to [-10, 10] (btManifoldResult::calculateCombinedFriction)."""
BODY_GROUP, PLANE_GROUP = 1, 2
"""Collision filter groups: a body collides with planes only (group & other mask on both sides)."""


def static_plane(client: int, plane) -> int:
    """A static multibody whose GEOM_PLANE (normal N, through its origin) sits at -d N, with :data:`PLANE_DYNAMICS`;
    it touches bodies (group :data:`BODY_GROUP`) only. Its unique id."""
    shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, planeNormal=plane.normal_world.tolist(),
                                          physicsClientId=client)
    uid = pybullet.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=shape,
                                   basePosition=(-plane.offset * plane.normal_world).tolist(), physicsClientId=client)
    pybullet.changeDynamics(uid, -1, **PLANE_DYNAMICS, physicsClientId=client)
    pybullet.setCollisionFilterGroupMask(uid, -1, PLANE_GROUP, BODY_GROUP, physicsClientId=client)
    return uid


def restitution_threshold(contact) -> float:
    """Bullet's restitutionVelocityThreshold [m/s]: the approach speed below which the scene's rule (a rebound
    k |v| below rest_speed ends in resting contact) drops restitution, rest_speed / k; the largest k > 0 of the
    scene when bodies differ (rest_speed when no k > 0)."""
    k = float(np.max(contact.restitution)) if contact.restitution.size else 0.0
    return contact.rest_speed / k if k > 0 else contact.rest_speed


def contact_parameters(contact, dt: float) -> dict:
    """setPhysicsEngineParameter arguments of a contact scene (module docstring gives each reason)."""
    return dict(contactERP=CONTACT_ERP, contactSlop=contact_params.POINT_RADIUS,
                restitutionVelocityThreshold=restitution_threshold(contact), useSplitImpulse=0,
                numSolverIterations=SOLVER_ITERATIONS, solverResidualThreshold=SOLVER_RESIDUAL, globalCFM=0.0,
                deterministicOverlappingPairs=1, contactBreakingThreshold=BREAKING_FACTOR)


def body_contact_dynamics(restitution: float, friction: float) -> dict:
    """changeDynamics arguments of a body in a contact scene (planes get restitution 1, lateral friction 1)."""
    return dict(restitution=restitution, lateralFriction=friction, rollingFriction=0.0, spinningFriction=0.0,
                contactProcessingThreshold=0.0 if restitution > 0 else SPECULATIVE_RANGE)


PLANE_DYNAMICS = dict(restitution=1.0, lateralFriction=1.0, rollingFriction=0.0, spinningFriction=0.0)
"""changeDynamics of every plane: 1, the neutral factor of Bullet's products."""


def contact_support(contact) -> Support:
    """Whether PyBullet can give every body-plane pair its material (one value per body, friction <= 10)."""
    if contact is None:
        return Support.yes()
    values, reason = contact_params.body_materials(contact)
    if values is None:
        return Support.no("PyBullet multiplies the restitution and friction of the two objects in contact, so a "
                          f"body has one value against every plane; {reason}")
    too_rough = [b for b, (_, mu) in enumerate(values) if mu > MAX_FRICTION]
    if too_rough:
        return Support.no(f"Bullet clamps friction coefficients to {MAX_FRICTION:g}; body {too_rough[0]} has mu_k "
                          f"{values[too_rough[0]][1]:g}")
    return Support.yes()


class _Client:
    """A private DIRECT-mode PyBullet world, disconnected when garbage-collected."""

    def __init__(self) -> None:
        self.id = pybullet.connect(pybullet.DIRECT)

    def __del__(self) -> None:
        try:
            pybullet.disconnect(physicsClientId=self.id)
        except Exception:  # noqa: BLE001 - interpreter shutdown may have unloaded pybullet
            pass


READ_BACK = ("fixedTimeStep", "numSubSteps", "numSolverIterations", "numNonContactInnerIterations")
"""The engine parameters PyBullet 3.2.7 reports back (getPhysicsEngineParameters returns only these, the
real-time flag and gravity; restitutionVelocityThreshold, contactERP, contactSlop, split impulse and the
breaking threshold cannot be read back: tests check their effect instead)."""


class _Simulation(PieceSimulation):
    """A scene in a private PyBullet world.

    Attributes
    ----------
    client : int
        The PyBullet client id.
    body_ids, plane_ids : list of int
        Multibody ids of the scene's bodies and planes (no planes without contact).
    engine_parameters : dict
        getPhysicsEngineParameters after configuring a contact scene ({} without contact).
    """

    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        self._client = _Client()
        c = self._client.id
        gravity = scene.forces.gravity_world
        pybullet.setGravity(*(gravity if gravity is not None else (0.0, 0.0, 0.0)), physicsClientId=c)
        pybullet.setTimeStep(dt, physicsClientId=c)
        pybullet.setPhysicsEngineParameter(numSubSteps=0, physicsClientId=c)
        contact = scene.contact
        if contact is not None:
            pybullet.setPhysicsEngineParameter(**contact_parameters(contact, dt), physicsClientId=c)
            materials, _ = contact_params.body_materials(contact)
            self._planes = [self._add_plane(plane) for plane in contact.planes]
        self._bodies, body_axes, self._initial = [], [], []
        for b, body in enumerate(scene.bodies):
            spheres = () if contact is None else contact_params.inflated_spheres(contact.shapes[b])
            uid = _load_urdf(c, body_urdf(body, spheres))
            pybullet.changeDynamics(
                uid, -1, linearDamping=0.0, angularDamping=0.0, maxJointVelocity=_MAX_VELOCITY,
                activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=c,
            )
            if contact is not None:
                assert materials is not None  # built only when supported: contact_support refuses differing materials
                pybullet.changeDynamics(uid, -1, **body_contact_dynamics(*materials[b]), physicsClientId=c)
                pybullet.setCollisionFilterGroupMask(uid, -1, BODY_GROUP, PLANE_GROUP, physicsClientId=c)
            _, axes = principal_axes(body.inertia_body)
            quat_inertial = matrix_to_quat_wxyz(quat_wxyz_to_matrix(body.quat_wxyz) @ axes)
            self._bodies.append(uid)
            body_axes.append(axes)
            self._initial.append((body.position_world, xyzw_from_wxyz(quat_inertial),
                                  body.velocity_world, body.angular_velocity_world))
        self._axes = np.stack(body_axes)
        self._forces = scene.forces
        self._drag = external_forces.has_drag(scene.forces) or external_forces.has_angular_drag(scene.forces)
        # Applied forces: (body index, force [N], application point in the base's INERTIAL frame [m]).
        self._applied = [(a.body, a.force_world.tolist(), self._axes[a.body].T @ a.point_body)
                         for a in scene.forces.applied]
        self._dt = dt
        self._contact = contact
        self.client, self.body_ids = c, list(self._bodies)
        self.plane_ids = list(self._planes) if contact is not None else []
        self.engine_parameters = pybullet.getPhysicsEngineParameters(physicsClientId=c) if contact is not None else {}
        read_back = ", ".join(f"{name}={self.engine_parameters[name]!r}" for name in READ_BACK
                              if name in self.engine_parameters)
        self.detail = (
            "PyBullet multibody; inertia from file; damping 0; sleeping off; gravity set explicitly"
            + ("" if contact is None else f"; {contact_detail(contact, dt)}; read back by "
               f"getPhysicsEngineParameters: {read_back}")
            + ("; applyExternalForce at each applied force's world point" if self._applied else "")
            + ("; loads that change with time at each step's start (stepSimulation's one evaluation), by "
               "applyExternalForce at the load's world point and applyExternalTorque (WORLD_FRAME)"
               if scene.forces.timed else "")
            + (f"; {external_forces.DETAIL}, as applyExternalForce at the COM and applyExternalTorque"
               if self._drag else "")
        )

    def _add_plane(self, plane) -> int:
        return static_plane(self._client.id, plane)

    def batched(self, copies: int) -> BatchedRun:
        """PyBullet has no batch API: NotBatchedError."""
        raise NotBatchedError("pybullet steps one world per stepSimulation call: no batched stepping")

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        c = self._client.id
        if self._contact is not None:  # Bullet's breaking threshold is process-global: another world may have set it
            pybullet.setPhysicsEngineParameter(contactBreakingThreshold=BREAKING_FACTOR, physicsClientId=c)
        for uid, (pos, quat, vel, omega) in zip(self._bodies, self._initial):
            pybullet.resetBasePositionAndOrientation(uid, pos, quat, physicsClientId=c)
            pybullet.resetBaseVelocity(uid, vel, omega, physicsClientId=c)
        b = len(self._bodies)
        last = np.empty((b, 13))
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            raw = np.empty((stop - start, b, 13))  # position 3, quat xyzw 4, velocity 3, omega 3
            for j, i in enumerate(range(start, stop)):
                if i:
                    self._apply(raw[j - 1] if j else last, (i - 1) * self._dt)
                    pybullet.stepSimulation(physicsClientId=c)
                for k, uid in enumerate(self._bodies):
                    pos, quat = pybullet.getBasePositionAndOrientation(uid, physicsClientId=c)
                    vel, omega = pybullet.getBaseVelocity(uid, physicsClientId=c)
                    raw[j, k] = (*pos, *quat, *vel, *omega)
            last = raw[-1]
            speeds = np.abs(raw[..., 7:13]).max()
            if speeds >= _CLAMPED:
                raise DivergedError(f"PyBullet clamped a velocity at {speeds:.3g} (its cap): the run blew up")
            quat_body = self._body_quat(raw[..., 3:7])
            yield Trajectory(np.arange(start, stop) * self._dt, raw[..., :3], quat_body, raw[..., 7:10], raw[..., 10:13])

    def _body_quat(self, quat_xyzw_inertial: np.ndarray) -> np.ndarray:
        """Body-frame quaternions from PyBullet's inertial-frame ones: R_body = R_inertial Q^T."""
        rotation_inertial = quat_wxyz_to_matrix(wxyz_from_xyzw(quat_xyzw_inertial))
        return matrix_to_quat_wxyz(rotation_inertial @ np.swapaxes(self._axes, -1, -2))

    def _apply(self, raw: np.ndarray, t: float) -> None:
        """Apply the scene's non-gravity forces, evaluated at the state ``raw`` (B, 13) at the step's start t [s]."""
        c = self._client.id
        for k, force, point_inertial in self._applied:
            rotation = np.reshape(pybullet.getMatrixFromQuaternion(raw[k, 3:7]), (3, 3))
            point = raw[k, :3] + rotation @ point_inertial
            pybullet.applyExternalForce(self._bodies[k], -1, force, point, pybullet.WORLD_FRAME, physicsClientId=c)
        for load in self._forces.timed:
            k = load.body
            rotation = np.reshape(pybullet.getMatrixFromQuaternion(raw[k, 3:7]), (3, 3)) @ self._axes[k].T
            force, torque = time_loads.load_world(load, t, rotation)
            point = raw[k, :3] + rotation @ load.point_body
            pybullet.applyExternalForce(self._bodies[k], -1, force, point, pybullet.WORLD_FRAME, physicsClientId=c)
            pybullet.applyExternalTorque(self._bodies[k], -1, torque, pybullet.WORLD_FRAME, physicsClientId=c)
        if not self._drag:
            return
        force = external_forces.drag_force_world(self._forces, raw[:, 7:10])
        torque = external_forces.drag_torque_world(self._forces, raw[:, 10:13])
        for k, uid in enumerate(self._bodies):
            pybullet.applyExternalForce(uid, -1, force[k], raw[k, :3], pybullet.WORLD_FRAME, physicsClientId=c)
            pybullet.applyExternalTorque(uid, -1, torque[k], pybullet.WORLD_FRAME, physicsClientId=c)


def contact_detail(contact, dt: float) -> str:
    """What PyBullet's contact is given for a contact scene (module docstring has the reasons)."""
    static = contact_params.static_friction_note(contact)
    return (f"contact: {len(contact.planes)} static GEOM_PLANE multibody(ies) at -d N (restitution 1, lateral friction "
            f"1, rolling/spinning 0); bodies: collision spheres (sphere r + {contact_params.POINT_RADIUS:g} m; point, "
            f"points and box corners {contact_params.POINT_RADIUS:g} m) with contactSlop "
            f"{contact_params.POINT_RADIUS:g} m, restitution k and lateral friction mu_k per body (Bullet multiplies "
            f"them with the plane's 1), rolling/spinning 0; bodies touch planes only (collision groups); "
            f"restitutionVelocityThreshold {restitution_threshold(contact):g} m/s = rest_speed "
            f"{contact.rest_speed:g} / max k (Bullet zeroes restitution below it, testing the approach speed where the scene "
            f"tests the rebound); "
            f"contactERP {CONTACT_ERP:g}; useSplitImpulse "
            f"0 (not implemented for multibody contacts); contactProcessingThreshold 0 for k > 0 (penetration up to "
            f"v dt after an impact) and {SPECULATIVE_RANGE:g} m for k = 0 (speculative: no penetration); "
            f"contactBreakingThreshold {BREAKING_FACTOR:g} (relative, process-global, set before each run); "
            f"numSolverIterations {SOLVER_ITERATIONS}, solverResidualThreshold {SOLVER_RESIDUAL:g}, globalCFM 0, "
            f"deterministicOverlappingPairs 1; two friction rows per contact, each within mu N (Bullet's multibody "
            f"friction)" + (f"; {static}" if static else ""))


LINK_STATE_RESOLUTION = (1e-6, 2e-6)
"""getLinkState is FLOAT32: ~6e-8 relative on coordinates of a few metres and ~3e-7 rad,
bounded with margin by 1e-6 m and 2e-6 rad (the tests' tolerances)."""


class PybulletChain(KinematicsModel):
    """A fixed-base chain in a private PyBullet world.

    Loads the chain's URDF file without geometry when it has one, else the adapter's export.

    Attributes
    ----------
    client : int
        The PyBullet client id.
    body : int
        The multibody's unique id.
    joints : list of int
        PyBullet joint index of each chain joint (= the index of its child link).
    end_link : int
        Link index of the end effector.
    dof_index : list of int
        Position of each chain joint among the body's movable joints (the order of the
        lists PyBullet's IK and Jacobian calls take and return).
    n_dof : int
        Movable joints of the whole body (a URDF file may have some off the chain).
    base : BaseFrame
        The chain's base link in PyBullet's world.
    end_inertial_rotation : (3, 3) ndarray
        Orientation of the end-effector link's inertial frame in its URDF link frame
        (``getDynamicsInfo``): PyBullet's IK matches a target orientation to that frame.
    """

    def __init__(self, chain: Chain) -> None:
        self._client = _Client()
        self.client = self._client.id
        self.body = _load_urdf(self.client, chain_urdf(chain), useFixedBase=True)
        info = [pybullet.getJointInfo(self.body, j, physicsClientId=self.client)
                for j in range(pybullet.getNumJoints(self.body, physicsClientId=self.client))]
        joint_index = {i[1].decode(): i[0] for i in info}
        link_index = {i[12].decode(): i[0] for i in info}
        self.joints = [joint_index[j.name] for j in chain.joints]
        self.end_link = link_index[chain.end_effector_name]
        movable = [i[0] for i in info if i[2] != pybullet.JOINT_FIXED]
        self.dof_index = [movable.index(j) for j in self.joints]
        self.n_dof = len(movable)
        self.resolution = LINK_STATE_RESOLUTION
        root = pybullet.getBodyInfo(self.body, physicsClientId=self.client)[0].decode()
        self.base = BaseFrame() if chain.base_link in (None, root) else self._link_frame(link_index[chain.base_link])
        inertial_xyzw = pybullet.getDynamicsInfo(self.body, self.end_link, physicsClientId=self.client)[4]
        self.end_inertial_rotation = quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(inertial_xyzw)))
        self.detail = (f"loadURDF of {chain_source(chain)}; getLinkState (float32 link frames); "
                       "calculateJacobian (double) at the end-effector link")

    def _link_frame(self, link: int) -> BaseFrame:
        """URDF frame of a link at the zero configuration (getLinkState: float32)."""
        state = pybullet.getLinkState(self.body, link, computeForwardKinematics=True, physicsClientId=self.client)
        return BaseFrame(np.array(state[4]), quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(state[5]))))

    def set(self, q_row: np.ndarray) -> None:
        """Put the joints at ``q_row`` (n,) [rad or m]."""
        for j, value in zip(self.joints, q_row):
            pybullet.resetJointState(self.body, j, float(value), physicsClientId=self.client)

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        q = np.atleast_2d(q)
        links = self.joints + [self.end_link]
        pos = np.empty((len(q), len(links), 3))
        quat = np.empty((len(q), len(links), 4))
        for k, row in enumerate(q):
            self.set(row)
            states = pybullet.getLinkStates(self.body, links, computeForwardKinematics=True,
                                            physicsClientId=self.client)
            for f, state in enumerate(states):
                pos[k, f], quat[k, f] = state[4], state[5]
        return FramePoses(*self.base.frames(pos, quat_wxyz_to_matrix(wxyz_from_xyzw(quat))))

    def end_effector_frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """End-effector positions (B, 3) [m] and rotations (B, 3, 3), float32 from getLinkState."""
        poses = self.forward_kinematics(q)
        return poses.position_world[:, -1], poses.rotation_world[:, -1]

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        zeros = [0.0] * self.n_dof
        positions = np.zeros(self.n_dof)  # joints off the chain stay at 0, as set() leaves them
        out = np.empty((len(q), 6, len(self.joints)))
        for k, row in enumerate(q):
            self.set(row)
            positions[self.dof_index] = row
            linear, angular = pybullet.calculateJacobian(
                self.body, self.end_link, [0.0, 0.0, 0.0], positions.tolist(), zeros, zeros,
                physicsClientId=self.client,
            )
            out[k, :3] = np.array(linear)[:, self.dof_index]
            out[k, 3:] = np.array(angular)[:, self.dof_index]
        return self.base.jacobian(out)


MAX_LINKS = 127
"""The most links of a body whose joint states PyBullet reads back: its shared-memory API sizes them by
MAX_DEGREE_OF_FREEDOM = MAX_NUM_LINKS = 128 (``SharedMemoryPublic.h``), and measured (pybullet 3.2, fresh clients,
with or without a fixed last joint) a body of 127 links reads, one of 128 fails every getJointState ('getJointState
failed', joint 0 too). A URDF's links past its root are its joints."""


def _links_support(urdf_text: str) -> Support:
    """No when the URDF PyBullet is given has more links (joints) than :data:`MAX_LINKS`."""
    links = urdf_text.count("<joint ")  # the adapter's own serialisation: one '<joint ' per joint element
    if links > MAX_LINKS:
        return Support.no(f"PyBullet reads back the joint states of at most {MAX_LINKS} links per body (its "
                          f"shared-memory MAX_DEGREE_OF_FREEDOM); this chain's URDF has {links}")
    return Support.yes()


def _dynamics_support(chain: Chain) -> Support:
    """Whether PyBullet can hold the chain's dynamics: a chain URDF can express (a prismatic joint needs limits
    there), no armature, at most :data:`MAX_LINKS` links, a floating base with a mass of its own
    (:func:`references.pybullet.floating_body.massless_base`)."""
    expressible = urdf_support(chain) if chain.robot_file is None else Support.yes()
    if not expressible.ok:
        return expressible
    armature = _armature_support(chain)
    if not armature.ok:
        return armature
    if chain.mjcf_path is not None:
        return _mjcf_loader_support(pybullet_mjcf(chain), chain_joint_names(chain))
    text = dynamics_urdf(chain)
    if chain.floating_base and (massless := massless_base(text)):
        return Support.no(massless)
    links = _links_support(text)
    return _loader_support(text) if links.ok else links


def _loader_support(text: str) -> Support:
    """No, in PyBullet's own words, when its URDF loader refuses the file every engine is given; no, naming the link,
    when it loads the file as another model (:func:`_zeroed_inertias`)."""
    client = _Client()  # disconnected when let go
    try:
        body = _load_urdf(client.id, text, useFixedBase=True)
    except pybullet.error as err:
        return Support.no(f"PyBullet's URDF loader refuses the file: {' '.join(str(err).split())}")
    zeroed = _zeroed_inertias(client.id, body, text)
    if zeroed:
        return Support.no(f"PyBullet's URDF loader sets the inertia of {len(zeroed)} link(s) to zero, first "
                          f"{zeroed[0]!r} (its rule for a tensor that is not physical: 'Bad inertia tensor properties, "
                          "setting inertia to zero', BulletUrdfImporter.cpp): its model is not the file's")
    return Support.yes()


def _zeroed_inertias(client: int, body: int, text: str) -> list[str]:
    """The links whose ``<inertia>`` in ``text`` has a non-zero entry but whose principal moments PyBullet holds as
    zero: its URDF importer replaces a tensor failing its physical check (a principal moment negative, or the triangle
    inequality broken) by zero, with a warning only (pybullet_data's xarm6_robot.urdf link2, example-robot-data's
    allegro_right_hand.urdf link_3.0; pinned by tests/references/pybullet/test_joint_dynamics.py)."""
    written = {}
    for link in parse_xml(text.encode(), "<dynamics urdf>", "robot").findall("link"):
        inertia = link.find("inertial/inertia")
        if inertia is not None:
            written[link.get("name")] = any(float(value) != 0.0 for value in inertia.attrib.values())
    zeroed = []
    for index in range(pybullet.getNumJoints(body, physicsClientId=client)):
        name = pybullet.getJointInfo(body, index, physicsClientId=client)[12].decode()
        moments = pybullet.getDynamicsInfo(body, index, physicsClientId=client)[2]
        if written.get(name) and not any(moments):
            zeroed.append(name)
    return zeroed


def _armature_support(chain: Chain) -> Support:
    """PyBullet has no joint armature: no when a joint of ``chain`` declares one."""
    armature = [j for j in chain.joints if j.armature > 0]
    if armature:
        return Support.no(f"PyBullet has no joint armature (rotor inertia added to M's diagonal); joint "
                          f"{armature[0].name!r} declares {armature[0].armature:g}")
    return Support.yes()


FLOATING_BASE_WHY = (
    "PyBullet's floating-base dynamics are not comparable at rounding: calculateInverseDynamics of a floating base "
    "(7 + n positions, 6 + n velocities, flags=0) agrees with the other engines with the base unturned and not once it "
    "is turned (Solo-12's leg at rest at a random pose: joint forces (-0.140, -0.128, -0.023) N m against Pinocchio's "
    "(-0.123, 0.050, 0.023): docs/examples/pybullet_floating_base.py), "
    "with flags=1 it corrupted the process's heap (malloc(): invalid size; NaNs in bullet3 issues 3149 and 4045), "
    "and its forward dynamics is a step of its simulator, which turns the base during the step "
    "(docs/floating-bases.md, PyBullet 3.2.7)")
"""Why PyBullet's joint-dynamics rows are n/a on a floating-base chain (pinned by
tests/references/test_floating_base_conventions.py); its motion is stepped (:mod:`references.pybullet.floating_body`)."""
FLOATING_MJCF_WHY = ("a floating base is stepped from a URDF only: an MJCF chain is loaded as PyBullet's loadMJCF "
                     "builds it, whose free root this adapter does not convert")
"""Why PyBullet's motion rows are n/a on a floating-base chain read from an MJCF file."""


@derives_own_inputs
class PybulletEngine(UrdfChains, Engine):
    """PyBullet (Bullet multibody), built from URDF the adapter writes or a chain's URDF file."""

    name = "pybullet"

    def version(self) -> str:
        return importlib.metadata.version("pybullet")

    def integrators(self) -> tuple[str, ...]:
        return ("euler",)

    def theoretical_order(self, integrator: str) -> int | None:
        """Bullet's semi-implicit Euler step is first order (free bodies and chains alike)."""
        return 1 if integrator == "euler" else None

    def stages(self, integrator: str) -> int | None:
        """One force evaluation per ``stepSimulation`` (the adapter's forces and a chain's joint torques, set before
        each step, are held over it); the constraint solver's iterations at a contact are not counted."""
        return 1 if integrator == "euler" else None

    def scheme(self, integrator: str, scene) -> str:
        """Bullet steps semi-implicit Euler, the orientation by the exponential map; with planes, its velocity-level
        impulses resolve contact; a chain's joints semi-implicit Euler (q from the new qdot, joint damping explicit:
        :mod:`references.pybullet.joint_motion`). Its IK is damped least squares (``-nullspace``: with a null-space
        rest pose)."""
        if isinstance(scene, JointMotionScene):
            if integrator not in self.joint_motion_integrators():
                return ""
            # a free multibody's base is its INERTIAL frame, stepped from its centre of mass's new velocity and turned
            # by the exponential map: another first-order discretisation than the joints' semi-implicit Euler
            return "engine_euler" if scene.chain.floating_base else "semi_implicit_euler"
        if isinstance(scene, IKScene):
            return ("damped_least_squares+nullspace" if integrator.endswith("nullspace") else
                    "damped_least_squares" if integrator in pybullet_ik.SOLVERS else "")
        if isinstance(scene, JointDynamicsScene):
            return integrator if integrator in self.joint_dynamics_methods() else ""
        if integrator != "euler":
            return ""
        contact = isinstance(scene, DynamicsScene) and scene.contact is not None
        return "impulse+engine_euler" if contact else "engine_euler"

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        named = self.check_integrator(integrator)
        return contact_support(scene.contact) if named.ok else named

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, integrator, dt)

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return PybulletChain(chain)

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        """Bullet's recursive algorithms: M and inverse dynamics from its inverse-dynamics library, forward dynamics
        from its simulator's articulated-body algorithm (:mod:`references.pybullet.joint_dynamics`)."""
        return ("recursive",)

    def supports_kinematics(self, chain: Chain) -> Support:
        named = super().supports_kinematics(chain)
        return _links_support(chain_urdf(chain)) if named.ok else named

    def supports_joint_dynamics(self, chain: Chain, method: str) -> Support:
        named = super().supports_joint_dynamics(chain, method)
        problem = chain.dynamics_problem() if named.ok else ""
        if problem:
            return Support.no(problem)
        if named.ok and chain.floating_base:
            return Support.no(FLOATING_BASE_WHY)
        return _dynamics_support(chain) if named.ok else named

    def build_joint_dynamics(self, chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
        # imported here: joint_dynamics reuses this module's client and loader
        from simparity.references.pybullet.joint_dynamics import PybulletJointDynamics

        return PybulletJointDynamics(chain, gravity_world)

    def joint_motion_integrators(self) -> tuple[str, ...]:
        """Bullet's own step of the multibody, named as for free bodies (:mod:`references.pybullet.joint_motion`)."""
        return ("euler",)

    def supports_joint_motion(self, scene: JointMotionScene, integrator: str) -> Support:
        """Bullet's own step; a floating base as a free multibody (:mod:`references.pybullet.floating_body`: its
        stepping is its simulator's, judged by truths that need no engine, not by the rounding-level dynamics
        :data:`FLOATING_BASE_WHY` refuses), from a URDF only."""
        named = super().supports_joint_motion(scene, integrator)
        if named.ok and scene.chain.floating_base and scene.chain.mjcf_path is not None:
            return Support.no(FLOATING_MJCF_WHY)
        return _dynamics_support(scene.chain) if named.ok else named

    def chain_contact(self, scene: JointMotionScene) -> Support:
        """Bullet's multibody contact of sphere shapes on the links (:mod:`references.pybullet.chain_contact`)."""
        return contact_params.plastic_only(scene, "PyBullet's spheres are set with restitution 0 here (one Moreau-Jean impulse per "
                                   "step, as the Pinocchio loop)")

    def build_joint_motion(self, scene: JointMotionScene, integrator: str, dt: float) -> JointSimulation:
        # imported here: joint_motion reuses this module's client, loader and chain kinematics
        from simparity.references.pybullet.joint_motion import PybulletJointMotion

        return PybulletJointMotion(scene, dt)

    def ik_solvers(self) -> tuple[str, ...]:
        return pybullet_ik.SOLVERS

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        named = super().supports_ik(chain, solver, position_only)
        above = movable_joints_above_base(chain) if named.ok else []
        if above:
            return Support.no(f"calculateInverseKinematics moves every joint of the body, and {', '.join(above)} "
                              f"above the chain's base link {chain.base_link} would move the base")
        held = [joint.name for joint in chain.joints if joint.lower == joint.upper]
        if named.ok and solver.endswith("-nullspace") and held:
            return Support.no(f"calculateInverseKinematics' null-space solve hangs on a joint with lower == upper "
                              f"({', '.join(held)}; measured: no answer within the 900 s case limit)")
        return named

    def build_ik(self, chain: Chain, solver: str, options: IKTolerances) -> IKModel:
        return pybullet_ik.PybulletIK(PybulletChain(chain), chain, solver, options)

    def export(self, scene, integrator, dt) -> str:
        if not isinstance(scene, DynamicsScene):
            return chain_export(scene.chain, "loadURDF(useFixedBase=True, URDF_USE_INERTIA_FROM_FILE)")
        integrator, dt = self._export_settings(scene, integrator, dt)
        gravity = scene.forces.gravity_world
        api = (
            f"<!-- Set through the API: setGravity({fmt(gravity if gravity is not None else [0, 0, 0])}), "
            f"setTimeStep({fmt([dt])}), numSubSteps=0; each body: loadURDF(flags=URDF_USE_INERTIA_FROM_FILE), "
            f"changeDynamics(linearDamping=0, angularDamping=0, maxJointVelocity={_MAX_VELOCITY:g}, "
            "activationState=ACTIVATION_STATE_DISABLE_SLEEPING), resetBasePositionAndOrientation and "
            "resetBaseVelocity to the scene's initial state (inertial frame). -->\n"
        )
        drags = [n for n in scene.forces.names() if n not in ("gravity", "applied_force", "timed_load")]
        if drags:
            api += (f"<!-- each step: applyExternalForce at the COM / applyExternalTorque (WORLD_FRAME) of "
                    f"{', '.join(drags)}, from the state at the step's start -->\n")
        for applied in scene.forces.applied:
            api += (f"<!-- each step: applyExternalForce({fmt(applied.force_world)} N) at the world position of "
                    f"body point {fmt(applied.point_body)} m (WORLD_FRAME), body {applied.body} -->\n")
        for load in scene.forces.timed:
            api += (f"<!-- each step, at its start time: applyExternalForce / applyExternalTorque (WORLD_FRAME) of a "
                    f"load that changes with time ({load.frame} axes) at body point {fmt(load.point_body)} m, body "
                    f"{load.body} -->\n")
        contact = scene.contact
        if contact is None:
            return api + "".join(body_urdf(b) for b in scene.bodies)
        settings = ", ".join(f"{name}={value!r}" for name, value in contact_parameters(contact, dt).items())
        api += f"<!-- setPhysicsEngineParameter({settings}); contactBreakingThreshold again before each run -->\n"
        for p, plane in enumerate(contact.planes):
            api += (f"<!-- plane {p}: createCollisionShape(GEOM_PLANE, planeNormal={fmt(plane.normal_world)}), "
                    f"createMultiBody(baseMass=0, basePosition={fmt(-plane.offset * plane.normal_world)}), "
                    f"changeDynamics({', '.join(f'{n}={v!r}' for n, v in PLANE_DYNAMICS.items())}), "
                    f"setCollisionFilterGroupMask(group={PLANE_GROUP}, mask={BODY_GROUP}) -->\n")
        materials, _ = contact_params.body_materials(contact)
        for b in range(len(scene.bodies)):
            if materials is not None:
                dynamics = ", ".join(f"{n}={v!r}" for n, v in body_contact_dynamics(*materials[b]).items())
                api += (f"<!-- body {b}: changeDynamics({dynamics}), setCollisionFilterGroupMask(group={BODY_GROUP}, "
                        f"mask={PLANE_GROUP}) -->\n")
        api += f"<!-- {contact_detail(contact, dt)} -->\n"
        return api + "".join(body_urdf(b, contact_params.inflated_spheres(s))
                             for b, s in zip(scene.bodies, contact.shapes))
