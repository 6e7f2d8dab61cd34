"""Error metrics of a trajectory or a kinematic evaluation against a reference, drifts, and
observed orders of convergence. Definitions with their reasons: ``docs/metrics.md``.

Each function returns ``{metric: Measured}``. Errors are maxima over every body, sample and
frame; "final" is at the last sample. A value that cannot mean anything (saturated, at the
rounding floor, nothing to compare against) is returned unmeasurable with the reason, and
becomes an ``n/a`` row. Rotations are SciPy's (:mod:`references.common.conventions`), never the
in-house code these metrics judge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simparity.comparisons.measure.body_scales import body_sizes, energy_scales
from simparity.comparisons.measure.contact_metrics import CONTACT_METRICS
from simparity.comparisons.measure.extents import (
    EnergyExtents, ErrorExtents, ReferenceExtents, RunExtents, energies,
)
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.results import (
    BELOW_THEORY,
    NOT_CONVERGING,
    NOTHING_TO_MEASURE,
    PRE_ASYMPTOTIC,
    ROUNDING_FLOOR,
    SATURATED,
    SUPERCONVERGENT,
)
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import FramePoses, Trajectory
from simparity.references.common.conventions import rotation_angle
from simparity.core.model.metric_catalogue import (
    order_source,
    units,
    ANGULAR_MOMENTUM_DRIFT_MAX, ANGULAR_VELOCITY_ERROR_MAX, ENERGY_DRIFT_MAX, JACOBIAN_ERROR_MAX,
    ORDER_ANGULAR_VELOCITY, ORDER_ORIENTATION, ORDER_POSITION, ORDER_VELOCITY, ORIENTATION_ERROR_MAX,
    POSITION_ERROR_FINAL, POSITION_ERROR_MAX, QUATERNION_NORM_DEVIATION_MAX, ROTATION_ORTHONORMALITY_DEVIATION_MAX,
    EVALUATIONS_PER_SECOND, TIME_PER_FK, TIME_PER_JACOBIAN, TIME_PER_STEP, TIME_PER_STEP_BATCHED, VELOCITY_ERROR_MAX,
)

DYNAMICS_METRICS = units(
    POSITION_ERROR_MAX,
    POSITION_ERROR_FINAL,
    ORIENTATION_ERROR_MAX,
    VELOCITY_ERROR_MAX,
    ANGULAR_VELOCITY_ERROR_MAX,
    QUATERNION_NORM_DEVIATION_MAX,
    TIME_PER_STEP,
    TIME_PER_STEP_BATCHED,
    EVALUATIONS_PER_SECOND,
)
DRIFT_METRICS = units(ENERGY_DRIFT_MAX, ANGULAR_MOMENTUM_DRIFT_MAX)
ORDER_METRICS = units(
    ORDER_POSITION,
    ORDER_ORIENTATION,
    ORDER_VELOCITY,
    ORDER_ANGULAR_VELOCITY,
)
"""Observed order p of convergence: slope of log(error) against log(dt) over the ladder's
asymptotic range."""
ORDER_SOURCES = {order: order_source(order) for order in ORDER_METRICS}
ROTATIONAL_ORDERS = (ORDER_ORIENTATION, ORDER_ANGULAR_VELOCITY)
"""Orders that need an integrator that moves orientation (point-mass rules do not)."""

KINEMATICS_METRICS = units(
    POSITION_ERROR_MAX,
    ORIENTATION_ERROR_MAX,
    JACOBIAN_ERROR_MAX,
    ROTATION_ORTHONORMALITY_DEVIATION_MAX,
    TIME_PER_FK,
    TIME_PER_JACOBIAN,
)

SATURATED_ORIENTATION = math.pi / 2
"""[rad] An orientation error of a trajectory at or beyond a quarter turn is saturated: the
geodesic angle is bounded by pi and folds an accumulated phase error of 2 pi - a back to a, so
past pi/2 it no longer grows with the true error. Such a value is n/a ("orientation lost"),
and it is left out of order fits. (Frame errors of forward kinematics do not accumulate and
are not saturated.)"""

SATURATED_FRACTION = 0.25
"""A position, velocity or angular-velocity error at or above this fraction of its quantity's own scale
(:func:`saturation_scales`) is saturated: the run is on another orbit, and the error no longer measures how
far. Two states of one scale on unrelated orbits differ by about the scale itself (4/pi of it on average for
vectors of one length in random directions), so an error of a quarter of it is as large as the quantity's
variation; a scheme whose error is a third of |omega| (a torque-free box near its separatrix) has lost the
orbit, which a rule of half the largest possible error (orientation's) would not see. Saturated errors are
n/a with the scale in the detail, and are left out of order fits."""

NEAR_SATURATION = 0.1
"""An order fit below :data:`MIN_CONSISTENT_ORDER` whose errors reach this fraction of saturation is read as
saturating (errors that stop falling within a decade of the quantity's own scale are leaving the orbit); one
whose errors stay below it does not converge (flag ``not-converging``)."""

MIN_CONSISTENT_ORDER = 0.5
"""A consistent scheme's error falls at least as dt^1: a clean fit below half of that is never an order of
convergence (it is saturation, or the errors do not converge)."""

THEORY_BAND = 0.5
"""An observed order more than this away from the scheme's theoretical order is flagged (``superconvergent``
above it, n/a: no scheme converges faster than its order in its asymptotic range; ``below-theory`` under it, ok, for
the gate to judge): half the gap between neighbouring integer orders."""

SATURATED_DRIFT = 1.0
"""A relative drift above 100 % of its scale says the quantity has nothing left in common with its start,
not how far it is off: n/a. (Growth that large is divergence: see comparisons.measure.divergence.)"""

ROUNDING_FLOOR_FACTOR = 2.0
"""The rounding floor of an error after N steps is this x eps x (N + kappa) x the state's scale:
every step rounds the state at eps relative to its size and N such errors add up (linearly at
worst), and a body's inertia condition number kappa amplifies the rounding of its angular
velocity once. Measured rounding of exact schemes (RK4 and midpoint under constant gravity,
up to 40,000 steps; RK4 on a principal-axis spin with kappa = 1000; MuJoCo, Pinocchio, core)
stays below 0.16 of eps x (N + kappa) x scale; the factor leaves at least 10 x margin."""

MIN_FIT_POINTS = 3
"""An order needs three time steps in the asymptotic range: two local slopes that agree."""

ASYMPTOTIC_SLOPE_TOLERANCE = 0.3
"""Local slopes (between neighbouring time steps) within this of the finest pair's are in the
asymptotic range; half the gap between neighbouring integer orders, less the drift of a slope
from the next error term at the ladders used (ratio 2)."""


def _distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.norm(a - b, axis=-1)


@dataclass(frozen=True)
class SaturationScale:
    """The scale an error metric is judged against for saturation, per body.

    Attributes
    ----------
    value : (B,) ndarray
        The scale [the metric's unit]: the largest of ``parts``.
    parts : dict of str to (B,) ndarray
        What it is the largest of, by name (the range of motion, the body's size, ...), for the detail.
    unit : str
    """

    value: np.ndarray
    parts: dict[str, np.ndarray]
    unit: str

    def text(self, body: int) -> str:
        """``2.1 m/s = max(|v| 2.1, sqrt(2 KE/m) 0.9, size/T 0.01)`` for ``body``."""
        parts = ", ".join(f"{name} {values[body]:.3g}" for name, values in self.parts.items())
        return f"{self.value[body]:.3g} {self.unit} = max({parts})"


def saturation_scales(scene: DynamicsScene, ref: Trajectory) -> dict[str, SaturationScale]:
    """:func:`saturation_scales_of` the whole reference trajectory ``ref``."""
    return saturation_scales_of(scene, ReferenceExtents.of(scene, ref))


def saturation_scales_of(scene: DynamicsScene, ref: ReferenceExtents) -> dict[str, SaturationScale]:
    """Per error metric, the scale of its own quantity over the reference trajectory, each with a physical
    floor so it never collapses to zero (a box spinning in place has no range of motion, a body at rest no
    speed), per body:

    - position: max(range of motion max_t |x(t) - x(0)|, the body's size :func:`body_sizes`) [m];
    - velocity: max(max_t |v|, sqrt(2 KE_max / m), position scale / T) [m/s], KE the whole kinetic energy
      (a spinning body's points move though its COM does not);
    - angular velocity: max(max_t |omega|, 1 / T) [rad/s] (a quarter of it is a quarter turn per run), and with
      contact the velocity scale over the size (an impact can turn a body's speed into spin).

    T is the run's duration. Every scale is invariant under a rigid motion of the scene and scales with its
    units; the order of the bodies is theirs.
    """
    mass = np.array([b.mass for b in scene.bodies])
    duration = max(float(ref.end - ref.start), np.finfo(float).tiny)
    kinetic, travel = ref.kinetic_max, ref.travel_max
    length = SaturationScale(np.maximum(travel, body_sizes(scene)), {"range of motion": travel,
                                                                      "size": body_sizes(scene)}, "m")
    speed = ref.speed_max
    energy_speed = np.sqrt(2 * kinetic / mass)
    velocity_parts = {"|v|": speed, "sqrt(2 KE/m)": energy_speed, "position scale/T": length.value / duration}
    spin = ref.spin_max
    spin_parts = {"|omega|": spin, "1/T": np.full(len(mass), 1.0 / duration)}
    if scene.contact is not None:  # an impact can turn a body's speed into spin
        spin_parts["velocity scale/size"] = np.maximum.reduce(list(velocity_parts.values())) / body_sizes(scene)
    velocity = SaturationScale(np.maximum.reduce(list(velocity_parts.values())), velocity_parts, "m/s")
    angular = SaturationScale(np.maximum.reduce(list(spin_parts.values())), spin_parts, "rad/s")
    return {POSITION_ERROR_MAX: length, POSITION_ERROR_FINAL: length, VELOCITY_ERROR_MAX: velocity,
            ANGULAR_VELOCITY_ERROR_MAX: angular}


def _orientation_error(angles: np.ndarray) -> tuple[Measured, float]:
    """(the orientation error of per-body maxima ``angles`` (B,) [rad], its saturation ratio)."""
    angle = float(angles.max())
    ratio = angle / SATURATED_ORIENTATION
    if ratio >= 1:
        return Measured(angle, "rad", flag=SATURATED, unmeasurable=(
            f"saturated: orientation error {angle:.3g} rad >= pi/2, the orientation is lost and the angle "
            "no longer measures how far")), ratio
    return Measured(angle, "rad"), ratio


def _saturating_error(metric: str, errors: np.ndarray, scale: SaturationScale | None) -> tuple[Measured, float]:
    """(the error of per-body maxima ``errors`` (B,), its saturation ratio: the largest error / (fraction x scale)
    over bodies; 0 without a scale)."""
    value, unit = float(errors.max()), scale.unit if scale is not None else ""
    if scale is None:
        return Measured(value, ""), 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = np.where(scale.value > 0, errors / (SATURATED_FRACTION * scale.value), 0.0)
    body = int(np.argmax(ratios))
    ratio = float(ratios[body])
    if ratio >= 1:
        return Measured(value, unit, flag=SATURATED, unmeasurable=(
            f"saturated: {metric.replace('_', ' ').removesuffix(' max')} {errors[body]:.3g} {unit} >= "
            f"{SATURATED_FRACTION:g} x the body's scale {scale.text(body)}: the run is on another orbit")), ratio
    return Measured(value, unit), ratio


_ERROR_UNITS = units(
    POSITION_ERROR_MAX,
    POSITION_ERROR_FINAL,
    VELOCITY_ERROR_MAX,
    ANGULAR_VELOCITY_ERROR_MAX,
)


def trajectory_errors(traj: Trajectory, ref: Trajectory,
                      scales: dict[str, SaturationScale] | None = None) -> dict[str, Measured]:
    """Position, orientation (geodesic angle) and velocity errors of ``traj`` against ``ref``, maxima over
    bodies; with ``scales`` (:func:`saturation_scales`) an error at or above :data:`SATURATED_FRACTION` of its
    body's scale is saturated (n/a, the scale in its reason). :func:`saturation_ratios` gives how near each is."""
    return judged_errors(ErrorExtents.of(traj, ref), scales)


def judged_errors(errors: ErrorExtents, scales: dict[str, SaturationScale] | None = None) -> dict[str, Measured]:
    """:func:`trajectory_errors` of a run's per-body errors ``errors``."""
    return {metric: measured for metric, (measured, _) in _errors(errors, scales).items()}


def saturation_ratios(errors: ErrorExtents, scales: dict[str, SaturationScale]) -> dict[str, float]:
    """Per error metric, its largest error over the bodies' saturation thresholds (>= 1: saturated)."""
    return {metric: ratio for metric, (_, ratio) in _errors(errors, scales).items()}


def _errors(errors: ErrorExtents, scales: dict[str, SaturationScale] | None) -> dict[str, tuple[Measured, float]]:
    out = {}
    for metric in (POSITION_ERROR_MAX, POSITION_ERROR_FINAL, VELOCITY_ERROR_MAX, ANGULAR_VELOCITY_ERROR_MAX):
        measured, ratio = _saturating_error(metric, errors.per_body[metric], None if scales is None else scales[metric])
        out[metric] = (Measured(measured.value, _ERROR_UNITS[metric], measured.unmeasurable, flag=measured.flag),
                       ratio)
    out[ORIENTATION_ERROR_MAX] = _orientation_error(errors.per_body[ORIENTATION_ERROR_MAX])
    return {m: out[m] for m in (POSITION_ERROR_MAX, POSITION_ERROR_FINAL, ORIENTATION_ERROR_MAX,
                                VELOCITY_ERROR_MAX, ANGULAR_VELOCITY_ERROR_MAX)}


def state_validity(run: RunExtents) -> dict[str, Measured]:
    """Whether the states an engine reports are states: ``quaternion_norm_deviation_max`` = max | |q| - 1 | over
    samples and bodies (a unit quaternion up to rounding; an orientation that is not one is no rotation at all,
    whatever its angle to the reference's)."""
    return {QUATERNION_NORM_DEVIATION_MAX: Measured(run.quaternion_deviation_max, "1")}


def frame_validity(poses: FramePoses) -> dict[str, Measured]:
    """``rotation_orthonormality_deviation_max`` = max |R^T R - I| (entries) over configurations and frames: a
    rotation matrix up to rounding."""
    rotation = np.asarray(poses.rotation_world, dtype=float)
    gram = np.einsum("...ji,...jk->...ik", rotation, rotation) - np.eye(3)
    return {ROTATION_ORTHONORMALITY_DEVIATION_MAX: Measured(float(np.abs(gram).max()), "1")}


def kinematics_errors(poses: FramePoses, jacobian: np.ndarray, ref_poses: FramePoses,
                      ref_jacobian: np.ndarray) -> dict[str, Measured]:
    """Frame position, frame orientation and Jacobian errors against the reference's."""
    return {
        POSITION_ERROR_MAX: Measured(float(_distance(poses.position_world, ref_poses.position_world).max()), "m"),
        ORIENTATION_ERROR_MAX: Measured(
            float(rotation_angle(poses.rotation_world, ref_poses.rotation_world).max()), "rad"),
        JACOBIAN_ERROR_MAX: Measured(float(np.abs(jacobian - ref_jacobian).max()), "m/rad or 1"),
    }


def dynamics_metrics(scene: DynamicsScene) -> dict[str, str]:
    """The per-case metrics of a scene: errors, time and cost, plus drift of what the scene conserves."""
    metrics = dict(DYNAMICS_METRICS)
    if scene.contact is not None:  # contact takes energy away and turns bodies: nothing is conserved
        return metrics | CONTACT_METRICS
    if scene.forces.conserves_energy:
        metrics[ENERGY_DRIFT_MAX] = DRIFT_METRICS[ENERGY_DRIFT_MAX]
    if scene.forces.conserves_angular_momentum and any(np.any(b.angular_velocity_world) for b in scene.bodies):
        metrics[ANGULAR_MOMENTUM_DRIFT_MAX] = DRIFT_METRICS[ANGULAR_MOMENTUM_DRIFT_MAX]
    return metrics


def headline_metric(scene: DynamicsScene) -> str:
    """The error a report ranks a dynamics scene's schemes by: the orientation error when a body
    turns (it starts spinning or a force exerts a torque), else the position error."""
    turns = scene.forces.exerts_torque or any(np.any(b.angular_velocity_world != 0) for b in scene.bodies)
    return ORIENTATION_ERROR_MAX if turns else POSITION_ERROR_MAX


def _relative_drift(change_max: np.ndarray, scale: np.ndarray, quantity: str) -> Measured:
    """Largest change / scale over bodies with a non-zero scale; change_max (B,) the largest change over the run,
    scale (B,)."""
    measurable = scale > 0
    if not measurable.any():
        return Measured(math.nan, "1", flag=NOTHING_TO_MEASURE,
                        unmeasurable=f"nothing to measure {quantity} drift against: it is 0")
    drift = float((change_max[measurable] / scale[measurable]).max())
    if drift > SATURATED_DRIFT:
        return Measured(drift, "1", flag=SATURATED, unmeasurable=(
            f"saturated: {quantity} changed by {drift:.3g} x its scale (> {SATURATED_DRIFT:.0%})"))
    return Measured(drift, "1")


def energy_scale(scene: DynamicsScene, energy: EnergyExtents) -> np.ndarray:
    """(B,) [J] what a body's energy drift is relative to (:func:`comparisons.measure.body_scales.energy_scales`)."""
    return energy_scales(scene, energy.kinetic0, energy.potential0, energy.potential_min)


def drifts(scene: DynamicsScene, traj: Trajectory) -> dict[str, Measured]:
    """:func:`drifts_of` the whole trajectory ``traj``."""
    return drifts_of(scene, RunExtents.of(scene, traj))


def drifts_of(scene: DynamicsScene, run: RunExtents) -> dict[str, Measured]:
    """Relative drifts of what the scene conserves (:func:`dynamics_metrics`), the worst body's:

    - ``energy_drift_max`` = max_t |E(t) - E(0)| / the body's energy scale
      (:func:`comparisons.measure.body_scales.energy_scales`: |E(0)| without gravity; with gravity not |E(0)|, which
      depends on where the origin is, but the kinetic energy the body has to trade);
    - ``angular_momentum_drift_max`` = max_t |L(t) - L(0)| / |L(0)|, L about the COM.
    """
    wanted = dynamics_metrics(scene)
    out = {}
    if ENERGY_DRIFT_MAX in wanted and run.energy is not None:
        out[ENERGY_DRIFT_MAX] = _relative_drift(run.energy.change_abs_max, energy_scale(scene, run.energy), "energy")
    if ANGULAR_MOMENTUM_DRIFT_MAX in wanted and run.momentum is not None:
        out[ANGULAR_MOMENTUM_DRIFT_MAX] = _relative_drift(run.momentum.change_max, run.momentum.size0,
                                                            "angular momentum")
    return out


def rounding_floors(scene: DynamicsScene, traj: Trajectory, n_steps: int) -> dict[str, float]:
    """:func:`rounding_floors_of` the whole trajectory ``traj``."""
    return rounding_floors_of(scene, RunExtents.of(scene, traj), n_steps)


def rounding_floors_of(scene: DynamicsScene, run: RunExtents, n_steps: int) -> dict[str, float]:
    """The rounding floor of each error metric after ``n_steps`` steps (see :data:`ROUNDING_FLOOR_FACTOR`).

    The state's scale: |x| + T |v| for positions [m] (a velocity rounded at each step moves the
    position for the rest of the run), |v| for velocities [m/s], 1 + T |omega| for orientations
    [rad], |omega| for angular velocities [rad/s]; maxima over the run. With contact, the velocity's floor adds
    what rounding the impacts' timing adds (:func:`event_velocity_floor`).
    """
    duration = run.duration
    speed = float(run.speed_max.max())
    spin = float(run.spin_max.max())
    scales = {
        POSITION_ERROR_MAX: float(run.position_norm_max.max()) + duration * speed,
        VELOCITY_ERROR_MAX: speed,
        ORIENTATION_ERROR_MAX: 1.0 + duration * spin,
        ANGULAR_VELOCITY_ERROR_MAX: spin,
    }
    kappa = max(np.linalg.cond(b.inertia_body) for b in scene.bodies)
    unit_roundoff = ROUNDING_FLOOR_FACTOR * np.finfo(float).eps * (max(n_steps, 1) + kappa)
    floors = {metric: unit_roundoff * scale for metric, scale in scales.items()}
    floors[VELOCITY_ERROR_MAX] += event_velocity_floor(scene, floors[POSITION_ERROR_MAX])
    return floors


def event_velocity_floor(scene: DynamicsScene, gap: float) -> float:
    """[m/s] What rounding a contact event's timing adds to the velocity's rounding floor.

    An impact is timed from the body's gap to a plane, known to ``gap`` [m] (the position's rounding floor: it
    grows with the distance from the origin); its time is off by gap / v_n, and the rebound, |g| (1 + k) times
    that, by at most 2 |g| gap / v_n. The slowest impact a scene has is one at its rest speed (slower ones end in
    resting contact), and never slower than a fall through the gap itself, sqrt(2 |g| gap). 0 without contact or
    gravity.
    """
    gravity = scene.forces.gravity_world
    if scene.contact is None or gravity is None or gap <= 0.0:
        return 0.0
    g = float(np.linalg.norm(gravity))
    slowest = max(scene.contact.rest_speed, math.sqrt(2.0 * g * gap))
    return 2.0 * g * gap / slowest if slowest > 0.0 else 0.0


def at_rounding_floor(errors: dict[str, Measured], floors: dict[str, float]) -> dict[str, Measured]:
    """``errors`` with each measured error at or below its rounding floor (:func:`rounding_floors`; the final
    position error has the position's) flagged ``rounding-floor``: still a number, but exact up to rounding, so
    that nothing compares it as a truncation error (an order fit leaves it out, a cross-check skips it)."""
    out = dict(errors)
    for metric, measured in errors.items():
        floor = floors.get(metric.replace("_final", "_max"))
        if floor is not None and not measured.unmeasurable and measured.value <= floor:
            out[metric] = Measured(measured.value, measured.unit, note=(
                f"at the rounding floor ({floor:.2g}): exact up to rounding"), flag=ROUNDING_FLOOR)
    return out


def _local_slopes(dts: np.ndarray, errors: np.ndarray) -> np.ndarray:
    return np.diff(np.log(errors)) / np.diff(np.log(dts))


def observed_order(dts, errors, floors=0.0, saturation=0.0, theory: int | None = None) -> Measured:
    """Observed order of convergence over a ladder of time steps, or why there is none.

    Parameters
    ----------
    dts : (K,) array_like
        Time steps [s].
    errors : (K,) array_like
        The error at each time step (NaN where none was measured).
    floors : float or (K,) array_like
        Rounding floor of each error (:func:`rounding_floors`); errors at or below it are rounding,
        not truncation, and are left out.
    saturation : float or (K,) array_like
        Saturation ratio of each error (:func:`saturation_ratios`; orientation: angle / (pi/2)); errors at
        a ratio of 1 or more are saturated and left out.
    theory : int or None
        The scheme's theoretical order (None: unknown).

    The fit is a least-squares line of log(error) against log(dt) over the finest time steps
    whose local slopes agree with the finest pair's (:data:`ASYMPTOTIC_SLOPE_TOLERANCE`); at
    least :data:`MIN_FIT_POINTS` are needed. The note gives the range, the local slopes and the
    largest log residual. What the fit shows is typed in the flag (:data:`core.results.FLAGS`): n/a when
    saturated, at the rounding floor, pre-asymptotic or not converging (a clean fit below
    :data:`MIN_CONSISTENT_ORDER`: saturating when its errors reach :data:`NEAR_SATURATION` of saturation,
    rounding when they stay within :data:`ROUNDING_MARGIN` of the floor, else ``not-converging``, an alarm).
    Against ``theory`` the fit is bounded on both sides: more than :data:`THEORY_BAND` above it, n/a flagged
    ``superconvergent`` (the fitted value kept for the harness, the local slopes in the reason: the steps are not in
    the scheme's asymptotic range, whose order is its theory); more than :data:`THEORY_BAND` below it, ok but flagged
    ``below-theory`` (a scheme that is not what it claims: the gate's lower bound decides). So an ``ok`` order with a
    known theory lies within :data:`THEORY_BAND` of it or under it, never above.
    """
    dts, errors = np.asarray(dts, dtype=float), np.asarray(errors, dtype=float)
    floors = np.broadcast_to(np.asarray(floors, dtype=float), dts.shape)
    ratios = np.broadcast_to(np.asarray(saturation, dtype=float), dts.shape)
    order = np.argsort(dts)
    dts, errors, floors, ratios = dts[order], errors[order], floors[order], ratios[order]
    measured = np.isfinite(errors)
    at_floor = measured & (errors <= floors)
    saturated = measured & ~at_floor & (ratios >= 1)
    usable = measured & ~at_floor & ~saturated
    left_out = []
    if at_floor.any():
        left_out.append(f"{at_floor.sum()} at the rounding floor, error <= {floors[at_floor].max():.2g}: "
                        "exact up to rounding")
    if saturated.any():
        left_out.append(f"{saturated.sum()} saturated (error >= its saturation threshold)")
    if (~measured).any():
        left_out.append(f"{(~measured).sum()} without an error (not run, failed or diverged)")
    why = "; ".join(left_out)
    if usable.sum() < MIN_FIT_POINTS:
        flag = (SATURATED if saturated.sum() >= max(at_floor.sum(), 1) else ROUNDING_FLOOR if at_floor.any()
                else "")
        return Measured(math.nan, "1", flag=flag, unmeasurable=(
            f"too few time steps above the rounding floor and below saturation: {usable.sum()} of {len(dts)}, "
            f"an order needs {MIN_FIT_POINTS}" + (f" ({why})" if why else "")))
    x, y, fit_floors, fit_ratios = dts[usable], errors[usable], floors[usable], ratios[usable]
    slopes = _local_slopes(x, y)
    agree = np.abs(slopes - slopes[0]) <= ASYMPTOTIC_SLOPE_TOLERANCE
    n_slopes = int(np.argmin(agree)) if not agree.all() else len(slopes)
    slope_text = ", ".join(f"{s:.3g}" for s in slopes)
    if n_slopes + 1 < MIN_FIT_POINTS:
        return Measured(math.nan, "1", flag=PRE_ASYMPTOTIC, unmeasurable=(
            f"not in the asymptotic range: local slopes {slope_text} (finest first) differ by more than "
            f"{ASYMPTOTIC_SLOPE_TOLERANCE:g}; finer time steps are needed"))
    fitted = slice(0, n_slopes + 1)
    lx, ly = np.log(x[fitted]), np.log(y[fitted])
    slope, intercept = np.polyfit(lx, ly, 1)
    residual = float(np.max(np.abs(ly - (slope * lx + intercept))))
    note = (f"fit over dt {x[0]:.3g}..{x[n_slopes]:.3g} ({n_slopes + 1} of {len(dts)} time steps), "
            f"local slopes {slope_text} (finest first), max log residual {residual:.2g}")
    if why:
        note += f"; left out: {why}"
    if slope < MIN_CONSISTENT_ORDER:
        return _inconsistent_fit(float(slope), note, fit_ratios[fitted], y[fitted] / np.maximum(fit_floors[fitted],
                                                                                                 np.finfo(float).tiny))
    if theory is not None and slope > theory + THEORY_BAND:
        return Measured(float(slope), "1", flag=SUPERCONVERGENT, unmeasurable=(
            f"superconvergent: {slope:.3g} > theory {theory} + {THEORY_BAND:g}, outside the asymptotic range (the "
            f"steps are before it, or error terms cancel): no order of the scheme; {note}"))
    if theory is not None and slope < theory - THEORY_BAND:
        return Measured(float(slope), "1", flag=BELOW_THEORY, note=(
            f"below theory: {slope:.3g} < theory {theory} - {THEORY_BAND:g}; {note}"))
    return Measured(float(slope), "1", note=note)


ROUNDING_MARGIN = 100.0
"""A clean fit below :data:`MIN_CONSISTENT_ORDER` whose errors all stay within this factor of their rounding
floor is rounding (or the reference's own error, of the same size) that the floor's estimate did not cover,
not a scheme that fails to converge."""


def _inconsistent_fit(slope: float, note: str, ratios: np.ndarray, above_floor: np.ndarray) -> Measured:
    """The n/a of a clean fit of order ``slope`` < :data:`MIN_CONSISTENT_ORDER`, with what its data supports:
    saturating (``ratios``, the errors' saturation ratios, reach :data:`NEAR_SATURATION`), rounding (every
    error within :data:`ROUNDING_MARGIN` of its floor, ``above_floor`` = error / floor) or not converging."""
    head = f"the errors fall only as dt^{slope:.3g} (a consistent scheme's fall at least as dt^1)"
    if ratios.max() >= NEAR_SATURATION:
        return Measured(slope, "1", flag=SATURATED, unmeasurable=(
            f"saturated: {head} within a decade of saturation (at {ratios.max():.2g} of it): the run is leaving "
            f"the orbit; {note}"))
    if above_floor.max() <= ROUNDING_MARGIN:
        return Measured(slope, "1", flag=ROUNDING_FLOOR, unmeasurable=(
            f"rounding: {head} within {ROUNDING_MARGIN:g} x the rounding floor (at most {above_floor.max():.3g} x "
            f"it): rounding or the reference's own error; {note}"))
    return Measured(slope, "1", flag=NOT_CONVERGING, unmeasurable=(
        f"not converging: {head} far from saturation (at most {ratios.max():.2g} of it) and from the rounding "
        f"floor: the scheme is inconsistent, or something dt does not control dominates (the reference's own "
        f"error, a discontinuity); {note}"))
