"""PyBullet behind the shared engine interface.

Conversions and overridden defaults (each pinned by a test in ``tests/test_pybullet_adapter.py``)
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
  geometry (:func:`references.urdf_export.chain_urdf`; ``useFixedBase``), so PyBullet opens
  no mesh; poses are re-expressed in the chain's base link (:mod:`references.base_frame`;
  the base link's pose comes from ``getLinkState``, float32, when it is not the root).
  Other chains from the adapter's URDF. What PyBullet prints while loading is kept off the
  console (:mod:`references.quiet`).
- ``getLinkState`` positions and orientations are FLOAT32 (errors ~1e-7); the Jacobian
  from ``calculateJacobian`` is double.
- PyBullet has one integrator (semi-implicit Euler, velocity then position); time step = dt,
  no sub-steps.
- Forces other than gravity, from the state at the start of each step, the way PyBullet
  users apply them: a force at a body point with ``applyExternalForce`` at the point's
  WORLD position (the base pose's ``getMatrixFromQuaternion``, double; PyBullet's
  ``multiplyTransforms`` would round it to float32; PyBullet computes the torque);
  drag and wind (:mod:`references.external_forces`, independent of core) as a world-frame
  force at the COM and a world-frame torque (``applyExternalTorque``). All with
  WORLD_FRAME (in 3.2.7 both honour the flag, which bullet3 #1949 once had swapped for the
  base); PyBullet clears them after every step.
"""

from __future__ import annotations

import importlib.metadata
import os
import tempfile

import numpy as np

from simparity.core.engine import Engine, IKModel, KinematicsModel, Simulation, Support
from simparity.core.errors import DivergedError
from simparity.core.ik.problem import IKTolerances
from simparity.core.scene import Chain, DynamicsScene
from simparity.core.trajectory import FramePoses, Trajectory
from simparity.references import external_forces, pybullet_ik
from simparity.references.base_frame import BaseFrame
from simparity.references.conventions import (
    fmt,
    matrix_to_quat_wxyz,
    principal_axes,
    quat_wxyz_to_matrix,
    wxyz_from_xyzw,
    xyzw_from_wxyz,
)
from simparity.references.pybullet_quiet import pybullet
from simparity.references.quiet import captured_output
from simparity.references.urdf_export import (
    UrdfChains,
    body_urdf,
    chain_export,
    chain_source,
    chain_urdf,
    movable_joints_above_base,
)

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


class _Client:
    """A private DIRECT-mode PyBullet world, disconnected when garbage-collected."""

    def __init__(self) -> None:
        self.id = pybullet.connect(pybullet.DIRECT)

    def __del__(self) -> None:
        try:
            pybullet.disconnect(physicsClientId=self.id)
        except Exception:  # noqa: BLE001 - interpreter shutdown may have unloaded pybullet
            pass


class _Simulation(Simulation):
    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        self._client = _Client()
        c = self._client.id
        gravity = scene.forces.gravity_world
        pybullet.setGravity(*(gravity if gravity is not None else (0.0, 0.0, 0.0)), physicsClientId=c)
        pybullet.setTimeStep(dt, physicsClientId=c)
        pybullet.setPhysicsEngineParameter(numSubSteps=0, physicsClientId=c)
        self._bodies, self._axes, self._initial = [], [], []
        for body in scene.bodies:
            uid = _load_urdf(c, body_urdf(body))
            pybullet.changeDynamics(
                uid, -1, linearDamping=0.0, angularDamping=0.0, maxJointVelocity=_MAX_VELOCITY,
                activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=c,
            )
            _, axes = principal_axes(body.inertia_body)
            quat_inertial = matrix_to_quat_wxyz(quat_wxyz_to_matrix(body.quat_wxyz) @ axes)
            self._bodies.append(uid)
            self._axes.append(axes)
            self._initial.append((body.position_world, xyzw_from_wxyz(quat_inertial),
                                  body.velocity_world, body.angular_velocity_world))
        self._axes = np.stack(self._axes)
        self._forces = scene.forces
        self._drag = external_forces.has_drag(scene.forces) or external_forces.has_angular_drag(scene.forces)
        # Applied forces: (body index, force [N], application point in the base's INERTIAL frame [m]).
        self._applied = [(a.body, a.force_world.tolist(), self._axes[a.body].T @ a.point_body)
                         for a in scene.forces.applied]
        self._dt = dt
        self.detail = (
            "PyBullet multibody; inertia from file; damping 0; sleeping off; gravity set explicitly"
            + ("; applyExternalForce at each applied force's world point" if self._applied else "")
            + (f"; {external_forces.DETAIL}, as applyExternalForce at the COM and applyExternalTorque"
               if self._drag else "")
        )

    def run(self, n_steps: int) -> Trajectory:
        c = self._client.id
        for uid, (pos, quat, vel, omega) in zip(self._bodies, self._initial):
            pybullet.resetBasePositionAndOrientation(uid, pos, quat, physicsClientId=c)
            pybullet.resetBaseVelocity(uid, vel, omega, physicsClientId=c)
        b = len(self._bodies)
        raw = np.empty((n_steps + 1, b, 13))  # position 3, quat xyzw 4, velocity 3, omega 3
        for i in range(n_steps + 1):
            if i:
                self._apply(raw[i - 1])
                pybullet.stepSimulation(physicsClientId=c)
            for k, uid in enumerate(self._bodies):
                pos, quat = pybullet.getBasePositionAndOrientation(uid, physicsClientId=c)
                vel, omega = pybullet.getBaseVelocity(uid, physicsClientId=c)
                raw[i, k] = (*pos, *quat, *vel, *omega)
        speeds = np.abs(raw[..., 7:13]).max()
        if speeds >= _CLAMPED:
            raise DivergedError(f"PyBullet clamped a velocity at {speeds:.3g} (its cap): the run blew up")
        quat_body = self._body_quat(raw[..., 3:7])
        times = np.arange(n_steps + 1) * self._dt
        return Trajectory(times, raw[..., :3], quat_body, raw[..., 7:10], raw[..., 10:13])

    def _body_quat(self, quat_xyzw_inertial: np.ndarray) -> np.ndarray:
        """Body-frame quaternions from PyBullet's inertial-frame ones: R_body = R_inertial Q^T."""
        rotation_inertial = quat_wxyz_to_matrix(wxyz_from_xyzw(quat_xyzw_inertial))
        return matrix_to_quat_wxyz(rotation_inertial @ np.swapaxes(self._axes, -1, -2))

    def _apply(self, raw: np.ndarray) -> None:
        """Apply the scene's non-gravity forces, evaluated at the state ``raw`` (B, 13)."""
        c = self._client.id
        for k, force, point_inertial in self._applied:
            rotation = np.reshape(pybullet.getMatrixFromQuaternion(raw[k, 3:7]), (3, 3))
            point = raw[k, :3] + rotation @ point_inertial
            pybullet.applyExternalForce(self._bodies[k], -1, force, point, pybullet.WORLD_FRAME, physicsClientId=c)
        if not self._drag:
            return
        force = external_forces.drag_force_world(self._forces, raw[:, 7:10])
        torque = external_forces.drag_torque_world(self._forces, raw[:, 10:13])
        for k, uid in enumerate(self._bodies):
            pybullet.applyExternalForce(uid, -1, force[k], raw[k, :3], pybullet.WORLD_FRAME, physicsClientId=c)
            pybullet.applyExternalTorque(uid, -1, torque[k], pybullet.WORLD_FRAME, physicsClientId=c)


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


class PybulletEngine(UrdfChains, Engine):
    """PyBullet (Bullet multibody), built from URDF the adapter writes or a chain's URDF file."""

    name = "pybullet"

    def version(self) -> str:
        return importlib.metadata.version("pybullet")

    def integrators(self) -> tuple[str, ...]:
        return ("euler",)

    def theoretical_order(self, integrator: str) -> int | None:
        """Bullet's semi-implicit Euler step is first order."""
        return 1 if integrator == "euler" else None

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        return self.check_integrator(integrator)

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        return _Simulation(scene, integrator, dt)

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return PybulletChain(chain)

    def ik_solvers(self) -> tuple[str, ...]:
        return pybullet_ik.SOLVERS

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        named = super().supports_ik(chain, solver, position_only)
        above = movable_joints_above_base(chain) if named.ok else []
        if above:
            return Support.no(f"calculateInverseKinematics moves every joint of the body, and {', '.join(above)} "
                              f"above the chain's base link {chain.base_link} would move the base")
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
        drags = [n for n in scene.forces.names() if n not in ("gravity", "applied_force")]
        if drags:
            api += (f"<!-- each step: applyExternalForce at the COM / applyExternalTorque (WORLD_FRAME) of "
                    f"{', '.join(drags)}, from the state at the step's start -->\n")
        for applied in scene.forces.applied:
            api += (f"<!-- each step: applyExternalForce({fmt(applied.force_world)} N) at the world position of "
                    f"body point {fmt(applied.point_body)} m (WORLD_FRAME), body {applied.body} -->\n")
        return api + "".join(body_urdf(b) for b in scene.bodies)
