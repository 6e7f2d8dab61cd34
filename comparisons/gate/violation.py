"""A row outside its bound, named for a message: what the CI gate reports, from a bound or a cross-check."""

from __future__ import annotations

import math
from dataclasses import dataclass


def row_label(scene: str, engine: str, integrator: str, dt: float, metric: str) -> str:
    """One row named for a message: ``scene engine integrator [dt=...] metric`` (``-`` for no integrator)."""
    at = "" if math.isnan(dt) else f" dt={dt:g}"
    return f"{scene} {engine} {integrator or '-'}{at} {metric}"


@dataclass(frozen=True)
class Violation:
    """One row outside its bound."""

    scene: str
    engine: str
    integrator: str
    dt: float
    metric: str
    found: str
    bound: str
    reason: str
    verdict: str = ""
    """The row's status (or alarm flag) when the violation is about the verdict, not a value: "" for a value."""

    def line(self) -> str:
        return (f"{row_label(self.scene, self.engine, self.integrator, self.dt, self.metric)}: {self.found}, "
                f"bound {self.bound} ({self.reason})")


GROUP_METRICS_SHOWN = 3
"""Metric names a grouped line spells out before it counts the rest."""


@dataclass(frozen=True)
class ViolationGroup:
    """The violations of one case (scene, engine, integrator, dt) for one reason: one line however many metrics."""

    violations: tuple[Violation, ...]

    def line(self) -> str:
        first = self.violations[0]
        if len(self.violations) == 1:
            return first.line()
        metrics = [v.metric for v in self.violations]
        shown = ", ".join(metrics[:GROUP_METRICS_SHOWN]) + (
            f", +{len(metrics) - GROUP_METRICS_SHOWN} more" if len(metrics) > GROUP_METRICS_SHOWN else "")
        found = first.found if all(v.found == first.found for v in self.violations) else f"{first.metric} {first.found}"
        bound = first.bound if all(v.bound == first.bound for v in self.violations) else f"{first.bound} and others"
        case = row_label(first.scene, first.engine, first.integrator, first.dt, "").rstrip()
        return f"{case}: {len(metrics)} metrics ({shown}): {found}, bound {bound} ({first.reason})"


def grouped(violations: list[Violation]) -> list[ViolationGroup]:
    """``violations`` as one group per case and reason, in first-seen order: a wrong verdict (a case that diverged,
    failed or raised an alarm) is one reason whatever bounds its metrics broke; a value outside its bound is one
    reason per bound."""
    groups: dict[tuple, list[Violation]] = {}
    for v in violations:
        why = (v.verdict,) if v.verdict else (v.reason, v.bound)
        key = (v.scene, v.engine, v.integrator, "nan" if math.isnan(v.dt) else v.dt, *why)
        groups.setdefault(key, []).append(v)
    return [ViolationGroup(tuple(members)) for members in groups.values()]
