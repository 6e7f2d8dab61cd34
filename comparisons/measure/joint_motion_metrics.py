"""Metrics of a chain's motion through time (:class:`JointMotionScene`): joint and end-effector errors against the
reference, the energy balance of each engine's own motion, divergence. Definitions with their reasons:
``docs/metrics.md``.

Every error is unitless, so a verdict does not depend on units, on where the world's origin is or on how the
chain is turned: a revolute joint's angle error is in radians, a prismatic joint's offset relative to the chain's
reach (:func:`joint_scales`); joint velocities relative to the fastest joint speed of the reference's motion; the
end effector relative to the reach; energies relative to the energy the chain exchanges (its kinetic energy plus
the range of its potential energy: not |E|, which depends on where the origin is).

Energies come from each engine's own model (:meth:`JointSimulation.energy`); nothing here is in-house code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_simpson

from simparity.comparisons.measure.step_jacobian_metrics import STEP_JACOBIAN_METRICS
from simparity.comparisons.measure.divergence import CONSERVED_GROWTH_LIMIT
from simparity.comparisons.measure.metrics import (
    ROUNDING_FLOOR_FACTOR, SATURATED_DRIFT, SATURATED_FRACTION, SATURATED_ORIENTATION,
)
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.engine import JointSimulation
from simparity.core.model.metric_catalogue import (
    CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX, CONTACT_CENTRE_ERROR, CONTACT_ENERGY_GAIN_MAX, CONTACT_PENETRATION_MAX,
    END_EFFECTOR_ERROR_MAX,
    FRICTION_CONE_VIOLATION_MAX, REST_ACCELERATION_MAX, REST_EQUILIBRIUM_ERROR, REST_WEIGHT_ERROR, SIGNORINI_VIOLATION_MAX,
    FRICTION_IMPULSE_ERROR, SLIDING_FRICTION_ANGLE_MAX, SLIDING_FRICTION_ERROR,
    TOUCHDOWN_TIME_ERROR, TOUCHDOWN_TIME_STEPS, ENERGY_DRIFT_MAX, EVALUATIONS_PER_SECOND,
    LINEAR_MOMENTUM_DRIFT_MAX, JOINT_ANGLE_ERROR_MAX, JOINT_VELOCITY_ERROR_MAX,
    ORDER_JOINT_ANGLE, ORDER_JOINT_VELOCITY, POWER_BALANCE_RESIDUAL_MAX, REFERENCE_PARTING_TIME,
    SEGMENT_REFERENCE_ERROR_MAX, SELF_PARTING_TIME,
    TIME_PER_STEP, TIME_PER_STEP_BATCHED, order_source, units,
)
from simparity.core.model.results import NOTHING_TO_MEASURE, ROUNDING_FLOOR, SATURATED
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory
from simparity.references.common import time_loads

JOINT_MOTION_METRICS = units(
    JOINT_ANGLE_ERROR_MAX,
    JOINT_VELOCITY_ERROR_MAX,
    END_EFFECTOR_ERROR_MAX,
    ENERGY_DRIFT_MAX,
    POWER_BALANCE_RESIDUAL_MAX,
    TIME_PER_STEP,
    TIME_PER_STEP_BATCHED,
    EVALUATIONS_PER_SECOND,
)
"""Every metric a joint-motion case may have; :func:`motion_metrics` those of one scene."""
MOMENTUM_METRICS = units(LINEAR_MOMENTUM_DRIFT_MAX, CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX)
"""Of a floating base: its momentum against the laws it obeys under joint forces alone (:func:`momentum_metrics`)."""
CHAIN_CONTACT_METRICS = units(TOUCHDOWN_TIME_ERROR, TOUCHDOWN_TIME_STEPS, CONTACT_CENTRE_ERROR, CONTACT_PENETRATION_MAX,
                              SIGNORINI_VIOLATION_MAX,
                              FRICTION_CONE_VIOLATION_MAX, SLIDING_FRICTION_ERROR, SLIDING_FRICTION_ANGLE_MAX,
                              FRICTION_IMPULSE_ERROR, CONTACT_ENERGY_GAIN_MAX, REST_WEIGHT_ERROR, REST_EQUILIBRIUM_ERROR, REST_ACCELERATION_MAX)
"""Of a scene with contact (in place of its energy drift or power balance): truths that need no engine
(:mod:`comparisons.measure.chain_contact_metrics`)."""
PREDICTABILITY_METRICS = units(SELF_PARTING_TIME, REFERENCE_PARTING_TIME)
"""Of a scene with a perturbation: when each engine's two runs part, and when it parts from the reference."""
JOINT_MOTION_ORDERS = units(ORDER_JOINT_ANGLE, ORDER_JOINT_VELOCITY)
JOINT_ORDER_SOURCES = {order: order_source(order) for order in JOINT_MOTION_ORDERS}
REFERENCE_ERRORS = (JOINT_ANGLE_ERROR_MAX, JOINT_VELOCITY_ERROR_MAX, END_EFFECTOR_ERROR_MAX)
"""The metrics measured against the reference (the others are each engine's own)."""

MAX_ENERGY_SAMPLES = 2001
"""Samples (evenly spaced, the first and last included) at which an engine's energy and end effector are
evaluated: its model is called outside the timed run, and 2,001 samples resolve any drift a scene of up to 10^6
steps shows (drift grows smoothly between samples; a blow-up is caught on the joint states themselves)."""

HORIZON_FLOOR = 1e-6
"""[rad] The reference is trusted while its two tolerances agree to this (the tight solve's own error is then
about a hundredth of it: its tolerance is 100 x tighter). Past the first sample where they differ by more, a
chaotic chain has amplified the reference's own error beyond use (e^(lambda t) 1e-13), and errors are measured
over the horizon before it only."""

PARTING = 1e-3
"""[rad] Two runs have parted when a joint differs by more than this (unitless joint values): a thousandth of a
radian is far above any scheme's rounding and far below the saturation of a lost orbit (Chung and Pollard 2016)."""

REFERENCE_FLOOR_MARGIN = 10.0
"""An error within this factor of the reference's own floor (its two tolerances' difference over the horizon)
is at the reference's floor: flagged, left out of order fits (the floor overestimates the tight solve's error,
so 10 keeps clear of it)."""


def exchanges_energy(scene: JointMotionScene) -> bool:
    """Whether the chain is damped or driven (a constant or a timed torque: its energy changes by the work done on
    it), else conservative."""
    return bool(np.any(np.asarray(scene.torque) != 0) or scene.timed_torque is not None
                or any(j.damping > 0 for j in scene.chain.joints))


def motion_metrics(scene: JointMotionScene) -> dict[str, str]:
    """The metrics of a case of ``scene``: its energy balance as a drift where the chain is conservative, as the
    power balance where it is damped or driven, neither with contact (its energy balance is
    :data:`CHAIN_CONTACT_METRICS`' gain); a floating base's momentum
    (:func:`momentum_metrics`)."""
    left_out = ((ENERGY_DRIFT_MAX, POWER_BALANCE_RESIDUAL_MAX) if scene.contact is not None else
                (ENERGY_DRIFT_MAX,) if exchanges_energy(scene) else (POWER_BALANCE_RESIDUAL_MAX,))
    metrics = {m: u for m, u in JOINT_MOTION_METRICS.items() if m not in left_out} | STEP_JACOBIAN_METRICS
    if scene.chain.floating_base:
        metrics |= MOMENTUM_METRICS
    if scene.contact is not None:
        metrics |= CHAIN_CONTACT_METRICS
    if scene.segments:
        return metrics | units(SEGMENT_REFERENCE_ERROR_MAX)
    return metrics | (PREDICTABILITY_METRICS if scene.perturbation > 0 else {})


def joint_scales(chain: Chain, motion: JointTrajectory) -> np.ndarray:
    """(n,) what one unit of each joint's error is: 1 rad for a revolute joint; for a prismatic one the larger of the
    chain's reach and the joint's own range of motion in ``motion`` (the reference's), so that joint errors are
    unitless, invariant under a change of length unit, and never scaled by joint limits (which do not act)."""
    travel = np.ptp(np.asarray(motion.q)[..., -chain.n_joints:], axis=0).max(axis=0)  # (n,) over samples and copies
    length = reach(chain)
    return np.array([1.0 if j.type == "revolute" else max(length, float(travel[k]), np.finfo(float).tiny)
                     for k, j in enumerate(chain.joints)])


def state_scales(chain: Chain, motion: JointTrajectory) -> tuple[np.ndarray, np.ndarray]:
    """((k,), (k,)) what one unit of each entry of :func:`configuration_gap` and :func:`velocity_gap` is: the joints'
    (:func:`joint_scales`), after a floating base's: its position and linear velocity the larger of the chain's reach
    and the base's travel in ``motion`` (the farthest it gets from where it starts, as a prismatic joint's), its
    orientation and angular velocity 1 (the quaternions' distance is half the angle between them, in radians:
    unitless as a revolute joint's)."""
    joints = joint_scales(chain, motion)
    if not chain.floating_base:
        return joints, joints
    position = np.asarray(motion.q)[..., :3]
    travel = float(np.linalg.norm(position - position[:1], axis=-1).max())
    length = max(reach(chain), travel, np.finfo(float).tiny)
    return np.concatenate([[length, 1.0], joints]), np.concatenate([[length, 1.0], joints])


def configuration_gap(chain: Chain, q: np.ndarray, like: np.ndarray) -> np.ndarray:
    """(..., k) how far configurations q are from ``like`` (..., nq): |q - like| joint by joint, after a floating
    base's two entries, each the same in every frame (a world turned or moved turns or moves both alike): the
    distance between the base positions and between the quaternions, q's taken in ``like``'s hemisphere (q and -q are
    one orientation; an engine that keeps w >= 0 flips the sign wherever w crosses 0), 2 sin(angle / 4) ~ half the
    angle between the orientations. k = nq - 5 for a floating base (7 base entries become 2), else nq."""
    q, like = np.asarray(q, dtype=float), np.asarray(like, dtype=float)
    if not chain.floating_base:
        return np.abs(q - like)
    turned = np.sum(q[..., 3:7] * like[..., 3:7], axis=-1, keepdims=True) < 0
    quat_gap = np.linalg.norm(np.where(turned, -q[..., 3:7], q[..., 3:7]) - like[..., 3:7], axis=-1)
    return np.concatenate([np.linalg.norm(q[..., :3] - like[..., :3], axis=-1)[..., None], quat_gap[..., None],
                           np.abs(q[..., 7:] - like[..., 7:])], axis=-1)


def velocity_gap(chain: Chain, qdot: np.ndarray, like: np.ndarray | float) -> np.ndarray:
    """(..., k) how far velocities qdot are from ``like`` (..., nv, or 0 for qdot's sizes): |qdot - like| joint by
    joint, after a floating base's two entries, the lengths of the linear and of the angular velocity's difference
    (world axes: the same in every frame). k = nv - 4 for a floating base (6 base entries become 2), else nv."""
    gap = np.asarray(qdot, dtype=float) - np.asarray(like, dtype=float)
    if not chain.floating_base:
        return np.abs(gap)
    return np.concatenate([np.linalg.norm(gap[..., :3], axis=-1)[..., None],
                           np.linalg.norm(gap[..., 3:6], axis=-1)[..., None], np.abs(gap[..., 6:])], axis=-1)


def reach(chain: Chain) -> float:
    """[m] The chain's size: the sum of its joint offsets after the first joint and its end-effector offset; at
    least the largest link's centre-of-mass offset and its radius of gyration sqrt(tr I_c / 2m) (a physical size of
    the chain itself, so that a chain whose joints all sit at one point still has one), never 0. Where the first
    joint sits in the base frame is left out (moving the chain's mount, a base 2 km away, changes no distance the
    chain can cover), and so are joint limits (they do not act on the motion)."""
    offsets = sum(float(np.linalg.norm(j.origin_xyz)) for j in chain.joints[1:])
    offsets += float(np.linalg.norm(chain.end_effector_xyz))
    links = [j.link for j in chain.joints if j.link is not None]
    com = max((float(np.linalg.norm(link.com_xyz)) for link in links), default=0.0)
    gyration = max((math.sqrt(max(float(np.trace(link.inertia_com)), 0.0) / (2 * link.mass)) for link in links
                    if link.mass > 0), default=0.0)
    return max(offsets, com, gyration, np.finfo(float).tiny)


ENERGY_SCALE_FLOOR = 1e-9
"""[1] The least energy a chain under gravity is judged to exchange, as a fraction of its weight lifted by its reach
(:func:`energy_floor`): the scale of its energy balance and its energy budget are never below it. A chain resting in
equilibrium exchanges only rounding (its energies are rounded at eps of their size, 2e-16 of that weight's energy
for a mount within a reach), which over the floor stays a rounding-level fraction, never a 100 % drift or a
diverged run; a swing of 1e-4 rad already exchanges 5e-9 of it, so no motion a scene is written to show is
judged against the floor."""


def energy_floor(scene: JointMotionScene) -> float:
    """[J] :data:`ENERGY_SCALE_FLOOR` x the chain's mass x |g| x :func:`reach`; 0 without gravity (a chain at rest
    without gravity has exact energies of 0: nothing to measure)."""
    if scene.gravity_world is None:
        return 0.0
    mass = sum(j.link.mass for j in scene.chain.joints if j.link is not None)
    return ENERGY_SCALE_FLOOR * mass * float(np.linalg.norm(scene.gravity_world)) * reach(scene.chain)


@dataclass(frozen=True)
class OwnReading:
    """What the judge reads of one engine's motion from its own model, at :data:`MAX_ENERGY_SAMPLES` samples.

    Attributes
    ----------
    index : (S,) int ndarray
        The samples of the trajectory read.
    kinetic, potential : (S, B) ndarray
        [J].
    end_effector : (S, B, 3) ndarray
        [m].
    """

    index: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    end_effector: np.ndarray


def sample_index(count: int) -> np.ndarray:
    """(S,) evenly spaced indices of ``count`` samples, the first and the last included."""
    if count <= MAX_ENERGY_SAMPLES:
        return np.arange(count)
    return np.unique(np.linspace(0, count - 1, MAX_ENERGY_SAMPLES).round().astype(int))


def read_own(sim: JointSimulation, traj: JointTrajectory) -> OwnReading:
    """The engine's own energies and end effector along ``traj`` (:class:`OwnReading`)."""
    index = sample_index(len(traj.times))
    samples, copies = len(index), traj.q.shape[1]
    q = np.ascontiguousarray(traj.q[index]).reshape(-1, traj.q.shape[2])
    qdot = np.ascontiguousarray(traj.qdot[index]).reshape(-1, traj.qdot.shape[2])
    kinetic, potential = sim.energy(q, qdot)
    end_effector = np.asarray(sim.end_effector_world(q), dtype=float)
    return OwnReading(index, np.asarray(kinetic, dtype=float).reshape(samples, copies),
                      np.asarray(potential, dtype=float).reshape(samples, copies),
                      end_effector.reshape(samples, copies, 3))


def applied_torque(scene: JointMotionScene, times: np.ndarray) -> np.ndarray:
    """(T, n) [N m or N] the joints' applied forces at ``times`` (T,) [s]: the constant torque and the timed one at
    each time, by the references' evaluation (none of core's code)."""
    torque = np.broadcast_to(np.asarray(scene.torque, dtype=float), (len(times), scene.chain.n_joints))
    if scene.timed_torque is not None:
        torque = torque + np.array([time_loads.at(scene.timed_torque, t) for t in times])
    return torque


def _work(scene: JointMotionScene, traj: JointTrajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(W, W_in, W_floor), each (T, B) [J]: the work done on the chain from t = 0 by the applied forces (the constant
    torque and the timed one at each sample's time) less the damping (the power qdot^T tau - qdot^T D qdot integrated by the composite Simpson rule over every step, fourth
    order), the work the applied forces put in at most (their positive power integrated), and what the quadrature of
    W cannot resolve: |W - W over every other sample| (Simpson's error at twice the step is 16 x its own, so this
    overestimates W's quadrature error some 15 times; 0 between the coarse samples' points, taken as its running
    maximum)."""
    damping = np.array([j.damping for j in scene.chain.joints])
    torque = applied_torque(scene, np.asarray(traj.times, dtype=float))
    rates = traj.qdot[..., scene.chain.base_dofs:]  # the joints' (a floating base takes no applied force)
    drive = np.einsum("tbi,ti->tb", rates, torque)
    power = drive - np.einsum("tbi,i,tbi->tb", rates, damping, rates)
    zero = np.zeros_like(power)
    if len(traj.times) < 3:
        return zero, zero, zero

    def integral(y: np.ndarray, x: np.ndarray) -> np.ndarray:
        return np.concatenate([np.zeros((1, y.shape[1])), cumulative_simpson(y, x=x, axis=0)])
    work = integral(power, traj.times)
    floor = zero
    if len(traj.times) >= 5:
        coarse = integral(power[::2], traj.times[::2])
        gap = np.zeros_like(power)
        gap[::2] = np.abs(work[::2] - coarse)
        floor = np.maximum.accumulate(gap, axis=0)
    return work, integral(np.maximum(drive, 0.0), traj.times), floor


def work_done(scene: JointMotionScene, traj: JointTrajectory) -> np.ndarray:
    """(T, B) [J] the work done on the chain from t = 0 by the applied forces less the damping (:func:`_work`'s W)."""
    return _work(scene, traj)[0]


def energy_budget(scene: JointMotionScene, traj: JointTrajectory, own: OwnReading) -> np.ndarray:
    """(B,) [J] the most kinetic energy the exact motion can have: its initial kinetic energy, the largest drop of
    its potential energy along the run and the work the applied forces put in (damping only takes energy); at least
    :func:`energy_floor`."""
    _, supplied, _ = _work(scene, traj)
    drop = own.potential[0] - own.potential.min(axis=0)
    return np.maximum(own.kinetic[0] + np.maximum(drop, 0.0) + supplied[own.index].max(axis=0), energy_floor(scene))


def divergence(scene: JointMotionScene, traj: JointTrajectory, own: OwnReading | None, saturated: bool = False) -> str:
    """Why ``traj`` counts as diverged ("" when it does not): a non-finite state, a kinetic energy more than
    1 + :data:`CONSERVED_GROWTH_LIMIT` times the budget the scene can supply (:func:`energy_budget`), or, when the
    run's joint values are ``saturated`` (on another orbit), a potential energy beyond what the exact motion can reach by more than
    :data:`UNREACHABLE_CLIMB` of that budget (:func:`climb`): the energy it left its bound by put it on another orbit,
    so the run is diverged, not an error too large to measure, whatever the amplitude at which it went there."""
    if not traj.is_finite():
        return "non-finite joint state"
    if own is None:
        return ""
    budget = energy_budget(scene, traj, own)
    peak = own.kinetic.max(axis=0)
    limit = (1.0 + CONSERVED_GROWTH_LIMIT) * budget
    over = np.flatnonzero(~(peak <= limit))
    if over.size:
        c = int(over[0])
        if not np.isfinite(peak[c]):
            return "kinetic energy overflows (the joint velocities grew past 1e150)"
        return (f"kinetic energy {peak[c]:.3g} J > {1 + CONSERVED_GROWTH_LIMIT:g} x the most the scene can supply "
                f"({budget[c]:.3g} J: initial kinetic energy, potential drop and the applied forces' work)")
    if saturated:
        climbed = climb(scene, traj, own)
        beyond = np.flatnonzero(climbed > UNREACHABLE_CLIMB * budget)
        if beyond.size:
            c = int(beyond[np.argmax(climbed[beyond] / budget[beyond])])
            return (f"its error saturated where its energy cannot take it: its potential energy rose {climbed[c]:.3g} J "
                    f"({climbed[c] / budget[c]:.3g} x the budget {budget[c]:.3g} J; limit {UNREACHABLE_CLIMB:g} x) "
                    "above the most the exact motion can reach (its initial energy and the applied forces' work): "
                    "energy pumped in carried the run to another orbit")
    return ""


UNREACHABLE_CLIMB = 0.05
"""The exact motion's potential energy never exceeds its initial energy plus the work the applied forces put in (its
kinetic energy is never negative). A run whose joint values' error saturated (it is on another orbit: a configuration,
what the potential energy is of) after its potential rose above that by more than this fraction of
:func:`energy_budget` went where the scene's energy cannot take it: energy pumped in carried it there (over the top of
a swing, past a barrier), and it is diverged, not an error too large to measure. Explicit Euler at 0.01-0.04 s on a rod released 2.5 rad from hanging climbs 0.10-0.11 of its budget, over
the top; released 0.3 rad from hanging at 0.02 s its kinetic energy passes twice the budget: both diverged. A run
that lost its orbit by its phase alone (chaos, a long run) does not climb, whatever energy it gains as speed: of the
built-in chains' saturated runs, the midpoint rule's on the double pendulum and every Euler's on the falling Panda
climb 0, MuJoCo's implicit on the double pendulum 0.013-0.026 (it gains 0.14-0.87 of the budget as speed, not
height); those that climb are pumped (explicit Euler at 10 ms on the large-amplitude pendulum 0.061, semi-implicit
Euler at 4 ms on the falling iiwa 0.24, both now diverged). A twentieth lies between."""


def climb(scene: JointMotionScene, traj: JointTrajectory, own: OwnReading) -> np.ndarray:
    """(B,) [J] how far the engine's own potential energy rose above the most the exact motion can reach, max_t (V(t)
    - T(0) - V(0) - W_in(t)) with W_in the work the applied forces put in up to t, at the samples :func:`read_own`
    read (0 when it stayed below)."""
    _, supplied, _ = _work(scene, traj)
    reachable = own.kinetic[0] + own.potential[0] + supplied[own.index]
    return np.maximum((own.potential - reachable).max(axis=0), 0.0)


def _relative(value: float, scale: float, what: str, note: str = "") -> Measured:
    if not scale > 0:
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=(
            f"the engine's own energies show no exchange (kinetic energy and the range of potential energy 0), so "
            f"its {what} has no scale"))
    ratio = value / scale
    if ratio > SATURATED_DRIFT:
        return Measured(ratio, "1", flag=SATURATED, unmeasurable=(
            f"saturated: {what} {ratio:.3g} x the energy the chain exchanges (> {SATURATED_DRIFT:g})"
            + (f"; {note}" if note else "")))
    return Measured(ratio, "1", note=note)


def energy_metrics(scene: JointMotionScene, traj: JointTrajectory, own: OwnReading) -> dict[str, Measured]:
    """``energy_drift_max`` (max_t |E(t) - E(0)|) where the chain is neither damped nor driven, else
    ``power_balance_residual_max`` (max_t |E(t) - E(0) - W(t)|, W the work of the applied forces less the
    damping's), relative to the energy the chain exchanges: its largest kinetic energy plus the range of its
    potential energy, maxima over copies, at least :func:`energy_floor` (the detail says when the floor acts).
    Reference-free."""
    energy = own.kinetic + own.potential
    exchanged, floor_energy = float((own.kinetic.max(axis=0) + np.ptp(own.potential, axis=0)).max()), energy_floor(scene)
    scale = max(exchanged, floor_energy)
    floored = (f"relative to the chain's energy floor {floor_energy:.3g} J ({ENERGY_SCALE_FLOOR:g} x m |g| reach): it "
               f"exchanges only {exchanged:.3g} J" if floor_energy > exchanged else "")
    work, _, quadrature = _work(scene, traj)
    balance = float(np.abs(energy - energy[0] - work[own.index]).max())
    if exchanges_energy(scene):
        measured = _relative(balance, scale, "power-balance residual", floored)
        floor = float(quadrature[own.index].max()) / scale if scale > 0 else 0.0
        if not measured.unmeasurable and balance / scale <= floor:
            measured = Measured(measured.value, "1", flag=ROUNDING_FLOOR, note="; ".join(filter(None, (
                f"at the quadrature floor ({floor:.2g}: the work's integral over the samples resolves no less)",
                floored))))
        return {POWER_BALANCE_RESIDUAL_MAX: measured}
    return {ENERGY_DRIFT_MAX: _relative(float(np.abs(energy - energy[0]).max()), scale, "energy drift", floored)}


def momentum_metrics(scene: JointMotionScene, sim: JointSimulation, traj: JointTrajectory,
                     own: OwnReading) -> dict[str, Measured]:
    """A floating base's momentum from the engine's own model (:meth:`JointSimulation.momentum`: P and the angular
    momentum about the robot's centre of mass) at the samples :func:`read_own` read, against the laws of a robot
    under joint forces alone (internal: they cancel in its momentum, and uniform gravity exerts no moment about the
    centre of mass): ``linear_momentum_drift_max`` max_t |P(t) - P(0) - m g t| (the centre of mass falls as a
    particle, or moves in a straight line without gravity) and ``chain_angular_momentum_drift_max`` max_t |L(t) -
    L(0)|. Relative to the momentum the motion about the centre of mass can carry, sqrt(2 m T_c) (T_c = T - |P|^2 /
    2m, the kinetic energy relative to the centre of mass, the largest over the run and copies: a fall, a uniform
    drift or a long run leave it alone), and that times the chain's reach for L. At most :data:`ROUNDING_FLOOR_FACTOR`
    eps x steps x how far the momentum's size (|P| over that scale) and, for L, the base's distance from the origin
    (over the reach) carry rounding: flagged at the rounding floor. Reference-free."""
    try:
        momentum = np.asarray(sim.momentum(np.ascontiguousarray(traj.q[own.index]).reshape(-1, traj.q.shape[2]),
                                           np.ascontiguousarray(traj.qdot[own.index]).reshape(-1, traj.qdot.shape[2])),
                              dtype=float).reshape(len(own.index), traj.q.shape[1], 6)
    except NotImplementedError as err:
        return {m: Measured(math.nan, "1", unmeasurable=str(err)) for m in MOMENTUM_METRICS}
    if scene.contact is not None and scene.contact.friction > 0:
        why = ("a plane with friction pushes along itself too: no component of the momentum is kept (its forces are "
               "judged by the friction cone and the sliding friction)")
        return {m: Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=why) for m in MOMENTUM_METRICS}
    chain = scene.chain
    assert chain.base_inertia is not None  # a floating chain's dynamics_problem() says so
    mass = chain.mass
    gravity = np.zeros(3) if scene.gravity_world is None else np.asarray(scene.gravity_world, dtype=float)
    linear, angular = momentum[..., :3], momentum[..., 3:]
    expected = linear[0] + mass * gravity * (traj.times[own.index] - traj.times[0])[:, None, None]
    linear_drift, angular_drift = linear - expected, angular - angular[0]
    along = ""
    if scene.contact is not None:  # a frictionless plane pushes along its normal N: only these components are kept
        normal = np.asarray(scene.contact.plane.normal_world)
        linear_drift = linear_drift - (linear_drift @ normal)[..., None] * normal
        angular_drift = (angular_drift @ normal)[..., None]
        along = "the components a frictionless plane leaves alone: P along the plane, L along its normal"
    size = np.linalg.norm(linear, axis=-1)  # (S, B)
    internal = float(np.max(own.kinetic - size**2 / (2.0 * mass)))
    scale = math.sqrt(2.0 * mass * max(internal, 0.0))
    length = reach(chain)
    if not scale > 0:
        why = "the robot does not move about its centre of mass: its momentum laws have no scale"
        return {m: Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=why) for m in MOMENTUM_METRICS}
    carried = max(1.0, float(size.max()) / scale)
    distance = float(np.linalg.norm(traj.q[own.index, :, :3], axis=-1).max())
    unit = ROUNDING_FLOOR_FACTOR * float(np.finfo(float).eps) * max(len(traj.times) - 1, 1)

    def relative(drift: float, size: float, floor: float, what: str) -> Measured:
        ratio = drift / size
        if ratio > SATURATED_DRIFT:
            return Measured(ratio, "1", flag=SATURATED, unmeasurable=(
                f"saturated: the {what} drifts {ratio:.3g} x the momentum the motion can carry "
                f"(> {SATURATED_DRIFT:g})"))
        if ratio <= floor:
            return Measured(ratio, "1", flag=ROUNDING_FLOOR, note="; ".join(filter(None, (along, (
                f"at the rounding floor ({floor:.2g}: {ROUNDING_FLOOR_FACTOR:g} eps x steps x the momentum's and the "
                "position's size): exact up to it")))))
        return Measured(ratio, "1", note=along)
    return {
        LINEAR_MOMENTUM_DRIFT_MAX: relative(float(np.linalg.norm(linear_drift, axis=-1).max()), scale,
                                            unit * carried, "linear momentum"),
        CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX: relative(float(np.linalg.norm(angular_drift, axis=-1).max()),
                                                   scale * length, unit * carried * max(1.0, distance / length),
                                                   "angular momentum about the centre of mass"),
    }


@dataclass(frozen=True)
class Horizon:
    """Where the reference can be trusted: its samples [0, ``end``) (``end`` = all of them without a chaotic
    horizon), and its own error floor over them per error metric (0 where not known)."""

    end: int
    floors: dict[str, float]
    note: str = ""


def reference_horizon(scene: JointMotionScene, ref: JointTrajectory, coarse: JointTrajectory | None) -> Horizon:
    """The reference's horizon from its run at a looser tolerance (``coarse``; None: a closed form, trusted
    everywhere): the samples before the two differ by more than :data:`HORIZON_FLOOR` rad (unitless joint
    values), and the differences over them as the floor of each error."""
    if coarse is None:
        return Horizon(len(ref.times), {})
    scales, rate_scales = state_scales(scene.chain, ref)
    angle = (configuration_gap(scene.chain, coarse.q, ref.q) / scales).max(axis=(1, 2))
    speed = _speed_scale(scene.chain, ref, rate_scales)
    velocity = (velocity_gap(scene.chain, ref.qdot, coarse.qdot) / rate_scales).max(axis=(1, 2)) / speed
    beyond = np.flatnonzero(~(angle <= HORIZON_FLOOR))
    end = int(beyond[0]) if beyond.size else len(ref.times)
    floors = {JOINT_ANGLE_ERROR_MAX: float(angle[:end].max(initial=0.0)),
              JOINT_VELOCITY_ERROR_MAX: float(velocity[:end].max(initial=0.0))}
    note = ""
    if end < len(ref.times):
        note = (f"measured over the reference's horizon t < {float(ref.times[end]):.3g} s of "
                f"{float(ref.times[-1]):.3g} s: past it its solves at two tolerances differ by more than "
                f"{HORIZON_FLOOR:g} rad (a chaotic chain amplifies every error)")
    return Horizon(end, floors, note)


def _speed_scale(chain: Chain, ref: JointTrajectory, scales: np.ndarray) -> float:
    """The fastest unitless joint speed of the reference's motion [1/s] (a floating base's linear and angular speeds
    among them), at least 1 / its duration."""
    duration = max(float(ref.times[-1] - ref.times[0]), np.finfo(float).tiny)
    return max(float((velocity_gap(chain, ref.qdot, 0.0) / scales).max()), 1.0 / duration)


def reference_errors(scene: JointMotionScene, traj: JointTrajectory, own: OwnReading, ref: JointTrajectory,
                     ref_end_effector: np.ndarray,
                     horizon: Horizon) -> tuple[dict[str, Measured], dict[str, float], dict[str, float]]:
    """(errors against the reference over its horizon, each error's saturation ratio, each error's floor) — joint values (unitless,
    saturated at a quarter turn like an orientation), joint velocities (relative to the fastest joint speed) and
    the end effector (relative to the reach; ``ref_end_effector`` (S, B, 3) at ``own.index``), maxima over samples,
    copies and joints. An error at or under the reference's floor (:data:`REFERENCE_FLOOR_MARGIN` x) or the rounding
    floor is flagged ``rounding-floor``."""
    if traj.q.shape != ref.q.shape:
        raise ValueError(f"joint trajectory shape {traj.q.shape} != reference {ref.q.shape}")
    if horizon.end < 2:
        why = ("saturated: the reference's horizon ends before the first step (its two tolerances differ by more "
               f"than {HORIZON_FLOOR:g} rad at once)")
        return ({m: Measured(math.nan, "1", flag=SATURATED, unmeasurable=why) for m in REFERENCE_ERRORS},
                {m: math.inf for m in REFERENCE_ERRORS}, {})
    (scales, rate_scales), end = state_scales(scene.chain, ref), horizon.end
    speed = _speed_scale(scene.chain, ref, rate_scales)
    travel = np.linalg.norm(ref_end_effector - ref_end_effector[:1], axis=-1).max()
    length = max(reach(scene.chain), float(travel))  # a slider's tip may travel farther than the chain is long
    within = own.index < end
    values = {
        JOINT_ANGLE_ERROR_MAX: float((configuration_gap(scene.chain, traj.q[:end], ref.q[:end]) / scales).max()),
        JOINT_VELOCITY_ERROR_MAX: float((velocity_gap(scene.chain, traj.qdot[:end], ref.qdot[:end]) / rate_scales).max())
                                  / speed,
        END_EFFECTOR_ERROR_MAX: float(np.linalg.norm(own.end_effector[within] - ref_end_effector[within],
                                                     axis=-1).max()) / length,
    }
    saturation = {JOINT_ANGLE_ERROR_MAX: SATURATED_ORIENTATION, JOINT_VELOCITY_ERROR_MAX: SATURATED_FRACTION,
                  END_EFFECTOR_ERROR_MAX: SATURATED_FRACTION}
    floors = _rounding_floors(scene, ref, scales, speed, end)
    out, ratios, used = {}, {}, {}
    for metric, value in values.items():
        ratios[metric] = value / saturation[metric]
        floor = used[metric] = max(floors[metric], REFERENCE_FLOOR_MARGIN * horizon.floors.get(metric, 0.0))
        note = horizon.note
        if ratios[metric] >= 1:
            out[metric] = Measured(value, "1", flag=SATURATED, unmeasurable=(
                f"saturated: {value:.3g} >= {saturation[metric]:.3g} (unitless): the run is on another orbit"))
        elif value <= floor:
            out[metric] = Measured(value, "1", note=("; ".join(filter(None, (note, (
                f"at the floor ({floor:.2g}: rounding, or {REFERENCE_FLOOR_MARGIN:g} x the reference's own "
                "error): exact up to it"))))), flag=ROUNDING_FLOOR)
        else:
            out[metric] = Measured(value, "1", note=note)
    return out, ratios, used


def _rounding_floors(scene: JointMotionScene, ref: JointTrajectory, scales: np.ndarray, speed: float,
                     end: int) -> dict[str, float]:
    """Rounding floor of each error after the horizon's steps: ROUNDING_FLOOR_FACTOR x eps x steps x the
    quantity's scale (joint values: their largest size plus the duration times the speed scale; velocities: 1,
    they are relative to the speed scale; the end effector: 1, relative to the reach)."""
    steps = max(end - 1, 1)
    duration = float(ref.times[end - 1] - ref.times[0])
    unit = ROUNDING_FLOOR_FACTOR * np.finfo(float).eps * steps
    sizes = configuration_gap(scene.chain, ref.q[:end], np.zeros_like(ref.q[:end]))  # a base's position: |p|
    size = float((sizes / scales).max()) + duration * speed
    return {JOINT_ANGLE_ERROR_MAX: unit * size, JOINT_VELOCITY_ERROR_MAX: unit,
            END_EFFECTOR_ERROR_MAX: unit * max(size, 1.0)}


def parting_times(scene: JointMotionScene, traj: JointTrajectory, perturbed: JointTrajectory | None,
                  ref: JointTrajectory | None) -> dict[str, Measured]:
    """When ``traj`` parts (a joint more than :data:`PARTING` off, unitless) from the engine's own run from the
    perturbed start, and from the reference's; n/a with the reason where they never part within the run or there is
    nothing to part from."""
    scales = state_scales(scene.chain, traj if ref is None else ref)[0]

    def parting(other: JointTrajectory | None, what: str) -> Measured:
        if other is None:
            return Measured(math.nan, "s", unmeasurable=f"no {what} to part from")
        apart = np.flatnonzero((configuration_gap(scene.chain, other.q, traj.q) / scales).max(axis=(1, 2)) > PARTING)
        if not apart.size:
            return Measured(math.nan, "s", unmeasurable=(
                f"within {PARTING:g} rad of {what} for the whole run ({float(traj.times[-1]):.3g} s)"))
        return Measured(float(traj.times[apart[0]]), "s")
    return {SELF_PARTING_TIME: parting(perturbed, f"its own run from a start {scene.perturbation:g} off"),
            REFERENCE_PARTING_TIME: parting(ref, "the reference")}
