"""Running scenes on several processes: one scene per task, results handed back in the scenes' order.

With ``jobs = 1`` everything runs in this process. With more, each worker process (started
fresh, ``spawn``) builds its own engines from their names; a scene's rows come back as soon as
it and every scene before it are done, so the stored run and the printed progress keep the
suite's order whatever finishes first.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import multiprocessing
import os
import queue
from typing import Callable, Iterator

from simparity.comparisons.engines import make_engine
from simparity.comparisons.runner import count_cases, run_scene
from simparity.core.results import ResultRow, SeriesRecord
from simparity.core.scene import DynamicsScene, IKScene


def default_jobs() -> int:
    """Worker processes by default: one per CPU."""
    return max(1, os.cpu_count() or 1)


BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""Set to 1 for the worker processes unless the user set them: many small matrix products on one CPU
per worker gain nothing from BLAS threads and lose to their oversubscription."""


SECONDS_PER_UNIT = {"dynamics": 5e-4, "ik": 1.7e-3, "kinematics": 1.2e-4}
"""Seconds per case x (steps x bodies, targets, or configurations), measured on the default suite
(2026-11-23, 2 cores, repeats on); only their ratios matter: they order the scenes."""


def estimated_cost(scene, engines: list) -> float:
    """A scene's rough cost [s], to start the costliest first: its cases times the work of one."""
    cases = count_cases(scene, engines)
    if isinstance(scene, DynamicsScene):
        steps = sum(scene.n_steps(dt) for dt in scene.dts) / len(scene.dts)
        return cases * steps * len(scene.bodies) * SECONDS_PER_UNIT["dynamics"]
    if isinstance(scene, IKScene):
        return cases * (scene.n_targets + len(scene.hard_targets)) * SECONDS_PER_UNIT["ik"]
    return cases * scene.n_configurations * SECONDS_PER_UNIT["kinematics"]


OnCase = Callable[[str, str, str], None]
"""Called with (scene, engine, integrator or solver) after each case, in the calling process."""

_POLL_SECONDS = 0.2
"""How often the calling process looks for finished cases while workers run."""


def _run(scene, engines: list, repeats: int, progress=None) -> tuple[list[ResultRow], list[SeriesRecord]]:
    series: list[SeriesRecord] = []
    return run_scene(scene, engines, make_engine, repeats=repeats, series=series, progress=progress), series


def _run_named(scene, engine_names: tuple[str, ...], repeats: int, events=None) -> tuple[list[ResultRow], list[SeriesRecord]]:
    progress = None if events is None else (lambda engine, integrator: events.put((scene.name, engine, integrator)))
    return _run(scene, [make_engine(n) for n in engine_names], repeats, progress)


def run_scenes(scenes: list, engine_names: tuple[str, ...], repeats: int, jobs: int,
               on_case: OnCase | None = None) -> Iterator[tuple[object, list[ResultRow], list[SeriesRecord]]]:
    """(scene, rows, sampled series) for every scene, in order, computed on ``jobs`` processes;
    ``on_case`` hears of every case as it finishes, whichever process ran it."""
    if jobs <= 1 or len(scenes) <= 1:
        engines = [make_engine(n) for n in engine_names]
        for scene in scenes:
            progress = None if on_case is None else (lambda e, i, name=scene.name: on_case(name, e, i))
            yield (scene, *_run(scene, engines, repeats, progress))
        return
    context = multiprocessing.get_context("spawn")
    for variable in BLAS_THREAD_VARIABLES:  # each worker is one CPU: no BLAS thread pools on top
        os.environ.setdefault(variable, "1")
    with contextlib.ExitStack() as stack:
        events = None if on_case is None else stack.enter_context(context.Manager()).Queue()
        pool = concurrent.futures.ProcessPoolExecutor(max_workers=min(jobs, len(scenes)), mp_context=context)
        stack.callback(pool.shutdown, wait=False, cancel_futures=True)
        # The costliest scenes start first (they would otherwise end the run alone); rows come back in order.
        futures: dict[int, concurrent.futures.Future] = {}
        engines = [make_engine(n) for n in engine_names]
        for k in sorted(range(len(scenes)), key=lambda k: -estimated_cost(scenes[k], engines)):
            futures[k] = pool.submit(_run_named, scenes[k], engine_names, repeats, events)
        for scene, future in zip(scenes, (futures[k] for k in range(len(scenes)))):
            while events is not None and not future.done():
                _drain(events, on_case, timeout=_POLL_SECONDS)
            if events is not None:
                _drain(events, on_case, timeout=0.0)
            yield (scene, *future.result())


def _drain(events, on_case: OnCase, timeout: float) -> None:
    """Hand every event waiting in ``events`` to ``on_case``, waiting up to ``timeout`` for the first."""
    try:
        event = events.get(timeout=timeout) if timeout else events.get_nowait()
    except queue.Empty:
        return
    on_case(*event)
    while True:
        try:
            on_case(*events.get_nowait())
        except queue.Empty:
            return
