"""What a reference is given: the scene as its file wrote it, every derived quantity computed with the references'
own code, never core's.

The loader builds a scene with core's code: roll-pitch-yaw to rotation matrices (``core.rotations``), a DH table to
joint frames (``core.dh``), point masses to a mass, centre of mass and inertia tensor (``core.dynamics.inertia``).
A reference that took those results would agree with core on any bug in them: the failure the independence rule
exists to prevent. So the data model also keeps the numbers as given (:attr:`Joint.origin_rpy`,
:attr:`Chain.end_effector_rpy`, :attr:`Chain.dh`, :attr:`PointMasses.positions_given` and
:attr:`PointMasses.frame_position_world`), and :func:`as_given` derives each quantity again from them:

- a rotation given as roll-pitch-yaw: SciPy's (:func:`references.common.conventions.rpy_to_matrix`);
- a DH chain's joint frames and end effector: :func:`references.common.dh_frames.dh_frames`;
- a body of point masses: its mass, tensor and centre of mass (:mod:`references.common.point_masses`), its
  ``position_world`` (the file's frame plus SciPy's rotation of that centre of mass) and the contact points of
  its ``points`` shape relative to it.

What was given directly (a matrix written in code, a link's mass properties, a URDF file, which every engine
reads itself) passes through untouched, and a scene with nothing derived is returned as it is (the same object).
:func:`derives_own_inputs` decorates a reference's :class:`~core.model.engine.Engine` class so that every method
that takes a scene or a chain is given it through :func:`as_given`.
"""

from __future__ import annotations

import functools
from dataclasses import replace
from typing import Any, TypeVar

from simparity.core.model.scenes.bodies import PointMasses, RigidBody
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.contact import Contact, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.references.common.conventions import quat_wxyz_to_matrix, rpy_to_matrix
from simparity.references.common.dh_frames import dh_frames
from simparity.references.common.point_masses import point_mass_properties

SCENE_METHODS = ("scene_integrators", "supports_dynamics", "build_dynamics", "supports_kinematics",
                 "build_kinematics", "supports_joint_dynamics", "build_joint_dynamics", "supports_joint_motion",
                 "build_joint_motion", "supports_ik", "build_ik", "scheme", "export")
"""The :class:`~core.model.engine.Engine` methods that take a scene or a chain (:func:`derives_own_inputs`)."""


def own_chain(chain: Chain) -> Chain:
    """``chain`` with its joint frames and end effector derived from the DH table or roll-pitch-yaw it was given as."""
    if chain.dh is not None:
        frames, (tip_xyz, tip_rotation) = dh_frames(chain.dh)
        joints = tuple(replace(j, origin_xyz=xyz, origin_rotation=rotation)
                       for j, (xyz, rotation) in zip(chain.joints, frames))
        return replace(chain, joints=joints, end_effector_xyz=tip_xyz, end_effector_rotation=tip_rotation)
    given = [j.origin_rpy is not None for j in chain.joints]
    if not any(given) and chain.end_effector_rpy is None:
        return chain
    joints = tuple(j if j.origin_rpy is None else replace(j, origin_rotation=rpy_to_matrix(j.origin_rpy))
                   for j in chain.joints)
    tip = chain.end_effector_rotation if chain.end_effector_rpy is None else rpy_to_matrix(chain.end_effector_rpy)
    return replace(chain, joints=joints, end_effector_rotation=tip)


def own_body(body: RigidBody) -> RigidBody:
    """``body`` with its mass properties, position and points derived from the point masses it was given as."""
    points = body.point_masses
    if points is None or points.positions_given is None or points.frame_position_world is None:
        return body
    mass, center, inertia = point_mass_properties(points.masses, points.positions_given)
    position = points.frame_position_world + quat_wxyz_to_matrix(body.quat_wxyz) @ center
    own = PointMasses(points.masses, points.positions_given - center, center, points.positions_given,
                      points.frame_position_world)
    return replace(body, mass=mass, inertia_body=inertia, position_world=position, point_masses=own)


def _own_shape(shape: Shape, body: RigidBody) -> Shape:
    """A ``points`` shape of a body of point masses: its points about the body's own centre of mass."""
    if shape.kind != "points" or body.point_masses is None or body.point_masses.positions_given is None:
        return shape
    return replace(shape, points_body=body.point_masses.points_body)


def _own_dynamics(scene: DynamicsScene) -> DynamicsScene:
    bodies = tuple(own_body(b) for b in scene.bodies)
    if all(own is given for own, given in zip(bodies, scene.bodies)):
        return scene
    contact: Contact | None = scene.contact
    if contact is not None:
        contact = replace(contact, shapes=tuple(_own_shape(s, b) for s, b in zip(contact.shapes, bodies)))
    return replace(scene, bodies=bodies, contact=contact)


_T = TypeVar("_T")


def as_given(value: _T) -> _T:
    """A scene or chain with every derived quantity computed by the references' code (module docstring); anything
    else, and a scene or chain with nothing derived, as it is."""
    result: Any = value
    if isinstance(value, Chain):
        result = own_chain(value)
    elif isinstance(value, DynamicsScene):
        result = _own_dynamics(value)
    elif isinstance(value, (KinematicsScene, IKScene, JointDynamicsScene, JointMotionScene)):
        chain = own_chain(value.chain)
        result = value if chain is value.chain else replace(value, chain=chain)
    return result


def _given(method):
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        return method(self, *(as_given(a) for a in args), **{k: as_given(v) for k, v in kwargs.items()})

    return wrapper


_E = TypeVar("_E", bound=type)


def derives_own_inputs(cls: _E) -> _E:
    """Class decorator of a reference engine: each of its :data:`SCENE_METHODS` is given scenes and chains through
    :func:`as_given`, so the engine never sees a quantity core derived from the scene file's numbers."""
    for name in SCENE_METHODS:
        setattr(cls, name, _given(getattr(cls, name)))
    return cls

