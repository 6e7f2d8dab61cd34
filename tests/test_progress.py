"""The progress bar: drawn only on a terminal, with counts and the time left; every case is counted,
whichever process ran it."""

import io

from simparity.comparisons.engines import make_engine
from simparity.comparisons.parallel import run_scenes
from simparity.comparisons.progress import ProgressBar
from simparity.comparisons.runner import count_cases
from tests.helpers import builtin


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bar_shows_counts_scene_and_time_left_on_a_terminal():
    clock = iter([0.0, 10.0, 20.0]).__next__   # start, then two cases 10 s apart
    stream = _Terminal()
    bar = ProgressBar(4, stream, clock=clock)
    bar.case_done("wind", "core", "rk4")
    bar.case_done("wind", "mujoco", "euler")
    text = stream.getvalue().split("\r")[-1]
    assert "2/4 cases · wind · mujoco euler" in text and "0m20s left" in text   # 20 s for 2, 2 to go
    bar.clear()
    assert stream.getvalue().endswith("\r\033[K")


def test_nothing_is_drawn_when_not_on_a_terminal():
    stream = io.StringIO()
    bar = ProgressBar(3, stream)
    bar.case_done("wind", "core", "rk4")
    bar.scene_done(3)
    assert stream.getvalue() == "" and not bar.active and bar.done == 3


def test_every_case_is_reported_from_worker_processes():
    """Two scenes on two processes: each case reaches the caller once, as count_cases predicts."""
    scenes = [builtin("lecture-projectile"), builtin("lecture-planar-arm")]
    names = ("core", "mujoco")
    heard = []
    results = list(run_scenes(scenes, names, 0, 2, lambda *event: heard.append(event)))
    assert [scene.name for scene, _, _ in results] == [s.name for s in scenes]
    engines = [make_engine(n) for n in names]
    assert len(heard) == sum(count_cases(s, engines) for s in scenes)
    assert {event[0] for event in heard} == {s.name for s in scenes}


def test_the_costliest_scene_starts_first_and_rows_still_come_back_in_order(monkeypatch):
    """Issue #11: the long scene is submitted first (it would otherwise end the run alone on one CPU),
    results keep the suite's order, and workers get one BLAS thread each unless the user chose."""
    from simparity.comparisons import parallel

    scenes = [builtin("lecture-planar-arm"), builtin("lecture-projectile")]
    engines = [make_engine("core")]
    assert parallel.estimated_cost(scenes[1], engines) > parallel.estimated_cost(scenes[0], engines)
    submitted = []
    real_submit = parallel.concurrent.futures.ProcessPoolExecutor.submit

    def recording_submit(self, fn, scene, *args):
        submitted.append(scene.name)
        return real_submit(self, fn, scene, *args)

    monkeypatch.setattr(parallel.concurrent.futures.ProcessPoolExecutor, "submit", recording_submit)
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    results = list(run_scenes(scenes, ("core",), 0, 2))
    assert submitted == ["lecture-projectile", "lecture-planar-arm"]
    assert [scene.name for scene, _, _ in results] == ["lecture-planar-arm", "lecture-projectile"]
    import os
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1" and os.environ["OMP_NUM_THREADS"] == "3"
