"""A chain's spheres meeting the scene's plane in PyBullet (issue #46): Bullet's own multibody contact.

What PyBullet is given, beside :mod:`references.pybullet.joint_motion`'s stepped body (every default there):

- Each sphere is a ``<collision>`` sphere of the scene's radius added to the link of its frame in the chain's dynamics
  URDF (a chain joint's frame is its child link's, the end effector its link, the base link the base), at its
  centre; ``URDF_USE_INERTIA_FROM_FILE`` keeps the file's inertia (the spheres weigh nothing).
- The plane is the free bodies' static ``GEOM_PLANE`` multibody (:func:`references.pybullet.adapter.static_plane`).
  Collision filters: the sphere links collide with the plane only (the adapter's body and plane groups), every other
  link with nothing; a copy never touches another.
- Without restitution, and with the scene's Coulomb friction: ``lateralFriction`` mu (0 on a frictionless plane),
  ``restitution`` 0, rolling and spinning friction 0 on the sphere links (Bullet multiplies the two objects': the plane
  keeps 1 of each); no speculative contact
  (``contactProcessingThreshold`` 0: a sphere above the plane gets no force).
- The solve: ``contactERP`` 0 (no position correction by velocity: it adds energy), ``contactSlop`` 0 (the contact
  distance is the spheres' and the plane's exact distance), ``numSolverIterations`` 100, ``solverResidualThreshold`` 0
  (every sweep runs: the threshold is a squared velocity, and any absolute value stops the solve at another point in
  another unit; with 1e-12 a held-out three-sphere arm in milliseconds settled to 1e-7 g instead of 8.5e-15 g),
  ``globalCFM`` 0, ``restitutionVelocityThreshold`` 0, split impulse off (not implemented for multibodies):
  Bullet's multibody step is semi-implicit Euler with the contact solved on velocities by its PGS, as the free
  bodies' (:mod:`references.pybullet.adapter`). ``enableConeFriction`` 1 (its default, stated): the friction's two
  rows scaled back into the Coulomb cone; with 0 Bullet clamps each row alone, a box whose diagonal is sqrt(2) mu f_n
  (measured on ``solo12-incline-slide``: a sliding foot's friction 1.414 mu f_n). Its rows still resist a sideways
  slip on their own: a sliding foot's friction is on the cone but up to 0.29 rad off the slip's opposite there.
- The force on a sphere at a state: a scratch copy of the world is put at the state (``resetJointState``, the scene's
  torque at that time) and stepped once; ``getContactPoints`` with the plane gives each point's ``normalForce``
  (Bullet's impulse over dt) along ``contactNormalOnB`` (from the plane to the link) and its two lateral friction
  forces along their directions (0 here), summed per sphere (a point is
  the sphere's whose centre, placed by PyBullet, is nearest to it). It is the force of the step from that state, as
  Pinocchio's (:mod:`references.pinocchio.contact`).
- On a floating base the body is free (``useFixedBase`` False) and its base's state converted
  (:mod:`references.pybullet.floating_body`); a sphere on the base link rides on the base link's frame.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact, frame_index
from simparity.references.common.conventions import fmt, quat_wxyz_to_matrix, wxyz_from_xyzw
from simparity.references.pybullet.adapter import BODY_GROUP, PLANE_GROUP, static_plane
from simparity.references.pybullet.floating_body import BaseInertial
from simparity.references.pybullet.quiet import pybullet

SOLVER = dict(contactERP=0.0, contactSlop=0.0, numSolverIterations=100, solverResidualThreshold=0.0, globalCFM=0.0,
              restitutionVelocityThreshold=0.0, useSplitImpulse=0, deterministicOverlappingPairs=1,
              enableConeFriction=1)
"""setPhysicsEngineParameter of a world with a chain's contact (the module docstring gives each reason)."""
SPHERE_DYNAMICS = dict(restitution=0.0, rollingFriction=0.0, spinningFriction=0.0, contactProcessingThreshold=0.0)
"""changeDynamics of every link that carries a sphere, beside its ``lateralFriction``, the scene's mu."""


def sphere_links(chain: Chain, contact: ChainContact, urdf_text: str) -> list[str]:
    """The URDF link of each sphere's frame in ``urdf_text`` (the chain's dynamics URDF; the base link's own name, or
    its first link, the base it exports)."""
    root = ET.fromstring(urdf_text)
    children = {str(j.get("name")): str(child.get("link")) for j in root.iter("joint")
                if (child := j.find("child")) is not None}
    base = chain.base_link or str(next(root.iter("link")).get("name"))
    names = tuple(j.name for j in chain.joints)
    out = []
    for sphere in contact.spheres:
        i = frame_index(sphere.frame, names, chain.end_effector_name, chain.base_link)
        out.append(base if i < 0 else chain.end_effector_name if i == len(names) else children[names[i]])
    return out


def with_spheres(urdf_text: str, chain: Chain, contact: ChainContact) -> str:
    """``urdf_text`` with each of ``contact``'s spheres a ``<collision>`` sphere on its frame's link."""
    root = ET.fromstring(urdf_text)
    links = {link.get("name"): link for link in root.iter("link")}
    for sphere, name in zip(contact.spheres, sphere_links(chain, contact, urdf_text)):
        collision = ET.SubElement(links[name], "collision")
        ET.SubElement(collision, "origin", xyz=fmt(np.asarray(sphere.centre_xyz, dtype=float)), rpy="0 0 0")
        ET.SubElement(ET.SubElement(collision, "geometry"), "sphere", radius=repr(float(sphere.radius)))
    return ET.tostring(root, encoding="unicode")


def link_index(body: int, client: int, name: str) -> int:
    """PyBullet's index of link ``name`` of ``body`` (-1: its base)."""
    if pybullet.getBodyInfo(body, physicsClientId=client)[0].decode() == name:
        return -1
    for j in range(pybullet.getNumJoints(body, physicsClientId=client)):
        if pybullet.getJointInfo(body, j, physicsClientId=client)[12].decode() == name:
            return j
    raise KeyError(name)


def link_frame(client: int, body: int, link: int, base: BaseInertial | None) -> tuple[np.ndarray, np.ndarray]:
    """(R (3, 3), origin (3,) [m]) of ``body``'s URDF link frame ``link`` in the world now, in double: a link's from
    its inertial frame (``getLinkState``'s centre of mass and orientation) moved back by ``getDynamicsInfo``'s local
    inertial pose (``worldLinkFramePosition`` is float32); the base's (-1) from the floating base's state
    (:class:`BaseInertial`), or the fixed base's pose (its inertial frame is its link frame: the dynamics URDF gives a
    fixed base an explicit zero inertial)."""
    if link < 0:
        if base is not None:
            q, _ = base.read(client, body)
            return quat_wxyz_to_matrix(q[3:7]), q[:3]
        position, orientation = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        return quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(orientation))), np.asarray(position)
    state = pybullet.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=client)
    local = pybullet.getDynamicsInfo(body, link, physicsClientId=client)
    inertial = quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(state[1])))
    local_rotation = quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(local[4])))
    rotation = inertial @ local_rotation.T
    return rotation, np.asarray(state[0]) - rotation @ np.asarray(local[3])


class PlaneContact:
    """The plane and the spheres' links of a world's bodies (the module docstring: shapes, filters, solve)."""

    def __init__(self, client: int, bodies: list[int], chain: Chain, contact: ChainContact, urdf_text: str,
                 base: BaseInertial | None = None) -> None:
        self._client, self._contact, self._base = client, contact, base
        names = sphere_links(chain, contact, urdf_text)
        self.links = [link_index(bodies[0], client, name) for name in names]
        self._points = np.array([s.centre_xyz for s in contact.spheres], dtype=float)
        self.plane = static_plane(client, contact.plane)
        for body in bodies:
            for link in set(self.links):
                pybullet.setCollisionFilterGroupMask(body, link, BODY_GROUP, PLANE_GROUP, physicsClientId=client)
                pybullet.changeDynamics(body, link, **SPHERE_DYNAMICS, lateralFriction=contact.friction,
                                        physicsClientId=client)
        pybullet.setPhysicsEngineParameter(**SOLVER, physicsClientId=client)

    def centres(self, body: int) -> np.ndarray:
        """(S, 3) [m] the spheres' centres of ``body`` as PyBullet places its links now (:func:`link_frame`)."""
        out = np.empty((len(self.links), 3))
        for k, (link, point) in enumerate(zip(self.links, self._points)):
            rotation, origin = link_frame(self._client, body, link, self._base)
            out[k] = origin + rotation @ point
        return out

    def forces(self, body: int) -> np.ndarray:
        """(S, 3) [N] the plane's force on each sphere of ``body`` in the last step (``getContactPoints``): the normal
        force along ``contactNormalOnB`` and both lateral friction forces along their directions (0 on the frictionless
        plane; reported, so that friction where there should be none is seen)."""
        out = np.zeros((len(self.links), 3))
        points = pybullet.getContactPoints(bodyA=body, bodyB=self.plane, physicsClientId=self._client)
        if not points:
            return out
        centres = self.centres(body)
        for point in points:
            candidates = [k for k, link in enumerate(self.links) if link == point[3]]
            at = np.asarray(point[5])
            k = min(candidates, key=lambda s: float(np.linalg.norm(centres[s] - at)))
            out[k] += (point[9] * np.asarray(point[7]) + point[10] * np.asarray(point[11])
                       + point[12] * np.asarray(point[13]))
        return out
