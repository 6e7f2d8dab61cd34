"""Progress of a run: on a terminal a one-line bar (scene, engine, integrator, cases done / total, time left); on
anything else (a CI log, a pipe) a plain line — no carriage return, no ANSI — whenever the run has been silent for
:data:`HEARTBEAT_SECONDS` (cases done / total, time elapsed and left), so that a long scene is never a long silence.
Given each case's modelled cost (:mod:`comparisons.execute.estimate`), the time left is the modelled cost still to run
at the pace measured so far: a run whose last case costs more than all the others together is not said to be nearly
done."""

from __future__ import annotations

import shutil
import threading
import time

from simparity.comparisons.execute.estimate import RunEstimate, duration

REDRAW_SECONDS = 0.1
"""Least time between two redraws of the bar: a terminal does not need more, a fast run is not slowed."""

HEARTBEAT_SECONDS = 30.0
"""Longest silence [s] of a run whose output is not a terminal: a CI service may end a job that printed nothing for
some minutes (Travis CI: 10), and a reader of the log wants to see it move; a scene line resets it."""

_WIDTH = 24
"""Characters of the bar itself."""


class ProgressBar:
    """Counts cases as they finish: draws the bar on ``stream`` when it is a terminal, else
    writes a heartbeat line to it after every ``heartbeat`` seconds [s] without a line (a background thread, from
    :meth:`start` to :meth:`close`: ``with bar:`` while the cases run).

    ``total`` is the number of cases the run will count (``comparisons.execute.execution.count_cases``); ``estimate``, what they
    are modelled to cost (None: every case alike). A case it does not know of (one restored by ``--resume``) counts
    at the mean cost.
    """

    def __init__(self, total: int, stream, clock=time.monotonic, estimate: RunEstimate | None = None,
                 heartbeat: float = HEARTBEAT_SECONDS) -> None:
        self.total, self.done, self.stream, self.clock = max(total, 1), 0, stream, clock
        self.costs = estimate.by_case if estimate is not None else {}
        self.total_cost = estimate.total_seconds if estimate is not None else 0.0
        self.mean_cost = self.total_cost / max(estimate.cases, 1) if estimate is not None else 0.0
        self.done_cost = 0.0
        self.active = bool(getattr(stream, "isatty", lambda: False)())
        self.start_time = self.said_at = clock()
        self.heartbeat = heartbeat
        self.by_scene: dict[str, int] = {}
        self._drawn_at = -float("inf")
        self._shown = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def _left(self, now: float) -> str:
        """The time left at ``now``: the modelled cost still to run at the pace so far ("estimating" before a case)."""
        elapsed = now - self.start_time
        if self.costs and self.done_cost > 0:
            return f"{duration(elapsed / self.done_cost * max(self.total_cost - self.done_cost, 0.0))} left"
        return f"{duration(elapsed / self.done * (self.total - self.done))} left" if self.done else "estimating"

    def line(self, scene: str, engine: str, integrator: str, now: float) -> str:
        """The bar's text at time ``now``: [####....] done/total cases · scene · engine integrator · time left."""
        fraction = min(self.done / self.total, 1.0)
        filled = int(round(fraction * _WIDTH))
        return (f"[{'#' * filled}{'.' * (_WIDTH - filled)}] {self.done}/{self.total} cases · {scene} · "
                f"{engine} {integrator}".rstrip() + f" · {self._left(now)}")

    def heartbeat_line(self, now: float) -> str:
        """The plain line of a non-terminal at time ``now``: progress: done/total cases · elapsed · time left."""
        return (f"progress: {self.done}/{self.total} cases · {duration(now - self.start_time)} elapsed · "
                f"{self._left(now)}")

    def case_done(self, scene: str, engine: str, integrator: str) -> None:
        self.done += 1
        self.by_scene[scene] = self.by_scene.get(scene, 0) + 1
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

    def scene_done(self, scene: str, cases: int) -> None:
        """``scene``'s ``cases`` are all done (a scene whose reference failed reports none one by one) and a line says
        so: the bar is cleared for it, the heartbeat's silence starts again."""
        self.done += max(cases - self.by_scene.get(scene, 0), 0)
        self.by_scene[scene] = max(cases, self.by_scene.get(scene, 0))
        self.said_at = self.clock()
        self.clear()

    def beat(self) -> None:
        """Write the heartbeat line when the output is no terminal and nothing was said for ``heartbeat`` seconds."""
        now = self.clock()
        if not self.active and now - self.said_at >= self.heartbeat:
            self.said_at = now
            self.stream.write(self.heartbeat_line(now) + "\n")
            self.stream.flush()

    def start(self) -> None:
        """Start the heartbeat (a daemon thread; nothing on a terminal, where the bar moves)."""
        if self.active or self._thread is not None:
            return
        self._thread = threading.Thread(target=self._beat_until_closed, name="simparity-heartbeat", daemon=True)
        self._thread.start()

    def _beat_until_closed(self) -> None:
        while not self._stop.wait(max(self.said_at + self.heartbeat - self.clock(), REDRAW_SECONDS)):
            self.beat()

    def __enter__(self) -> ProgressBar:
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Stop the heartbeat and erase the bar."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        self.clear()
