"""Where a ``simparity run`` spends its time: the quick default suite run in this process, its stack sampled.

A sampling thread looks at the running thread's stack every :data:`SAMPLE_SECONDS` and charges the sample to the
innermost frame inside simparity, by its folder (``core/dynamics``, ``references/pinocchio``, ``comparisons/measure``,
``reports``, ...): the time NumPy or an engine's compiled code spends counts for the simparity code that called it,
and no per-call hook slows the Python-heavy parts more than the rest (cProfile does). Each part's seconds are its
share of the samples times the phase's wall time. The phases are timed apart: loading the scenes, running the cases
and storing their rows (in this process: no worker to start, so the start-up of a worker, with its engine imports,
is timed on its own in a fresh interpreter), and drawing the report (figures, markdown and HTML).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import simparity

SAMPLE_SECONDS = 0.005
"""Interval of the stack samples [s]: about 200 a second, a few thousand over a quick suite."""

PACKAGE_ROOT = Path(simparity.__file__).resolve().parent
"""The installed package's folder: frames of files under it are simparity's."""

OUTSIDE = "outside simparity (interpreter, imports)"
"""The part of samples whose stack holds no simparity frame."""

WORKER_IMPORTS = ("import simparity.comparisons.execute.case_worker, simparity.comparisons.engines.registry, "
                  "mujoco, pybullet, pinocchio")
"""What a worker process imports before its first case."""


@dataclass(frozen=True)
class ProfilePart:
    """Seconds of wall time a phase spent in one part of the code."""

    phase: str
    part: str
    seconds: float


PACKAGE_FOLDERS = ("core", "references", "comparisons", "reports")
"""The package's folders (a checkout also holds tests/ and examples/ beside them: not the package)."""


def folder_of(filename: str) -> str | None:
    """The simparity folder of a source file (``core/dynamics``, ``reports``), None outside the package's folders."""
    try:
        relative = Path(filename).resolve().relative_to(PACKAGE_ROOT)
    except ValueError:
        return None
    folders = relative.parts[:-1]
    return "/".join(folders[:2]) if folders and folders[0] in PACKAGE_FOLDERS else None


class StackSampler:
    """Samples one thread's stack every :data:`SAMPLE_SECONDS` while in a ``with`` block; ``counts`` holds the
    samples per simparity folder (the innermost simparity frame's)."""

    def __init__(self, thread_id: int | None = None) -> None:
        self._thread_id = threading.get_ident() if thread_id is None else thread_id
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self.counts: Counter[str] = Counter()

    def __enter__(self) -> "StackSampler":
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()

    def _sample(self) -> None:
        while not self._stop.wait(SAMPLE_SECONDS):
            frame = sys._current_frames().get(self._thread_id)
            part: str | None = OUTSIDE
            while frame is not None:
                if frame.f_code.co_filename == __file__:  # the sampled thread starting or stopping this sampler
                    part = None
                    break
                folder = folder_of(frame.f_code.co_filename)
                if folder is not None:
                    part = folder
                    break
                frame = frame.f_back
            if part is not None:
                self.counts[part] += 1


def _phase(name: str, call: Callable[[], object]) -> list[ProfilePart]:
    """The parts of ``call``'s wall time, from its stack samples."""
    start = time.perf_counter()
    with StackSampler() as sampler:
        call()
    seconds = time.perf_counter() - start
    total = sum(sampler.counts.values())
    if not total:  # shorter than one sample
        return [ProfilePart(name, OUTSIDE, seconds)]
    return [ProfilePart(name, part, seconds * n / total) for part, n in sampler.counts.most_common()]


def worker_start_seconds() -> float:
    """Wall time [s] of a fresh interpreter importing what a worker imports before its first case."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", WORKER_IMPORTS], check=True, capture_output=True)
    return time.perf_counter() - start


def run_profile(scene_names: list[str], engine_names: tuple[str, ...], profile: str = "quick") -> list[ProfilePart]:
    """The parts of a run of ``scene_names`` (built-in scenes, suites' members) on ``engine_names`` in ``profile``, in
    this process: loading the scenes, the cases (with storing their rows), the report, and one worker's start-up."""
    from simparity.comparisons.engines.registry import EngineSet, check_engine_names
    from simparity.comparisons.pipeline.session import IN_PROCESS, Execution, Session, write_run_report
    from simparity.comparisons.scenes import library

    engines = EngineSet(check_engine_names(engine_names))
    scenes: list = []
    parts = _phase("load scenes", lambda: scenes.extend(library.load(scene_names, engines=engines)))
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "run"
        session = Session(scenes, engines, profile=profile, repeats=0, execution=Execution(IN_PROCESS, 1),
                          out_dir=out, report=False)
        parts += _phase("cases", session.run)
        parts += _phase("report", lambda: write_run_report(out, lambda line: None))
    parts.append(ProfilePart("worker start", "imports of the engines", worker_start_seconds()))
    return parts


def profile_markdown(parts: list[ProfilePart], command: str) -> list[str]:
    """BENCHMARKS.md's section on where a run spends its time."""
    total = sum(p.seconds for p in parts)
    lines = ["## Where a run spends its time", "",
             f"`{command}` run in one process (no workers: their start-up is timed apart, per worker), its stack sampled "
             f"every {SAMPLE_SECONDS * 1000:g} ms and each sample charged to the innermost simparity folder on it "
             "(NumPy's and the engines' compiled code count for the simparity code that called them). "
             f"{total:.1f} s in all.", "",
             "| phase | part | s | share |", "|---|---|---|---|"]
    for p in sorted(parts, key=lambda p: -p.seconds):
        lines.append(f"| {p.phase} | {p.part} | {p.seconds:.1f} | {p.seconds / total:.0%} |")
    return lines + [""]
