"""Closed-form joint motion of a chain of one joint: the physical pendulum, and a joint under constant forces.

The chain's base frame is the world frame. Its one joint sits at p0 = ``origin_xyz`` with the rotation R0 =
``origin_rotation``; its axis in the world is n = R0 a (a = ``Joint.axis``), and the link frame at q is
R0 Rot(a, q) = Rot(n, q) R0 (revolute) or R0 moved by n q (prismatic). A point x of the link (its centre of mass,
the end effector) is at p0 + Rot(n, q) R0 x or p0 + R0 x + n q: Rodrigues' formula, no forward kinematics of
anyone else. Joint limits are not enforced (every engine steps the joint free).

1. The physical pendulum: a revolute joint whose link's centre of mass is off the axis line (r = R0 c, its
   component across the axis r_perp, d = |r_perp| > 0) under gravity with a component across the axis
   (g_perp, G = |g_perp| > 0), no damping, no applied torque. With u = r_perp / d, w = n x u and
   g_perp = G (cos psi u + sin psi w), the potential is V = -m g.c(q) = -m G d cos(q - psi) + const (gravity's
   component along n does no work), so theta = q - psi is measured from the stable equilibrium (the centre of
   mass hanging along g_perp) and I theta'' = -m G d sin theta, omega0^2 = m G d / I,
   I = a^T I_c a + m d^2 + armature (the inertia about the axis: the link's about its centre of mass, transported).
   With k^2 = sin^2(theta0 / 2) + (theta0' / (2 omega0))^2 (the energy in units of 2 m G d):

   - libration (k < 1; the large-amplitude pendulum of Wikipedia's "Pendulum (mechanics)"): sin(theta / 2) =
     k sn(u, m), theta' = 2 k omega0 cn(u, m), cos(theta / 2) = dn(u, m), u = omega0 t + u0, m = k^2;
     am(u0) = atan2(sin(theta0 / 2), theta0' / (2 omega0)), so u0 = F(am(u0) | m) carries the sign of the
     velocity. Period 4 K(m) / omega0.
   - rotation (k > 1): theta / 2 = s am(u, m'), theta' = 2 s k omega0 dn(u, m'), u = k omega0 t + u0,
     m' = 1 / k^2, s = sign(theta0'), u0 = F(s theta0 / 2 | m'): from (theta' / 2)^2 = omega0^2 (k^2 -
     sin^2(theta / 2)). One turn takes 2 K(m') / (k omega0).
   - the separatrix (k = 1) is refused, and with it a band ``SEPARATRIX_BAND`` about it: on it the pendulum
     takes infinitely long to reach the upright equilibrium, and beside it libration and rotation part, so the
     rounding of q0 and qdot0 decides which motion a step-by-step engine follows; SciPy's ``ellipj`` also
     switches to a series valid near u = 0 only for m > 1 - 1e-10.

2. Any other one-joint chain whose joint force is constant: a revolute joint with no gravity torque (no gravity,
   gravity along the axis, or the centre of mass on the axis) or a prismatic joint (gravity's force along the
   axis, m g.n, is constant), with damping b >= 0 and applied force tau. I = the inertia about the axis as above
   (revolute) or m + armature (prismatic), f = tau (+ m g.n, prismatic): I q'' = f - b q', the equation of a
   point with linear drag, whose closed form :func:`simparity.references.analytic.solutions.linear_drag` gives:
   q' = q0' e^(-b t / I) + f / b (1 - e^(-b t / I)), uniform acceleration f / I at b = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ellipj, ellipk, ellipkinc

from simparity.core.model.engine import JointSimulation, Support
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory
from simparity.references.analytic.forced import damped_drive_supported, driven_joint
from simparity.references.analytic.solutions import linear_drag

SEPARATRIX_BAND = 1e-9
"""Initial states with |1 - k^2| at most this are refused (the module docstring): ten times SciPy's switch to its
series (m > 1 - 1e-10), and a state this close to the separatrix is already ill-conditioned: rounding q0 by
1e-16 moves the period by ~1e-16 / |1 - k^2| ~ 1e-7 of itself."""

_ZERO_RTOL = 1e-12
"""Relative tolerance of "the centre of mass is on the axis" (d against |r|) and "gravity is along the axis"
(|g_perp| against |g|): a chain built so in code or through URDF rpy angles is off by rounding (~1e-16) only."""


@dataclass(frozen=True)
class OneJoint:
    """A one-joint chain's numbers in the base (world) frame.

    Attributes
    ----------
    revolute : bool
        True for a revolute joint, False for a prismatic one.
    origin : (3,) ndarray
        p0, the joint's origin [m].
    axis : (3,) ndarray
        n, the joint's unit axis.
    com, end_effector : (3,) ndarray
        R0 c and R0 x_ee: the link's centre of mass and the end effector from p0 at q = 0 [m].
    mass : float
        [kg].
    inertia : float
        I, the joint's inertia: about the axis with armature [kg m^2] (revolute) or mass + armature [kg].
    damping, torque : float
        b [N m s/rad or N s/m] and the applied joint force [N m or N].
    gravity : (3,) ndarray
        [m/s^2], zero without gravity.
    """

    revolute: bool
    origin: np.ndarray
    axis: np.ndarray
    com: np.ndarray
    end_effector: np.ndarray
    mass: float
    inertia: float
    damping: float
    torque: float
    gravity: np.ndarray

    def across(self, vector: np.ndarray) -> np.ndarray:
        """The component of ``vector`` (3,) perpendicular to the axis."""
        return vector - (self.axis @ vector) * self.axis

    def is_pendulum(self) -> bool:
        """True when gravity exerts a torque about a revolute axis: d > 0 and |g_perp| > 0 beyond rounding."""
        r, g = self.com, self.gravity
        return (self.revolute and np.linalg.norm(self.across(r)) > _ZERO_RTOL * np.linalg.norm(r)
                and np.linalg.norm(self.across(g)) > _ZERO_RTOL * np.linalg.norm(g))

    def place(self, offset: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(B, 3) [m]: the link point at ``offset`` (3,) from p0 at q = 0 moved to joint values q (B,)."""
        n, q = self.axis, q[:, None]
        if not self.revolute:
            return self.origin + offset + n * q
        # Rodrigues: Rot(n, q) x = x cos q + (n x x) sin q + n (n . x) (1 - cos q).
        return self.origin + offset * np.cos(q) + np.cross(n, offset) * np.sin(q) + n * (n @ offset) * (1 - np.cos(q))


def one_joint(scene: JointMotionScene) -> OneJoint:
    """The scene's one joint as :class:`OneJoint` (the scene's chain has exactly one joint)."""
    joint = scene.chain.joints[0]
    link = joint.link
    assert link is not None  # a JointMotionScene's chain has mass properties on every link
    rotation = joint.origin_rotation
    com = rotation @ link.com_xyz
    revolute = joint.type == "revolute"
    axis = rotation @ joint.axis
    across = com - (axis @ com) * axis
    inertia = (float(joint.axis @ link.inertia_com @ joint.axis) + link.mass * float(across @ across)
               if revolute else link.mass)
    gravity = np.zeros(3) if scene.gravity_world is None else np.asarray(scene.gravity_world, dtype=float)
    return OneJoint(revolute, np.asarray(joint.origin_xyz, dtype=float), axis, com,
                    rotation @ scene.chain.end_effector_xyz, link.mass, inertia + joint.armature, joint.damping,
                    float(scene.torque[0]), gravity)


@dataclass(frozen=True)
class Pendulum:
    """The physical pendulum's numbers: theta = q - psi, I theta'' = -I omega0^2 sin theta.

    Attributes
    ----------
    omega0 : float
        [rad/s], sqrt(m |g_perp| d / I).
    psi : float
        [rad], the joint value of the stable equilibrium (the centre of mass hanging along g_perp).
    """

    omega0: float
    psi: float


def pendulum_of(joint: OneJoint) -> Pendulum:
    """omega0 and psi of a pendulum joint (:meth:`OneJoint.is_pendulum`), from the module docstring's plane."""
    r_perp = joint.across(joint.com)
    g_perp = joint.across(joint.gravity)
    d = float(np.linalg.norm(r_perp))
    u = r_perp / d
    w = np.cross(joint.axis, u)
    omega0 = np.sqrt(joint.mass * float(np.linalg.norm(g_perp)) * d / joint.inertia)
    return Pendulum(float(omega0), float(np.arctan2(g_perp @ w, g_perp @ u)))


def modulus_squared(theta0: np.ndarray, thetadot0: np.ndarray, omega0: float) -> tuple[np.ndarray, np.ndarray]:
    """(k^2, 1 - k^2), each like theta0: k^2 = sin^2(theta0 / 2) + (theta0' / (2 omega0))^2, and 1 - k^2 as
    cos^2(theta0 / 2) - (theta0' / (2 omega0))^2 (no cancellation against 1). theta0 [rad], theta0' [rad/s]."""
    half, rate = 0.5 * np.asarray(theta0), 0.5 * np.asarray(thetadot0) / omega0
    return np.sin(half) ** 2 + rate**2, np.cos(half) ** 2 - rate**2


def pendulum_motion(theta0: np.ndarray, thetadot0: np.ndarray, omega0: float,
                    times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pendulum theta'' = -omega0^2 sin theta from (theta0, theta0') in closed form (module docstring).

    Parameters
    ----------
    theta0, thetadot0 : (B,) ndarray
        [rad], [rad/s]; theta0 any real angle (the whole turns it holds are kept). No state within
        ``SEPARATRIX_BAND`` of the separatrix.
    omega0 : float
        [rad/s], > 0.
    times : (T,) ndarray
        [s].

    Returns
    -------
    theta, thetadot : (T, B) ndarray
        [rad], [rad/s]; continuous in time (a rotating pendulum's angle grows without wrapping).
    """
    turns = np.round(np.asarray(theta0) / (2 * np.pi))
    theta0 = np.asarray(theta0) - 2 * np.pi * turns
    m, m1 = modulus_squared(theta0, thetadot0, omega0)
    if np.any(np.abs(m1) <= SEPARATRIX_BAND):
        raise ValueError(f"pendulum_motion: an initial state within {SEPARATRIX_BAND:g} of the separatrix "
                         f"(1 - k^2 = {m1.tolist()})")
    t = np.asarray(times, dtype=float)
    theta = np.empty((len(t), len(theta0)))
    thetadot = np.empty_like(theta)
    for copy in range(len(theta0)):
        solve = _librate if m1[copy] > 0 else _rotate
        theta[:, copy], thetadot[:, copy] = solve(theta0[copy], thetadot0[copy], omega0, m[copy], t)
    return theta + 2 * np.pi * turns, thetadot


def _librate(theta0: float, thetadot0: float, omega0: float, m: float, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Libration (m = k^2 < 1), theta0 in [-pi, pi]: theta / 2 = atan2(k sn, dn), theta' = 2 k omega0 cn."""
    k, quarter = np.sqrt(m), ellipk(m)
    u = omega0 * t + ellipkinc(np.arctan2(np.sin(0.5 * theta0), 0.5 * thetadot0 / omega0), m)
    u -= 4 * quarter * np.round(u / (4 * quarter))  # sn, cn, dn have the period 4 K
    sn, cn, dn, _ = ellipj(u, m)
    return 2 * np.arctan2(k * sn, dn), 2 * k * omega0 * cn


def _rotate(theta0: float, thetadot0: float, omega0: float, m: float, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (m = k^2 > 1), theta0 in [-pi, pi]: theta / 2 = s am(u, 1 / k^2), theta' = 2 s k omega0 dn."""
    k, parameter, s = np.sqrt(m), 1.0 / m, np.sign(thetadot0)
    half_period = 2 * ellipk(parameter)  # am(u + 2 K) = am(u) + pi, dn has the period 2 K
    u = k * omega0 * t + ellipkinc(s * 0.5 * theta0, parameter)
    turns = np.round(u / half_period)
    _, _, dn, am = ellipj(u - turns * half_period, parameter)
    return 2 * s * (am + np.pi * turns), 2 * s * k * omega0 * dn


def constant_force_motion(q0: np.ndarray, qdot0: np.ndarray, joint: OneJoint,
                          times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """I q'' = f - b q' from (q0, q0') ((B,) each): (q, q'), each (T, B) [rad or m, per second]; f the applied
    force plus, on a prismatic joint, gravity's m g.n."""
    force = joint.torque + (0.0 if joint.revolute else joint.mass * float(joint.gravity @ joint.axis))
    q, qdot = np.empty((len(times), len(q0))), np.empty((len(times), len(q0)))
    for copy in range(len(q0)):
        # The joint's equation is a point's with linear drag k = b / I under the acceleration f / I, along x.
        position, velocity = linear_drag([q0[copy], 0.0, 0.0], [qdot0[copy], 0.0, 0.0],
                                         [force / joint.inertia, 0.0, 0.0], joint.damping / joint.inertia, times)
        q[:, copy], qdot[:, copy] = position[:, 0], velocity[:, 0]
    return q, qdot


def supports(scene: JointMotionScene) -> Support:
    """Whether the scene has a closed form here (the reason names what does not fit)."""
    chain = scene.chain
    if chain.floating_base:
        return Support.no("no closed form for a floating base's motion here: its momentum laws are checked on every "
                          "engine's own run (linear_momentum_drift_max, chain_angular_momentum_drift_max)")
    if chain.n_joints != 1:
        return Support.no(f"no closed form: the chain has {chain.n_joints} joints (the closed-form joint motion is "
                          "for one joint: a physical pendulum, or a joint under constant forces)")
    joint, name = one_joint(scene), chain.joints[0].name
    if not joint.inertia > 0:
        return Support.no(f"no closed form: joint '{name}' moves no inertia along its axis (I = 0)")
    if scene.timed_torque is not None:
        if joint.is_pendulum():
            return Support.no(f"no closed form for a pendulum driven by a torque that changes with time: joint "
                              f"'{name}' swings under gravity")
        why = damped_drive_supported(scene.timed_torque) if joint.damping > 0 else ""
        return Support.no(f"{why} (joint '{name}')") if why else Support.yes()
    if not joint.is_pendulum():
        return (Support.no(f"no closed form for contact off a pendulum: joint '{name}' swings under no gravity torque")
                if scene.contact is not None else Support.yes())
    if joint.damping > 0:
        return Support.no(f"no closed form for a damped pendulum: joint '{name}' has damping {joint.damping:g} "
                          "and gravity exerts a torque about its axis")
    if joint.torque != 0:
        return Support.no(f"no closed form for a driven pendulum: joint '{name}' has the constant torque "
                          f"{joint.torque:g} N m and gravity exerts a torque about its axis")
    pendulum = pendulum_of(joint)
    _, m1 = modulus_squared(scene.q0[:, 0] - pendulum.psi, scene.qdot0[:, 0], pendulum.omega0)
    near = np.flatnonzero(np.abs(m1) <= SEPARATRIX_BAND)
    if near.size:
        return Support.no(f"no closed form on the pendulum's separatrix: copy {near[0]} starts with the energy of "
                          f"the upright equilibrium (|1 - k^2| = {abs(m1[near[0]]):.1e} <= {SEPARATRIX_BAND:g}): it "
                          "takes infinitely long to reach the top, and rounding decides whether it swings or turns")
    return Support.yes()


class ClosedFormJointMotion(JointSimulation):
    """A supported scene's closed form, sampled at k dt (no stepping: every sample from the initial states)."""

    def __init__(self, scene: JointMotionScene, dt: float) -> None:
        self._scene, self._dt, self._joint = scene, dt, one_joint(scene)
        self._pendulum = pendulum_of(self._joint) if self._joint.is_pendulum() else None
        # pendulum_contact builds on this module's pendulum: imported here, where a scene has contact
        from simparity.references.analytic.pendulum_contact import striking_pendulum
        self._striking = (striking_pendulum(scene, self._joint, self._pendulum)
                          if self._pendulum is not None and scene.contact is not None else None)
        if self._pendulum is not None:
            self.detail = (f"closed form: physical pendulum (Jacobi elliptic functions), omega0 = "
                           f"{self._pendulum.omega0:.6g} rad/s; joint limits not enforced"
                           + ("; impacts on the plane found on the closed form (Brent's method), q' -> -e q' at each"
                              if self._striking is not None else ""))
        else:
            self.detail = (f"closed form: one joint under a constant force"
                           + (" and a torque that changes with time" if scene.timed_torque is not None else "")
                           + f", damping {self._joint.damping:g}, inertia {self._joint.inertia:.6g}; joint limits "
                           "not enforced")

    def run(self, n_steps: int) -> JointTrajectory:
        times = np.arange(n_steps + 1) * self._dt
        q0, qdot0 = self._scene.q0[:, 0], self._scene.qdot0[:, 0]
        if self._striking is not None:
            from simparity.references.analytic.pendulum_contact import striking_motion
            pairs = [striking_motion(self._striking, a, b, times) for a, b in zip(q0, qdot0)]
            q, qdot = np.stack([p for p, _ in pairs], axis=1), np.stack([v for _, v in pairs], axis=1)
        elif self._pendulum is None and self._scene.timed_torque is not None:
            joint = self._joint
            force = joint.torque + (0.0 if joint.revolute else joint.mass * float(joint.gravity @ joint.axis))
            pairs = [driven_joint(a, b, joint.inertia, joint.damping, force, self._scene.timed_torque, times)
                     for a, b in zip(q0, qdot0)]
            q, qdot = np.stack([p for p, _ in pairs], axis=1), np.stack([v for _, v in pairs], axis=1)
        elif self._pendulum is None:
            q, qdot = constant_force_motion(q0, qdot0, self._joint, times)
        else:
            psi = self._pendulum.psi
            theta, qdot = pendulum_motion(q0 - psi, qdot0, self._pendulum.omega0, times)
            q = theta + psi
        return JointTrajectory(times, q[:, :, None], qdot[:, :, None])

    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(1/2 I qdot^2, -m g.c(q)), each (B,) [J], at q, qdot (B, 1)."""
        joint = self._joint
        q, qdot = np.atleast_2d(q)[:, 0], np.atleast_2d(qdot)[:, 0]
        potential = -joint.mass * joint.place(joint.com, q) @ joint.gravity
        return 0.5 * joint.inertia * qdot**2, potential

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        return self._joint.place(self._joint.end_effector, np.atleast_2d(q)[:, 0])


def build(scene: JointMotionScene, dt: float) -> ClosedFormJointMotion:
    """The supported ``scene`` sampled every ``dt`` [s]."""
    return ClosedFormJointMotion(scene, dt)
