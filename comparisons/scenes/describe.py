"""``simparity show``: a scene as the loader understood it, in SI units and the project's conventions.

It reports what the loader computed (a body built from point masses: its mass, centre of mass and
inertia tensor; planes normalised to unit normals; every body-plane material; a sweep's variant: its
swept values) so a user can check the scene before running it.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.scenes.sweep import value_text
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import BASE_POSITION_RANGE, JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.core.model.scenes.time_functions import HeldFunction, TimeFunction
from simparity.references.common.dynamics_mjcf import mjcf_source
from simparity.references.common.dynamics_urdf import model_changes


def _vector(values) -> str:
    return "[" + ", ".join(f"{v:.10g}" for v in np.ravel(values)) + "]"


def _matrix(values) -> str:
    return "[" + ", ".join(_vector(row) for row in np.asarray(values)) + "]"


def function_text(function: TimeFunction, unit: str) -> str:
    """A time function in words and SI numbers: ``smooth: sum_k c_k t^k ... + sinusoids`` or ``held: ...``."""
    if isinstance(function, HeldFunction):
        return (f"held every {function.period_s:.10g} s from {function.phase_s:.10g} s: "
                f"{len(function.samples)} samples {_matrix(function.samples[:4])}"
                + (" ..." if len(function.samples) > 4 else "") + f" {unit} (0 before the first)")
    terms = [f"{_vector(row)} t^{k}" for k, row in enumerate(function.polynomial)]
    terms += [f"{_vector(s.amplitude)} sin(2 pi {s.frequency_hz:.10g} t + {s.phase_rad:.10g})"
              for s in function.sinusoids]
    return "smooth: " + " + ".join(terms) + f" {unit}"


def _body_lines(scene: DynamicsScene) -> list[str]:
    lines = []
    for k, body in enumerate(scene.bodies):
        lines.append(f"body {body.name}: mass {body.mass:.10g} kg, COM {_vector(body.position_world)} m, "
                     f"quat_wxyz {_vector(body.quat_wxyz)}, velocity_world {_vector(body.velocity_world)} m/s, "
                     f"angular_velocity_world {_vector(body.angular_velocity_world)} rad/s")
        lines.append(f"  inertia_body about the COM {_matrix(body.inertia_body)} kg m^2")
        for load in (load for load in scene.forces.timed if load.body == k):
            lines.append(f"  load in {load.frame} axes at {_vector(load.point_body)} m"
                         + (f"; force {function_text(load.force, 'N')}" if load.force is not None else "")
                         + (f"; torque {function_text(load.torque, 'N m')}" if load.torque is not None else ""))
        points = body.point_masses
        if points is not None:
            lines.append(f"  computed from {len(points.masses)} point masses: M = sum m_i = {body.mass:.10g} kg; "
                         f"COM = sum m_i q_i / M = {_vector(points.center_of_mass_given)} m in the frame the points "
                         "are given in; I = sum m_i (|r_i|^2 E - r_i r_i^T) about the COM, off-diagonal entries "
                         "-sum m x y (the physical sign; the lecture's table prints them without the minus)")
        if scene.contact is not None:
            shape = scene.contact.shapes[k]
            size = {"sphere": f" radius {shape.radius:.10g} m",
                    "box": f" half_extents {_vector(shape.half_extents_body)} m at {_vector(shape.center_body)} m",
                    "points": f" {len(shape.points_body)} points"}.get(shape.kind, "")
            lines.append(f"  shape {shape.kind}{size}")
    return lines


def _contact_lines(scene: DynamicsScene) -> list[str]:
    contact = scene.contact
    if contact is None:
        return ["contact: none (no engine is given any)"]
    lines = [f"contact: methods {', '.join(contact.methods)}; rest_speed {contact.rest_speed:.10g} m/s; penalty "
             f"stiffness {contact.penalty_stiffness:.10g} N/m, damping "
             + (f"{contact.penalty_damping:.10g} N s/m" if contact.penalty_damping is not None else
                "from each pair's restitution (linear spring-damper)")]
    for plane in contact.planes:
        lines.append(f"plane {plane.name}: E(p) = N . p + d, N = {_vector(plane.normal_world)}, "
                     f"d = {plane.offset:.10g} m (normalised)")
    for body, row in zip(scene.bodies, contact.materials):
        for plane, material in zip(contact.planes, row):
            lines.append(f"  {body.name} on {plane.name}: restitution {material.restitution:.10g}, friction static "
                         f"{material.friction_static:.10g}, kinetic {material.friction_kinetic:.10g}")
    return lines


def _scales(values) -> str:
    """One number when every joint shares it, else the list."""
    values = list(values)
    return f"{values[0]:.10g}" if len(set(values)) == 1 else _vector(values)


def _joint_dynamics_lines(scene: JointDynamicsScene) -> list[str]:
    gravity = "none" if scene.gravity_world is None else f"{_vector(scene.gravity_world)} m/s^2"
    chain = scene.chain
    frame = "world" if chain.floating_base else "base"
    lines = [f"gravity_world {gravity} (in the {frame} frame); {scene.n_states} states (seed {scene.seed}): q within "
             f"the limits, |qdot| <= {_scales(scene.velocity_scale)}, |qddot| <= {_scales(scene.acceleration_scale)}, "
             f"|tau| <= {_scales(scene.torque_scale)} per component"]
    base = chain.base_inertia
    if chain.floating_base and base is not None:
        lines.append(f"floating base {chain.base_link}: origin uniform in [-{BASE_POSITION_RANGE:g}, "
                     f"{BASE_POSITION_RANGE:g}]^3 m, orientation uniform; its velocity (linear, angular), acceleration "
                     f"and wrench (force, torque about its origin) in world axes first in qdot, qddot and tau; mass "
                     f"{base.mass:.10g} kg, centre of mass {_vector(base.com_xyz)} m, inertia diagonal "
                     f"{_vector(np.diag(base.inertia_com))} kg m^2 (everything welded to it and the held branches)")
    return lines + _link_lines(chain)


def _joint_motion_lines(scene: JointMotionScene) -> list[str]:
    gravity = "none" if scene.gravity_world is None else f"{_vector(scene.gravity_world)} m/s^2"
    accuracy = (f"self-consistency over {scene.segments} segments (each engine against itself at a 16 x smaller step)"
                if scene.segments else "truths that need no engine (soft contact)"
                if scene.contact is not None and not scene.contact.rigid
                else "against the reference" + (" and truths that need no engine (rigid contact)"
                                                if scene.contact is not None else ""))
    timed = scene.timed_torque
    chain, base = scene.chain, scene.chain.base_inertia
    frame = "world" if chain.floating_base else "base"
    lines = [f"gravity_world {gravity} (in the {frame} frame); joint torques {_vector(scene.torque)} (constant)"
             + (f" + timed {function_text(timed, 'N m or N')}" if timed is not None else ""),
             f"q0 {_vector(scene.q0[0])}; qdot0 {_vector(scene.qdot0[0])}"
             + (f" ({scene.copies} copies)" if scene.copies > 1 else ""),
             f"duration {scene.duration:.10g} s; dt {', '.join(f'{dt:.10g}' for dt in scene.dts)} s; accuracy {accuracy}"]
    if chain.floating_base and base is not None:
        lines.append(f"floating base {chain.base_link}: q0 starts with its origin [m] and quat_wxyz, qdot0 with its "
                     f"origin's velocity and its angular velocity in world axes; no force on it; mass "
                     f"{base.mass:.10g} kg, centre of mass {_vector(base.com_xyz)} m, inertia diagonal "
                     f"{_vector(np.diag(base.inertia_com))} kg m^2 (everything welded to it and the held branches)")
    contact = scene.contact
    if contact is not None:
        lines.append(f"contact: plane {contact.plane.name} (normal {_vector(contact.plane.normal_world)}, offset "
                     f"{contact.plane.offset:.10g} m), frictionless; spheres "
                     + "; ".join(f"{s.frame} at {_vector(s.centre_xyz)} m, radius {s.radius:.10g} m"
                                 for s in contact.spheres)
                     + "; " + _chain_contact_model(contact) + ("" if contact.rest_after is None else
                                  f"at rest from {contact.rest_after:.10g} s (rest_acceleration_max); ")
                     + ("against the reference's closed form where it has one" if contact.rigid else
                        "no reference: each engine against truths that need no engine"))
    return lines + _link_lines(chain)


def _chain_contact_model(contact: ChainContact) -> str:
    """How hard a chain's contact is, as the scene says: core's penalty constants, or rigid with a restitution."""
    if contact.rigid:
        return (f"rigid: restitution {contact.restitution:.10g}, plastic below {contact.rest_speed:.10g} m/s "
                "(core's impulses, time backed up); ")
    return f"core's penalty k_s {contact.penalty_stiffness:.10g} N/m, k_d {contact.penalty_damping:.10g} N s/m; "


def _link_lines(chain: Chain) -> list[str]:
    """Each joint's link: mass, centre of mass, inertia diagonal, damping and armature; what every engine's model of
    the chain's URDF file changes, link by link (:func:`references.common.dynamics_urdf.model_changes`)."""
    lines = []
    for joint in chain.joints:
        link = joint.link
        assert link is not None  # a joint-dynamics scene's chain has mass properties (checked when built)
        lines.append(f"  {joint.name} ({joint.type}): link mass {link.mass:.10g} kg, centre of mass "
                     f"{_vector(link.com_xyz)} m, inertia diagonal {_vector(link.inertia_com.diagonal())} kg m^2, "
                     f"damping {joint.damping:.10g}, armature {joint.armature:.10g}")
    if chain.mjcf_path is not None:
        return lines + [f"every engine reads {mjcf_source(chain)}"]
    changes = model_changes(chain).sentences(str(chain.base_link))
    if chain.urdf_path is not None:
        lines.append(f"every engine reads {chain.urdf_path} below {chain.base_link} without geometry and <dynamics>"
                     + (", and:" if changes else ", nothing else changed"))
    return lines + [f"  {sentence}" for sentence in changes]


def describe(scene) -> str:
    """The text ``simparity show`` prints for ``scene``."""
    head = [f"scene {scene.name} ({scene.kind}), reference {scene.reference}, suites {', '.join(scene.suites)}",
            f"from {scene.source}"]
    if scene.sweep is not None:
        values = ", ".join(f"{key} = {value_text(value)}" for key, value in scene.sweep.values)
        head.append(f"variant {scene.sweep.index + 1} of {scene.sweep.count} of the sweep of {scene.sweep.base}: "
                    f"{values} (as written in the file)")
    if isinstance(scene, DynamicsScene):
        forces = scene.forces
        gravity = "none" if forces.gravity_world is None else f"{_vector(forces.gravity_world)} m/s^2"
        head += [f"gravity_world {gravity}; forces {', '.join(forces.names()) or 'none'}",
                 f"duration {scene.duration:.10g} s; dt {', '.join(f'{dt:.10g}' for dt in scene.dts)} s"]
        head += _body_lines(scene) + _contact_lines(scene)
    elif isinstance(scene, (KinematicsScene, IKScene, JointDynamicsScene, JointMotionScene)):
        chain = scene.chain
        head.append(f"chain {chain.name}: {chain.n_joints} joints ({', '.join(j.name for j in chain.joints)}), "
                    f"end effector {chain.end_effector_name}")
    if isinstance(scene, JointDynamicsScene):
        head += _joint_dynamics_lines(scene)
    if isinstance(scene, JointMotionScene):
        head += _joint_motion_lines(scene)
    return "\n".join(head) + "\n"
