"""Analytic ground truth behind the shared engine interface.

Dynamics: closed forms from :mod:`references.analytic.solutions`, evaluated at the sample
times of the step being compared (the "integrator" is ``exact``). Translation and rotation
decouple (no force here couples them), and each is solved per body:

- translation: the projectile; linear drag with or without wind; quadratic drag along the
  line of gravity (still air only);
- rotation, in the body's principal axes: steady spin, torque-free axisymmetric (steady
  precession), torque-free asymmetric (Jacobi elliptic functions + quadrature), linear
  angular drag on an isotropic body.

- loads that change with time (:mod:`references.analytic.forced`): world-axes forces (smooth or held) on a body
  without drag; torques along a fixed principal axis the body spins about (or from rest).

Anything else (applied forces, both drags at once, quadratic angular drag, ...) gets
``n/a`` with the reason. Scenes with contact go to :mod:`references.analytic.contact`
(translating bodies bouncing, resting and sliding on a plane, event by event).

Kinematics: planar chains (revolute joints about z, origins in the xy plane): the end
effector is a sum of rotated link vectors, sum_k Rz(phi_k) o_k with phi_k the cumulative
angle, and the Jacobian is its closed-form derivative. IK: the planar 2-link arm solved
geometrically (the elbow is where the circle |e| = l1 about the base meets the circle
|p - e| = l2 about the target), a formulation of its own, independent of core's
law-of-cosines solver that it checks.

Joint-space dynamics: planar revolute arms of one or two links (the physical pendulum, Spong's
planar elbow manipulator) in closed form, :mod:`simparity.references.analytic.joint_dynamics`.

Joint motion: a chain of one joint, the physical pendulum at any amplitude (Jacobi elliptic functions) or a joint
under constant forces with viscous damping, :mod:`simparity.references.analytic.joint_motion` (the integrator is
``closed_form``). Rotations are SciPy's
(:mod:`simparity.references.common.conventions`).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from simparity.core.model.engine import (
    Engine,
    IKModel,
    JointDynamicsModel,
    JointSimulation,
    KinematicsModel,
    PieceSimulation,
    Simulation,
    Support,
)
from simparity.core.model.ik_problem import IKTolerances, check_inputs
from simparity.core.model.ik_result import IKReason, IKResult
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.time_functions import HeldFunction
from simparity.core.model.trajectory import FramePoses, Trajectory, piece_bounds
from simparity.references.analytic import contact as analytic_contact
from simparity.references.analytic import forced
from simparity.references.analytic import joint_dynamics as planar_dynamics
from simparity.references.analytic import joint_motion, pendulum_contact
from simparity.references.analytic import solutions as closed
from simparity.references.common.conventions import matrix_to_quat_wxyz, principal_axes, quat_wxyz_to_matrix, rotvec_to_matrix
from simparity.references.common.scene_inputs import derives_own_inputs

# Relative tolerance deciding that principal moments are equal, or omega lies on a
# principal axis: such scenes are built exactly so; 1e-12 only absorbs rounding.
_EQUAL_RTOL = 1e-12


def _loads(scene: DynamicsScene, k: int):
    """The loads that change with time on body k."""
    return [load for load in scene.forces.timed if load.body == k]


def _torque_vectors(function) -> np.ndarray:
    """(N, 3) every vector a torque function is made of (its polynomial rows, amplitudes or samples)."""
    if isinstance(function, HeldFunction):
        return function.samples
    return np.concatenate([function.polynomial] + [s.amplitude[None] for s in function.sinusoids])


def fixed_torque_axis(scene: DynamicsScene, k: int) -> tuple[np.ndarray | None, str]:
    """(the world axis (3,) body k turns about under its timed torques, or None with the reason there is none)."""
    body = scene.bodies[k]
    if any(load.force is not None and np.any(load.point_body) for load in _loads(scene, k)):
        return None, f"no closed form for the moment of a time-varying force at a point of body '{body.name}'"
    rotation0 = quat_wxyz_to_matrix(body.quat_wxyz)
    vectors = [(rotation0 @ v.T).T if load.frame == "body" else v for load in _loads(scene, k)
               if load.torque is not None for v in [_torque_vectors(load.torque)]]
    every = np.concatenate(vectors) if vectors else np.zeros((0, 3))
    nonzero = every[np.linalg.norm(every, axis=1) > 0]
    axis = nonzero[0] / np.linalg.norm(nonzero[0])
    if np.any(np.linalg.norm(np.cross(nonzero, axis), axis=1) > _EQUAL_RTOL * np.linalg.norm(nonzero, axis=1)):
        return None, f"no closed form: the time-varying torques on body '{body.name}' do not share one axis"
    axis_body = rotation0.T @ axis
    inertia_axis = body.inertia_body @ axis_body
    if np.linalg.norm(np.cross(inertia_axis, axis_body)) > _EQUAL_RTOL * np.linalg.norm(inertia_axis):
        return None, f"no closed form: the time-varying torque on body '{body.name}' is not along a principal axis"
    omega = body.angular_velocity_world
    if np.linalg.norm(np.cross(omega, axis)) > _EQUAL_RTOL * np.linalg.norm(omega):
        return None, f"no closed form: body '{body.name}' spins about another axis than its time-varying torque's"
    return axis, ""


def _rotation_kind(scene: DynamicsScene, k: int) -> tuple[str, str]:
    """(kind, reason-if-unsupported) of body k's rotation."""
    forces, body = scene.forces, scene.bodies[k]
    moments, _ = principal_axes(body.inertia_body)
    isotropic = np.ptp(moments) <= _EQUAL_RTOL * moments.max()
    if any(a.body == k for a in forces.applied):
        return "", f"no closed form for the torque of an applied force on body '{body.name}'"
    twisting = [load for load in _loads(scene, k) if (load.torque is not None and np.any(_torque_vectors(load.torque)))
                or (load.force is not None and np.any(load.point_body))]
    if twisting:
        if any(drag is not None and drag[k] > 0 for drag in (forces.angular_linear_drag, forces.angular_quadratic_drag)):
            return "", f"no closed form for a time-varying torque with angular drag on body '{body.name}'"
        axis, why = fixed_torque_axis(scene, k)
        return ("fixed_axis", "") if axis is not None else ("", why)
    if forces.angular_quadratic_drag is not None and forces.angular_quadratic_drag[k] > 0:
        return "", f"no closed form for quadratic angular drag on body '{body.name}'"
    if forces.angular_linear_drag is not None and forces.angular_linear_drag[k] > 0:
        if not isotropic:
            return "", f"closed-form angular drag needs an isotropic inertia; body '{body.name}' is not"
        return "angular_drag", ""
    omega = body.angular_velocity_world
    rotation = quat_wxyz_to_matrix(body.quat_wxyz)
    l_world = rotation @ body.inertia_body @ rotation.T @ omega
    cross = np.linalg.norm(np.cross(l_world, omega))
    if not np.any(omega) or cross <= _EQUAL_RTOL * np.linalg.norm(l_world) * np.linalg.norm(omega):
        return "steady", ""
    gaps = np.diff(moments)
    if np.any(gaps <= _EQUAL_RTOL * moments.max()):
        return "axisymmetric", ""
    return "asymmetric", ""


def _translation_kind(scene: DynamicsScene, k: int) -> tuple[str, str]:
    forces, name = scene.forces, scene.bodies[k].name
    linear = forces.linear_drag is not None and forces.linear_drag[k] > 0
    quadratic = forces.quadratic_drag is not None and forces.quadratic_drag[k] > 0
    pushed = [load for load in _loads(scene, k) if load.force is not None]
    if pushed:
        if linear or quadratic:
            return "", f"no closed form for a time-varying force with drag on body '{name}'"
        if any(load.frame != "world" for load in pushed):
            return "", f"no closed form for a time-varying force in the turning axes of body '{name}'"
        return "forced", ""
    if linear and quadratic:
        return "", f"no closed form for linear and quadratic drag together on body '{name}'"
    if quadratic:
        if forces.air_velocity_world is not None and np.any(forces.air_velocity_world):
            return "", f"no closed form for quadratic drag in wind on body '{name}'"
        body = scene.bodies[k]
        g = forces.gravity_world if forces.gravity_world is not None else np.zeros(3)
        if np.any(g) and np.any(body.velocity_world) and np.linalg.norm(np.cross(g, body.velocity_world)) > (
            _EQUAL_RTOL * np.linalg.norm(g) * np.linalg.norm(body.velocity_world)
        ):
            return "", f"quadratic drag has a closed form only along the line of gravity; body '{name}' leaves it"
        return "quadratic_drag", ""
    return ("linear_drag" if linear else "projectile"), ""


def _translation(scene: DynamicsScene, k: int, kind: str, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    forces, body = scene.forces, scene.bodies[k]
    g = forces.gravity_world if forces.gravity_world is not None else np.zeros(3)
    if kind == "linear_drag":
        assert forces.linear_drag is not None  # the kind says body k has linear drag
        air = forces.air_velocity_world if forces.air_velocity_world is not None else np.zeros(3)
        return closed.linear_drag(body.position_world, body.velocity_world, g,
                                  forces.linear_drag[k] / body.mass, times, air_velocity=air)
    if kind == "quadratic_drag":
        assert forces.quadratic_drag is not None  # the kind says body k has quadratic drag
        return closed.quadratic_drag_along_line(body.position_world, body.velocity_world, g,
                                                forces.quadratic_drag[k] / body.mass, times)
    if kind == "forced":
        return forced.forced_translation(body.position_world, body.velocity_world, g, body.mass,
                                         [load.force for load in _loads(scene, k) if load.force is not None], times)
    return closed.projectile(body.position_world, body.velocity_world, g, times)


def _rotation(scene: DynamicsScene, k: int, kind: str, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(quat_wxyz (T, 4), angular_velocity_world (T, 3)) of body k."""
    body = scene.bodies[k]
    omega = body.angular_velocity_world
    rotation0 = quat_wxyz_to_matrix(body.quat_wxyz)
    if kind == "steady":
        rotation = rotvec_to_matrix(times[:, None] * omega) @ rotation0
        return matrix_to_quat_wxyz(rotation), np.broadcast_to(omega, (len(times), 3))
    if kind == "fixed_axis":
        axis, _ = fixed_torque_axis(scene, k)
        assert axis is not None  # the kind says the axis exists
        moment = float(axis @ rotation0 @ body.inertia_body @ rotation0.T @ axis)
        torques = [(load.torque, rotation0.T @ axis if load.frame == "body" else axis)
                   for load in _loads(scene, k) if load.torque is not None]
        theta, omega_world = forced.fixed_axis_rotation(axis, moment, omega, torques, times)
        return matrix_to_quat_wxyz(rotvec_to_matrix(theta[:, None] * axis) @ rotation0), omega_world
    moments, axes = principal_axes(body.inertia_body)
    if kind == "angular_drag":
        assert scene.forces.angular_linear_drag is not None  # the kind says body k has linear angular drag
        quat, omega_world, _ = closed.linear_angular_drag_isotropic(
            moments[0], scene.forces.angular_linear_drag[k], omega, body.quat_wxyz, times)
        return quat, omega_world
    solve = closed.torque_free_axisymmetric if kind == "axisymmetric" else closed.torque_free_asymmetric
    if kind == "axisymmetric" and moments[1] - moments[0] > moments[2] - moments[1]:
        # The closed form wants the equal pair first (I1 == I2): cycle the axes (still proper).
        moments, axes = moments[[1, 2, 0]], axes[:, [1, 2, 0]]
    # Torque-free: solve in the principal frame R_p = R Q, then return to the body frame.
    rotation_principal = rotation0 @ axes
    omega_principal = rotation_principal.T @ omega
    quat_p, omega_world, _ = solve(moments, omega_principal, matrix_to_quat_wxyz(rotation_principal), times)
    return matrix_to_quat_wxyz(quat_wxyz_to_matrix(quat_p) @ axes.T), omega_world


class _Simulation(PieceSimulation):
    def __init__(self, scene: DynamicsScene, dt: float, kinds: list[tuple[str, str]]) -> None:
        self._scene, self._dt, self._kinds = scene, dt, kinds
        self.detail = "closed form: " + ", ".join(sorted({f"{t}/{r}" for t, r in kinds}))

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        """The closed forms at each piece's times k dt (each sample a function of its time alone)."""
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            times = np.arange(start, stop) * self._dt
            pos, vel, quat, omg = [], [], [], []
            for k, (translation, rotation) in enumerate(self._kinds):
                p, v = _translation(self._scene, k, translation, times)
                q, w = _rotation(self._scene, k, rotation, times)
                pos.append(p)
                vel.append(v)
                quat.append(q)
                omg.append(w)
            yield Trajectory(times, *(np.stack(a, axis=1) for a in (pos, quat, vel, omg)))


def _planar(chain: Chain) -> Support:
    ez = np.array([0.0, 0.0, 1.0])
    for joint in chain.joints:
        if joint.type != "revolute" or not np.array_equal(joint.axis, ez):
            return Support.no(f"no closed form: joint '{joint.name}' is not a revolute joint about +z")
        if not np.array_equal(joint.origin_rotation, np.eye(3)) or joint.origin_xyz[2] != 0:
            return Support.no(f"no closed form: joint '{joint.name}' is not in the xy plane of its parent")
    if chain.end_effector_xyz[2] != 0 or not np.array_equal(chain.end_effector_rotation, np.eye(3)):
        return Support.no("no closed form: the end effector is not in the xy plane of the last link")
    return Support.yes()


class _PlanarKinematics(KinematicsModel):
    def __init__(self, chain: Chain) -> None:
        # Link vectors o_1..o_n (joint origins) and the end-effector offset, in the xy plane.
        self._offsets = np.stack([j.origin_xyz[:2] for j in chain.joints] + [chain.end_effector_xyz[:2]])
        self.detail = "closed form: sum of rotated link vectors"

    def _terms(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cumulative angles (B, n + 1), rotated offsets (B, n + 1, 2), their derivatives."""
        q = np.atleast_2d(q)
        # The k-th offset is rotated by the sum of the joint angles before it.
        phi = np.concatenate([np.zeros((len(q), 1)), np.cumsum(q, axis=1)], axis=1)
        c, s = np.cos(phi), np.sin(phi)
        ox, oy = self._offsets[:, 0], self._offsets[:, 1]
        rotated = np.stack([c * ox - s * oy, s * ox + c * oy], axis=-1)
        derivative = np.stack([-s * ox - c * oy, c * ox - s * oy], axis=-1)
        return phi, rotated, derivative

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        phi, rotated, _ = self._terms(q)
        # Frame i (joint i's link, then the end effector) sits at o_1 + ... rotated: a cumsum.
        xy = np.cumsum(rotated, axis=1)
        angles = np.concatenate([phi[:, 1:], phi[:, -1:]], axis=1)
        b, f = xy.shape[:2]
        pos = np.concatenate([xy, np.zeros((b, f, 1))], axis=-1)
        rot = np.zeros((b, f, 3, 3))
        rot[..., 0, 0], rot[..., 0, 1] = np.cos(angles), -np.sin(angles)
        rot[..., 1, 0], rot[..., 1, 1] = np.sin(angles), np.cos(angles)
        rot[..., 2, 2] = 1.0
        return FramePoses(pos, rot)

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        _, _, derivative = self._terms(q)
        b, n = derivative.shape[0], derivative.shape[1] - 1
        # d/dq_j of Rz(phi_k) o_k is Rz'(phi_k) o_k for every k > j (phi_k contains q_j).
        tail = np.cumsum(derivative[:, ::-1], axis=1)[:, ::-1]  # sum over k >= index
        jac = np.zeros((b, 6, n))
        jac[:, :2, :] = tail[:, 1:, :].transpose(0, 2, 1)
        jac[:, 5, :] = 1.0
        return jac


def _two_link(chain: Chain) -> Support:
    planar = _planar(chain)
    if not planar.ok:
        return planar
    if chain.n_joints != 2 or np.any(chain.joints[0].origin_xyz) or np.any(chain.joints[1].origin_xyz[1:]) or np.any(
            chain.end_effector_xyz[1:]):
        return Support.no("the analytic IK is the lecture's 2-link arm: two z joints, links along x from the origin")
    return Support.yes()


def elbow_solutions(l1: float, l2: float, target_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Both joint solutions of the planar 2-link arm, from the elbow's position.

    The elbow e lies on the circle |e| = l1 about the base and on |p - e| = l2 about the
    target p: at distance a = (l1^2 - l2^2 + r^2) / (2 r) along p / r and h = +-sqrt(l1^2 -
    a^2) across it (r = |p|). Then q1 = angle(e) and q2 = angle(p - e) - q1. A target out
    of reach (h^2 < 0) gets the elbow on the line through p (h = 0, a clipped to +-l1):
    the arm stretched toward it or folded. At r = 0 the line is taken along +x.

    Parameters
    ----------
    l1, l2 : float
        Link lengths [m].
    target_xy : (B, 2) ndarray
        [m].

    Returns
    -------
    q : (B, 2, 2) ndarray
        [target, branch, joint] angles [rad] (branch 0 has the elbow to the left of the
        line from the base to the target).
    reachable : (B,) bool ndarray
        |l1 - l2| <= r <= l1 + l2.
    """
    p = np.asarray(target_xy, dtype=float)
    r = np.hypot(p[:, 0], p[:, 1])
    along = np.where(r[:, None] > 0, p / np.where(r > 0, r, 1.0)[:, None], [1.0, 0.0])
    across = np.stack([-along[:, 1], along[:, 0]], axis=1)
    a = np.clip((l1 * l1 - l2 * l2 + r * r) / (2 * np.where(r > 0, r, 1.0)), -l1, l1)
    h = np.sqrt(np.maximum(l1 * l1 - a * a, 0.0))
    reachable = (r <= l1 + l2) & (r >= abs(l1 - l2))
    q = np.empty((len(p), 2, 2))
    for branch, side in enumerate((1.0, -1.0)):
        elbow = a[:, None] * along + side * h[:, None] * across
        q1 = np.arctan2(elbow[:, 1], elbow[:, 0])
        forearm = p - elbow
        q2 = np.arctan2(forearm[:, 1], forearm[:, 0]) - q1
        q[:, branch] = np.stack([q1, np.angle(np.exp(1j * q2))], axis=1)
    return q, reachable


class _TwoLinkIK(IKModel):
    """The planar 2-link arm solved geometrically (:func:`elbow_solutions`); of the two elbow
    branches, the one within the limits that is nearest to the start pose (wrapped angle distance)."""

    def __init__(self, chain: Chain, options: IKTolerances) -> None:
        self._chain, self._options = chain, options
        self._l1, self._l2 = chain.joints[1].origin_xyz[0], chain.end_effector_xyz[0]
        self._fk = _PlanarKinematics(chain)
        self.detail = "closed form: the elbow where two circles meet (both branches; the nearest within the limits)"

    def solve(self, target_position_world, target_rotation_world, q_start) -> IKResult:
        p, _, q0 = check_inputs(self._chain, target_position_world, None, q_start)
        solutions, reachable = elbow_solutions(self._l1, self._l2, p[:, :2])
        lower, upper = self._chain.lower, self._chain.upper
        inside = np.all((solutions >= lower) & (solutions <= upper), axis=2)  # (B, branch)
        distance = np.linalg.norm(np.angle(np.exp(1j * (solutions - q0[:, None, :]))), axis=2)
        branch = np.argmin(np.where(inside, distance, np.inf), axis=1)
        q = solutions[np.arange(len(p)), branch]
        blocked = ~np.any(inside, axis=1)
        q = np.where(blocked[:, None], np.clip(q, lower, upper), q)
        reached = self._fk.forward_kinematics(q).position_world[:, -1]
        residual = np.linalg.norm(reached - p, axis=1)
        success = reachable & ~blocked & (residual <= self._options.position_tolerance)
        reason = np.where(success, IKReason.SOLVED,
                          np.where(~reachable, IKReason.UNREACHABLE,
                                   np.where(blocked, IKReason.LIMIT_BLOCKED, IKReason.SINGULAR)))
        violation = np.max(np.maximum(np.maximum(lower - q, q - upper), 0.0), axis=1)
        return IKResult(q, success, np.zeros(len(p), int), residual, np.zeros(len(p)), violation, reason)


@derives_own_inputs
class AnalyticEngine(Engine):
    """Closed-form ground truths; ``n/a`` wherever no closed form is implemented."""

    name = "analytic"

    def version(self) -> str:
        return "closed form"

    def integrators(self) -> tuple[str, ...]:
        return ("exact",)

    def scheme(self, integrator: str, scene) -> str:
        """Every answer of this engine is a closed form."""
        return "closed_form"

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        named = self.check_integrator(integrator)
        if not named.ok:
            return named
        if scene.contact is not None:
            return analytic_contact.supports(scene)
        for k in range(len(scene.bodies)):
            for kind, reason in (_translation_kind(scene, k), _rotation_kind(scene, k)):
                if not kind:
                    return Support.no(reason)
        return Support.yes()

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        if scene.contact is not None:
            return analytic_contact.ContactSimulation(scene, dt)
        kinds = [(_translation_kind(scene, k)[0], _rotation_kind(scene, k)[0]) for k in range(len(scene.bodies))]
        return _Simulation(scene, dt, kinds)

    def supports_kinematics(self, chain: Chain) -> Support:
        return _planar(chain)

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return _PlanarKinematics(chain)

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        return ("closed_form",)

    def supports_joint_dynamics(self, chain: Chain, method: str) -> Support:
        named = super().supports_joint_dynamics(chain, method)
        if not named.ok:
            return named
        return planar_dynamics.supports(chain)

    def build_joint_dynamics(self, chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
        return planar_dynamics.build(chain, gravity_world)

    def joint_motion_integrators(self) -> tuple[str, ...]:
        return ("closed_form",)

    def supports_joint_motion(self, scene: JointMotionScene, integrator: str) -> Support:
        named = super().supports_joint_motion(scene, integrator)
        if not named.ok:
            return named
        return joint_motion.supports(scene)

    def chain_contact(self, scene: JointMotionScene) -> Support:
        """A pendulum striking a plane with a rigid contact (:mod:`references.analytic.pendulum_contact`)."""
        return pendulum_contact.supports(scene)

    def build_joint_motion(self, scene: JointMotionScene, integrator: str, dt: float) -> JointSimulation:
        return joint_motion.build(scene, dt)

    def ik_solvers(self) -> tuple[str, ...]:
        return ("two_link",)

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        named = super().supports_ik(chain, solver, position_only)
        if not named.ok:
            return named
        if not position_only:
            return Support.no("the analytic 2-link IK solves position targets in the plane")
        return _two_link(chain)

    def build_ik(self, chain: Chain, solver: str, options: IKTolerances) -> IKModel:
        return _TwoLinkIK(chain, options)
