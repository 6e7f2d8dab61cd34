"""Error metrics of a trajectory or a kinematic evaluation against a reference, drifts, and
observed orders of convergence. Definitions with their reasons: ``docs/metrics.md``.

Each function returns ``{metric: Measured}``. Errors are maxima over every body, sample and
frame; "final" is at the last sample. A value that cannot mean anything (saturated, at the
rounding floor, nothing to compare against) is returned unmeasurable with the reason, and
becomes an ``n/a`` row. Rotations are SciPy's (:mod:`references.conventions`), never the
in-house code these metrics judge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simparity.comparisons.contact_metrics import CONTACT_METRICS
from simparity.comparisons.invariants import angular_momentum_world, kinetic_energy, potential_energy
from simparity.comparisons.rows import Measured
from simparity.core.scene import DynamicsScene
from simparity.core.trajectory import FramePoses, Trajectory
from simparity.references.conventions import quat_wxyz_angle, quat_wxyz_to_matrix, rotation_angle

DYNAMICS_METRICS = {
    "position_error_max": "m",
    "position_error_final": "m",
    "orientation_error_max": "rad",
    "velocity_error_max": "m/s",
    "angular_velocity_error_max": "rad/s",
    "time_per_step": "s",
}
DRIFT_METRICS = {"energy_drift_max": "1", "angular_momentum_drift_max": "1"}
ORDER_METRICS = {
    "order_position": "1",
    "order_orientation": "1",
    "order_velocity": "1",
    "order_angular_velocity": "1",
}
"""Observed order p of convergence: slope of log(error) against log(dt) over the ladder's
asymptotic range."""
ORDER_SOURCES = {
    "order_position": "position_error_max",
    "order_orientation": "orientation_error_max",
    "order_velocity": "velocity_error_max",
    "order_angular_velocity": "angular_velocity_error_max",
}
ROTATIONAL_ORDERS = ("order_orientation", "order_angular_velocity")
"""Orders that need an integrator that moves orientation (point-mass rules do not)."""

KINEMATICS_METRICS = {
    "position_error_max": "m",
    "orientation_error_max": "rad",
    "jacobian_error_max": "m/rad or 1",
    "time_per_fk": "s",
    "time_per_jacobian": "s",
}

SATURATED_ORIENTATION = math.pi / 2
"""[rad] An orientation error of a trajectory at or beyond a quarter turn is saturated: the
geodesic angle is bounded by pi and folds an accumulated phase error of 2 pi - a back to a, so
past pi/2 it no longer grows with the true error. Such a value is n/a ("orientation lost"),
and it is left out of order fits. (Frame errors of forward kinematics do not accumulate and
are not saturated.)"""

SATURATED_DRIFT = 1.0
"""A relative drift above 100 % says the quantity has nothing left in common with its start,
not how far it is off: n/a. (Growth that large is divergence: see comparisons.divergence.)"""

ENERGY_NEAR_ZERO = 1e-3
"""|E(0)| below this fraction of the run's largest energy term (kinetic plus |potential|) is
"near zero": dividing by it would turn rounding into drift. The drift is then relative to the
run's largest kinetic energy, and the row says so."""

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


def _orientation_error(angle: float) -> Measured:
    if angle >= SATURATED_ORIENTATION:
        return Measured(angle, "rad", unmeasurable=(
            f"saturated: orientation error {angle:.3g} rad >= pi/2, the orientation is lost and the angle "
            "no longer measures how far"))
    return Measured(angle, "rad")


def trajectory_errors(traj: Trajectory, ref: Trajectory) -> dict[str, Measured]:
    """Position, orientation (geodesic angle) and velocity errors of ``traj`` against ``ref``."""
    if traj.position_world.shape != ref.position_world.shape:
        raise ValueError(f"trajectory shape {traj.position_world.shape} != reference {ref.position_world.shape}")
    position = _distance(traj.position_world, ref.position_world)
    return {
        "position_error_max": Measured(float(position.max()), "m"),
        "position_error_final": Measured(float(position[-1].max()), "m"),
        "orientation_error_max": _orientation_error(float(quat_wxyz_angle(traj.quat_wxyz, ref.quat_wxyz).max())),
        "velocity_error_max": Measured(float(_distance(traj.velocity_world, ref.velocity_world).max()), "m/s"),
        "angular_velocity_error_max": Measured(
            float(_distance(traj.angular_velocity_world, ref.angular_velocity_world).max()), "rad/s"),
    }


def kinematics_errors(poses: FramePoses, jacobian: np.ndarray, ref_poses: FramePoses,
                      ref_jacobian: np.ndarray) -> dict[str, Measured]:
    """Frame position, frame orientation and Jacobian errors against the reference's."""
    return {
        "position_error_max": Measured(float(_distance(poses.position_world, ref_poses.position_world).max()), "m"),
        "orientation_error_max": Measured(
            float(rotation_angle(poses.rotation_world, ref_poses.rotation_world).max()), "rad"),
        "jacobian_error_max": Measured(float(np.abs(jacobian - ref_jacobian).max()), "m/rad or 1"),
    }


def dynamics_metrics(scene: DynamicsScene) -> dict[str, str]:
    """The per-case metrics of a scene: errors and time, plus drift of what the scene conserves."""
    metrics = dict(DYNAMICS_METRICS)
    if scene.contact is not None:  # contact takes energy away and turns bodies: nothing is conserved
        return metrics | CONTACT_METRICS
    if scene.forces.conserves_energy:
        metrics["energy_drift_max"] = DRIFT_METRICS["energy_drift_max"]
    if scene.forces.conserves_angular_momentum and any(np.any(b.angular_velocity_world) for b in scene.bodies):
        metrics["angular_momentum_drift_max"] = DRIFT_METRICS["angular_momentum_drift_max"]
    return metrics


def headline_metric(scene: DynamicsScene) -> str:
    """The error a report ranks a dynamics scene's schemes by: the orientation error when a body
    turns (it starts spinning or a force exerts a torque), else the position error."""
    turns = scene.forces.exerts_torque or any(np.any(b.angular_velocity_world != 0) for b in scene.bodies)
    return "orientation_error_max" if turns else "position_error_max"


def energies(scene: DynamicsScene, traj: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(total E, kinetic, potential) [J] per sample and body, each (T, B); potential -m g.x, zero at
    the world origin (0 without gravity)."""
    mass = np.array([b.mass for b in scene.bodies])
    inertia = np.stack([b.inertia_body for b in scene.bodies])
    rotation = quat_wxyz_to_matrix(traj.quat_wxyz)
    kinetic = kinetic_energy(mass, inertia, traj.velocity_world, traj.angular_velocity_world, rotation)
    potential = (np.zeros_like(kinetic) if scene.forces.gravity_world is None
                 else potential_energy(mass, scene.forces.gravity_world, traj.position_world))
    return kinetic + potential, kinetic, potential


def energy_scale(kinetic: np.ndarray, potential: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(what energy drift is relative to, per body (B,); True where that is the fallback).

    |E(0)|, or the largest kinetic energy of the run where |E(0)| is near zero
    (:data:`ENERGY_NEAR_ZERO`)."""
    energy0 = np.abs(kinetic[0] + potential[0])
    magnitude = (kinetic + np.abs(potential)).max(axis=0)
    fallback = energy0 < ENERGY_NEAR_ZERO * magnitude
    return np.where(fallback, kinetic.max(axis=0), energy0), fallback


def _relative_drift(change: np.ndarray, scale: np.ndarray, quantity: str) -> Measured:
    """Largest change / scale over bodies with a non-zero scale; change (T, B), scale (B,)."""
    measurable = scale > 0
    if not measurable.any():
        return Measured(math.nan, "1", unmeasurable=f"nothing to measure {quantity} drift against: it is 0")
    drift = float((change[:, measurable] / scale[measurable]).max())
    if drift > SATURATED_DRIFT:
        return Measured(drift, "1", unmeasurable=(
            f"saturated: {quantity} changed by {drift:.3g} x its initial size (> {SATURATED_DRIFT:.0%})"))
    return Measured(drift, "1")


@dataclass(frozen=True)
class ConservedChanges:
    """How far what a scene conserves moved, per sample and body; None where the scene does not
    conserve it (:func:`dynamics_metrics`). Computed once per case, read by the drift metrics and
    the sampled series.

    Attributes
    ----------
    energy : (T, B) ndarray or None
        E(t) - E(0) [J], signed.
    energy_scale : (B,) ndarray or None
        What energy drift is relative to (:func:`energy_scale`).
    energy_fallback : (B,) ndarray of bool or None
        Where that scale is the fallback (|E(0)| near zero).
    angular_momentum : (T, B) ndarray or None
        |L(t) - L(0)| [kg m^2/s], L about the COM.
    angular_momentum_size : (B,) ndarray or None
        |L(0)|.
    """

    energy: np.ndarray | None = None
    energy_scale: np.ndarray | None = None
    energy_fallback: np.ndarray | None = None
    angular_momentum: np.ndarray | None = None
    angular_momentum_size: np.ndarray | None = None


def conserved_changes(scene: DynamicsScene, traj: Trajectory) -> ConservedChanges:
    """Energy and angular momentum changes of ``traj`` where the scene conserves them."""
    wanted = dynamics_metrics(scene)
    out = {}
    if "energy_drift_max" in wanted:
        energy, kinetic, potential = energies(scene, traj)
        scale, fallback = energy_scale(kinetic, potential)
        out |= {"energy": energy - energy[0], "energy_scale": scale, "energy_fallback": fallback}
    if "angular_momentum_drift_max" in wanted:
        inertia = np.stack([b.inertia_body for b in scene.bodies])
        momentum = angular_momentum_world(inertia, traj.angular_velocity_world, quat_wxyz_to_matrix(traj.quat_wxyz))
        out |= {"angular_momentum": np.linalg.norm(momentum - momentum[0], axis=-1),
                "angular_momentum_size": np.linalg.norm(momentum[0], axis=-1)}
    return ConservedChanges(**out)


def drifts(scene: DynamicsScene, traj: Trajectory, changes: ConservedChanges | None = None) -> dict[str, Measured]:
    """Relative drifts of what the scene conserves, the worst body's:

    - ``energy_drift_max`` = max_t |E(t) - E(0)| / |E(0)| (fallback: :func:`energy_scale`);
    - ``angular_momentum_drift_max`` = max_t |L(t) - L(0)| / |L(0)|, L about the COM.

    ``changes``: :func:`conserved_changes` of ``traj`` when already computed.
    """
    changes = changes or conserved_changes(scene, traj)
    out = {}
    if changes.energy is not None:
        scale = changes.energy_scale
        drift = _relative_drift(np.abs(changes.energy), scale, "energy")
        if changes.energy_fallback[scale > 0].any() and not drift.unmeasurable:
            drift = Measured(drift.value, "1", note=(
                f"relative to the run's largest kinetic energy: |E(0)| < {ENERGY_NEAR_ZERO:g} x its energies"))
        out["energy_drift_max"] = drift
    if changes.angular_momentum is not None:
        out["angular_momentum_drift_max"] = _relative_drift(changes.angular_momentum, changes.angular_momentum_size,
                                                            "angular momentum")
    return out


def rounding_floors(scene: DynamicsScene, traj: Trajectory, n_steps: int) -> dict[str, float]:
    """The rounding floor of each error metric after ``n_steps`` steps (see :data:`ROUNDING_FLOOR_FACTOR`).

    The state's scale: |x| + T |v| for positions [m] (a velocity rounded at each step moves the
    position for the rest of the run), |v| for velocities [m/s], 1 + T |omega| for orientations
    [rad], |omega| for angular velocities [rad/s]; maxima over the run.
    """
    duration = float(traj.times[-1] - traj.times[0])
    speed = float(np.linalg.norm(traj.velocity_world, axis=-1).max())
    spin = float(np.linalg.norm(traj.angular_velocity_world, axis=-1).max())
    scales = {
        "position_error_max": float(np.linalg.norm(traj.position_world, axis=-1).max()) + duration * speed,
        "velocity_error_max": speed,
        "orientation_error_max": 1.0 + duration * spin,
        "angular_velocity_error_max": spin,
    }
    kappa = max(np.linalg.cond(b.inertia_body) for b in scene.bodies)
    unit_roundoff = ROUNDING_FLOOR_FACTOR * np.finfo(float).eps * (max(n_steps, 1) + kappa)
    return {metric: unit_roundoff * scale for metric, scale in scales.items()}


def _local_slopes(dts: np.ndarray, errors: np.ndarray) -> np.ndarray:
    return np.diff(np.log(errors)) / np.diff(np.log(dts))


def observed_order(dts, errors, floors=0.0, saturation: float = math.inf) -> Measured:
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
    saturation : float
        Errors at or above it are saturated and left out.

    The fit is a least-squares line of log(error) against log(dt) over the finest time steps
    whose local slopes agree with the finest pair's (:data:`ASYMPTOTIC_SLOPE_TOLERANCE`); at
    least :data:`MIN_FIT_POINTS` are needed. The note gives the range, the local slopes and the
    largest log residual.
    """
    dts, errors = np.asarray(dts, dtype=float), np.asarray(errors, dtype=float)
    floors = np.broadcast_to(np.asarray(floors, dtype=float), dts.shape)
    order = np.argsort(dts)
    dts, errors, floors = dts[order], errors[order], floors[order]
    measured = np.isfinite(errors)
    at_floor = measured & (errors <= floors)
    saturated = measured & (errors >= saturation)
    usable = measured & ~at_floor & ~saturated
    left_out = []
    if at_floor.any():
        left_out.append(f"{at_floor.sum()} at the rounding floor, error <= {floors[at_floor].max():.2g}: "
                        "exact up to rounding")
    if saturated.any():
        left_out.append(f"{saturated.sum()} saturated (error >= {saturation:.3g})")
    if (~measured).any():
        left_out.append(f"{(~measured).sum()} without an error (not run, failed or diverged)")
    why = "; ".join(left_out)
    if usable.sum() < MIN_FIT_POINTS:
        return Measured(math.nan, "1", unmeasurable=(
            f"too few time steps above the rounding floor and below saturation: {usable.sum()} of {len(dts)}, "
            f"an order needs {MIN_FIT_POINTS}" + (f" ({why})" if why else "")))
    x, y = dts[usable], errors[usable]
    slopes = _local_slopes(x, y)
    agree = np.abs(slopes - slopes[0]) <= ASYMPTOTIC_SLOPE_TOLERANCE
    n_slopes = int(np.argmin(agree)) if not agree.all() else len(slopes)
    slope_text = ", ".join(f"{s:.3g}" for s in slopes)
    if n_slopes + 1 < MIN_FIT_POINTS:
        return Measured(math.nan, "1", unmeasurable=(
            f"not in the asymptotic range: local slopes {slope_text} (finest first) differ by more than "
            f"{ASYMPTOTIC_SLOPE_TOLERANCE:g}; finer time steps are needed"))
    lx, ly = np.log(x[: n_slopes + 1]), np.log(y[: n_slopes + 1])
    slope, intercept = np.polyfit(lx, ly, 1)
    residual = float(np.max(np.abs(ly - (slope * lx + intercept))))
    note = (f"fit over dt {x[0]:.3g}..{x[n_slopes]:.3g} ({n_slopes + 1} of {len(dts)} time steps), "
            f"local slopes {slope_text} (finest first), max log residual {residual:.2g}")
    if why:
        note += f"; left out: {why}"
    return Measured(float(slope), "1", note=note)
