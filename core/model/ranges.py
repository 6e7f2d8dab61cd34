"""The physical range of every number a scene or URDF may give, and norms that cannot overflow.

Ranges are generous (they admit a microgram bead and a freight train) but physical: a value
outside them is a typo or an attack, and letting it through would give meaningless numbers (a
mass of 5e-324 kg, a velocity of 1e308 m/s) or overflow inside an engine. They are held by the
scene loader (``comparisons.scenes.loading``) and the URDF reader (:mod:`core.urdf`), and listed in
``docs/scenes.md``.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class Range:
    """The magnitudes a value may have (SI), and why.

    Attributes
    ----------
    low, high : float
        Smallest and largest magnitude allowed (``low`` 0 allows zero).
    unit : str
    why : str
        What the range admits, for the error message.
    zero : bool
        Whether 0 (none) is allowed besides [low, high].
    """

    low: float
    high: float
    unit: str
    why: str
    zero: bool = False

    def allows(self, magnitude: float) -> bool:
        """True for a magnitude inside [low, high], or 0 where :attr:`zero` (False for NaN)."""
        return self.low <= magnitude <= self.high or (self.zero and magnitude == 0)

    def text(self) -> str:
        low = "0" if self.low == 0 else f"{self.low:g}"
        none = "0 (none), or " if self.zero and self.low > 0 else ""
        return f"{none}magnitudes {low} to {self.high:g} {self.unit}: {self.why}".strip()


_LENGTH = Range(0.0, 1e6, "m", "a scene within 1000 km")
RANGE_INERTIA_LOW, RANGE_INERTIA_HIGH = 1e-15, 1e12
"""[kg m^2] The smallest and largest moments of inertia (a microgram bead of 1 mm, a ship), and so of the rotor
inertia a joint's armature adds."""
_ANGLE = Range(0.0, 1e3, "rad", "an angle; larger is a typo")
_JOINT = Range(0.0, 1e4, "rad or m", "a joint range; leave the limits out (URDF: type='continuous') for none")
RANGES = {
    "mass": Range(1e-9, 1e9, "kg", "a microgram to a million tonnes"),
    "inertia_moment": Range(RANGE_INERTIA_LOW, RANGE_INERTIA_HIGH, "kg m^2", "a microgram bead of 1 mm to a ship"),
    "position_world": _LENGTH, "origin_xyz": _LENGTH, "end_effector_xyz": _LENGTH, "point_body": _LENGTH,
    "a": _LENGTH, "d": _LENGTH,
    "velocity_world": Range(0.0, 1e6, "m/s", "slower than 1000 km/s"),
    "air_velocity_world": Range(0.0, 1e6, "m/s", "slower than 1000 km/s"),
    "angular_velocity_world": Range(0.0, 1e6, "rad/s", "below a million rad/s"),
    "base_position": _LENGTH,
    "base_velocity_world": Range(0.0, 1e4, "m/s", "orbital speeds included; faster, the base's speed cancels in the "
                                 "joints' accelerations and float64 keeps too few of their digits (at 1e6 m/s RK4's "
                                 "joints part from the reference by 2e-5)"),
    "base_angular_velocity_world": Range(0.0, 1e6, "rad/s", "below a million rad/s"),
    "gravity_world": Range(0.0, 1e4, "m/s^2", "up to 1000 g"),
    "velocity_scale": Range(1e-9, 1e6, "rad/s or m/s", "a joint speed from 1e-9 to a million per second"),
    "acceleration_scale": Range(1e-9, 1e9, "rad/s^2 or m/s^2", "a joint acceleration from 1e-9 to 1e9"),
    "torque_scale": Range(1e-9, 1e9, "N m or N", "a joint force from 1e-9 to 1e9"),
    "force_world": Range(0.0, 1e12, "N", "up to a terranewton"),
    "linear_drag": Range(0.0, 1e9, "N s/m", "a drag coefficient"),
    "quadratic_drag": Range(0.0, 1e9, "N s^2/m^2", "a drag coefficient"),
    "angular_linear_drag": Range(0.0, 1e9, "N m s", "a drag coefficient"),
    "angular_quadratic_drag": Range(0.0, 1e9, "N m s^2", "a drag coefficient"),
    "duration": Range(1e-9, 1e7, "s", "a nanosecond to four months"),
    "dt": Range(1e-9, 1e3, "s", "a nanosecond to a quarter of an hour"),
    "rate_hz": Range(1e-3, 1e9, "Hz", "the inverse of the dt range"),
    "lower": _JOINT, "upper": _JOINT, "start": Range(0.0, 1e4, "rad or m", "a joint value"),
    "q": Range(0.0, 1e4, "rad or m", "a joint value"),
    "qdot": Range(0.0, 1e6, "rad/s or m/s", "a joint speed below a million per second"),
    "torque": Range(0.0, 1e9, "N m or N", "a joint force up to 1e9"),
    "damping": Range(0.0, 1e9, "N m s/rad or N s/m", "a joint's viscous damping, like a drag coefficient (real "
                     "arms: 0.01 to 100; PR2's torso lift 2e4 N s/m)"),
    "armature": Range(RANGE_INERTIA_LOW, RANGE_INERTIA_HIGH, "kg m^2 or kg", "a rotor's inertia through its "
                      "gearing, within the moments of inertia", zero=True),
    "com_xyz": _LENGTH,
    "origin_rpy": _ANGLE, "end_effector_rpy": _ANGLE, "alpha": _ANGLE, "theta_offset": _ANGLE,
    "position_tolerance": Range(1e-15, 1e6, "m", "a tolerance above rounding, and at most a tenth of the reach"),
    "orientation_tolerance": Range(1e-15, 0.5, "rad", "a tolerance, not a quarter turn"),
    "radius": Range(1e-6, 1e6, "m", "a micrometre to 1000 km"),
    "half_extents": Range(1e-6, 1e6, "m", "a micrometre to 1000 km"),
    "shape_center_body": _LENGTH, "position": _LENGTH,
    "rest_speed": Range(1e-9, 1e3, "m/s", "a rebound slower than this comes to rest: above rounding, below a bullet"),
    "penalty_stiffness": Range(1e-3, 1e12, "N/m", "a spring from a rubber band to steel contact"),
    "penalty_damping": Range(0.0, 1e9, "N s/m", "a damper coefficient"),
    "friction_static": Range(0.0, 1e2, "1", "a Coulomb coefficient (rubber on rough concrete is ~1)"),
    "friction_kinetic": Range(0.0, 1e2, "1", "a Coulomb coefficient (rubber on rough concrete is ~1)"),
    "friction": Range(0.0, 1e2, "1", "a Coulomb coefficient (rubber on rough concrete is ~1)"),
    "friction_speed": Range(1e-9, 1e3, "m/s", "a slip speed, from creep to a fast vehicle's"),
    # time functions (core.model.scenes.time_functions): their values are forces [N] or torques [N m]
    "period": Range(1e-9, 1e7, "s", "a control period from a nanosecond to four months, like a scene's duration"),
    "phase": Range(0.0, 1e7, "s", "the first sample instant, within the first control period"),
    "frequency_hz": Range(0.0, 1e9, "Hz", "the inverse of the dt range: a faster sinusoid no step resolves"),
    "phase_rad": _ANGLE,
    "amplitude": Range(0.0, 1e12, "N or N m", "a load up to a terranewton"),
    "samples": Range(0.0, 1e12, "N or N m", "a load up to a terranewton"),
    "polynomial": Range(0.0, 1e12, "N/s^k or N m/s^k", "a coefficient up to 1e12"),
}
"""By key name (the last component of a key path). Vectors are held to the range entry by entry."""

INERTIA_RTOL = 1e-5
"""Relative tolerance of an inertia tensor's symmetry and triangle-inequality checks, as a fraction of its largest
principal moment (:func:`core.dynamics.inertia.inertia_problem`, ``link_tensor_problem``, and the data model's
symmetry check). Scene files quote inertias to ~6 significant digits; rounding a, b and c by half a unit in the 6th
digit breaks a thin plate's exact a + b = c (or the symmetry of a tensor typed twice) by a few 1e-6 relative.
Physically meaningful violations are far larger."""

SMALLEST_NORMAL = sys.float_info.min
"""The smallest magnitude a non-zero number may have (2.2e-308). Below it a float64 is subnormal: it keeps fewer than
16 significant digits (5e-324 keeps one), and code built with flush-to-zero (fast-math, SSE FTZ/DAZ) reads it as 0
where other code reads it as given: one input, two meanings. No physical value is written so (the smallest number in
the installed robot files is an inertia residue of 2.4e-35)."""


def subnormal(value: float) -> bool:
    """True for a non-zero number of magnitude below :data:`SMALLEST_NORMAL` (refused wherever a number is read)."""
    return value != 0 and abs(value) < SMALLEST_NORMAL


SUBNORMAL_RULE = f"0, or magnitudes of at least {SMALLEST_NORMAL:.3g} (no subnormal numbers)"
"""The allowed part of a message refusing a subnormal number."""

NORM_RANGES = {
    "quat_wxyz": Range(1e-6, 1e6, "", "a quaternion is normalised on loading; its norm must survive that"),
    "axis": Range(1e-9, 1e9, "", "a joint axis is normalised on loading; its norm must survive that"),
}
"""Vectors whose direction is all that counts: their norm (computed without overflow) is held."""


def safe_norm(vector) -> float:
    """Euclidean norm without overflow or underflow (scaled by the largest entry); NaN stays NaN."""
    values = [float(v) for v in vector]
    if any(math.isnan(v) for v in values):
        return math.nan
    largest = max((abs(v) for v in values), default=0.0)
    if largest == 0.0 or not math.isfinite(largest):
        return largest
    return largest * math.sqrt(sum((v / largest) ** 2 for v in values))

