"""Metrics of a chain's contact with a plane (a :class:`JointMotionScene` with ``contact``, issue #46): truths that need
no engine, measured on each engine's own run with its own model. Definitions with their reasons: ``docs/metrics.md``.

Every engine's contact is its own (core's penalty springs, MuJoCo's soft constraints), so no engine is compared with
another's trajectory; each is held to what any correct contact must give:

- ``touchdown_time_error``: a robot at rest (no joint or base rotation rates, no torque) falls as one rigid body, every
  sphere's gap closing as h + v t + 1/2 a t^2 (a = g . N, v the base's velocity along N), so the first sphere touches at
  the closed-form time; the engine's touchdown is where its own sphere centres, extrapolated from its last two samples
  before any sphere touches by the same law, reach the plane. Relative to the closed-form time.
- ``contact_centre_error``: the engine's sphere centres (those it measures every gap by) where the robot file puts
  them, by Pinocchio's forward kinematics of the file at the same configurations (an independent model): the largest
  distance over the radius. A sphere read off its frame (a link's inertial frame taken for its link frame) is off
  by O(0.1-1) of its radius while still well inside the penetration bound.
- ``contact_penetration_max``: the deepest a sphere sinks into the plane, relative to its radius (soft contact
  penetrates by its own stiffness; past 1 a sphere has gone through).
- ``signorini_violation_max``: a plane pushes a touching sphere and nothing else: max of a pull (-f.N)^+ and of a force
  on a sphere off the plane, |f| gap / radius, relative to the robot's weight m |g|.
- ``friction_cone_violation_max``: how far a force leaves the plane's Coulomb cone, (|f - (f.N) N| - mu f.N)^+ (on a
  frictionless plane, mu = 0, its whole tangential force), relative to the weight.
- ``sliding_friction_error`` and ``sliding_friction_angle_max``: where a pushed sphere slides (:data:`SLIDING_SPEED`;
  its contact point's velocity by Pinocchio's model of the file, an independent model), Coulomb's friction is on its
  cone, |f_t| = mu f_n (the error is ||f_t| - mu f_n| / (mu f_n), the largest), and opposes the slip (the angle between
  f_t and -u_t, the largest: 0 for Coulomb's maximal dissipation; friction that only takes energy keeps it below
  pi / 2, a bound any engine meets, while soft and per-direction solvers turn it by their own amounts).
- ``friction_impulse_error``: the friction an engine reports is the friction that moved it. A floating base meets
  the plane and gravity only, so its momentum's change along the plane is the impulse of gravity and of the reported
  contact forces along it (Newton): |t(P(T) - P(0) - int (sum f + m g) dt)| over the friction impulse the plane
  could give, mu int f_n dt, the largest copy (t the part along the plane). The forces are read at every step, in
  order along the run (the other metrics take their samples from them: :func:`_reads_every_step`), and integrated
  by the closer of the left and trapezoid rules: the left rule is a one-step explicit or semi-implicit scheme's own
  (its step applies the force at its start, a chattering contact's too), the trapezoid within O(dt^2) of a smooth
  force's. An engine that reports
  Coulomb's friction but steps without it reads ~1, and so does a scheme that stalls where its forces do not balance
  (core's RK4 at 1 ms on a stiff regularised friction sits at a spurious fixed point, reporting 0.08 of the weight
  along the plane). Over the whole run it sees the impulse, not when it came: forces reported a step late differ
  from the true ones by end terms only.
- ``contact_energy_gain_max``: contact and damping only take energy (a soft contact stores some while it is
  compressed, and gives back at most that), so the mechanical energy never exceeds what it was at any earlier instant
  where no contact stores any (every sphere off the plane, or carrying no force where the engine reports forces:
  :data:`UNLOADED`; the start counts: a sphere starts at most 1e-9 m inside), less the applied forces' work: max_t (E(t) - W(t) - min over earlier contact-free s of
  (E(s) - W(s)))^+, relative to the energy the motion can have (:func:`energy_budget`).
- ``rest_weight_error``: at rest (the centre of mass's acceleration over the last sampled interval below
  :data:`REST_ACCELERATION` of g, from the engine's own momentum) the plane carries the weight: |sum f + m g| / m |g|
  at the last sample.
- ``rest_equilibrium_error``: at rest (also every joint's acceleration below :data:`REST_ACCELERATION` g / reach) the
  engine's contact forces, gravity, the applied joint forces and the damping balance on every joint and on a floating
  base, by Pinocchio's model of the file (:class:`references.pinocchio.statics.PinocchioStatics`: an independent
  model, none of the engine's): |g(q) - sum_s J_s^T f_s - tau + D qdot| row by row (tau the constant and the timed
  torque at that sample's time), a force over m |g|, a moment over
  m |g| reach, the largest. The fixed-base arm's closed form f = J^-T (g - tau) is this balance.
- ``rest_acceleration_max``: where the scene says from when its robot rests (``[contact] rest_after``), the largest
  acceleration of any joint (over g / reach; a slide's over g) or of a floating base (linear over g, angular over
  g / reach) over the sampled intervals from then: a run that never settles (a contact that lets a pushed sphere creep,
  a chattering solve) is a number the bounds judge, where the rest checks above could only be n/a.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import trapezoid

from simparity.comparisons.measure.joint_motion_metrics import (
    CHAIN_CONTACT_METRICS, OwnReading, applied_torque, energy_budget, reach, work_done,
)
from simparity.comparisons.common.error_text import error_text
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.engine import JointSimulation
from simparity.core.model.metric_catalogue import (
    CONTACT_CENTRE_ERROR, CONTACT_ENERGY_GAIN_MAX, CONTACT_PENETRATION_MAX, FRICTION_CONE_VIOLATION_MAX,
    FRICTION_IMPULSE_ERROR, REST_ACCELERATION_MAX,
    REST_WEIGHT_ERROR, REST_EQUILIBRIUM_ERROR, SIGNORINI_VIOLATION_MAX, SLIDING_FRICTION_ANGLE_MAX,
    SLIDING_FRICTION_ERROR, TOUCHDOWN_TIME_ERROR, TOUCHDOWN_TIME_STEPS,
)
from simparity.core.model.results import NOT_AT_REST, NOTHING_TO_MEASURE
from simparity.core.model.scenes.chain_contact import ChainContact
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory

FORCE_METRICS = (SIGNORINI_VIOLATION_MAX, FRICTION_CONE_VIOLATION_MAX, SLIDING_FRICTION_ERROR,
                 SLIDING_FRICTION_ANGLE_MAX, FRICTION_IMPULSE_ERROR, REST_WEIGHT_ERROR, REST_EQUILIBRIUM_ERROR)
"""The metrics that need the engine's contact forces (:meth:`JointSimulation.contact_forces`)."""

REST_ACCELERATION = 1e-3
"""[1] A robot is at rest when its centre of mass accelerates by at most this fraction of g over the last sampled
interval (its own momentum's change): the plane then carries its weight to about this fraction, and a contact force
that is wrong by a factor, a sign or a missing sphere is off by O(1)."""
SAMPLE_TIME_RTOL = 1e-9
"""[1] A sample at k dt is at or after ``rest_after`` when its time is within this of it (k dt rounds)."""
TOUCHING = 0.0
"""[m] A sphere touches the plane when its gap is at most this (the scene's radius; margins are switched off)."""
SLIDING_SPEED = 0.1
"""[1 of sqrt(g reach)] A pushed sphere slides when its contact point slips along the plane at least this fast, at a
sample and at the next one in nearly the same direction (:data:`SLIDING_TURN`): sqrt(g reach) is the speed of a fall
by the robot's reach, so a slip of a tenth of it is no creep of a held foot (core's regularised friction creeps below
1 cm/s; Solo-12's threshold is 0.2 m/s). Slipping at both ends of a sampled interval, it slid through the step
between them, whose force an engine that steps on impulses reports."""
FRICTION_ROUNDING = 1e-9
"""[1 of mu f_n] A sliding contact's friction this small is rounding (a normal force's tangential residue): it has no
direction for ``sliding_friction_angle_max`` to judge (``sliding_friction_error`` reads its absence, 1)."""
REGULARISED_SLIPS = 2.0
"""A sliding sphere also slips at least this many times the scene's ``friction_speed``, below which core's penalty
friction is regularised (inside the cone by design): a scene that sets it high is judged on faster slips."""
SLIDING_TURN = 0.1
"""[rad] The most a sliding sphere's slip may turn between two samples (:data:`SLIDING_SPEED`)."""
UNLOADED = 1e-12
"""[1 of the weight] A touching sphere whose force is at most this stores no energy in its contact (a spring at
rounding: f^2 / 2k). Such instants are baselines of ``contact_energy_gain_max`` too: a sphere that touches all the
time with no load (a hub on a fixed axis, a sphere at a gap of +-1e-17 by rounding) no longer hides every later gain
(a held-out trial: 0 against 0.12 made). More baselines can only lower the least earlier energy, never hide a gain."""


def _states(traj: JointTrajectory, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q (S B, nq), qdot (S B, nv)) at the samples ``index``, copies flattened."""
    return (np.ascontiguousarray(traj.q[index]).reshape(-1, traj.q.shape[2]),
            np.ascontiguousarray(traj.qdot[index]).reshape(-1, traj.qdot.shape[2]))


def _forces_along_each_run(sim: JointSimulation, traj: JointTrajectory, index: np.ndarray) -> np.ndarray:
    """(S, B, spheres, 3) the engine's contact forces [N] at the samples ``index``, read copy by copy, each copy's in
    the order of its run (an engine whose reading carries contact history, PyBullet's manifolds, carries its own
    copy's, not another's: :func:`_reads_every_step`)."""
    q, qdot = (np.ascontiguousarray(np.swapaxes(x[index], 0, 1)).reshape(-1, x.shape[2]) for x in (traj.q, traj.qdot))
    times = np.tile(np.asarray(traj.times, dtype=float)[index], traj.q.shape[1])
    forces = np.asarray(sim.contact_forces(q, qdot, times), dtype=float)
    return np.swapaxes(forces.reshape((traj.q.shape[1], len(index)) + forces.shape[1:]), 0, 1)


def _centres(sim: JointSimulation, traj: JointTrajectory, index: np.ndarray, spheres: int) -> np.ndarray:
    """(S, B, spheres, 3) the engine's sphere centres at the samples ``index``."""
    q, _ = _states(traj, index)
    return np.asarray(sim.contact_centres(q), dtype=float).reshape(len(index), traj.q.shape[1], spheres, 3)


def closed_form_touchdown(scene: JointMotionScene,
                          gaps0: np.ndarray) -> tuple[np.ndarray, np.ndarray, str]:
    """(t (B,) [s], the first-order shift's factor a t / v at it (B,) [1], "") each copy's first sphere's touchdown in
    free fall from gaps ``gaps0`` (B, S) [m] (the engine's own at t = 0), with its fall's acceleration a and speed v
    along the normal there; or (nan, nan, why) when the scene's start is no rigid fall or nothing reaches the plane
    within its duration."""
    contact = scene.contact
    assert contact is not None
    chain, normal = scene.chain, np.asarray(contact.plane.normal_world)
    if not chain.floating_base:
        return _NONE, _NONE, "a fixed base does not fall"
    if scene.gravity_world is None:
        return _NONE, _NONE, "no gravity: nothing falls"
    if (np.any(scene.qdot0[:, 3:] != 0) or np.any(scene.torque != 0) or scene.timed_torque is not None):
        return _NONE, _NONE, ("the robot does not start as one rigid body falling (joint or base rotation rates, or "
                          "applied torques): its touchdown has no closed form")
    if np.any(gaps0 <= TOUCHING):
        return _NONE, _NONE, "a sphere touches the plane at t = 0"
    a = float(np.asarray(scene.gravity_world) @ normal)
    v = (np.asarray(scene.qdot0[:, :3]) @ normal)[:, None]  # (B, 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        roots = np.where(a != 0, (-v - np.sqrt(np.maximum(v**2 - 2 * a * gaps0, 0.0))) / a, -gaps0 / v)
        reached = (v**2 - 2 * a * gaps0 >= 0) & (roots > 0)
    times = np.where(reached, roots, np.inf).min(axis=1)
    if not np.all(times <= scene.duration):
        return _NONE, _NONE, f"no sphere reaches the plane within the run's {scene.duration:g} s"
    speed = np.abs(v[:, 0] + a * times)
    with np.errstate(divide="ignore"):
        return times, np.where(speed > 0, abs(a) * times / speed, np.inf), ""


_NONE = np.array([math.nan])
"""No closed-form touchdown (the reason says why)."""


def _engine_touchdown(scene: JointMotionScene, sim: JointSimulation, traj: JointTrajectory, index: np.ndarray,
                      gaps: np.ndarray) -> np.ndarray:
    """(B,) each copy's touchdown [s]: its gaps at its last two steps before a sphere touches (every step up to the
    first sample that sees a touch: a first contact between two read samples is not missed), extrapolated by the
    fall's law (the known acceleration g . N) to zero; a copy that has not touched by then, from that sample."""
    contact = scene.contact
    assert contact is not None and scene.gravity_world is not None
    a = float(np.asarray(scene.gravity_world) @ np.asarray(contact.plane.normal_world))
    touched = np.flatnonzero((gaps <= TOUCHING).any(axis=(1, 2)))
    first = int(index[touched[0]])
    window = np.arange(first + 1)  # every step up to the first sample that sees a touch
    fine = contact.gaps(_centres(sim, traj, window, len(contact.spheres)))
    out = []
    for b in range(traj.q.shape[1]):
        free = np.asarray((fine[:, b] > TOUCHING).all(axis=1))
        last = max(int(np.argmin(free)) - 1, 0) if not free.all() else window.size - 1
        k = window[last]
        dt = float(traj.times[k] - traj.times[k - 1]) if k > 0 else 0.0
        h = fine[last, b]
        v = ((h - contact.gaps(_centres(sim, traj, np.array([k - 1]), len(contact.spheres)))[0, b]) / dt + 0.5 * a * dt
             if k > 0 else np.full(h.shape, float(np.asarray(scene.qdot0[b, :3]) @ contact.plane.normal_world)))
        with np.errstate(invalid="ignore", divide="ignore"):
            root = np.where(a != 0, (-v - np.sqrt(np.maximum(v**2 - 2 * a * h, 0.0))) / a, -h / v)
        out.append(float(traj.times[k]) + float(np.min(np.where(root >= 0, root, np.inf))))
    return np.array(out)


def _touchdown(scene: JointMotionScene, sim: JointSimulation, traj: JointTrajectory, index: np.ndarray,
               gaps: np.ndarray) -> dict[str, Measured]:
    """``touchdown_time_error`` (relative to the closed-form time t_c) and ``touchdown_time_steps`` (in the fall's
    first-order shift dt a t_c / v_c: a step of the fall's position error a t dt / 2 at speed v_c moves it by half
    that, early for semi-implicit Euler, late for explicit Euler, whatever the scene)."""
    exact_each, factor, why = closed_form_touchdown(scene, gaps[0])
    if why:
        return {m: Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=why)
                for m in (TOUCHDOWN_TIME_ERROR, TOUCHDOWN_TIME_STEPS)}
    dt = float(traj.times[1] - traj.times[0])
    shift, exact = dt * factor, float(exact_each.max())
    if not (gaps <= TOUCHING).any():
        late = float(traj.times[-1]) - exact  # it touches down after its run ends, if ever: at least this late
        note = (f"no sphere of the engine's reached the plane by the run's end {float(traj.times[-1]):.6g} s; the "
                f"closed form touches down at {exact:.6g} s: at least this late")
        return {TOUCHDOWN_TIME_ERROR: Measured(late / exact, "1", note=note),
                TOUCHDOWN_TIME_STEPS: Measured(late / float(shift[int(np.argmax(exact_each))]), "1", note=note)}
    measured_each = _engine_touchdown(scene, sim, traj, index, gaps)
    off = np.abs(measured_each - exact_each)  # each copy against its own closed form
    worst = int(np.argmax(off / exact_each))
    note = f"touchdown at {measured_each[worst]:.9g} s, closed form {exact_each[worst]:.9g} s"
    return {TOUCHDOWN_TIME_ERROR: Measured(float((off / exact_each).max()), "1", note=note),
            TOUCHDOWN_TIME_STEPS: Measured(float((off / shift).max()), "1", note=(
                f"{note}; the fall's first-order shift dt a t_c / v_c {float(shift[worst]):.3g} s"))}


def _forces(scene: JointMotionScene, contact: ChainContact, forces: np.ndarray, gaps: np.ndarray,
            weight: float) -> dict[str, Measured]:
    """The Signorini and friction-cone violations of forces (S, B, spheres, 3) at gaps (S, B, spheres)."""
    normal = np.asarray(contact.plane.normal_world)
    f_n = forces @ normal
    outside = np.maximum(np.linalg.norm(forces - f_n[..., None] * normal, axis=-1) - contact.friction * f_n, 0.0)
    at_distance = np.linalg.norm(forces, axis=-1) * np.maximum(gaps, 0.0) / contact.radii
    signorini = float(np.maximum(np.maximum(-f_n, 0.0), at_distance).max()) / weight
    return {SIGNORINI_VIOLATION_MAX: Measured(signorini, "1", note="pull or force off the plane, over the weight"),
            FRICTION_CONE_VIOLATION_MAX: Measured(float(outside.max()) / weight, "1", note=(
                "tangential force on a frictionless plane, over the weight" if contact.friction == 0 else
                f"tangential force beyond the Coulomb cone (mu = {contact.friction:g}), over the weight"))}


class _Truth:
    """Pinocchio's model of the scene's chain and contact (:class:`references.pinocchio.statics.PinocchioStatics`),
    built once for a case's metrics: the independent model their truths are read by; ``why`` says why not where it
    cannot be built (not installed, or Pinocchio refuses the chain)."""

    def __init__(self, scene: JointMotionScene) -> None:
        self.model, self.why = None, ""
        contact = scene.contact
        assert contact is not None
        try:
            from simparity.references.pinocchio.statics import PinocchioStatics
            self.model = PinocchioStatics(scene.chain, scene.gravity_world, contact)
        except Exception as err:  # noqa: BLE001 - not installed, or Pinocchio refuses the chain
            self.why = f"Pinocchio's model of the chain, which cannot be built here: {error_text(err)}"


def _centre_error(scene: JointMotionScene, traj: JointTrajectory, index: np.ndarray, centres: np.ndarray,
                  truth: _Truth) -> Measured:
    """``contact_centre_error``: the engine's sphere centres (S, B, spheres, 3) at the samples ``index`` against
    Pinocchio's forward kinematics of the file at the same configurations, the largest distance over the radius."""
    contact = scene.contact
    assert contact is not None
    if truth.model is None:
        return Measured(math.nan, "1", unmeasurable=f"the spheres' places are read by {truth.why}")
    try:
        places = truth.model.centres(_states(traj, index)[0])
    except Exception as err:  # noqa: BLE001 - Pinocchio refuses a configuration
        return Measured(math.nan, "1", unmeasurable=f"Pinocchio's kinematics failed: {error_text(err)}")
    off = np.linalg.norm(centres - places.reshape(centres.shape), axis=-1) / contact.radii
    return Measured(float(off.max()), "1", note="the engine's sphere centres against Pinocchio's kinematics of the "
                                                "file, over the radius")


def _sliding(scene: JointMotionScene, traj: JointTrajectory, index: np.ndarray, forces: np.ndarray,
             weight: float, truth: _Truth) -> dict[str, Measured]:
    """``sliding_friction_error`` and ``sliding_friction_angle_max`` of forces (S, B, spheres, 3) at the samples
    ``index`` (see the module docstring); n/a with why on a frictionless plane or where nothing slides."""
    contact = scene.contact
    assert contact is not None
    units = {SLIDING_FRICTION_ERROR: "1", SLIDING_FRICTION_ANGLE_MAX: "rad"}
    if contact.friction == 0:
        return {m: Measured(math.nan, unit, flag=NOTHING_TO_MEASURE,
                            unmeasurable=("a frictionless plane: nothing to slide against (friction_cone_violation_max "
                                          "holds its tangential force to 0)")) for m, unit in units.items()}
    if truth.model is None:
        return {m: Measured(math.nan, unit, unmeasurable=f"the slip is read by {truth.why}")
                for m, unit in units.items()}
    velocities = truth.model.contact_point_velocities(*_states(traj, index)).reshape(forces.shape)
    normal = np.asarray(contact.plane.normal_world)
    slip = velocities - (velocities @ normal)[..., None] * normal
    speed = np.linalg.norm(slip, axis=-1)
    threshold = max(SLIDING_SPEED * math.sqrt(weight / scene.chain.mass * reach(scene.chain)),  # weight / m = |g|
                    REGULARISED_SLIPS * contact.friction_speed)
    direction = slip / np.where(speed > 0, speed, 1.0)[..., None]
    f_n = forces @ normal
    tangential = forces - f_n[..., None] * normal
    held = ((speed[:-1] >= threshold) & (speed[1:] >= threshold) & (f_n[:-1] > UNLOADED * weight)
            & (np.sum(direction[:-1] * direction[1:], axis=-1) >= math.cos(SLIDING_TURN)))
    if not held.any():
        why = (f"no pushed sphere slid faster than {threshold:.3g} m/s (0.1 sqrt(g reach), at least twice the "
               f"friction_speed) at two samples in a row")
        return {m: Measured(math.nan, unit, flag=NOTHING_TO_MEASURE, unmeasurable=why) for m, unit in units.items()}
    f_t, bound = tangential[:-1][held], contact.friction * f_n[:-1][held]
    size = np.linalg.norm(f_t, axis=-1)
    pointing = size > FRICTION_ROUNDING * bound  # a friction at rounding has no direction to judge
    back = -direction[:-1][held]  # atan2 of |f x s| and f . s: exact near 0 and pi, where arccos loses half the digits
    angle = np.where(pointing, np.arctan2(np.linalg.norm(np.cross(f_t, back), axis=-1),
                                          np.sum(f_t * back, axis=-1)), 0.0)
    note = f"{int(held.sum())} sliding instants (slip >= {threshold:.3g} m/s)"
    return {SLIDING_FRICTION_ERROR: Measured(float((np.abs(size - bound) / bound).max()), "1",
                                             note=f"||f_t| - mu f_n| / (mu f_n) over {note}"),
            SLIDING_FRICTION_ANGLE_MAX: Measured(float(angle.max()), "rad",
                                                 note=f"angle between the friction and -slip over {note}")}


def _along_plane(vectors: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """(..., 3) the part of ``vectors`` (..., 3) along the plane of unit ``normal`` (3,)."""
    return vectors - (vectors @ normal)[..., None] * normal


def _reads_every_step(scene: JointMotionScene) -> bool:
    """Whether the engine's contact forces are read at every step of its run, in order (the samples taken from them),
    not only at the samples: where ``friction_impulse_error`` integrates them (friction on a floating base). A stiff
    friction that flips at every step aliases on samples that skip steps in a pattern (a held-out a1 read 0.31 on them
    against 8e-8 at every step), and an engine whose step carries more than the state (PyBullet's contact manifolds keep
    points from earlier steps) reports at a state what its run applied only when read along that run (Solo-12's
    landing on the slope: totals 607 N of 4,976 N apart read in reverse)."""
    contact = scene.contact
    return contact is not None and contact.friction > 0 and scene.chain.floating_base


def _friction_impulse(scene: JointMotionScene, sim: JointSimulation, traj: JointTrajectory, forces: np.ndarray,
                      mass: float) -> Measured:
    """``friction_impulse_error`` of the engine's forces at every step of ``traj`` (``forces`` (T, B, spheres, 3), see
    the module docstring and :func:`_reads_every_step`); n/a with why on a frictionless plane, a fixed base, or where
    nothing presses."""
    contact = scene.contact
    assert contact is not None and scene.gravity_world is not None
    if contact.friction == 0:
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=(
            "a frictionless plane: the momentum along it is held by the momentum laws"))
    if not scene.chain.floating_base:
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE,
                        unmeasurable="a fixed base's mount pushes it by a force nobody reports")
    ends = np.array([0, len(traj.times) - 1])
    try:
        momentum = np.asarray(sim.momentum(*_states(traj, ends)), dtype=float).reshape(2, -1, 6)[..., :3]
    except NotImplementedError as err:
        return Measured(math.nan, "1", unmeasurable=f"the momentum's change cannot be read: {err}")
    times = np.asarray(traj.times, dtype=float)
    assert len(forces) == len(times)  # read at every step where friction acts on a floating base
    normal = np.asarray(contact.plane.normal_world)
    pressing = contact.friction * trapezoid(np.maximum(forces @ normal, 0.0).sum(axis=2), times, axis=0)  # (B,)
    if not (pressing > 0).all():
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable="no sphere pressed on the plane")
    tangential = _along_plane(forces.sum(axis=2), normal)  # (T, B, 3)
    change = _along_plane(momentum[1] - momentum[0] - mass * (times[-1] - times[0]) * np.asarray(scene.gravity_world),
                          normal)
    left = np.sum(np.diff(times)[:, None, None] * tangential[:-1], axis=0)
    unexplained = np.minimum(np.linalg.norm(change - left, axis=-1),
                             np.linalg.norm(change - trapezoid(tangential, times, axis=0), axis=-1)) / pressing
    return Measured(float(unexplained.max()), "1", note=(
        "the momentum's change along the plane less gravity's and the reported forces' impulse at every step (the "
        "closer of the left and trapezoid rules), over mu int f_n dt"))


def _rest(scene: JointMotionScene, sim: JointSimulation, traj: JointTrajectory, index: np.ndarray,
          forces: np.ndarray, weight: float, mass: float) -> Measured:
    if not scene.chain.floating_base:
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE,
                        unmeasurable="a fixed base's mount carries an unknown share of the weight")
    last = index[-2:]
    try:
        momentum = np.asarray(sim.momentum(*_states(traj, last)), dtype=float).reshape(2, traj.q.shape[1], 6)
    except NotImplementedError as err:  # a scene that says its robot stands needs it told: an alarm then
        return Measured(math.nan, "1", flag=NOT_AT_REST if scene.contact is not None and scene.contact.stands else "",
                        unmeasurable=f"at rest cannot be told: {err}")
    interval = float(traj.times[last[1]] - traj.times[last[0]])
    acceleration = float(np.linalg.norm(momentum[1, :, :3] - momentum[0, :, :3], axis=-1).max()) / (mass * interval)
    g = float(np.linalg.norm(np.asarray(scene.gravity_world)))
    if acceleration > REST_ACCELERATION * g:
        contact = scene.contact
        assert contact is not None
        return Measured(math.nan, "1", flag=NOT_AT_REST if contact.stands else NOTHING_TO_MEASURE, unmeasurable=(
            f"not at rest at the end: the centre of mass accelerates {acceleration / g:.3g} g over the last sampled "
            f"interval (rest: at most {REST_ACCELERATION:g} g)"))
    residual = forces[-1].sum(axis=1) + mass * np.asarray(scene.gravity_world)
    return Measured(float(np.linalg.norm(residual, axis=-1).max()) / weight, "1",
                    note=f"at rest (centre of mass accelerating {acceleration / g:.2g} g): |sum f + m g| / m |g|")


def _interval_accelerations(scene: JointMotionScene, traj: JointTrajectory, index: np.ndarray,
                            base: bool) -> np.ndarray:
    """(I,) per sampled interval between the samples ``index``, the largest acceleration (the rates' change over the
    interval) over every copy: each joint's over g / reach (a prismatic joint's over g; g: 9.81 m/s^2 without gravity),
    and with ``base`` a floating base's linear rows over g and its angular rows over g / reach."""
    g = float(np.linalg.norm(scene.gravity_world)) if scene.gravity_world is not None else 9.81
    scale = [g if j.type == "prismatic" else g / reach(scene.chain) for j in scene.chain.joints]
    if base and scene.chain.floating_base:
        scale = [g] * 3 + [g / reach(scene.chain)] * 3 + scale
    if not scale:
        return np.zeros(len(index) - 1)
    rates = np.asarray(traj.qdot[index][..., traj.qdot.shape[2] - len(scale):])
    intervals = np.diff(np.asarray(traj.times)[index])
    change = np.abs(rates[1:] - rates[:-1]) / intervals[:, None, None] / np.array(scale)
    return change.reshape(len(intervals), -1).max(axis=1)


def _joints_at_rest(scene: JointMotionScene, traj: JointTrajectory, index: np.ndarray) -> str:
    """Why the chain's joints are not at rest at the end ("" when they are): a joint's acceleration over the last sampled
    interval above :data:`REST_ACCELERATION` g / reach (g: 9.81 m/s^2 without gravity), rad/s^2 (a prismatic joint's
    over g)."""
    worst = float(_interval_accelerations(scene, traj, index[-2:], base=False)[-1])
    if worst > REST_ACCELERATION:
        return (f"not at rest at the end: a joint accelerates {worst:.3g} x g / reach over the last sampled interval "
                f"(rest: at most {REST_ACCELERATION:g})")
    return ""


def _rest_acceleration(scene: JointMotionScene, traj: JointTrajectory, index: np.ndarray) -> Measured:
    """``rest_acceleration_max``: from the scene's ``rest_after`` on, the largest acceleration of any joint or of a
    floating base over its rest scale (:func:`_interval_accelerations`); n/a where the scene does not say."""
    contact = scene.contact
    assert contact is not None
    if contact.rest_after is None:
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=(
            "the scene does not say when its robot rests ([contact] rest_after)"))
    starts = np.asarray(traj.times)[index[:-1]]
    after = starts >= contact.rest_after * (1 - SAMPLE_TIME_RTOL)
    if not after.any():
        return Measured(math.nan, "1", unmeasurable=f"no sampled interval starts after rest_after = "
                                                    f"{contact.rest_after:g} s")
    worst = float(_interval_accelerations(scene, traj, index, base=True)[after].max())
    return Measured(worst, "1", note=(f"largest acceleration from t = {contact.rest_after:g} s: a joint's over "
                                      "g / reach (a slide's over g), a floating base's linear over g and angular over "
                                      "g / reach"))


def _equilibrium(scene: JointMotionScene, traj: JointTrajectory, index: np.ndarray, forces: np.ndarray,
                 weight: float, rest: Measured, truth: _Truth) -> Measured:
    """``rest_equilibrium_error`` at the last sample (see the module docstring); n/a with why when not at rest."""
    if scene.chain.floating_base and rest.unmeasurable:
        return Measured(math.nan, "1", flag=rest.flag or NOTHING_TO_MEASURE, unmeasurable=rest.unmeasurable)
    moving = _joints_at_rest(scene, traj, index)
    if moving:
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=moving)
    if truth.model is None:
        return Measured(math.nan, "1", unmeasurable=f"its truth is {truth.why}")
    q = np.asarray(traj.q[index[-1]])
    qdot = np.asarray(traj.qdot[index[-1]])
    try:
        balance = truth.model.balance(q, forces[-1])
    except Exception as err:  # noqa: BLE001 - Pinocchio refuses a configuration
        return Measured(math.nan, "1",
                        unmeasurable=f"its truth, Pinocchio's model of the chain, failed: {error_text(err)}")
    n = scene.chain.n_joints
    held = np.zeros_like(balance)  # what holds the chain: the applied joint forces less the damping (none on a base)
    damping = np.array([j.damping for j in scene.chain.joints])
    torque = applied_torque(scene, np.asarray(traj.times, dtype=float)[index[-1:]])  # the timed one at that time
    held[:, balance.shape[1] - n:] = torque - damping * qdot[:, qdot.shape[1] - n:]
    scale = weight * reach(scene.chain) ** (1 - scene.chain.length_powers)
    worst = float((np.abs(balance - held) / scale).max())
    return Measured(worst, "1", note=("at rest: |g(q) - sum J^T f - tau + D qdot| by Pinocchio's model, a force over "
                                      "m |g|, a moment over m |g| reach"))


def _energy_gain(scene: JointMotionScene, traj: JointTrajectory, own: OwnReading, gaps: np.ndarray,
                 unloaded: np.ndarray | None) -> Measured:
    """The gain against the energy at earlier instants where no contact stores any: every sphere off the plane or,
    where the engine reports its forces, carrying none (``unloaded`` (S, B, spheres); None: not reported)."""
    energy = own.kinetic + own.potential - work_done(scene, traj)[own.index]
    storing = gaps <= TOUCHING if unloaded is None else (gaps <= TOUCHING) & ~unloaded
    free = np.array(~storing.any(axis=2), dtype=bool)  # (S, B): no energy stored in a contact
    free[0] = True  # the start: every sphere outside or touching within the loader's 1e-9 m, nothing stored
    baseline = np.minimum.accumulate(np.where(free, energy, np.inf), axis=0)
    gain = float(np.max(np.where(np.isfinite(baseline), energy - baseline, 0.0)))
    scale = float(energy_budget(scene, traj, own).max())
    return Measured(max(gain, 0.0) / scale, "1",
                    note=("mechanical energy above its value at an earlier instant no contact stored any, over the "
                          "energy budget"))


def contact_metrics(scene: JointMotionScene, sim: JointSimulation, traj: JointTrajectory,
                    own: OwnReading) -> dict[str, Measured]:
    """:data:`CHAIN_CONTACT_METRICS` of the engine's run (see the module docstring), at the samples ``own`` read."""
    contact = scene.contact
    assert contact is not None
    index = own.index
    try:
        centres = _centres(sim, traj, index, len(contact.spheres))  # (S, B, spheres, 3)
    except NotImplementedError as err:
        return {m: Measured(math.nan, "1", unmeasurable=str(err)) for m in CHAIN_CONTACT_METRICS}
    gaps = contact.gaps(centres)
    truth = _Truth(scene)
    out = _touchdown(scene, sim, traj, index, gaps) | {
        CONTACT_CENTRE_ERROR: _centre_error(scene, traj, index, centres, truth),
        REST_ACCELERATION_MAX: _rest_acceleration(scene, traj, index),
        CONTACT_PENETRATION_MAX: Measured(float(np.maximum(-gaps / contact.radii, 0.0).max()), "1",
                                          note="deepest sinking over the sphere's radius"),
    }
    mass = scene.chain.mass  # as the file declares it: every importer reads the same (model parity, issue #45)
    weight = mass * float(np.linalg.norm(scene.gravity_world)) if scene.gravity_world is not None else 0.0
    if not weight > 0:
        why = "no weight (no gravity or no mass): the contact forces have no scale"
        return out | {CONTACT_ENERGY_GAIN_MAX: _energy_gain(scene, traj, own, gaps, None)} | {
            m: Measured(math.nan, "1", flag=NOTHING_TO_MEASURE, unmeasurable=why) for m in FORCE_METRICS}
    read = np.arange(len(traj.times)) if _reads_every_step(scene) else index
    try:
        read_forces = _forces_along_each_run(sim, traj, read)
    except NotImplementedError as err:
        return out | {CONTACT_ENERGY_GAIN_MAX: _energy_gain(scene, traj, own, gaps, None)} | {
            m: Measured(math.nan, "1", unmeasurable=str(err)) for m in FORCE_METRICS}
    forces = read_forces[index] if len(read) > len(index) else read_forces  # (S, B, spheres, 3) at the samples
    out[CONTACT_ENERGY_GAIN_MAX] = _energy_gain(scene, traj, own, gaps,
                                                np.linalg.norm(forces, axis=-1) <= UNLOADED * weight)
    rest = _rest(scene, sim, traj, index, forces, weight, mass)
    return out | _forces(scene, contact, forces, gaps, weight) | _sliding(scene, traj, index, forces, weight, truth) | {
        FRICTION_IMPULSE_ERROR: _friction_impulse(scene, sim, traj, read_forces, mass),
        REST_WEIGHT_ERROR: rest, REST_EQUILIBRIUM_ERROR: _equilibrium(scene, traj, index, forces, weight, rest, truth)}
