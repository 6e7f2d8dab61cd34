"""Closed-form joint-space dynamics of planar revolute chains of one or two links.

The planar elbow manipulator of Spong, Hutchinson and Vidyasagar ("Robot Modeling and Control", the
two-link planar arm of the Euler-Lagrange chapter), written for a chain's own numbers; one link is the
physical pendulum (the same formulas with a massless, locked second link).

The chain is reduced to the plane once, at q = 0, in the base frame (the world frame). n is joint 1's
axis in the world; joint 2's axis is s2 n (s2 = +-1: an opposite axis turns the other way). The
plane through joint 1's origin perpendicular to n gets the basis (u, w), w = n x u, and a point of it
the complex coordinate z = x.u + i x.w; a turn by theta about n multiplies z by exp(i theta). The
absolute angles of the links are theta1 = q1 and theta2 = q1 + s2 q2, and

- link 1's centre of mass is at   lc1 exp(i (theta1 + phi1)),
- joint 2 is at                    l1 exp(i (theta1 + beta)),
- link 2's centre of mass is at   l1 exp(i (theta1 + beta)) + lc2 exp(i (theta2 + phi2)),

with (lc1, phi1), (l1, beta), (lc2, phi2) the lengths and phases of link 1's COM, of joint 2's origin
(both from joint 1) and of link 2's COM (from joint 2) at q = 0: COM offsets off the link line and
joint 2 off link 1's x axis are these phases. I_k is link k's inertia about its COM and about n.
With gamma = s2 q2 + phi2 - beta (the angle between joint 2's position and link 2's COM):

    M11 = I1 + I2 + m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 cos gamma)
    M12 = M21 = s2 (I2 + m2 lc2^2 + m2 l1 lc2 cos gamma)
    M22 = I2 + m2 lc2^2

plus each joint's armature on the diagonal. The Christoffel symbols c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j
- dM_ij/dq_k) with h = -m2 l1 lc2 sin gamma (dM11/dq2 = 2 s2 h, dM12/dq2 = h, M depends on q2 alone):

    c111 = 0, c121 = c211 = s2 h, c221 = h;   c112 = -s2 h, c122 = c212 = c222 = 0

so (C qdot)_1 = 2 s2 h qdot1 qdot2 + h qdot2^2 and (C qdot)_2 = -s2 h qdot1^2. Gravity from the potential
V = -sum_k m_k g.c_k, with g's component in the plane |g| exp(i psi):

    dV/dtheta1 = |g| (m1 lc1 sin(theta1 + phi1 - psi) + m2 l1 sin(theta1 + beta - psi))
    dV/dtheta2 = |g| m2 lc2 sin(theta2 + phi2 - psi)
    g1 = dV/dtheta1 + dV/dtheta2,  g2 = s2 dV/dtheta2.

Spong's arm is phi1 = beta = phi2 = 0, s2 = 1, psi = -pi/2. Gravity's component along the axis does no
work on any motion of the chain (every point moves in planes perpendicular to n), so it is dropped exactly;
the engine interface asks about support without gravity, so it is not a reason to refuse.

What is supported (:func:`supports`): one or two revolute joints, parallel axes (same or opposite), joint 2's
origin and every link's COM in the plane through joint 1 perpendicular to the axis, each link's inertia with
the axis as a principal axis, all to rounding (``_PLANAR_RTOL``); damping and armature as declared.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.engine import JointDynamicsModel, Support
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.chain import Chain, LinkInertia

_PLANAR_RTOL = 1e-12
"""Relative tolerance of "parallel", "in the plane" and "a principal axis": a chain built planar in code or a URDF
file, through rpy angles such as pi, is off by rounding (~1e-16) only; a genuinely tilted chain is far outside."""


@dataclass(frozen=True)
class PlanarArm:
    """A one- or two-link planar arm's numbers (a one-link arm has a massless second link).

    Attributes
    ----------
    n_joints : int
        1 or 2.
    axis_world : (3,) ndarray
        n, joint 1's axis in the base frame (unit).
    sign2 : float
        s2: +1 when joint 2's axis is n, -1 when it is -n.
    mass : (2,) ndarray
        m1, m2 [kg].
    inertia_axis : (2,) ndarray
        I1, I2: each link's inertia about its COM and about n [kg m^2].
    com1, joint2, com2 : complex
        lc1 exp(i phi1), l1 exp(i beta), lc2 exp(i phi2) [m] at q = 0 (see the module docstring).
    gravity : complex
        The gravity's component in the plane, |g| exp(i psi) [m/s^2].
    armature, damping : (n,) ndarray
        [kg m^2], [N m s/rad].
    """

    n_joints: int
    axis_world: np.ndarray
    sign2: float
    mass: np.ndarray
    inertia_axis: np.ndarray
    com1: complex
    joint2: complex
    com2: complex
    gravity: complex
    armature: np.ndarray
    damping: np.ndarray


@dataclass(frozen=True)
class _Reduction:
    """The chain at q = 0 in the base frame: n, the plane's basis, each link's frame and its mass properties."""

    axis: np.ndarray
    basis: np.ndarray  # (2, 3): u, w
    origins: list[np.ndarray]  # link frame origins [m]
    rotations: list[np.ndarray]  # link frame -> base
    links: list[LinkInertia]
    sign2: float


def _reduce(chain: Chain) -> tuple[_Reduction | None, str]:
    """The chain reduced to the plane, or (None, the one-line reason it does not fit)."""
    problem = chain.dynamics_problem()
    if problem:
        return None, problem
    if chain.floating_base:
        return None, "no closed form: the base floats (the closed form is for a planar chain on a fixed base)"
    if chain.n_joints not in (1, 2):
        return None, f"no closed form: the chain has {chain.n_joints} joints (the closed form is for 1 or 2)"
    origins: list[np.ndarray] = []
    rotations: list[np.ndarray] = []
    links: list[LinkInertia] = []
    position, rotation = np.zeros(3), np.eye(3)
    for joint in chain.joints:
        if joint.type != "revolute":
            return None, f"no closed form: joint '{joint.name}' is {joint.type} (the closed form is for revolute joints)"
        assert joint.link is not None  # dynamics_problem() is "": every link has mass properties
        position, rotation = position + rotation @ joint.origin_xyz, rotation @ joint.origin_rotation
        origins.append(position)
        rotations.append(rotation)
        links.append(joint.link)
    axis = rotations[0] @ chain.joints[0].axis
    sign2 = 1.0
    if chain.n_joints == 2:
        second = chain.joints[1]
        axis2 = rotations[1] @ second.axis
        if np.linalg.norm(np.cross(axis, axis2)) > _PLANAR_RTOL:
            return None, (f"no closed form: the axis of joint '{second.name}' is not parallel to the axis of joint "
                          f"'{chain.joints[0].name}' (the arm is not planar)")
        sign2 = float(np.sign(axis @ axis2))
    points = [(f"the origin of joint '{j.name}'", origins[k]) for k, j in enumerate(chain.joints)][1:]
    points += [(f"the centre of mass of joint '{j.name}'s link", origins[k] + rotations[k] @ links[k].com_xyz)
               for k, j in enumerate(chain.joints)]
    offsets = [p - origins[0] for _, p in points]
    scale = max(float(np.linalg.norm(d)) for d in offsets)
    for (what, _), offset in zip(points, offsets):
        if abs(axis @ offset) > _PLANAR_RTOL * scale:
            return None, (f"no closed form: {what} is off the plane of motion (through joint "
                          f"'{chain.joints[0].name}', perpendicular to its axis)")
    for k, joint in enumerate(chain.joints):
        inertia = rotations[k] @ links[k].inertia_com @ rotations[k].T
        spin = inertia @ axis
        if np.linalg.norm(spin - (axis @ spin) * axis) > _PLANAR_RTOL * np.linalg.norm(inertia):
            return None, (f"no closed form: the axis is not a principal axis of the inertia of joint '{joint.name}'s "
                          "link (products of inertia about it are not zero)")
    # u: the base axis least aligned with n, made perpendicular to it; w = n x u.
    seed = np.eye(3)[np.argmin(np.abs(axis))]
    u = seed - (seed @ axis) * axis
    u /= np.linalg.norm(u)
    return _Reduction(axis, np.stack([u, np.cross(axis, u)]), origins, rotations, links, sign2), ""


def supports(chain: Chain) -> Support:
    """Whether the chain is a planar revolute arm of one or two links (the reason names what does not fit)."""
    reduction, reason = _reduce(chain)
    return Support.yes() if reduction is not None else Support.no(reason)


def planar_arm(chain: Chain, gravity_world: np.ndarray | None) -> PlanarArm:
    """The arm's numbers; ``gravity_world`` (3,) [m/s^2] in the base frame or None. Call only when supported."""
    reduction, reason = _reduce(chain)
    if reduction is None:
        raise SceneError("<code>", "chain", reason, "a planar revolute arm of 1 or 2 links")
    basis = reduction.basis

    def plane(vector: np.ndarray) -> complex:
        x, y = basis @ vector
        return complex(x, y)

    origins, rotations, links = reduction.origins, reduction.rotations, reduction.links
    coms = [origins[k] + rotations[k] @ links[k].com_xyz for k in range(chain.n_joints)]
    axis_inertia = [float(reduction.axis @ rotations[k] @ links[k].inertia_com @ rotations[k].T @ reduction.axis)
                    for k in range(chain.n_joints)]
    two = chain.n_joints == 2
    gravity = np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float)
    return PlanarArm(
        n_joints=chain.n_joints, axis_world=reduction.axis, sign2=reduction.sign2,
        mass=np.array([links[0].mass, links[1].mass if two else 0.0]),
        inertia_axis=np.array([axis_inertia[0], axis_inertia[1] if two else 0.0]),
        com1=plane(coms[0] - origins[0]),
        joint2=plane(origins[1] - origins[0]) if two else 0j,
        com2=plane(coms[1] - origins[1]) if two else 0j,
        gravity=plane(gravity),
        armature=np.array([j.armature for j in chain.joints]),
        damping=np.array([j.damping for j in chain.joints]),
    )


class ClosedFormJointDynamics(JointDynamicsModel):
    """M, C qdot, g of a :class:`PlanarArm` in closed form (the module docstring's formulas).

    Every function takes (B, n) arrays [rad, rad/s, rad/s^2, N m] (a single (n,) state is read as B = 1).
    A one-link arm is evaluated as the two-link formulas with a massless second link locked at q2 = 0,
    of which the first joint's entries are its own.
    """

    def __init__(self, arm: PlanarArm) -> None:
        self._arm = arm
        axis = ", ".join(f"{a:.6g}" for a in arm.axis_world)
        kind = "physical pendulum" if arm.n_joints == 1 else "planar elbow manipulator (Spong et al.)"
        self.detail = f"closed form: {kind} about ({axis}), joint 2's axis sign {arm.sign2:+.0f}"

    def _padded(self, *arrays: np.ndarray) -> list[np.ndarray]:
        """Each (B, n) array as (B, 2), a one-link arm's second joint at 0."""
        out = []
        for a in arrays:
            a = np.atleast_2d(np.asarray(a, dtype=float))
            out.append(np.concatenate([a, np.zeros((len(a), 2 - a.shape[1]))], axis=1))
        return out

    def _gamma(self, q2: np.ndarray) -> np.ndarray:
        """gamma = s2 q2 + phi2 - beta, (B,) [rad]."""
        arm = self._arm
        return arm.sign2 * q2 + np.angle(arm.com2) - np.angle(arm.joint2)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        arm = self._arm
        (q,) = self._padded(q)
        m1, m2 = arm.mass
        i1, i2 = arm.inertia_axis
        lc1, l1, lc2 = abs(arm.com1), abs(arm.joint2), abs(arm.com2)
        cos_gamma = np.cos(self._gamma(q[:, 1]))
        m = np.empty((len(q), 2, 2))
        m[:, 0, 0] = i1 + i2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * cos_gamma)
        m[:, 0, 1] = m[:, 1, 0] = arm.sign2 * (i2 + m2 * lc2**2 + m2 * l1 * lc2 * cos_gamma)
        m[:, 1, 1] = i2 + m2 * lc2**2
        n = arm.n_joints
        return m[:, :n, :n] + np.diag(arm.armature)

    def _coriolis(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """C(q, qdot) qdot, (B, 2), from the Christoffel symbols."""
        arm = self._arm
        s2 = arm.sign2
        h = -arm.mass[1] * abs(arm.joint2) * abs(arm.com2) * np.sin(self._gamma(q[:, 1]))
        c111, c121, c211, c221 = 0.0, s2 * h, s2 * h, h
        c112, c122, c212, c222 = -s2 * h, 0.0, 0.0, 0.0
        qd1, qd2 = qd[:, 0], qd[:, 1]
        first = c111 * qd1 * qd1 + (c121 + c211) * qd1 * qd2 + c221 * qd2 * qd2
        second = c112 * qd1 * qd1 + (c122 + c212) * qd1 * qd2 + c222 * qd2 * qd2
        return np.stack([first, second], axis=1)

    def _gravity(self, q: np.ndarray) -> np.ndarray:
        """g(q) = dV/dq, (B, 2) [N m]."""
        arm = self._arm
        m1, m2 = arm.mass
        g, psi = abs(arm.gravity), np.angle(arm.gravity)
        theta1, theta2 = q[:, 0], q[:, 0] + arm.sign2 * q[:, 1]
        d_theta1 = g * (m1 * abs(arm.com1) * np.sin(theta1 + np.angle(arm.com1) - psi)
                        + m2 * abs(arm.joint2) * np.sin(theta1 + np.angle(arm.joint2) - psi))
        d_theta2 = g * m2 * abs(arm.com2) * np.sin(theta2 + np.angle(arm.com2) - psi)
        return np.stack([d_theta1 + d_theta2, arm.sign2 * d_theta2], axis=1)

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        q, qdot = self._padded(q, qdot)
        return (self._coriolis(q, qdot) + self._gravity(q))[:, :self._arm.n_joints]

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        q, qdot, qddot = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (q, qdot, qddot))
        inertial = np.einsum("bij,bj->bi", self.mass_matrix(q), qddot)
        return inertial + self.bias_forces(q, qdot) + self._arm.damping * qdot

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        q, qdot, tau = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (q, qdot, tau))
        m = self.mass_matrix(q)
        rhs = tau - self.bias_forces(q, qdot) - self._arm.damping * qdot
        if self._arm.n_joints == 1:
            return rhs / m[:, :, 0]
        # The 2x2 inverse: adj(M) / det(M).
        det = m[:, 0, 0] * m[:, 1, 1] - m[:, 0, 1] * m[:, 1, 0]
        first = m[:, 1, 1] * rhs[:, 0] - m[:, 0, 1] * rhs[:, 1]
        second = m[:, 0, 0] * rhs[:, 1] - m[:, 1, 0] * rhs[:, 0]
        return np.stack([first, second], axis=1) / det[:, None]

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """sum_k 1/2 m_k |v_ck|^2 + 1/2 I_k thetadot_k^2 [J], (B,): the COM velocities differentiated by hand
        (d/dt r exp(i theta) = i thetadot r exp(i theta)), each link's angular velocity thetadot_k n."""
        arm = self._arm
        q, qdot = self._padded(q, qdot)
        theta1, theta2 = q[:, 0], q[:, 0] + arm.sign2 * q[:, 1]
        omega1, omega2 = qdot[:, 0], qdot[:, 0] + arm.sign2 * qdot[:, 1]
        v1 = 1j * omega1 * arm.com1 * np.exp(1j * theta1)
        v2 = 1j * omega1 * arm.joint2 * np.exp(1j * theta1) + 1j * omega2 * arm.com2 * np.exp(1j * theta2)
        m1, m2 = arm.mass
        i1, i2 = arm.inertia_axis
        return 0.5 * (m1 * np.abs(v1) ** 2 + m2 * np.abs(v2) ** 2 + i1 * omega1**2 + i2 * omega2**2)


def build(chain: Chain, gravity_world: np.ndarray | None) -> ClosedFormJointDynamics:
    """The chain's closed-form joint-space dynamics under ``gravity_world`` ((3,) [m/s^2] or None)."""
    return ClosedFormJointDynamics(planar_arm(chain, gravity_world))
