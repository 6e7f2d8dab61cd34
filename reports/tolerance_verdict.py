"""The run held to tolerances, as the report shows it: handed to :func:`reports.content.build` by whoever checked
the run (the gate); the flagged findings say it (:mod:`reports.sections.findings`), and the engines it holds open the
report with a section each (:mod:`reports.own_engine`)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ToleranceVerdict:
    """The run held to tolerances, as the report's flagged findings show it: how many metrics had a bound,
    how many had none, and the lines saying which metrics were outside their bounds."""

    checked: int
    unchecked: int
    violations: tuple[str, ...] = ()
    outside: int | None = None
    """Metrics outside their bounds (``violations`` may say them in fewer lines: one per case and reason); None:
    one per line."""

    engines: tuple[str, ...] = ()
    """The engine each line of ``violations`` is about (empty: not said)."""
    held: tuple[str, ...] | None = None
    """The engines the gate holds (None: every engine of the run): a user's engine among them has a section of its
    own first (:mod:`reports.own_engine`)."""
    cases: tuple[tuple[str, str], ...] = ()
    """The (scene, first metric) each line of ``violations`` is about (empty: not said): the robot table names a
    cell's first disagreement by them (:mod:`reports.sections.robots`)."""

    @property
    def outside_count(self) -> int:
        return len(self.violations) if self.outside is None else self.outside
