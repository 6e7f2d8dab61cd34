"""What a scene may ask for: the physical range of every number, and the resource limits a run is
refused beyond (before anything runs); names follow :mod:`core.names`. Documented in
``docs/scenes.md``.

Ranges are generous (they admit a microgram bead and a freight train) but physical: a value
outside them is a typo or an attack, and letting it through would give meaningless numbers
(a mass of 5e-324 kg, a velocity of 1e308 m/s) or overflow inside an engine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

@dataclass(frozen=True)
class Range:
    """The magnitudes a value may have (SI), and why."""

    low: float
    high: float
    unit: str
    why: str

    def allows(self, magnitude: float) -> bool:
        return self.low <= magnitude <= self.high

    def text(self) -> str:
        low = "0" if self.low == 0 else f"{self.low:g}"
        return f"magnitudes {low} to {self.high:g} {self.unit}: {self.why}".strip()


_LENGTH = Range(0.0, 1e6, "m", "a scene within 1000 km")
_ANGLE = Range(0.0, 1e3, "rad", "an angle; larger is a typo")
RANGES = {
    "mass": Range(1e-9, 1e9, "kg", "a microgram to a million tonnes"),
    "inertia_moment": Range(1e-15, 1e12, "kg m^2", "a microgram bead of 1 mm to a ship"),
    "position_world": _LENGTH, "origin_xyz": _LENGTH, "end_effector_xyz": _LENGTH, "point_body": _LENGTH,
    "a": _LENGTH, "d": _LENGTH,
    "velocity_world": Range(0.0, 1e6, "m/s", "slower than 1000 km/s"),
    "air_velocity_world": Range(0.0, 1e6, "m/s", "slower than 1000 km/s"),
    "angular_velocity_world": Range(0.0, 1e6, "rad/s", "below a million rad/s"),
    "gravity_world": Range(0.0, 1e4, "m/s^2", "up to 1000 g"),
    "force_world": Range(0.0, 1e12, "N", "up to a terranewton"),
    "linear_drag": Range(0.0, 1e9, "N s/m", ""), "quadratic_drag": Range(0.0, 1e9, "N s^2/m^2", ""),
    "angular_linear_drag": Range(0.0, 1e9, "N m s", ""), "angular_quadratic_drag": Range(0.0, 1e9, "N m s^2", ""),
    "duration": Range(1e-9, 1e7, "s", "a nanosecond to four months"),
    "dt": Range(1e-9, 1e3, "s", "a nanosecond to a quarter of an hour"),
    "rate_hz": Range(1e-3, 1e9, "Hz", "the inverse of the dt range"),
    "lower": Range(0.0, 1e4, "rad or m", "a joint range"), "upper": Range(0.0, 1e4, "rad or m", "a joint range"),
    "start": Range(0.0, 1e4, "rad or m", "a joint value"),
    "origin_rpy": _ANGLE, "end_effector_rpy": _ANGLE, "alpha": _ANGLE, "theta_offset": _ANGLE,
    "orientation_tolerance": Range(1e-15, 0.5, "rad", "a tolerance, not a quarter turn"),
}
"""By key name (the last component of a key path). Vectors are held to the range entry by entry."""

NORM_RANGES = {
    "quat_wxyz": Range(1e-6, 1e6, "", "a quaternion is normalised on loading; its norm must survive that"),
    "axis": Range(1e-9, 1e9, "", "a joint axis is normalised on loading; its norm must survive that"),
}
"""Vectors whose direction is all that counts: their norm (computed without overflow) is held."""

POSITION_TOLERANCE_OF_REACH = 0.1
"""An IK position tolerance may be at most this fraction of the chain's reach: beyond it, wild
misses would count as solved."""


def safe_norm(vector) -> float:
    """Euclidean norm without overflow or underflow (scaled by the largest entry)."""
    largest = max((abs(v) for v in vector), default=0.0)
    if largest == 0.0 or not math.isfinite(largest):
        return largest
    return largest * math.sqrt(sum((v / largest) ** 2 for v in vector))


@dataclass(frozen=True)
class Limits:
    """Resource limits a scene is checked against before anything runs.

    Attributes
    ----------
    max_steps : int
        Body-steps per time step of a dynamics case (steps x bodies); ``--max-steps``.
    max_samples : int
        Configurations of a kinematics scene, or random targets of an IK scene; ``--max-samples``.
    max_dts : int
        Time steps in a ladder.
    max_bodies : int
    max_iterations : int
        IK iterations per target.
    max_joints : int
        Movable joints on a chain, and joints in a URDF file (every engine loads the whole file).
    max_file_bytes : int
        Size of a scene or URDF file.
    """

    max_steps: int = 2_000_000
    max_samples: int = 100_000
    max_dts: int = 20
    max_bodies: int = 1_000
    max_iterations: int = 100_000
    max_joints: int = 256
    max_file_bytes: int = 10_000_000


DEFAULT_LIMITS = Limits()
