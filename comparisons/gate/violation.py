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

    def line(self) -> str:
        return (f"{row_label(self.scene, self.engine, self.integrator, self.dt, self.metric)}: {self.found}, "
                f"bound {self.bound} ({self.reason})")
