"""A floating base's state on a PyBullet body, in the project's convention (``docs/floating-bases.md``), and the
body's own mass distribution in motion (issue #46).

PyBullet keeps a free multibody's base as its INERTIAL frame (``getBasePositionAndOrientation``: the base link's
centre of mass and principal axes, quat_xyzw) moving with ``getBaseVelocity`` (that point's linear velocity and the
angular velocity, both in world axes). The project's base is the base link's URDF frame and its velocity the ORIGIN's
(:mod:`references.common.floating_base`). With the inertial frame's pose (p_i, R_i) in the link frame
(``getDynamicsInfo(body, -1)``'s local inertial position and orientation):

- R_inertial = R R_i, p_inertial = p + R p_i (the quaternions multiplied, the product in double);
- v_inertial = v + w x (R p_i), the angular velocity w the same in both.

Every link's centre-of-mass velocity (``getLinkStates(computeLinkVelocity=1)``'s ``worldLinkLinearVelocity``: the
centre of mass's, measured against differences of its position; the URDF link frame's would differ by w x r) and its
angular velocity, with its inertial frame's orientation (double) and ``getDynamicsInfo``'s mass and principal moments,
give the kinetic energy and momentum from PyBullet's own model of the body.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from simparity.references.common.conventions import (
    quat_wxyz_conjugate, quat_wxyz_multiply, quat_wxyz_to_matrix, wxyz_from_xyzw, xyzw_from_wxyz,
)
from simparity.references.pybullet.quiet import pybullet


def massless_base(urdf_text: str) -> str:
    """Why PyBullet cannot step ``urdf_text``'s root link as a free base, "" when it can: Bullet holds a free
    multibody whose base has mass 0 kinematic (``useFixedBase=False`` or not: its base velocity never changes, a
    robot in free flight keeps its first angular velocity and one under gravity hangs in the air; held-out a1, whose
    root ``base`` has no inertial and carries ``trunk`` welded to it, 1.35 rad off at every step while every check
    passed). The root's own mass counts: links welded to it are links of their own in PyBullet."""
    root = ET.fromstring(urdf_text)
    children = {child.get("link") for joint in root.iter("joint") if (child := joint.find("child")) is not None}
    base = next(link for link in root.iter("link") if link.get("name") not in children)
    mass = base.find("inertial/mass")
    if mass is not None and float(mass.get("value", "0")) > 0:
        return ""
    return (f"PyBullet holds a free multibody whose base link has no mass kinematic (its base never accelerates): "
            f"the base link {base.get('name')!r} has mass 0 in the file (its welded links' mass does not count)")


@dataclass(frozen=True)
class BaseInertial:
    """The base's inertial frame in its link frame: ``position`` (3,) [m], ``quat_wxyz`` (4,)."""

    position: np.ndarray
    quat_wxyz: np.ndarray

    @classmethod
    def of(cls, client: int, body: int) -> "BaseInertial":
        info = pybullet.getDynamicsInfo(body, -1, physicsClientId=client)
        return cls(np.asarray(info[3], dtype=float), wxyz_from_xyzw(np.asarray(info[4], dtype=float)))

    def put(self, client: int, body: int, q: np.ndarray, qdot: np.ndarray) -> None:
        """Put ``body``'s base at the project's base pose q[:7] (position, quat_wxyz) and velocity qdot[:6] (the
        origin's linear velocity, the angular velocity; world axes)."""
        rotation = quat_wxyz_to_matrix(q[3:7])
        arm = rotation @ self.position
        quat = quat_wxyz_multiply(q[3:7], self.quat_wxyz)
        pybullet.resetBasePositionAndOrientation(body, (q[:3] + arm).tolist(), xyzw_from_wxyz(quat).tolist(),
                                                 physicsClientId=client)
        pybullet.resetBaseVelocity(body, (qdot[:3] + np.cross(qdot[3:6], arm)).tolist(), qdot[3:6].tolist(),
                                   physicsClientId=client)

    def read(self, client: int, body: int) -> tuple[np.ndarray, np.ndarray]:
        """(q (7,), qdot (6,)): ``body``'s base pose and velocity now, in the project's convention."""
        position, orientation = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        linear, angular = pybullet.getBaseVelocity(body, physicsClientId=client)
        if not np.all(np.isfinite(orientation)) or not np.any(orientation):  # a blown-up run: the runner says so
            return np.full(7, np.nan), np.full(6, np.nan)
        quat = quat_wxyz_multiply(wxyz_from_xyzw(np.asarray(orientation, dtype=float)),
                                  quat_wxyz_conjugate(self.quat_wxyz))
        arm = quat_wxyz_to_matrix(quat) @ self.position
        omega = np.asarray(angular, dtype=float)
        return (np.concatenate([np.asarray(position, dtype=float) - arm, quat]),
                np.concatenate([np.asarray(linear, dtype=float) - np.cross(omega, arm), omega]))


@dataclass(frozen=True)
class MassStates:
    """Every link of a body, its base included, at one state: ``mass`` (L,) [kg], ``inertia_world`` (L, 3, 3)
    [kg m^2] about each centre of mass, ``com`` (L, 3) [m], ``velocity`` (L, 3) [m/s] of each centre of mass,
    ``omega`` (L, 3) [rad/s]; world axes."""

    mass: np.ndarray
    inertia_world: np.ndarray
    com: np.ndarray
    velocity: np.ndarray
    omega: np.ndarray

    @classmethod
    def of(cls, client: int, body: int, links: list[int]) -> "MassStates":
        """``body``'s links ``links`` and its base as PyBullet has them now (:func:`getLinkStates`, double)."""
        info = [pybullet.getDynamicsInfo(body, link, physicsClientId=client) for link in (-1, *links)]
        states = pybullet.getLinkStates(body, links, computeLinkVelocity=1, computeForwardKinematics=1,
                                        physicsClientId=client)
        position, orientation = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        linear, angular = pybullet.getBaseVelocity(body, physicsClientId=client)
        com = np.array([position, *(s[0] for s in states)], dtype=float)
        frames = wxyz_from_xyzw(np.array([orientation, *(s[1] for s in states)], dtype=float))
        rotation = quat_wxyz_to_matrix(frames)
        moments = np.array([i[2] for i in info], dtype=float)
        return cls(np.array([i[0] for i in info], dtype=float),
                   np.einsum("lij,lj,lkj->lik", rotation, moments, rotation), com,
                   np.array([linear, *(s[6] for s in states)], dtype=float),
                   np.array([angular, *(s[7] for s in states)], dtype=float))

    def kinetic(self) -> float:
        """[J] sum 1/2 m |v|^2 + 1/2 w^T I w."""
        return float(0.5 * (self.mass @ np.sum(self.velocity**2, axis=1)
                            + np.einsum("li,lij,lj->", self.omega, self.inertia_world, self.omega)))

    def potential(self, gravity_world: np.ndarray) -> float:
        """[J] -sum m g . c."""
        return float(-self.mass @ (self.com @ gravity_world))

    def momentum(self) -> np.ndarray:
        """(6,): P [kg m/s] and the angular momentum about the centre of mass [kg m^2/s], world axes."""
        linear = self.mass @ self.velocity
        centre = self.mass @ self.com / self.mass.sum()
        angular = (np.einsum("l,lij,lj->i", self.mass, _skew(self.com - centre), self.velocity)
                   + np.einsum("lij,lj->i", self.inertia_world, self.omega))
        return np.concatenate([linear, angular])


def _skew(v: np.ndarray) -> np.ndarray:
    """(L, 3, 3) [v]x of (L, 3)."""
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    return out - np.swapaxes(out, -1, -2)
