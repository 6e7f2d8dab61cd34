"""Issue #12: a run's cases, wherever they execute, come back scene by scene in the suite's order, the same
bit for bit whatever the executor and the number of workers; a resumed run recomputes nothing that finished."""

from __future__ import annotations

import dataclasses

import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.estimate import group_seconds
from simparity.comparisons.execute.execution import count_cases, run_scenes
from simparity.comparisons.execute.isolation import CaseLimits, IsolatedPool
from simparity.comparisons.execute.journal import Journal
from simparity.core.model.results import STATUSES, case_counts
from tests.helpers import LEAN_INTEGRATORS, InProcess, built_engines, comparable, smoke_scenes

LEAN_STEPS = 60
"""Steps at a dynamics scene's coarsest time step in :func:`lean_scenes`: the bouncing ball (dropped from 1 m,
coarsest dt 0.01 s) still meets the floor, at t = sqrt(2 h / g) = 0.45 s, and leaves it before the end (0.6 s):
its impact and rebound metrics are measured at both time steps."""

LEAN_ITERATIONS = 20
"""IK iterations in :func:`lean_scenes`: every solver still iterates, reaches its cap on the hard targets and
reports its failures (the case's every path), at a tenth of the 200 that dominated the mixed scenes' cost."""


SPREAD_SCENES = ("ball-bounce-k05", "lecture-2link-ik")
"""The fewest scenes whose groups spread over two workers: three groups (the IK scene's one, the ball's two time
steps), so each worker runs one and one of them a second, forked from a worker that already ran one; contact (every
engine's contact schemes) and iterative IK (every solver's loop), the cases that carry the most state. Each group costs
a case process per engine, most of the test's CPU: the free-flight, rotating and kinematics scenes' five more groups
ran the same code paths of the executors."""


def lean_scenes():
    """The :data:`SPREAD_SCENES` as smoke scenes, shortened further for the tests that run them whole several
    times: what they compare is bit-identity and what ran, not accuracy."""
    def lean(scene):
        if hasattr(scene, "duration"):
            return dataclasses.replace(scene, duration=min(scene.duration, LEAN_STEPS * max(scene.dts)),
                                       integrators=LEAN_INTEGRATORS)
        if hasattr(scene, "max_iterations"):
            return dataclasses.replace(scene, max_iterations=LEAN_ITERATIONS)
        return scene
    return [lean(scene) for scene in smoke_scenes(SPREAD_SCENES)]


@pytest.fixture(scope="module")
def in_process():
    """The lean scenes run once in this process on every engine: the rows the other executors must give."""
    scenes = lean_scenes()
    return scenes, list(run_scenes(scenes, built_engines(), make_engine, 0, InProcess()))


@pytest.mark.slow
def test_worker_processes_give_bit_identical_results_whatever_their_number(in_process):
    """Determinism: one worker, two workers and this process agree on every non-timing value."""
    scenes, expected = in_process
    for workers in (1, 2):
        with IsolatedPool(workers, CaseLimits.default(workers)) as pool:
            got = list(run_scenes(scenes, built_engines(), make_engine, 0, pool))
        assert [s.name for s, _, _ in got] == [s.name for s in scenes]
        assert comparable(got) == comparable(expected), workers


def test_every_case_is_heard_once_and_the_costliest_group_goes_first():
    scenes = smoke_scenes(("lecture-planar-arm", "lecture-projectile"))
    heard = []
    executor = InProcess()
    results = list(run_scenes(scenes, built_engines(("core",)), make_engine, 0, executor,
                              on_case=lambda *event: heard.append(event)))
    assert [s.name for s, _, _ in results] == ["lecture-planar-arm", "lecture-projectile"]
    assert len(heard) == sum(count_cases(scenes, built_engines(("core",)), make_engine))
    costs = [group_seconds(job.group) for job in executor.jobs]
    assert costs == sorted(costs, reverse=True) and executor.jobs[0].group.scene.name == "lecture-projectile"


def test_a_scene_is_said_as_it_finishes_while_the_stored_order_is_the_suites():
    """Issue #41: the costliest scene runs first; it is said done at once, not after every scene before it in the suite
    (a CI log used to get every scene's line at the end of the run)."""
    scenes = smoke_scenes(("lecture-planar-arm", "lecture-projectile"))
    events = []
    for scene, rows, _ in run_scenes(scenes, built_engines(("core",)), make_engine, 0, InProcess(),
                                     on_scene=lambda scene, rows: events.append(("said", scene.name, len(rows)))):
        events.append(("handed back", scene.name, len(rows)))
    said = [e for e in events if e[0] == "said"]
    assert said[0][1] == "lecture-projectile" and events.index(said[0]) == 0
    assert [e[1] for e in events if e[0] == "handed back"] == ["lecture-planar-arm", "lecture-projectile"]
    assert sorted(e[1:] for e in said) == sorted(e[1:] for e in events if e[0] == "handed back")


@pytest.mark.slow
def test_an_interrupted_run_resumes_without_recomputing_what_finished(tmp_path, in_process):
    scenes, expected = in_process
    total = sum(count_cases(scenes, built_engines(), make_engine))
    first = InProcess(stop_after=total // 2)
    handed_back = []
    with pytest.raises(KeyboardInterrupt):
        for item in run_scenes(scenes, built_engines(), make_engine, 0, first, Journal(tmp_path)):
            handed_back.append(item)
    assert len(Journal(tmp_path)) == total // 2
    # every finished case reached the caller before the interruption did, complete scenes whole
    assert sum(case_counts(rows)[s] for _, rows, _ in handed_back for s in STATUSES) == total // 2
    second = InProcess()
    resumed = list(run_scenes(scenes, built_engines(), make_engine, 0, second, Journal(tmp_path)))
    assert second.ran == total - total // 2  # nothing that finished ran again
    assert comparable(resumed) == comparable(expected)


@pytest.mark.slow
def test_a_changed_scene_or_engine_version_is_computed_again(tmp_path, monkeypatch):
    scenes = smoke_scenes(("lecture-projectile",))
    list(run_scenes(scenes, built_engines(("core",)), make_engine, 0, InProcess(), Journal(tmp_path)))
    again = InProcess()
    list(run_scenes(scenes, built_engines(("core",)), make_engine, 0, again, Journal(tmp_path)))
    assert again.ran == 0
    engines = built_engines(("core",))
    monkeypatch.setattr(type(engines[0]), "version", lambda self: "another")
    newer = InProcess()
    list(run_scenes(scenes, engines, make_engine, 0, newer, Journal(tmp_path)))
    assert newer.ran == count_cases(scenes, engines, make_engine)[0]
