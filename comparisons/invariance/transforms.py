"""Metamorphic transforms: the same physics written in another frame, body order or system of units.

A :class:`Transform` maps every point x of a scene to x' = L R x + t (R a rotation, t a translation
[m of the transformed scene], L the number of new length units in one of the scene's), lists the bodies
in another order, and counts mass and time in other units (M, T new units in one of the scene's).
Every quantity of the scene follows its dimension: a velocity becomes (L / T) R v, gravity (L / T^2) R g,
an angular velocity R omega / T, a body's inertia tensor M L^2 I (body axes do not turn with the world:
the body's orientation does, q' = q_R q), a drag coefficient of N s/m becomes (M / T) b, a contact
stiffness (M / T^2) k, the rest speed (L / T) v_rest, a time step T dt. A load that changes with time follows its
time too: f'(t') = s R f(t' / T) (s the factor of its unit, R only for world axes), so a polynomial's coefficient of
t^k becomes s R c_k / T^k, a sinusoid's frequency f / T (its amplitude s R A, its phase unchanged), a hold's period
and first instant T times theirs (its samples s R s_k). Physics says the transformed scene
moves exactly as the transformed original, so every result, carried back into the scene's own units
(:meth:`Transform.to_scene_units`), must be the same up to rounding: ``comparisons.invariance.metamorphic`` checks it.

What a kind of scene can express:

- dynamics scenes take every transform;
- kinematics and IK scenes (a fixed-base chain, its targets made from the chain's FK) take a rotation,
  translation and length scale through the chain's first joint origin (the base's placement in the
  world) and every length of the chain (joint origins, end effector, prismatic limits and start values,
  the position tolerance); a chain has no mass, no time and no free bodies, so the other parts leave it
  as it is. A chain read from a URDF file is loaded from that file by every engine, so neither its base
  nor its lengths can be changed in the scene: :class:`~simparity.core.model.errors.TransformError`.

Rotations are SciPy's (:mod:`references.common.conventions`), never core's. The numbers a file gave, which the references
derive their quantities from (:mod:`references.common.scene_inputs`), are transformed with the rest: a point-mass
body's points are scaled and the frame they were given in placed; the first joint's roll-pitch-yaw becomes that of
R times its rotation (as a file in the transformed frame would write it); a DH table's lengths are scaled and its
base placed by R and t.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from simparity.comparisons.invariance.units import unit_factor
from simparity.core.model.arrays import readonly
from simparity.core.model.errors import TransformError, one_line
from simparity.core.model.scenes.bodies import AppliedForce, Forces, PointMasses, RigidBody
from simparity.core.model.scenes.chain import Chain, DHTable, Joint, LinkInertia
from simparity.core.model.scenes.contact import Contact, Plane, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.chain_contact import ChainContact, ContactSphere, frame_index
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.core.model.scenes.time_functions import (
    WORLD,
    HeldFunction,
    Sinusoid,
    SmoothFunction,
    TimedLoad,
    TimeFunction,
)
from simparity.references.common.conventions import (
    matrix_to_quat_wxyz,
    matrix_to_rpy,
    quat_wxyz_multiply,
    quat_wxyz_to_matrix,
    rpy_to_matrix,
)

IDENTITY_QUAT = (1.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Transform:
    """A change of frame, body order and units (module docstring).

    Attributes
    ----------
    name : str
        Short name, used in result rows (``invariance_ratio_<name>``).
    translation_world : (3,) ndarray
        t [m of the transformed scene], added after rotating and scaling.
    quat_wxyz : (4,) ndarray
        R, the rotation of the whole scene (world to world), unit norm.
    body_order : tuple of int or None
        Explicit new order of the bodies: new body i is old body ``body_order[i]``.
    shuffle_seed : int or None
        A seeded reordering of however many bodies a scene has (a derangement of the identity when it has
        more than one); only when ``body_order`` is None.
    length_scale, mass_scale, time_scale : float
        L, M, T: new units in one of the scene's metre, kilogram, second (T = 1000: milliseconds).
    description : str
        What the transform is, for result details.
    """

    name: str
    translation_world: np.ndarray = field(default_factory=lambda: np.zeros(3))
    quat_wxyz: np.ndarray = field(default_factory=lambda: np.array(IDENTITY_QUAT))
    body_order: tuple[int, ...] | None = None
    shuffle_seed: int | None = None
    length_scale: float = 1.0
    mass_scale: float = 1.0
    time_scale: float = 1.0
    description: str = ""

    def __post_init__(self) -> None:
        translation = np.asarray(self.translation_world, dtype=float).reshape(-1)
        if translation.shape != (3,) or not np.all(np.isfinite(translation)):
            raise TransformError("<transform>", f"{self.name}.translation_world", f"{translation.tolist()!r:.80}",
                                 "three finite numbers [m]")
        object.__setattr__(self, "translation_world", readonly(translation, shape=(3,)))
        quat = np.asarray(self.quat_wxyz, dtype=float).reshape(-1)
        norm = float(np.linalg.norm(quat)) if quat.shape == (4,) and np.all(np.isfinite(quat)) else 0.0
        if norm == 0.0:
            raise TransformError("<transform>", f"{self.name}.quat_wxyz", f"{quat.tolist()!r:.80}",
                                 "a finite non-zero quaternion (w, x, y, z)")
        object.__setattr__(self, "quat_wxyz", readonly(quat / norm, shape=(4,)))
        for key in ("length_scale", "mass_scale", "time_scale"):
            value = getattr(self, key)
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not (number and math.isfinite(value) and value > 0):
                raise TransformError("<transform>", f"{self.name}.{key}", f"{value!r:.60}", "a finite number > 0")
            object.__setattr__(self, key, float(value))
        if self.body_order is not None:
            object.__setattr__(self, "body_order", tuple(int(i) for i in self.body_order))

    @classmethod
    def from_rotation_matrix(cls, name: str, rotation_matrix, **fields) -> "Transform":
        """A transform whose rotation R is given as a (3, 3) proper rotation matrix."""
        matrix = np.asarray(rotation_matrix, dtype=float)
        if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)) or np.linalg.det(matrix) <= 0:
            raise TransformError("<transform>", f"{name}.rotation_matrix", "not a finite (3, 3) proper rotation",
                                 "a rotation matrix, det > 0")
        return cls(name, quat_wxyz=matrix_to_quat_wxyz(matrix), **fields)

    @property
    def rotation_matrix(self) -> np.ndarray:
        """(3, 3) R."""
        return quat_wxyz_to_matrix(self.quat_wxyz)

    @property
    def moves_frame(self) -> bool:
        """True when the transform rotates, translates or rescales lengths (what a chain can feel)."""
        return (bool(np.any(self.translation_world)) or not np.array_equal(self.quat_wxyz, IDENTITY_QUAT)
                or self.length_scale != 1.0)

    def factor(self, length: int = 0, mass: int = 0, time: int = 0) -> float:
        """L^length M^mass T^time."""
        return self.length_scale ** length * self.mass_scale ** mass * self.time_scale ** time

    def order_for(self, n_bodies: int) -> tuple[int, ...]:
        """The new order of ``n_bodies`` bodies: new body i is old body ``order[i]``."""
        if self.body_order is not None:
            if sorted(self.body_order) != list(range(n_bodies)):
                raise TransformError("<transform>", f"{self.name}.body_order", f"{list(self.body_order)!r:.80} is "
                                     f"not an order of the scene's {n_bodies} bodies",
                                     f"a permutation of 0..{n_bodies - 1}")
            return self.body_order
        if self.shuffle_seed is None or n_bodies < 2:
            return tuple(range(n_bodies))
        order = np.random.default_rng(self.shuffle_seed).permutation(n_bodies)
        if np.array_equal(order, np.arange(n_bodies)):
            order = np.roll(order, 1)  # a shuffle that left everything in place would test nothing
        return tuple(int(i) for i in order)

    def changes(self, scene) -> bool:
        """True when the transform changes anything of ``scene`` (a chain feels only frame and length; one
        body has no other order)."""
        if isinstance(scene, (JointDynamicsScene, JointMotionScene)):  # mass, time and gravity: every scale is felt
            return self.moves_frame or self.mass_scale != 1.0 or self.time_scale != 1.0
        if not isinstance(scene, DynamicsScene):
            return self.moves_frame
        reordered = self.order_for(len(scene.bodies)) != tuple(range(len(scene.bodies)))
        return self.moves_frame or reordered or self.mass_scale != 1.0 or self.time_scale != 1.0

    def point(self, position_world: np.ndarray) -> np.ndarray:
        """x' = L R x + t of points (..., 3) [m]."""
        return self.length_scale * (np.asarray(position_world, dtype=float) @ self.rotation_matrix.T) \
            + self.translation_world

    def vector(self, vector_world: np.ndarray, length: int = 0, mass: int = 0, time: int = 0) -> np.ndarray:
        """R v scaled by L^length M^mass T^time, for world vectors (..., 3) of that dimension."""
        return self.factor(length, mass, time) * (np.asarray(vector_world, dtype=float) @ self.rotation_matrix.T)

    def to_scene_units(self, value: float, unit: str) -> float:
        """A result of the transformed scene, in ``unit``, carried back to the scene's own units.

        Raises
        ------
        UnitError
            When ``unit`` is unknown or mixes dimensions this transform scales differently.
        """
        return value / unit_factor(unit, self.length_scale, self.mass_scale, self.time_scale)

    def then(self, other: "Transform") -> "Transform":
        """This transform followed by ``other`` (which must keep the body order): x -> L2 R2 (L1 R1 x + t1) + t2."""
        if other.body_order is not None or other.shuffle_seed is not None:
            raise TransformError("<transform>", f"{other.name}.body_order", "a second transform that reorders bodies",
                                 "a transform that keeps the order after another")
        return Transform(f"{self.name}+{other.name}", translation_world=other.point(self.translation_world),
                         quat_wxyz=quat_wxyz_multiply(other.quat_wxyz, self.quat_wxyz), body_order=self.body_order,
                         shuffle_seed=self.shuffle_seed, length_scale=self.length_scale * other.length_scale,
                         mass_scale=self.mass_scale * other.mass_scale, time_scale=self.time_scale * other.time_scale,
                         description=f"{self.text()} then {other.text()}")

    def text(self) -> str:
        """The transform in words, for result details."""
        return f"{self.name} ({self.description})" if self.description else self.name


def transform_scene(scene, transform: Transform):
    """``scene`` written in ``transform``'s frame, body order and units (module docstring); same name.

    Raises
    ------
    TransformError
        When the scene cannot express the transformed physics (a URDF chain's base or lengths).
    """
    if isinstance(scene, DynamicsScene):
        return _dynamics(scene, transform)
    if isinstance(scene, (KinematicsScene, IKScene)):
        return _chain_scene(scene, transform)
    if isinstance(scene, JointDynamicsScene):
        return _joint_dynamics_scene(scene, transform)
    if isinstance(scene, JointMotionScene):
        return _joint_motion_scene(scene, transform)
    raise TransformError(getattr(scene, "source", "<code>"), "kind", f"a {type(scene).__name__} has no transform",
                         "dynamics, kinematics, IK, joint-dynamics and joint-motion scenes")


def _body(body: RigidBody, t: Transform) -> RigidBody:
    rotation_quat = quat_wxyz_multiply(t.quat_wxyz, body.quat_wxyz)
    points = body.point_masses
    if points is not None:  # body axes: scaled, not turned; the frame the points were given in placed
        given, frame = points.positions_given, points.frame_position_world
        points = PointMasses(t.mass_scale * points.masses, t.length_scale * points.points_body,
                             t.length_scale * points.center_of_mass_given,
                             None if given is None else t.length_scale * given, None if frame is None else t.point(frame))
    return replace(body, mass=t.mass_scale * body.mass, inertia_body=t.factor(length=2, mass=1) * body.inertia_body,
                   position_world=t.point(body.position_world), quat_wxyz=rotation_quat,
                   velocity_world=t.vector(body.velocity_world, length=1, time=-1),
                   angular_velocity_world=t.vector(body.angular_velocity_world, time=-1), point_masses=points)


def _per_body(values: np.ndarray | None, order: tuple[int, ...], scale: float) -> np.ndarray | None:
    return None if values is None else scale * np.asarray(values)[list(order)]


def _forces(forces: Forces, t: Transform, order: tuple[int, ...]) -> Forces:
    new_index = {old: new for new, old in enumerate(order)}
    gravity, air = forces.gravity_world, forces.air_velocity_world
    return Forces(
        gravity_world=None if gravity is None else t.vector(gravity, length=1, time=-2),
        air_velocity_world=None if air is None else t.vector(air, length=1, time=-1),
        linear_drag=_per_body(forces.linear_drag, order, t.factor(mass=1, time=-1)),  # N s/m = kg/s
        quadratic_drag=_per_body(forces.quadratic_drag, order, t.factor(length=-1, mass=1)),  # N s^2/m^2 = kg/m
        angular_linear_drag=_per_body(forces.angular_linear_drag, order, t.factor(length=2, mass=1, time=-1)),
        angular_quadratic_drag=_per_body(forces.angular_quadratic_drag, order, t.factor(length=2, mass=1)),
        applied=tuple(AppliedForce(new_index[a.body], t.vector(a.force_world, length=1, mass=1, time=-2),
                                   t.length_scale * a.point_body) for a in forces.applied),
        timed=tuple(_timed_load(load, t, new_index) for load in forces.timed),
    )


def _time_function(function: TimeFunction, t: Transform, scale, turned: bool) -> TimeFunction:
    """``function`` in the transform's time unit, its values times ``scale`` (a number, or one per component) and
    turned by R when ``turned`` (world axes): f'(t') = scale R f(t' / T) (module docstring)."""
    def values(rows: np.ndarray) -> np.ndarray:
        scaled = scale * np.asarray(rows, dtype=float)
        return t.vector(scaled) if turned else scaled

    if isinstance(function, HeldFunction):
        return HeldFunction(values(function.samples), t.time_scale * function.period_s, t.time_scale * function.phase_s)
    powers = t.time_scale ** -np.arange(len(function.polynomial), dtype=float)
    return SmoothFunction(powers[:, None] * values(function.polynomial) if len(function.polynomial)
                          else function.polynomial,
                          tuple(Sinusoid(values(s.amplitude), s.frequency_hz / t.time_scale, s.phase_rad)
                                for s in function.sinusoids))


def _timed_load(load: TimedLoad, t: Transform, new_index: dict[int, int]) -> TimedLoad:
    """A body's timed load: a force of N = kg m / s^2, a torque of N m; world axes turned, body axes not."""
    turned = load.frame == WORLD
    force, torque = load.force, load.torque
    return TimedLoad(new_index[load.body], load.frame, t.length_scale * load.point_body,
                     None if force is None else _time_function(force, t, t.factor(length=1, mass=1, time=-2), turned),
                     None if torque is None else _time_function(torque, t, t.factor(length=2, mass=1, time=-2),
                                                                turned))


def _plane(plane: Plane, t: Transform) -> Plane:
    """N . x + d = 0 becomes N' . x' + d' = 0 with N' = R N, d' = L d - N' . t."""
    normal = t.vector(plane.normal_world)
    return Plane(normal, t.length_scale * plane.offset - float(normal @ t.translation_world), plane.name)


def _shape(shape: Shape, t: Transform) -> Shape:
    length = t.length_scale  # body axes: scaled, not turned
    return Shape(shape.kind, length * shape.radius, length * shape.half_extents_body, length * shape.center_body,
                 length * shape.points_body)


def _contact(contact: Contact, t: Transform, order: tuple[int, ...]) -> Contact:
    damping = contact.penalty_damping
    return replace(contact, planes=tuple(_plane(p, t) for p in contact.planes),
                   shapes=tuple(_shape(contact.shapes[i], t) for i in order),
                   materials=tuple(contact.materials[i] for i in order),
                   rest_speed=t.factor(length=1, time=-1) * contact.rest_speed,
                   penalty_stiffness=t.factor(mass=1, time=-2) * contact.penalty_stiffness,  # N/m = kg/s^2
                   penalty_damping=None if damping is None else t.factor(mass=1, time=-1) * damping)


def _dynamics(scene: DynamicsScene, t: Transform) -> DynamicsScene:
    order = t.order_for(len(scene.bodies))
    return replace(scene, bodies=tuple(_body(scene.bodies[i], t) for i in order),
                   forces=_forces(scene.forces, t, order), duration=t.time_scale * scene.duration,
                   dts=tuple(t.time_scale * dt for dt in scene.dts),
                   contact=None if scene.contact is None else _contact(scene.contact, t, order))


def _joint(joint: Joint, t: Transform, first: bool) -> Joint:
    """A joint with its lengths (and its link's mass properties, damping and armature) scaled; the first also placed
    by R and t (its origin is in the world)."""
    length = t.length_scale
    prismatic = length if joint.type == "prismatic" else 1.0
    origin = t.point(joint.origin_xyz) if first else length * joint.origin_xyz
    rotation = t.rotation_matrix @ joint.origin_rotation if first else joint.origin_rotation
    rpy = joint.origin_rpy  # as a file in the transformed frame would write it (SciPy's, as the references read it)
    if first and rpy is not None:
        rpy = matrix_to_rpy(t.rotation_matrix @ rpy_to_matrix(rpy))
    link = joint.link
    if link is not None:  # link axes: scaled, not turned (the rotation is the first joint's placement)
        link = LinkInertia(t.mass_scale * link.mass, length * link.com_xyz, t.factor(length=2, mass=1) * link.inertia_com)
    # damping N m s/rad = kg m^2/s or N s/m = kg/s; armature kg m^2 or kg
    per_rad = 0 if joint.type == "prismatic" else 2
    return replace(joint, origin_xyz=origin, origin_rotation=rotation, origin_rpy=rpy, lower=prismatic * joint.lower,
                   upper=prismatic * joint.upper, link=link,
                   damping=t.factor(length=per_rad, mass=1, time=-1) * joint.damping,
                   armature=t.factor(length=per_rad, mass=1) * joint.armature)


def _chain(chain: Chain, t: Transform, source: str, base_in_state: bool = False) -> Chain:
    if chain.robot_file is not None:
        what = ("which every engine loads itself: the scene cannot scale its lengths (or masses); its floating base "
                "moves with the state under a rotation or translation" if base_in_state and chain.floating_base else
                "which every engine loads itself with its base link as the world: the scene cannot move its base or "
                "scale its lengths (or masses)")
        raise TransformError(source, f"transform {t.name}", f"chain {one_line(chain.name)} is read from the "
                             f"{'URDF' if chain.urdf_path is not None else 'MJCF'} file "
                             f"{one_line(chain.robot_file)}, {what}",
                             "a chain written in the scene file (joints or dh), or the transform applied to the URDF "
                             "file itself")
    free_slides = [j.name for j in chain.joints if j.type == "prismatic" and not j.limited]
    if free_slides and t.length_scale != 1.0:
        raise TransformError(source, f"transform {t.name}", f"prismatic joint {one_line(free_slides[0])} has no "
                             "limits: its configurations are sampled in [-1, 1] m whatever the unit of length "
                             "(core.scene.sample_configurations), so a length scale changes which configurations "
                             "are drawn", "limits on every prismatic joint, or no length scale")
    joints = tuple(_joint(j, t, k == 0) for k, j in enumerate(chain.joints))
    return replace(chain, joints=joints, end_effector_xyz=t.length_scale * chain.end_effector_xyz,
                   dh=None if chain.dh is None else _dh(chain.dh, t))


def _dh(table: DHTable, t: Transform) -> DHTable:
    """A DH table with its lengths scaled and its base placed by R and t (the first joint's placement)."""
    return replace(table, a=t.length_scale * table.a, d=t.length_scale * table.d, base_xyz=t.point(table.base_xyz),
                   base_rotation=t.rotation_matrix @ table.base_rotation)


def _chain_scene(scene: KinematicsScene | IKScene, t: Transform):
    if not t.moves_frame:
        return scene  # no mass, no time and no free bodies in a chain: nothing else to change
    chain = _chain(scene.chain, t, scene.source)
    if isinstance(scene, KinematicsScene):
        return replace(scene, chain=chain)
    prismatic = np.array([t.length_scale if j.type == "prismatic" else 1.0 for j in scene.chain.joints])
    return replace(scene, chain=chain, q_start=prismatic * scene.q_start,
                   position_tolerance=t.length_scale * scene.position_tolerance)


def _timed_chain(chain: Chain, t: Transform, source: str, base_in_state: bool = False) -> Chain:
    """A chain with mass and time: placed and scaled (:func:`_chain`); under a change of the unit of time alone, only
    its joints' damping (N m s/rad: per second) changes, and a URDF chain keeps its file (the engines take damping
    from the chain, never from the file's ``<dynamics>``). With ``base_in_state`` (a floating base, which the scene's
    state places in the world) a rotation or translation moves the state, not the chain: its file is kept then too."""
    rigid_move = base_in_state and chain.floating_base and t.length_scale == 1.0
    if (t.moves_frame and not rigid_move) or t.mass_scale != 1.0:
        return _chain(chain, t, source, base_in_state)
    return replace(chain, joints=tuple(replace(j, damping=j.damping / t.time_scale) for j in chain.joints))


def _joint_dynamics_scene(scene: JointDynamicsScene, t: Transform) -> JointDynamicsScene:
    """The chain placed, scaled and given mass and time units; gravity turned and scaled; each joint's sampling scales
    in the new units (a prismatic joint's variable is a length, a revolute one's an angle), so that the same seeded
    draws are the same states."""
    chain = _timed_chain(scene.chain, t, scene.source)
    variable = scene.chain.length_powers  # power of length: m or rad
    gravity = scene.gravity_world
    return replace(scene, chain=chain, gravity_world=None if gravity is None else t.vector(gravity, length=1, time=-2),
                   velocity_scale=t.length_scale ** variable / t.time_scale * scene.velocity_scale,
                   acceleration_scale=t.length_scale ** variable / t.time_scale ** 2 * scene.acceleration_scale,
                   torque_scale=t.length_scale ** (2 - variable) * t.factor(mass=1, time=-2) * scene.torque_scale)


def _joint_motion_scene(scene: JointMotionScene, t: Transform) -> JointMotionScene:
    """The chain placed, scaled and given mass and time units as a joint-dynamics scene's (a floating base's robot
    file kept under a rotation or translation: the base is placed by the state); gravity turned and scaled; the
    initial joint values, velocities and torques (the timed one's time too), a floating base's pose and velocity
    placed, turned and scaled, the duration and the time steps in the new units."""
    chain = _timed_chain(scene.chain, t, scene.source, base_in_state=True)
    variable = scene.chain.length_powers[scene.chain.base_dofs:]  # the joints' power of length: m or rad
    gravity, timed = scene.gravity_world, scene.timed_torque
    torque_scale = t.length_scale ** (2 - variable) * t.factor(mass=1, time=-2)
    q0 = t.length_scale ** scene.chain.configuration_length_powers * scene.q0
    qdot0 = t.length_scale ** scene.chain.length_powers / t.time_scale * scene.qdot0
    if scene.chain.floating_base:  # the base's pose and velocity are the world's: placed and turned
        q0[:, :3], q0[:, 3:7] = t.point(scene.q0[:, :3]), quat_wxyz_multiply(t.quat_wxyz, scene.q0[:, 3:7])
        qdot0[:, :3] = t.vector(scene.qdot0[:, :3], length=1, time=-1)
        qdot0[:, 3:6] = t.vector(scene.qdot0[:, 3:6], time=-1)
    return replace(scene, chain=chain, gravity_world=None if gravity is None else t.vector(gravity, length=1, time=-2),
                   contact=None if scene.contact is None else _chain_contact(scene, scene.contact, t),
                   q0=q0, qdot0=qdot0,
                   torque=torque_scale * scene.torque,
                   timed_torque=None if timed is None else _time_function(timed, t, torque_scale, turned=False),
                   duration=t.time_scale * scene.duration, dts=tuple(t.time_scale * dt for dt in scene.dts))


def _chain_contact(scene: JointMotionScene, contact: ChainContact, t: Transform) -> ChainContact:
    """The plane moved with the world; each sphere scaled in its link's frame (the frames move with the chain), one on
    a fixed base's link placed as a world point (that frame is the world's); core's penalty constants in the new
    units (N/m = kg/s^2, N s/m = kg/s) and its friction's regularisation speed; the time from which the robot rests in
    the new unit of time, a rigid contact's rest speed in the new units (its restitution and the friction have none)."""
    names = tuple(j.name for j in scene.chain.joints)
    chain = scene.chain

    def centre(sphere: ContactSphere) -> np.ndarray:
        on_base = frame_index(sphere.frame, names, chain.end_effector_name, chain.base_link) < 0
        return t.point(sphere.centre_xyz) if on_base and not chain.floating_base else t.length_scale * sphere.centre_xyz
    return replace(contact, plane=_plane(contact.plane, t),
                   spheres=tuple(replace(s, centre_xyz=centre(s), radius=t.length_scale * s.radius)
                                 for s in contact.spheres),
                   penalty_stiffness=_scaled(t.factor(mass=1, time=-2), contact.penalty_stiffness),
                   penalty_damping=_scaled(t.factor(mass=1, time=-1), contact.penalty_damping),
                   rest_after=_scaled(t.factor(time=1), contact.rest_after),
                   rest_speed=t.factor(length=1, time=-1) * contact.rest_speed,
                   friction_speed=t.factor(length=1, time=-1) * contact.friction_speed)


def _scaled(factor: float, value: float | None) -> float | None:
    """``factor`` times ``value``, None for a value the scene does not give."""
    return None if value is None else factor * value


FIXED_SEED = 22
"""Seed of the fixed transforms (issue #22): the same rotation, translation and body order on every run."""

FAR_DISTANCE = 2000.0
"""[m] How far :data:`FIXED_TRANSFORMS`' translation moves a scene: 2 km, where a float64 position carries
~4.5e-13 m of rounding (2000 x eps) instead of ~2e-16 m at 1 m: absolute thresholds near the rounding floor
(touch gaps, rest tests, rounding floors) show."""

RESCALE = (3.7, 0.3, 1.9)
"""(L, M, T) of the fixed rescale: none a power of two (which would scale every float exactly and hide
rounding), lengths and times up, masses down."""

MILLISECONDS = 1000.0
"""T of the fixed change of the time unit to milliseconds: g = 9.81e-6 m/ms^2, dt = 10 ms."""


def _fixed() -> tuple[Transform, ...]:
    rng = np.random.default_rng(FIXED_SEED)
    direction = rng.normal(size=3)
    rotation = Rotation.random(random_state=rng).as_quat(scalar_first=True)
    length, mass, time = RESCALE
    return (
        Transform("translate", translation_world=FAR_DISTANCE * direction / np.linalg.norm(direction),
                  description=f"moved {FAR_DISTANCE:g} m from the origin"),
        Transform("rotate", quat_wxyz=rotation,
                  description=f"turned by {float(Rotation.from_quat(rotation, scalar_first=True).magnitude()):.4g} "
                              "rad with gravity"),
        Transform("permute", shuffle_seed=FIXED_SEED, description="bodies listed in another order"),
        Transform("rescale", length_scale=length, mass_scale=mass, time_scale=time,
                  description=f"units: L x {length:g}, M x {mass:g}, T x {time:g}"),
        Transform("ms", time_scale=MILLISECONDS, description="time in milliseconds"),
    )


FIXED_TRANSFORMS = _fixed()
"""The fixed, seeded transforms every scene is checked under: far from the origin, a random rotation, another
body order, a rescale of L, M and T, and time alone in milliseconds."""

TRANSFORM_NAMES = tuple(t.name for t in FIXED_TRANSFORMS)


def fixed_transforms(names) -> tuple[Transform, ...]:
    """The transforms of :data:`FIXED_TRANSFORMS` called ``names``, in that order; TransformError for another."""
    known = {t.name: t for t in FIXED_TRANSFORMS}
    unknown = [n for n in names if n not in known]
    if unknown or not names:
        raise TransformError("--transform", one_line(", ".join(unknown)) or "(none)",
                             "no such transform" if unknown else "no transform named", ", ".join(TRANSFORM_NAMES))
    return tuple(known[n] for n in dict.fromkeys(names))
