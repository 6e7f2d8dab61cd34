"""Error metrics of a trajectory or a kinematic evaluation against a reference.

Each function returns ``{metric: (value, unit)}``. Errors are maxima over every body,
sample and frame; "final" is at the last sample.
"""

from __future__ import annotations

import math

import numpy as np

from simparity.comparisons.invariants import angular_momentum_world, kinetic_energy, potential_energy
from simparity.core.rotations import geodesic_angle_matrix, geodesic_angle_quat_wxyz, quat_wxyz_to_matrix
from simparity.core.scene import DynamicsScene
from simparity.core.trajectory import FramePoses, Trajectory

DYNAMICS_METRICS = {
    "position_error_max": "m",
    "position_error_final": "m",
    "orientation_error_max": "rad",
    "velocity_error_max": "m/s",
    "angular_velocity_error_max": "rad/s",
    "time_per_step": "s",
}
DRIFT_METRICS = {"energy_drift_max": "1", "angular_momentum_drift_max": "1"}
ORDER_METRICS = {"order_position": "1", "order_orientation": "1"}
"""Observed order p of convergence, from a least-squares fit of log(error) = p log(dt) + c."""

ROUNDING_FLOOR = 1e-11
"""Errors below this absolute value ([m] for positions, [rad] for orientations, both of order
1 in the library's scenes) are rounding, not truncation: they are left out of order fits."""

KINEMATICS_METRICS = {
    "position_error_max": "m",
    "orientation_error_max": "rad",
    "jacobian_error_max": "m/rad or 1",
    "time_per_fk": "s",
    "time_per_jacobian": "s",
}


def _distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.norm(a - b, axis=-1)


def trajectory_errors(traj: Trajectory, ref: Trajectory) -> dict[str, tuple[float, str]]:
    """Position, orientation (geodesic angle) and velocity errors of ``traj`` against ``ref``."""
    if traj.position_world.shape != ref.position_world.shape:
        raise ValueError(f"trajectory shape {traj.position_world.shape} != reference {ref.position_world.shape}")
    position = _distance(traj.position_world, ref.position_world)
    return {
        "position_error_max": (float(position.max()), "m"),
        "position_error_final": (float(position[-1].max()), "m"),
        "orientation_error_max": (float(geodesic_angle_quat_wxyz(traj.quat_wxyz, ref.quat_wxyz).max()), "rad"),
        "velocity_error_max": (float(_distance(traj.velocity_world, ref.velocity_world).max()), "m/s"),
        "angular_velocity_error_max": (
            float(_distance(traj.angular_velocity_world, ref.angular_velocity_world).max()), "rad/s"),
    }


def kinematics_errors(
    poses: FramePoses, jacobian: np.ndarray, ref_poses: FramePoses, ref_jacobian: np.ndarray
) -> dict[str, tuple[float, str]]:
    """Frame position, frame orientation and Jacobian errors against the reference's."""
    return {
        "position_error_max": (float(_distance(poses.position_world, ref_poses.position_world).max()), "m"),
        "orientation_error_max": (
            float(geodesic_angle_matrix(poses.rotation_world, ref_poses.rotation_world).max()), "rad"),
        "jacobian_error_max": (float(np.abs(jacobian - ref_jacobian).max()), "m/rad or 1"),
    }


def dynamics_metrics(scene: DynamicsScene) -> dict[str, str]:
    """The per-case metrics of a scene: errors and time, plus drift of what the scene conserves."""
    metrics = dict(DYNAMICS_METRICS)
    if scene.forces.conserves_energy:
        metrics["energy_drift_max"] = DRIFT_METRICS["energy_drift_max"]
    if scene.forces.conserves_angular_momentum and any(np.any(b.angular_velocity_world) for b in scene.bodies):
        metrics["angular_momentum_drift_max"] = DRIFT_METRICS["angular_momentum_drift_max"]
    return metrics


def drifts(scene: DynamicsScene, traj: Trajectory) -> dict[str, tuple[float, str]]:
    """Relative drifts, per body (the worst is kept): max_t |E(t) - E(0)| / max(|E(0)|, max_t kinetic
    energy) and max_t |L(t) - L(0)| / |L(0)|; NaN when no body has anything to compare against.
    """
    wanted = dynamics_metrics(scene)
    mass = np.array([b.mass for b in scene.bodies])
    inertia = np.stack([b.inertia_body for b in scene.bodies])
    rotation = quat_wxyz_to_matrix(traj.quat_wxyz)
    out = {}
    if "energy_drift_max" in wanted:
        energy = kinetic_energy(mass, inertia, traj.velocity_world, traj.angular_velocity_world, rotation)
        if scene.forces.gravity_world is not None:
            energy = energy + potential_energy(mass, scene.forces.gravity_world, traj.position_world)
        # Relative to |E(0)|, or to the largest kinetic energy when E(0) is near 0 (a body
        # dropped from rest at the potential's zero): a drift relative to nothing is n/a.
        kinetic = kinetic_energy(mass, inertia, traj.velocity_world, traj.angular_velocity_world, rotation)
        scale = np.maximum(np.abs(energy[0]), kinetic.max(axis=0))  # per body
        moving = scale > 0
        drift = np.max(np.abs(energy - energy[0])[:, moving] / scale[moving]) if moving.any() else math.nan
        out["energy_drift_max"] = (float(drift), "1")
    if "angular_momentum_drift_max" in wanted:
        momentum = angular_momentum_world(inertia, traj.angular_velocity_world, rotation)
        size = np.linalg.norm(momentum[0], axis=-1)
        spinning = size > 0
        change = np.linalg.norm(momentum - momentum[0], axis=-1)[:, spinning] / size[spinning]
        out["angular_momentum_drift_max"] = (float(change.max()), "1")
    return out


def observed_order(dts, errors) -> tuple[float, str]:
    """(slope p, explanation) of log(error) against log(dt); NaN with the reason when unfit.

    Only errors above :data:`ROUNDING_FLOOR` count; at least two time steps are needed.
    """
    dts, errors = np.asarray(dts, dtype=float), np.asarray(errors, dtype=float)
    usable = np.isfinite(errors) & (errors > ROUNDING_FLOOR)
    if usable.sum() < 2:
        return math.nan, f"fewer than 2 time steps with errors above the rounding floor {ROUNDING_FLOOR:g}"
    x, y = np.log(dts[usable]), np.log(errors[usable])
    slope, intercept = np.polyfit(x, y, 1)
    residual = float(np.max(np.abs(y - (slope * x + intercept)))) if usable.sum() > 2 else 0.0
    pairs = ", ".join(f"{d:.3g}: {e:.3g}" for d, e in zip(dts[usable], errors[usable]))
    return float(slope), f"fit over dt (error) {pairs}; max log residual {residual:.2g}"
