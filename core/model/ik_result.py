"""What an IK solver returns: solutions and per-target diagnostics, never an exception."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from simparity.core.model.arrays import readonly

class IKReason(str, Enum):
    """Why a target was not reached, or :attr:`SOLVED` (``""``) when it was. A member is its text (the str value
    written to ``IKResult.reason`` and the results), so it compares, hashes and formats as that text.

    - ``UNREACHABLE``: the target is beyond the chain's reach (a bound, or the arm stretched toward it);
    - ``SINGULAR``: the task Jacobian lost rank where the iteration stopped;
    - ``LIMIT_BLOCKED``: a joint limit stopped the progress;
    - ``ITERATION_CAP``: stopped by the iteration cap, or by a solver that names no cause;
    - ``OUTSIDE_LIMITS``: the residuals are within their tolerances but the joint values are not within their
      limits (an engine's solver that ignores limits): not a solution for the robot.
    """

    SOLVED = ""
    UNREACHABLE = "unreachable"
    SINGULAR = "singular"
    LIMIT_BLOCKED = "limit_blocked"
    ITERATION_CAP = "iteration_cap"
    OUTSIDE_LIMITS = "outside_limits"

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


REASONS = tuple(reason.value for reason in IKReason)
"""The failure vocabulary as text: :class:`IKReason`'s values, ``""`` for a success."""

LIMIT_TOLERANCE = 1e-6
"""[rad or m] A joint value this close outside its limit still counts as inside: PyBullet returns
float32 joint values (resolution 2.4e-7 rad at pi), and URDF limits are often written to 4-6
significant digits. Far below any limit violation that matters to a robot."""


@dataclass(frozen=True)
class IKResult:
    """Outcome of solving a batch of B targets for an n-joint chain.

    Attributes
    ----------
    q : (B, n) ndarray
        Final joint values [rad or m]; the best configuration found when the target was
        not reached. The in-house solvers keep it inside the joint limits; an engine's
        solver may not, and ``limit_violation`` says by how much.
    success : (B,) bool ndarray
        Both residuals within their tolerances and every joint within its limits (up to
        :data:`LIMIT_TOLERANCE`).
    iterations : (B,) int ndarray
        Joint updates applied to each target.
    position_residual : (B,) ndarray
        Distance from the end effector to the target position at ``q`` [m].
    orientation_residual : (B,) ndarray
        Angle of the rotation from the end effector to the target orientation [rad];
        0 for position-only targets.
    limit_violation : (B,) ndarray
        Largest amount by which a joint of ``q`` is outside its limits [rad or m]; 0 when
        inside.
    reason : (B,) str ndarray
        ``""`` on success, else one of :data:`REASONS`.

    Raises
    ------
    ValueError
        On inconsistent shapes, a non-finite value, a reason outside :data:`REASONS`, or a
        reason that disagrees with ``success``.
    """

    q: np.ndarray
    success: np.ndarray
    iterations: np.ndarray
    position_residual: np.ndarray
    orientation_residual: np.ndarray
    limit_violation: np.ndarray
    reason: np.ndarray

    def __post_init__(self) -> None:
        q = readonly(self.q, float)
        if q.ndim != 2:
            raise ValueError(f"IKResult.q has shape {q.shape}, expected (B, n)")
        object.__setattr__(self, "q", q)
        batch = q.shape[0]
        for name, dtype in (("success", bool), ("iterations", int), ("position_residual", float),
                            ("orientation_residual", float), ("limit_violation", float), ("reason", str)):
            value = readonly(getattr(self, name), dtype)
            if value.shape != (batch,):
                raise ValueError(f"IKResult.{name} has shape {value.shape}, expected ({batch},)")
            object.__setattr__(self, name, value)
        for name in ("q", "position_residual", "orientation_residual", "limit_violation"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise ValueError(f"IKResult.{name} has a non-finite value")
        unknown = set(self.reason.tolist()) - set(REASONS)
        if unknown:
            raise ValueError(f"IKResult.reason has {sorted(unknown)}, allowed: {REASONS}")
        if np.any(self.success != (self.reason == "")):
            raise ValueError("IKResult.reason must be '' exactly where success is True")

    @property
    def solve_rate(self) -> float:
        """Fraction of targets solved (0 for an empty batch)."""
        return float(np.mean(self.success)) if self.success.size else 0.0
