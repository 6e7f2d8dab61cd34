"""Cases run in the calling process: no worker to start and nothing between an engine and the caller
(``isolate=False``, the metamorphic checks' reruns, the tests)."""

from __future__ import annotations

from typing import Callable, Iterator

from simparity.comparisons.execute.cases import CaseOutcome
from simparity.comparisons.execute.execution import run_scenes
from simparity.comparisons.execute.isolation import Job
from simparity.comparisons.execute.runner import DEFAULT_REPEATS, run_group
from simparity.core.model.engine import Engine
from simparity.core.model.results import ResultRow, SeriesRecord


class InProcessExecutor:
    """Every job in this process, one after the other (``isolate=False``): no worker to start, and nothing between
    an engine and the caller, so an engine that crashes ends the caller's interpreter."""

    def __init__(self, engine_for: Callable[[str], Engine]) -> None:
        self._engine_for = engine_for

    def run(self, jobs: list[Job]) -> Iterator[tuple[object, int, CaseOutcome]]:
        for job in jobs:
            for index, outcome in run_group(job.group, self._engine_for, skip=frozenset(job.skip),
                                            reference_failure=job.reference_failure):
                yield job.key, index, outcome

    def close(self) -> None:
        return None


def run_in_process(scene, engines: list[Engine], make_reference: Callable[[str], Engine],
                   repeats: int = DEFAULT_REPEATS, series: list[SeriesRecord] | None = None) -> list[ResultRow]:
    """All rows of one scene on ``engines`` (objects, used as given) against ``make_reference(scene.reference)``,
    through the same pipeline as every run, its cases in this process. ``series``, when a list, gets the scene's
    sampled series (:mod:`comparisons.measure.series`)."""
    by_name = {e.name: e for e in engines}

    def engine_for(name: str) -> Engine:
        if name not in by_name:
            by_name[name] = make_reference(name)
        return by_name[name]

    [(_, rows, records)] = run_scenes([scene], engines, engine_for, repeats, InProcessExecutor(engine_for))
    if series is not None:
        series += records
    return rows
