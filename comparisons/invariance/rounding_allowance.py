"""How far rounding alone may move a scene's results: an allowance per unit, from the scene's own scales.

A result at the rounding floor (an exact scheme's error, a solve converged to the last digit) is rounding
noise: another frame or another system of units rounds every operation differently and gives another
sample of that noise, while the initial state perturbed by one ulp does not (adding the same increments to
a shifted value rounds the same way: a projectile's velocity error is bit-identical under a one-ulp change
of its initial state, and six times larger in a rotated frame, both far below its rounding floor). Such
values are compared within the floor the metrics define (``comparisons.measure.metrics.rounding_floors``: 2 eps x
(N + kappa) x the state's scale, N rounded steps, kappa the inertia's condition number), taken here from
the scene's data alone, as upper bounds of its state's scale:

- speed V = max over bodies of |w| + |v(0) - w| + (|g| + sum |f_i| / m) T (drag only slows a body relative
  to the air w), length X = the farthest body's |x(0)| + V T + the farthest plane's |d|;
- spin Omega = (|L(0)| + sum |p_i| |f_i| T) / I_min, with contact also sqrt(m V^2 / I_min) (every joule of
  the body's kinetic energy in its spin, as a plane's impulse can turn it), and at least V / r, r the body's
  radius of gyration sqrt(tr I / 2m): an engine that steps a body's six velocities together (MuJoCo's free
  joint) rounds its linear motion into a spin of that order;
- a chain: X = the distance its first joint lies from the origin plus every joint offset and the end
  effector (its reach bound), N its joints (kinematics) or the solver's iterations (IK); its joint-space dynamics
  (every metric a ratio): N its joints, times X over the chain's own extent (X less its first joint's distance).

A metric of dimension L^a M^b T^c (``comparisons.invariance.units``) then has the allowance FACTOR x eps x (N + kappa) x
its scale: m -> X, m/s -> V, rad/s -> Omega, rad and 1 (both dimensionless) -> 1 + T Omega, s -> T, others
X^a M^b T^c (M the heaviest body). Counts (impacts missed, iterations, solve rates) are integers or fractions
of integers: rounding moves them only across a threshold, which the ulp spread and the status rules judge.

Contact adds the rounding of events: an impact's time is where a point's rounded distance to a plane crosses
zero, so it carries the length allowance over the approach speed, at least the settling speed rest_speed / k
(slower impacts end at rest and are not compared), and every result after it inherits that: a velocity
(1 + k) |g| dt_event, a position V dt_event, a spin that velocity over r, a ratio of speeds that velocity over
the settling speed. Two km from the origin a position carries 2000 x the rounding it carries at 1 m, and the
late, slow bounces of a ball multiply it into its impact times.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.comparisons.invariance.units import Dimension
from simparity.comparisons.measure.load_budget import load_budget
from simparity.comparisons.measure.body_scales import contact_of
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene

ALLOWANCE_FACTOR = 16.0
"""The metrics' rounding floor is 2 eps (N + kappa) x the scale (measured rounding of exact schemes stays below
0.16 of eps (N + kappa) x the scale); a step of RK4 composes four stages and several rotations, each rounding
at eps, and two frames' results differ by both frames' rounding: measured on Pinocchio's RK4 with a force at a
turning point (point-force-torque, rotated), the orientation errors differ by 2 eps (N + kappa) (1 + T Omega).
16 leaves a margin of 8 over that and is still 3.5e-11 relative after 10^4 steps, far below any error a
metric reports."""


@dataclass(frozen=True)
class Floors:
    """What rounding alone may move a scene's quantities by (module docstring).

    Attributes
    ----------
    length [m], speed [m/s], spin [rad/s], angle [rad] (also any ratio), time [s] : float
    generic : float
        The unit roundoff eps x (N + kappa) x FACTOR, for other dimensions times their scale.
    length_scale, mass_scale, time_scale : float
        X [m], the heaviest body [kg], T [s]: the scales of other dimensions.
    """

    length: float
    speed: float
    spin: float
    angle: float
    time: float
    generic: float
    length_scale: float
    mass_scale: float
    time_scale: float

    def of(self, dimension: Dimension) -> float:
        known = {Dimension(length=1): self.length, Dimension(length=1, time=-1): self.speed,
                 Dimension(time=-1): self.spin, Dimension(): self.angle, Dimension(time=1): self.time}
        if dimension in known:
            return known[dimension]
        return self.generic * (self.length_scale ** dimension.length * self.mass_scale ** dimension.mass
                               * self.time_scale ** dimension.time)


def _dynamics_floors(scene: DynamicsScene) -> Floors:
    forces, duration = scene.forces, scene.duration
    gravity = 0.0 if forces.gravity_world is None else float(np.linalg.norm(forces.gravity_world))
    air = np.zeros(3) if forces.air_velocity_world is None else np.asarray(forces.air_velocity_world)
    speeds, spins, radii = [], [], []
    for index, body in enumerate(scene.bodies):
        force, torque = load_budget(scene, index)
        speed = float(np.linalg.norm(air) + np.linalg.norm(body.velocity_world - air)
                      + (gravity + force / body.mass) * duration)
        moment = float(np.linalg.eigvalsh(body.inertia_body)[0])
        momentum = float(np.linalg.norm(body.inertia_body)) * float(np.linalg.norm(body.angular_velocity_world))
        radius = float(np.sqrt(np.trace(body.inertia_body) / (2 * body.mass)))
        spin = max((momentum + torque * duration) / moment, speed / radius)
        if scene.contact is not None:
            spin = max(spin, float(np.sqrt(body.mass * speed * speed / moment)))
        speeds.append(speed)
        spins.append(spin)
        radii.append(radius)
    offsets = [abs(p.offset) for p in scene.contact.planes] if scene.contact is not None else [0.0]
    length = max(float(np.linalg.norm(b.position_world)) for b in scene.bodies) + max(speeds) * duration + max(offsets)
    kappa = max(float(np.linalg.cond(b.inertia_body)) for b in scene.bodies)
    unit = ALLOWANCE_FACTOR * float(np.finfo(float).eps) * (max(scene.n_steps(dt) for dt in scene.dts) + kappa)
    speed, spin = max(speeds), max(spins)
    floors = dict(length=unit * length, speed=unit * speed, spin=unit * spin, angle=unit * (1 + duration * spin),
                  time=unit * duration)
    if scene.contact is not None:
        floors = _with_events(scene, floors, speed, gravity, min(radii))
    return Floors(**floors, generic=unit, length_scale=length, mass_scale=max(b.mass for b in scene.bodies),
                  time_scale=duration)


def _with_events(scene: DynamicsScene, floors: dict, speed: float, gravity: float, radius: float) -> dict:
    """``floors`` with the rounding of contact events added (module docstring)."""
    restitution = float(np.max(contact_of(scene).restitution, initial=0.0))
    settling = contact_of(scene).rest_speed / restitution if restitution > 0 else contact_of(scene).rest_speed
    event = floors["length"] / settling  # [s] an impact's time, found from rounded distances
    kick = (1 + restitution) * gravity * event  # [m/s] what a mis-timed impact leaves in a velocity
    return dict(length=floors["length"] + speed * event, speed=floors["speed"] + kick,
                spin=floors["spin"] + kick / radius, angle=floors["angle"] + 2 * kick / settling,
                time=floors["time"] + event)


def _reach(chain: Chain) -> float:
    """[m] The first joint's distance from the origin plus every later offset and the end effector's (and a
    prismatic joint's largest travel): no frame of the chain is farther from the origin."""
    lengths = [float(np.linalg.norm(j.origin_xyz)) for j in chain.joints]
    lengths.append(float(np.linalg.norm(chain.end_effector_xyz)))
    lengths += [max(abs(j.lower), abs(j.upper)) for j in chain.joints if j.type == "prismatic" and j.limited]
    return sum(lengths)


def _chain_floors(scene: KinematicsScene | IKScene) -> Floors:
    operations = (scene.max_iterations if isinstance(scene, IKScene) else 0) + scene.chain.n_joints
    unit = ALLOWANCE_FACTOR * float(np.finfo(float).eps) * operations
    reach = _reach(scene.chain)
    return Floors(length=unit * reach, speed=0.0, spin=0.0, angle=unit, time=0.0, generic=unit, length_scale=reach,
                  mass_scale=1.0, time_scale=1.0)


def _joint_dynamics_floors(scene: JointDynamicsScene) -> Floors:
    """A chain's joint-space dynamics: every metric is a ratio, rounded like the chain's frames relative to its own
    size: N its joints, times the reach bound over the chain's own extent (a chain placed 2 km away rounds its
    frames at 2000 x eps, its lever arms of ~1 m at eps)."""
    unit = ALLOWANCE_FACTOR * float(np.finfo(float).eps) * scene.chain.n_joints
    reach = _reach(scene.chain)
    size = reach - float(np.linalg.norm(scene.chain.joints[0].origin_xyz))
    ratio = unit * max(1.0, reach / size) if size > 0 else unit
    return Floors(length=unit * reach, speed=0.0, spin=0.0, angle=ratio, time=0.0, generic=ratio, length_scale=reach,
                  mass_scale=1.0, time_scale=1.0)


def _joint_motion_floors(scene: JointMotionScene) -> Floors:
    """A chain's motion: every metric is a ratio; each step rounds the state at eps relative to its size (its joint
    count's operations), and N steps add up (linearly at worst), as for free bodies; with the lever arms' rounding of a
    chain placed far away (:func:`_joint_dynamics_floors`; a floating base's by its initial place, its frames within
    the chain's reach bound of it)."""
    steps = max(scene.n_steps(dt) for dt in scene.dts)
    unit = ALLOWANCE_FACTOR * float(np.finfo(float).eps) * scene.chain.n_joints * steps
    reach = _reach(scene.chain)
    size = reach - float(np.linalg.norm(scene.chain.joints[0].origin_xyz))
    if scene.chain.floating_base:  # the chain's frames lie around its base, which the state places in the world
        size = reach
        reach += float(np.linalg.norm(np.asarray(scene.q0)[:, :3], axis=1).max())
    ratio = unit * max(1.0, reach / size) if size > 0 else unit
    return Floors(length=unit * reach, speed=0.0, spin=0.0, angle=ratio, time=unit * scene.duration, generic=ratio,
                  length_scale=reach, mass_scale=1.0, time_scale=scene.duration)


def rounding_floors(scene) -> Floors:
    """What rounding alone may move ``scene``'s quantities by (module docstring)."""
    if isinstance(scene, DynamicsScene):
        return _dynamics_floors(scene)
    if isinstance(scene, (KinematicsScene, IKScene)):
        return _chain_floors(scene)
    if isinstance(scene, JointDynamicsScene):
        return _joint_dynamics_floors(scene)
    if isinstance(scene, JointMotionScene):
        return _joint_motion_floors(scene)
    raise TypeError(f"no rounding allowance for a {type(scene).__name__}")
