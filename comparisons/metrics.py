"""Error metrics of a trajectory or a kinematic evaluation against a reference.

Each function returns ``{metric: (value, unit)}``. Errors are maxima over every body,
sample and frame; "final" is at the last sample.
"""

from __future__ import annotations

import numpy as np

from core.rotations import geodesic_angle_matrix, geodesic_angle_quat_wxyz
from core.trajectory import FramePoses, Trajectory

DYNAMICS_METRICS = {
    "position_error_max": "m",
    "position_error_final": "m",
    "orientation_error_max": "rad",
    "velocity_error_max": "m/s",
    "angular_velocity_error_max": "rad/s",
    "time_per_step": "s",
}
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
