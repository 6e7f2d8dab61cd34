"""Progress of a run: a one-line bar on a terminal (scene, engine, integrator, cases done / total,
time left), nothing extra when the output is not a terminal (CI logs keep one line per scene). Given each case's
modelled cost (:mod:`comparisons.execute.estimate`), the time left is the modelled cost still to run at the pace
measured so far: a run whose last case costs more than all the others together is not said to be nearly done."""

from __future__ import annotations

import shutil
import time

from simparity.comparisons.execute.estimate import RunEstimate, duration

REDRAW_SECONDS = 0.1
"""Least time between two redraws of the bar: a terminal does not need more, a fast run is not slowed."""

_WIDTH = 24
"""Characters of the bar itself."""


class ProgressBar:
    """Counts cases as they finish and draws the bar on ``stream`` when it is a terminal.

    ``total`` is the number of cases the run will count (``comparisons.execute.execution.count_cases``); ``estimate``, what they
    are modelled to cost (None: every case alike). A case it does not know of (one restored by ``--resume``) counts
    at the mean cost.
    """

    def __init__(self, total: int, stream, clock=time.monotonic, estimate: RunEstimate | None = None) -> None:
        self.total, self.done, self.stream, self.clock = max(total, 1), 0, stream, clock
        self.costs = estimate.by_case if estimate is not None else {}
        self.total_cost = estimate.total_seconds if estimate is not None else 0.0
        self.mean_cost = self.total_cost / max(estimate.cases, 1) if estimate is not None else 0.0
        self.done_cost = 0.0
        self.active = bool(getattr(stream, "isatty", lambda: False)())
        self.start = clock()
        self._drawn_at = -float("inf")
        self._shown = False

    def line(self, scene: str, engine: str, integrator: str, now: float) -> str:
        """The bar's text at time ``now``: [####....] done/total cases · scene · engine integrator · time left."""
        fraction = min(self.done / self.total, 1.0)
        filled = int(round(fraction * _WIDTH))
        elapsed = now - self.start
        if self.costs and self.done_cost > 0:
            left = f"{duration(elapsed / self.done_cost * max(self.total_cost - self.done_cost, 0.0))} left"
        else:
            left = f"{duration(elapsed / self.done * (self.total - self.done))} left" if self.done else "estimating"
        return (f"[{'#' * filled}{'.' * (_WIDTH - filled)}] {self.done}/{self.total} cases · {scene} · "
                f"{engine} {integrator}".rstrip() + f" · {left}")

    def case_done(self, scene: str, engine: str, integrator: str) -> None:
        self.done += 1
        self.done_cost += self.costs.get((scene, engine, integrator), self.mean_cost)
        now = self.clock()
        if self.active and now - self._drawn_at >= REDRAW_SECONDS:
            self._drawn_at = now
            width = shutil.get_terminal_size((100, 20)).columns - 1
            self.stream.write("\r" + self.line(scene, engine, integrator, now)[:width].ljust(width))
            self.stream.flush()
            self._shown = True

    def clear(self) -> None:
        """Erase the bar (before a line is printed on the same terminal)."""
        if self._shown:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self._shown = False

    def scene_done(self, cases_so_far: int) -> None:
        """A scene is stored: its cases all count (a scene whose reference failed reports none one by one)."""
        self.done = max(self.done, cases_so_far)
        self.clear()
