"""One-ulp perturbations of a scene: how far its results move under rounding alone.

A result that moves when a scene moves by one unit in the last place (ulp) carries that much rounding noise:
a chaotic motion (the Dzhanibekov flip), a contact that settles in a soft or penalty contact, an IK solve near
a singular pose amplify it, a closed form does not. ``comparisons.invariance.metamorphic`` takes this spread as the bound
within which a transformed scene's result may differ, and a verdict that flips under it as sitting on its
threshold.

:func:`ulp_perturbed` moves, with seeded signs,

- every component of a dynamics scene's initial state (each body's position, orientation, velocity and
  angular velocity) and of a chain's geometry (every joint origin and the end-effector offset: what the random
  configurations' poses and the IK targets are made of) and an IK scene's start configuration, by one ulp of
  the vector's largest component (so a zero component moves as much as its neighbours; an all-zero vector, a
  body at rest, stays exactly at rest);
- and its units of length, mass and time by one ulp each (:func:`ulp_transform`: factors 1 + 2^-52 or
  1 - 2^-53), which changes the low bits of every operand of every step, as a transform does, and so samples
  the rounding of the whole run: adding the same increments to an initial state shifted by one ulp rounds the
  same way, and a projectile's velocity error is bit-identical under it.

A chain read from a URDF file is loaded from the file by the engines: only its start configuration moves.
The numbers a file gave, from which the references derive what core derived for the state and geometry above (a DH
table's lengths ``a`` and ``d``, the frame a body's point masses were given in), move by one ulp too, with signs from
a stream of their own (:data:`INPUTS_STREAM`), so that a scene without them is perturbed exactly as before.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simparity.comparisons.invariance.transforms import Transform, transform_scene
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene

ULP_FACTORS = (np.nextafter(1.0, 2.0), np.nextafter(1.0, 0.0))
"""The two nearest floats to 1: a unit one ulp longer or shorter."""

UNITS_STREAM = 1
"""Second seed word of the units' signs: drawn independently of the state's (stream 0)."""

INPUTS_STREAM = 2
"""Second seed word of the signs of the numbers as given (:func:`_nudged_inputs`): drawn independently of the
state's, so that a scene without them is perturbed as before."""


def ulp_nudge(values: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``values`` (k,) with each component moved by +-1 ulp of the largest |component| (random signs)."""
    values = np.asarray(values, dtype=float)
    size = float(np.max(np.abs(values), initial=0.0))
    if size == 0.0:
        return values.copy()
    return values + rng.choice((-1.0, 1.0), size=values.shape) * np.spacing(size)


def ulp_transform(seed: int, scene) -> Transform:
    """The one-ulp change of units of perturbation ``seed`` for ``scene`` (a chain from a robot file keeps its lengths and
    masses: every engine reads both from the file, so only the unit of time can change)."""
    length, mass, time = np.random.default_rng([seed, UNITS_STREAM]).choice(ULP_FACTORS, size=3)
    if getattr(getattr(scene, "chain", None), "robot_file", None) is not None:
        length = mass = 1.0
    return Transform(f"ulp-{seed}", length_scale=float(length), mass_scale=float(mass), time_scale=float(time),
                     description="units one ulp off")


def _nudged(scene, rng: np.random.Generator):
    if isinstance(scene, DynamicsScene):
        bodies = tuple(replace(b, position_world=ulp_nudge(b.position_world, rng),
                               quat_wxyz=ulp_nudge(b.quat_wxyz, rng), velocity_world=ulp_nudge(b.velocity_world, rng),
                               angular_velocity_world=ulp_nudge(b.angular_velocity_world, rng))
                       for b in scene.bodies)
        return replace(scene, bodies=bodies)
    chain = scene.chain
    if chain.robot_file is None:
        chain = replace(chain, joints=tuple(replace(j, origin_xyz=ulp_nudge(j.origin_xyz, rng)) for j in chain.joints),
                        end_effector_xyz=ulp_nudge(chain.end_effector_xyz, rng))
    if isinstance(scene, KinematicsScene):
        return replace(scene, chain=chain)
    if isinstance(scene, IKScene):
        return replace(scene, chain=chain, q_start=ulp_nudge(scene.q_start, rng))
    if isinstance(scene, JointDynamicsScene):
        gravity = scene.gravity_world
        return replace(scene, chain=chain, gravity_world=None if gravity is None else ulp_nudge(gravity, rng))
    if isinstance(scene, JointMotionScene):
        gravity = scene.gravity_world
        return replace(scene, chain=chain, gravity_world=None if gravity is None else ulp_nudge(gravity, rng),
                       q0=ulp_nudge(scene.q0, rng), qdot0=ulp_nudge(scene.qdot0, rng))
    raise TypeError(f"no perturbation for a {type(scene).__name__}")


def _nudged_inputs(scene, rng: np.random.Generator):
    """``scene`` with the numbers its file gave, from which core derived what ``_nudged`` moves, moved too: the
    references derive those quantities from these (``references.common.scene_inputs``). A DH table's lengths for
    its joint origins, a point-mass body's frame for its position."""
    if isinstance(scene, DynamicsScene):
        bodies = tuple(b if b.point_masses is None or b.point_masses.frame_position_world is None else
                       replace(b, point_masses=replace(b.point_masses, frame_position_world=ulp_nudge(
                           b.point_masses.frame_position_world, rng))) for b in scene.bodies)
        return replace(scene, bodies=bodies)
    table = scene.chain.dh
    if table is None:
        return scene
    table = replace(table, a=ulp_nudge(table.a, rng), d=ulp_nudge(table.d, rng))
    return replace(scene, chain=replace(scene.chain, dh=table))


def ulp_perturbed(scene, seed: int) -> tuple[object, Transform]:
    """(``scene`` perturbed by one ulp with signs drawn from ``seed`` (module docstring), the change of units its
    results are carried back with); same name."""
    units = ulp_transform(seed, scene)
    nudged = _nudged_inputs(_nudged(scene, np.random.default_rng(seed)), np.random.default_rng([seed, INPUTS_STREAM]))
    return transform_scene(nudged, units), units
