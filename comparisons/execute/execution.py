"""Running a run's scenes: planned into case groups, executed anywhere, handed back scene by scene in order.

Every scene is planned into groups of cases (:mod:`comparisons.execute.cases`); cases already in the run's
:class:`~comparisons.execute.journal.Journal` (a resumed run) are taken from it, the others go to an
executor — local worker processes (:class:`~comparisons.execute.isolation.IsolatedPool`) or a Dask cluster
(:mod:`comparisons.execute.dask_executor`) — costliest group first (as :mod:`comparisons.execute.estimate` models them).
Each case is journaled as it finishes; a scene is assembled, and its caller told (``on_scene``), as soon as its last
case finishes, in whatever order the scenes finish (the costliest groups run first); its rows come back once every
scene before it is complete too, so the stored run keeps the suite's order whatever finished first, and is the same
whatever executed it. A scene's outcomes are let go once it is assembled, so the caller holds the cases of the scenes
still incomplete and the rows of those waiting for their turn, not the run's cases.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable, Iterator, Protocol, cast

from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome, CaseSpec, case_key, plan_scene
from simparity.comparisons.execute.estimate import RunEstimate, SchemeOf, estimate_run, group_seconds
from simparity.comparisons.execute.isolation import Job
from simparity.comparisons.execute.journal import Journal
from simparity.comparisons.execute.runner import assemble_scene
from simparity.comparisons.measure.rows import declared_scheme
from simparity.core.model.engine import Engine
from simparity.core.model.results import ResultRow, SeriesRecord
from simparity.core.model.scenes.kinds import Scene

OnCase = Callable[[str, str, str], None]
"""Called with (scene, engine, integrator or solver) after each case, in the calling process."""

OnScene = Callable[[Scene, list[ResultRow]], None]
"""Called with a scene and its rows as soon as its last case finishes (before the scenes ahead of it in the run's order
are complete), in the calling process."""

def default_jobs() -> int:
    """Worker processes by default: one per CPU."""
    return max(1, os.cpu_count() or 1)


class Executor(Protocol):
    """Runs jobs (case groups) somewhere and hands back each case's outcome as it finishes."""

    def run(self, jobs: list[Job]) -> Iterator[tuple[object, int, CaseOutcome]]:
        """(job key, case index, outcome) of every case not skipped; the jobs are given costliest first."""

    def close(self) -> None:
        """Stop the workers."""


def scheme_lookup(engines: list[Engine]) -> SchemeOf:
    """The kind of scheme each case's engine (one of ``engines``, by name) declares on the case's scene: what its
    modelled cost depends on (:mod:`comparisons.execute.estimate`); "" for an engine not among them."""
    by_name = {e.name: e for e in engines}

    def scheme_of(group: CaseGroup, spec: CaseSpec) -> str:
        engine = by_name.get(spec.engine)
        return "" if engine is None else declared_scheme(engine, spec.integrator, group.scene)

    return scheme_of


@dataclass
class _Scene:
    """A scene of the run: its groups and, as they arrive, its cases' outcomes (``outcomes[g][c]``)."""

    scene: Scene
    groups: list[CaseGroup]
    outcomes: list[list[CaseOutcome | None]]

    @property
    def complete(self) -> bool:
        return all(o is not None for group in self.outcomes for o in group)

    def release(self) -> None:
        """Forget the outcomes once the scene's rows and series were handed back: a run holds the cases of the scenes
        not yet complete, never every case of a sweep of a thousand variants."""
        self.outcomes = []


def plan_run(scenes: list, engines: list[Engine], make_engine: Callable[[str], Engine], repeats: int,
             specs: dict[str, str] | None = None) -> list[_Scene]:
    """Every scene's groups on ``engines`` (built from ``specs`` when not from their names), outcomes still to
    come."""
    by_name = {e.name: e for e in engines}
    planned = []
    for scene in scenes:
        reference = by_name.get(scene.reference) or by_name.setdefault(scene.reference, make_engine(scene.reference))
        groups = plan_scene(scene, engines, reference, repeats, specs)
        planned.append(_Scene(scene, groups, [[None] * len(g.cases) for g in groups]))
    return planned


def run_scenes(scenes: list, engines: list[Engine], make_engine: Callable[[str], Engine], repeats: int,
               executor: Executor, journal: Journal | None = None, on_case: OnCase | None = None,
               specs: dict[str, str] | None = None,
               on_scene: OnScene | None = None) -> Iterator[tuple[Scene, list[ResultRow], list[SeriesRecord]]]:
    """(scene, rows, sampled series) for every scene, in order. Cases found in ``journal`` are not run
    again; every case run is journaled as it finishes. Interrupted (KeyboardInterrupt), it first hands back
    the finished cases of every scene not yet complete (without what needs them all: orders, agreement),
    then raises. ``on_case`` hears of every case, restored ones first; ``on_scene`` of every scene as soon as it
    is complete (restored ones first), whatever order they finish in. ``specs`` maps engine names to what the
    workers build them from, when that is not the name."""
    on_case = on_case or (lambda scene, engine, integrator: None)
    versions = {e.name: e.version() for e in engines}
    planned = plan_run(scenes, engines, make_engine, repeats, specs)
    jobs = []
    for s, item in enumerate(planned):
        for g, group in enumerate(item.groups):
            skip = set()
            for c, spec in enumerate(group.cases):
                found = None if journal is None else journal.load(case_key(group, spec, versions))
                if found is not None:
                    item.outcomes[g][c] = found
                    skip.add(c)
                    on_case(item.scene.name, spec.engine, spec.integrator)
            if len(skip) < len(group.cases):
                jobs.append(Job((s, g), group, skip))
    scheme_of = scheme_lookup(engines)
    jobs.sort(key=lambda job: -group_seconds(job.group, scheme_of, frozenset(job.skip)))
    ready: dict[int, tuple[Scene, list[ResultRow], list[SeriesRecord]]] = {}  # assembled, not yet handed back

    def assemble(s: int) -> None:
        ready[s] = _assembled(planned[s])
        planned[s].release()
        if on_scene is not None:
            on_scene(ready[s][0], ready[s][1])

    for s, item in enumerate(planned):  # restored whole from the journal
        if item.complete:
            assemble(s)
    emitted = 0
    try:
        while emitted in ready:
            yield ready.pop(emitted)
            emitted += 1
        for key, c, outcome in executor.run(jobs):
            s, g = cast(tuple[int, int], key)  # the keys given to the jobs above
            item = planned[s]
            group = item.groups[g]
            item.outcomes[g][c] = outcome
            if journal is not None:
                journal.save(case_key(group, group.cases[c], versions), outcome)
            on_case(item.scene.name, group.cases[c].engine, group.cases[c].integrator)
            if item.complete:
                assemble(s)
            while emitted in ready:
                yield ready.pop(emitted)
                emitted += 1
    except KeyboardInterrupt:  # hand back every finished case of the scenes not handed back yet, then stop
        for s in range(emitted, len(planned)):
            if s in ready:
                yield ready[s]
                continue
            outcomes = [o for results in planned[s].outcomes for o in results if o is not None]
            if outcomes:
                yield planned[s].scene, [r for o in outcomes for r in o.rows], [r for o in outcomes for r in o.series]
        raise
    for s in range(emitted, len(planned)):  # an executor that handed back fewer cases than it was given: fails there
        yield _assembled(planned[s])


def _assembled(item: _Scene) -> tuple[Scene, list[ResultRow], list[SeriesRecord]]:
    rows, series = assemble_scene(item.scene, item.groups, cast(list[list[CaseOutcome]], item.outcomes))  # complete
    return item.scene, rows, series


def count_cases(scenes: list, engines: list[Engine], make_engine: Callable[[str], Engine]) -> list[int]:
    """The number of cases of each scene (each reported once to ``on_case``)."""
    return [sum(len(g.cases) for g in item.groups) for item in plan_run(scenes, engines, make_engine, 0)]


def estimate(scenes: list, engines: list[Engine], make_engine: Callable[[str], Engine], workers: int,
             journal: Journal | None = None, specs: dict[str, str] | None = None) -> tuple[list[int], RunEstimate]:
    """(the number of cases of each scene, the :class:`RunEstimate` of those not in ``journal`` on ``workers``), from
    one plan of the run, before any case runs."""
    planned = plan_run(scenes, engines, make_engine, 0, specs)
    versions = {e.name: e.version() for e in engines}

    def done(group: CaseGroup) -> frozenset[int]:
        if journal is None:
            return frozenset()
        return frozenset(c for c, spec in enumerate(group.cases) if case_key(group, spec, versions) in journal)

    groups = [(group, done(group)) for item in planned for group in item.groups]
    return ([sum(len(g.cases) for g in item.groups) for item in planned],
            estimate_run(groups, workers, scheme_lookup(engines)))
