"""Trajectories of free bodies and of chains' joints, and kinematic results, in the project's conventions."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from simparity.core.model.arrays import readonly


@dataclass(frozen=True)
class Trajectory:
    """States of B bodies at T sample times (the initial state included).

    Attributes
    ----------
    times : (T,) ndarray
        [s], starting at 0.
    position_world : (T, B, 3) ndarray
        Centre of mass [m].
    quat_wxyz : (T, B, 4) ndarray
        Orientation, body to world (sign as the engine returned it).
    velocity_world : (T, B, 3) ndarray
        Centre-of-mass velocity [m/s].
    angular_velocity_world : (T, B, 3) ndarray
        [rad/s].
    """

    times: np.ndarray
    position_world: np.ndarray
    quat_wxyz: np.ndarray
    velocity_world: np.ndarray
    angular_velocity_world: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.times)
        for name, last in (
            ("position_world", 3),
            ("quat_wxyz", 4),
            ("velocity_world", 3),
            ("angular_velocity_world", 3),
        ):
            value = np.asarray(getattr(self, name))
            if value.ndim != 3 or value.shape[0] != n or value.shape[2] != last:
                raise ValueError(f"Trajectory.{name} has shape {value.shape}, expected ({n}, B, {last})")
            object.__setattr__(self, name, readonly(value))
        object.__setattr__(self, "times", readonly(self.times))

    @property
    def n_bodies(self) -> int:
        return self.position_world.shape[1]

    def sliced(self, samples: slice) -> Trajectory:
        """The samples ``samples`` of this trajectory (views, no copies)."""
        return Trajectory(*(getattr(self, name)[samples] for name in TRAJECTORY_FIELDS))

    def is_finite(self) -> bool:
        """True when every recorded value is finite."""
        return all(
            bool(np.all(np.isfinite(a)))
            for a in (self.position_world, self.quat_wxyz, self.velocity_world, self.angular_velocity_world)
        )


TRAJECTORY_FIELDS = ("times", "position_world", "quat_wxyz", "velocity_world", "angular_velocity_world")
"""A :class:`Trajectory`'s arrays, in its constructor's order."""


def piece_bounds(n_steps: int, samples_per_piece: int) -> Iterator[tuple[int, int]]:
    """The sample ranges [start, stop) of ``n_steps`` steps' ``n_steps + 1`` samples in consecutive pieces of at most
    ``samples_per_piece`` samples (the first starts at the initial state, sample 0)."""
    size = max(int(samples_per_piece), 1)
    for start in range(0, n_steps + 1, size):
        yield start, min(start + size, n_steps + 1)


def trajectory_pieces(traj: Trajectory, samples_per_piece: int) -> Iterator[Trajectory]:
    """``traj`` in consecutive pieces of at most ``samples_per_piece`` samples (views, no copies)."""
    for start, stop in piece_bounds(len(traj.times) - 1, samples_per_piece):
        yield traj.sliced(slice(start, stop))


def joined(pieces: Iterable[Trajectory]) -> Trajectory:
    """One trajectory of consecutive ``pieces`` (the only one itself, not a copy)."""
    parts = list(pieces)
    if len(parts) == 1:
        return parts[0]
    return Trajectory(*(np.concatenate([getattr(p, name) for p in parts]) for name in TRAJECTORY_FIELDS))


@dataclass(frozen=True)
class JointTrajectory:
    """Joint states of B copies of a chain at T sample times (the initial state included).

    Attributes
    ----------
    times : (T,) ndarray
        [s], starting at 0.
    q : (T, B, nq) ndarray
        Joint values [rad or m] (nq = n); a floating-base chain's configuration (nq = 7 + n: base position [m], base
        orientation quat_wxyz, joint values; :class:`core.model.scenes.chain.Chain`).
    qdot : (T, B, nv) ndarray
        Joint velocities [rad/s or m/s] (nv = n); a floating base's velocity first (nv = 6 + n: base origin linear
        velocity and base angular velocity in world axes).
    """

    times: np.ndarray
    q: np.ndarray
    qdot: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.times)
        for name in ("q", "qdot"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.ndim != 3 or value.shape[0] != n:
                raise ValueError(f"JointTrajectory.{name} has shape {value.shape}, expected ({n}, B, n)")
            object.__setattr__(self, name, readonly(value))
        if self.q.shape[:2] != self.qdot.shape[:2] or self.q.shape[2] not in (self.qdot.shape[2],
                                                                            self.qdot.shape[2] + 1):
            raise ValueError(f"JointTrajectory.qdot has shape {self.qdot.shape}, q has {self.q.shape} (expected the "
                             "same samples and copies, and nq = nv, or nq = nv + 1 for a floating base)")
        object.__setattr__(self, "times", readonly(np.asarray(self.times, dtype=float)))

    def is_finite(self) -> bool:
        """True when every recorded value is finite."""
        return bool(np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.qdot)))


@dataclass(frozen=True)
class FramePoses:
    """Poses of the frames of a chain at a batch of configurations.

    Attributes
    ----------
    position_world : (B, F, 3) ndarray
        Frame origins [m].
    rotation_world : (B, F, 3, 3) ndarray
        Frame to world rotations.
    """

    position_world: np.ndarray
    rotation_world: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "position_world", readonly(self.position_world))
        object.__setattr__(self, "rotation_world", readonly(self.rotation_world))
