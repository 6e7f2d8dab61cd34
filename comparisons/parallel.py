"""Running scenes on several processes: one scene per task, results handed back in the scenes' order.

With ``jobs = 1`` everything runs in this process. With more, each worker process (started
fresh, ``spawn``) builds its own engines from their names; a scene's rows come back as soon as
it and every scene before it are done, so the stored run and the printed progress keep the
suite's order whatever finishes first.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os
from typing import Iterator

from simparity.comparisons.engines import make_engine
from simparity.comparisons.runner import run_scene
from simparity.core.results import ResultRow


def default_jobs() -> int:
    """Worker processes by default: one per CPU."""
    return max(1, os.cpu_count() or 1)


def _run_named(scene, engine_names: tuple[str, ...], repeats: int) -> list[ResultRow]:
    return run_scene(scene, [make_engine(n) for n in engine_names], make_engine, repeats=repeats)


def run_scenes(scenes: list, engine_names: tuple[str, ...], repeats: int, jobs: int) -> Iterator[tuple[object, list]]:
    """(scene, rows) for every scene, in order, computed on ``jobs`` processes."""
    if jobs <= 1 or len(scenes) <= 1:
        engines = [make_engine(n) for n in engine_names]
        for scene in scenes:
            yield scene, run_scene(scene, engines, make_engine, repeats=repeats)
        return
    context = multiprocessing.get_context("spawn")
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=min(jobs, len(scenes)), mp_context=context)
    try:
        futures = [pool.submit(_run_named, scene, engine_names, repeats) for scene in scenes]
        for scene, future in zip(scenes, futures):
            yield scene, future.result()
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
