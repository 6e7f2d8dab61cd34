"""The bench's verdict on one of the issue's targets, and the sizes the targets are set for: a target measured at
another size (``--quick``) is "not comparable", never met or missed."""

from __future__ import annotations

from dataclasses import dataclass

TARGET_BATCH = 10_000
"""Bodies and configurations per batch the speed targets are set for (the largest batch of a full bench)."""
TARGET_IK_TARGETS = 10_000
"""IK targets per arm the IK targets are set for (the ``bench`` suite's count; core solves them as one batch)."""
TARGET_MEMORY_STEPS = 1_000_000
"""Steps the memory targets are set for (:data:`comparisons.bench.memory.MEMORY_SCENE` uncut)."""


@dataclass(frozen=True)
class Verdict:
    """One of the issue's targets: what it requires, what this run compared for it (with the numbers), whether met."""

    target: str
    compared: str
    met: bool | None
    """None: not judged, because not measured or (``set_for``) measured at another size than the target's."""
    measured_at: str = ""
    set_for: str = ""
    """The size the target is set for (``B = 10,000``) where this run measured at another, ``measured_at``."""

    @property
    def status(self) -> str:
        """``met``, ``MISSED``, ``not comparable`` (measured at another size) or ``n/a`` (not measured)."""
        if self.met is not None:
            return "met" if self.met else "MISSED"
        return "not comparable" if self.set_for else "n/a"

    @property
    def label(self) -> str:
        """The status with why a target was not comparable."""
        return (f"{self.status} (measured at {self.measured_at}, target set for {self.set_for})" if self.set_for
                else self.status)


def sized(target: str, compared: str, met: bool, measured_at: str, set_for: str) -> Verdict:
    """The verdict on a target set for one size (batch, targets, steps): judged only at that size. Core's batched
    speed and a run's memory change with the size, so a verdict at a quick size would be an artefact of it."""
    if measured_at != set_for:
        return Verdict(target, compared, None, measured_at, set_for)
    return Verdict(target, compared, met)
